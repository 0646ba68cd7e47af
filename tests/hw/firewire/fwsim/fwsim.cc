// The libraw1394 stand-in (fwsim.h says what it models). The libraw1394
// functions keep libraw1394's C names and argument types
// (hw/firewire/raw1394_api.h); everything else is internal.
#include "tests/hw/firewire/fwsim/fwsim.h"

#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "hw/firewire/raw1394_api.h"

#define FWSIM_EXPORT extern "C" __attribute__((visibility("default")))

namespace r = vmh::hw::fw::r1394;

struct raw1394_handle;

namespace {

constexpr std::int64_t kCycleNs = 125000;  // 8000 isochronous cycles a second
constexpr std::uint64_t kOmniVendorQuadlet = 0x000b9900u;
constexpr unsigned kEvents = 8192;         // a handle's waiting events

// -- the model --

struct Synth {
  double counts0[3] = {0, 0, 0};
  double speed[3] = {0, 0, 0};  // counts a second of bus time
  int pots[3] = {1024, 1024, 1024};
  bool docked = false;
  int buttons = 0;  // bit 0, 1: pressed
  bool calibrate = false;
  double dock_s = 2.0;
  double sweep_lo[3] = {300, 300, 300};  // codes the sweep goes between
  double sweep_hi[3] = {1700, 1700, 1700};
};

struct Node {
  std::uint64_t guid = 0;
  bool omni = false;
  bool has_vendor = false;
  std::uint32_t vendor_quadlet = 0;
  std::uint32_t serial_quadlet = 0;
  int phy = 0;
  // the Omni's registers
  std::uint8_t r1000 = 0x3f, r1001 = 0x3f, r1087 = 0;
  std::uint8_t r20010[4] = {0, 0, 0, 0};
  bool wrote_20010 = false;
  bool keep_on_reset = false;
  bool quirk_no_readback = false;  // 0x1001 reads 0x3f whatever was written
  bool quirk_not_ready = false;    // 0x1083 reads 0x40
  double rate_hz = 1000.0;
  // streaming
  bool streaming = false;
  std::int64_t stream_start_ns = 0;
  std::int64_t first_stream_ns = -1;  // the calibrate program's time zero
  std::int64_t stream_index = 0;  // packets since the stream started
  std::int64_t next_packet_ns = 0;
  std::uint32_t counter = 0;
  std::int32_t counts[3] = {0, 0, 0};
  Synth synth;
  bool has_ops = false;
  fwsim_device_ops ops{};
  // what happened
  std::uint64_t packets_sent = 0, packets_received = 0, packets_dropped = 0;
  std::uint64_t commands = 0;
  std::uint8_t last_command[16] = {};
  std::int64_t last_command_ns = -1;
  std::int64_t last_packet_ns = -1;
};

struct Port {
  std::string name;
  std::vector<Node> nodes;  // remote nodes, in configuration order
  int local_phy = 0;
  unsigned generation = 1;
  std::uint64_t channels = 0;  // allocated at the resource manager
  std::vector<std::int64_t> resets_ns;
  std::size_t next_reset = 0;
};

enum class EvType : std::uint8_t { kReset, kIso };
struct Event {
  EvType type = EvType::kReset;
  unsigned generation = 0;
  std::uint32_t epoch = 0;
};

struct IsoCtx {
  bool init = false, started = false, recv = false;
  int channel = 0;
  unsigned buf_packets = 0, max_packet = 0, irq = 1;
  r::IsoRecvHandler rh = nullptr;
  r::IsoXmitHandler xh = nullptr;
  std::vector<std::uint8_t> data;  // buf_packets slots of max_packet bytes
  std::vector<unsigned> len, cycle;
  unsigned head = 0, count = 0;  // receive: queued packets; transmit: filled slots
  unsigned since_irq = 0;
  std::uint32_t epoch = 0;
};

}  // namespace

struct raw1394_handle {
  int port = -1;
  unsigned generation = 0;
  void* userdata = nullptr;
  r::BusResetHandler reset_handler = nullptr;
  int notify = r::kNotifyOn;
  int efd = -1;
  std::array<Event, kEvents> events{};
  unsigned ev_head = 0, ev_count = 0;
  IsoCtx iso;
  std::vector<std::uint8_t> scratch;
  std::vector<unsigned> scratch_len, scratch_cycle;
};

namespace {

struct Bus {
  bool configured = false;
  bool wall = false;
  std::vector<Port> ports;
  bool renumber = false;
  int eagain_every = 0;
  int eagain_next = 0;
  long transactions = 0;
  long eagain_count = 0;
  long underruns = 0;
  std::string log_path;
  std::FILE* log = nullptr;
  std::vector<fwsim_transaction> log_entries;
  std::int64_t now_ns = 0;
  std::int64_t next_cycle_ns = kCycleNs;
  std::int64_t wall_t0_ns = 0;
  std::vector<raw1394_handle*> handles;
  std::vector<double> resets_after_start_s;  // on the first port
  bool streamed = false;  // an Omni has started streaming
  std::string error;
  std::thread thread;
  std::atomic<bool> stop{false};
};

std::mutex g_mu;
Bus g_bus;
std::once_flag g_env_once;

std::int64_t mono_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000LL + ts.tv_nsec;
}

void put_be32(std::uint8_t* p, std::uint32_t v) {
  p[0] = static_cast<std::uint8_t>(v >> 24);
  p[1] = static_cast<std::uint8_t>(v >> 16);
  p[2] = static_cast<std::uint8_t>(v >> 8);
  p[3] = static_cast<std::uint8_t>(v);
}
void put_le16(std::uint8_t* p, std::uint32_t v) {
  p[0] = static_cast<std::uint8_t>(v);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}
void put_le32(std::uint8_t* p, std::uint32_t v) {
  put_le16(p, v & 0xffffu);
  put_le16(p + 2, v >> 16);
}

Node* find_guid(std::uint64_t guid, int* port_out = nullptr) {
  for (std::size_t p = 0; p < g_bus.ports.size(); ++p) {
    for (Node& n : g_bus.ports[p].nodes) {
      if (n.guid == guid) {
        if (port_out != nullptr) *port_out = static_cast<int>(p);
        return &n;
      }
    }
  }
  return nullptr;
}

Node* find_phy(Port& p, int phy) {
  for (Node& n : p.nodes) {
    if (n.phy == phy) return &n;
  }
  return nullptr;
}

void push_event(raw1394_handle* h, const Event& e) {
  if (h->ev_count >= kEvents) return;  // more than a real queue would hold
  h->events[(h->ev_head + h->ev_count) % kEvents] = e;
  ++h->ev_count;
  const std::uint64_t one = 1;
  if (write(h->efd, &one, sizeof one) != static_cast<ssize_t>(sizeof one)) {
    // an eventfd takes writes up to 2^64 - 2: never here
  }
}

// -- the built-in Omni --

int synth_pot(const Synth& s, int j, double t_s) {
  if (s.calibrate && t_s >= s.dock_s) {
    const double phase = 2.0 * 3.14159265358979323846 * (t_s - s.dock_s) +
                         2.0 * j;  // each pot out of step with the others
    const double mid = 0.5 * (s.sweep_lo[j] + s.sweep_hi[j]);
    const double half = 0.5 * (s.sweep_hi[j] - s.sweep_lo[j]);
    return static_cast<int>(std::lround(mid + half * std::sin(phase)));
  }
  return s.pots[j];
}

unsigned synth_packet(Node& n, std::int64_t t_ns, std::uint8_t* out) {
  const double t_s = 1e-9 * static_cast<double>(t_ns);
  // the calibrate program runs from the first stream
  const double prog_s = 1e-9 * static_cast<double>(t_ns - std::max<std::int64_t>(0, n.first_stream_ns));
  std::memset(out, 0, 44);
  put_le32(out + 0, 0x001e0000u);  // as phantom-drivers saw it: 00 00 1e 00
  for (int i = 0; i < 3; ++i) {
    const double c = n.synth.counts0[i] + n.synth.speed[i] * t_s;
    n.counts[i] = static_cast<std::int32_t>(std::llround(c));
    put_le16(out + 4 + 2 * i, static_cast<std::uint32_t>(n.counts[i]) & 0xffffu);
    const int code = std::clamp(synth_pot(n.synth, i, prog_s), 0, 2047);
    put_le16(out + 10 + 2 * i, static_cast<std::uint32_t>(code) << 5);
    put_le16(out + 22 + 2 * i, static_cast<std::uint32_t>(2047 - code) << 5);
  }
  const bool docked = n.synth.calibrate ? prog_s < n.synth.dock_s : n.synth.docked;
  std::uint8_t status = 0;
  if ((n.synth.buttons & 1) == 0) status |= 0x01;  // released
  if ((n.synth.buttons & 2) == 0) status |= 0x02;
  if (!docked) status |= 0x04;
  out[18] = static_cast<std::uint8_t>(n.counter & 0xffu);
  out[19] = status;
  put_le32(out + 32, n.counter);
  put_le32(out + 40, static_cast<std::uint32_t>((t_ns / 1000) & 0xffffffffLL));
  return 44;
}

// -- the bus --

void set_streaming(Node& n, bool on) {
  if (on == n.streaming) return;
  n.streaming = on;
  if (on && !g_bus.streamed) {
    // resets timed from the first stream
    g_bus.streamed = true;
    if (!g_bus.ports.empty()) {
      Port& p0 = g_bus.ports[0];
      for (const double d : g_bus.resets_after_start_s) {
        p0.resets_ns.push_back(g_bus.now_ns + static_cast<std::int64_t>(std::llround(d * 1e9)));
      }
      std::sort(p0.resets_ns.begin() + static_cast<std::ptrdiff_t>(p0.next_reset),
                p0.resets_ns.end());
    }
  }
  if (on) {
    if (n.first_stream_ns < 0) n.first_stream_ns = g_bus.now_ns;
    n.stream_start_ns = g_bus.now_ns;
    n.stream_index = 0;
    n.next_packet_ns =
        n.stream_start_ns + static_cast<std::int64_t>(std::llround(1e9 / n.rate_hz));
  }
}

void update_streaming(Node& n) {
  set_streaming(n, n.omni && (n.r1087 & 0x08) != 0 && n.r1001 < 64);
}

void send_packet(Port& port, Node& n) {
  const std::int64_t t = n.next_packet_ns;
  std::uint8_t bytes[256];
  ++n.counter;
  unsigned len = n.has_ops && n.ops.state != nullptr
                     ? n.ops.state(n.ops.user, t, bytes, sizeof bytes)
                     : synth_packet(n, t, bytes);
  ++n.stream_index;
  n.next_packet_ns = n.stream_start_ns +
                     static_cast<std::int64_t>(std::llround(
                         static_cast<double>(n.stream_index + 1) * 1e9 / n.rate_hz));
  if (len == 0) {
    --n.counter;
    return;
  }
  len = std::min<unsigned>(len, sizeof bytes);
  ++n.packets_sent;
  n.last_packet_ns = t;
  const unsigned cycle = static_cast<unsigned>((t / kCycleNs) % 8000);
  const int port_index = static_cast<int>(&port - g_bus.ports.data());
  for (raw1394_handle* h : g_bus.handles) {
    IsoCtx& c = h->iso;
    if (h->port != port_index || !c.init || !c.started || !c.recv ||
        c.channel != n.r1001) {
      continue;
    }
    if (c.count >= c.buf_packets) {
      ++n.packets_dropped;
      continue;
    }
    const unsigned slot = (c.head + c.count) % c.buf_packets;
    const unsigned l = std::min(len, c.max_packet);
    std::memcpy(c.data.data() + static_cast<std::size_t>(slot) * c.max_packet, bytes, l);
    c.len[slot] = l;
    c.cycle[slot] = cycle;
    ++c.count;
    ++n.packets_received;
    if (++c.since_irq >= c.irq) {
      c.since_irq = 0;
      push_event(h, Event{EvType::kIso, 0, c.epoch});
    }
  }
}

void tx_cycle(std::int64_t t) {
  for (raw1394_handle* h : g_bus.handles) {
    IsoCtx& c = h->iso;
    if (h->port < 0 || !c.init || !c.started || c.recv) continue;
    if (c.count == 0) {
      ++g_bus.underruns;
      continue;
    }
    const std::uint8_t* d = c.data.data() + static_cast<std::size_t>(c.head) * c.max_packet;
    const unsigned l = c.len[c.head];
    for (Node& n : g_bus.ports[static_cast<std::size_t>(h->port)].nodes) {
      if (!n.streaming || n.r1000 != c.channel) continue;
      ++n.commands;
      std::memcpy(n.last_command, d, std::min<unsigned>(l, 16));
      n.last_command_ns = t;
      if (n.has_ops && n.ops.command != nullptr) n.ops.command(n.ops.user, t, d, l);
    }
    c.head = (c.head + 1) % c.buf_packets;
    --c.count;
    if (++c.since_irq >= c.irq) {
      c.since_irq = 0;
      push_event(h, Event{EvType::kIso, 0, c.epoch});
    }
  }
}

void do_reset(std::size_t port_index) {
  Port& p = g_bus.ports[port_index];
  ++p.generation;
  p.channels = 0;
  if (g_bus.renumber && p.nodes.size() > 1) {
    // the remote nodes' numbers in the reverse order
    std::vector<int> phys;
    for (const Node& n : p.nodes) phys.push_back(n.phy);
    std::reverse(phys.begin(), phys.end());
    for (std::size_t i = 0; i < p.nodes.size(); ++i) p.nodes[i].phy = phys[i];
  }
  for (Node& n : p.nodes) {
    if (!n.omni || n.keep_on_reset) continue;
    n.r1000 = n.r1001 = 0x3f;
    n.r1087 = 0;
    update_streaming(n);
  }
  for (raw1394_handle* h : g_bus.handles) {
    if (h->port == static_cast<int>(port_index)) {
      push_event(h, Event{EvType::kReset, p.generation, 0});
    }
  }
}

// runs the bus up to t_ns: resets, transmit cycles, then packets, in time
// order (a cycle at the same time as a packet first: the device takes the
// host's command, then sends its state)
void run_until(std::int64_t t_ns) {
  for (;;) {
    std::int64_t t_reset = INT64_MAX, t_rx = INT64_MAX;
    std::size_t reset_port = 0;
    Port* rx_port = nullptr;
    Node* rx_node = nullptr;
    for (std::size_t pi = 0; pi < g_bus.ports.size(); ++pi) {
      Port& p = g_bus.ports[pi];
      if (p.next_reset < p.resets_ns.size() && p.resets_ns[p.next_reset] < t_reset) {
        t_reset = p.resets_ns[p.next_reset];
        reset_port = pi;
      }
      for (Node& n : p.nodes) {
        if (n.streaming && n.next_packet_ns < t_rx) {
          t_rx = n.next_packet_ns;
          rx_port = &p;
          rx_node = &n;
        }
      }
    }
    const std::int64_t t_cycle = g_bus.next_cycle_ns;
    const std::int64_t t = std::min({t_reset, t_rx, t_cycle});
    if (t > t_ns) break;
    g_bus.now_ns = std::max(g_bus.now_ns, t);
    if (t == t_reset) {
      ++g_bus.ports[reset_port].next_reset;
      do_reset(reset_port);
    } else if (t == t_cycle) {
      tx_cycle(t);
      g_bus.next_cycle_ns += kCycleNs;
    } else {
      send_packet(*rx_port, *rx_node);
    }
  }
  g_bus.now_ns = std::max(g_bus.now_ns, t_ns);
}

void wall_thread() {
  while (!g_bus.stop.load()) {
    std::int64_t sleep_until;
    {
      const std::lock_guard<std::mutex> lock(g_mu);
      run_until(mono_ns() - g_bus.wall_t0_ns);
      std::int64_t next = g_bus.now_ns + 1000000;  // a millisecond at most
      for (const Port& p : g_bus.ports) {
        if (p.next_reset < p.resets_ns.size()) next = std::min(next, p.resets_ns[p.next_reset]);
        for (const Node& n : p.nodes) {
          if (n.streaming) next = std::min(next, n.next_packet_ns);
        }
      }
      sleep_until = next + g_bus.wall_t0_ns;
    }
    timespec ts{};
    ts.tv_sec = static_cast<time_t>(sleep_until / 1000000000LL);
    ts.tv_nsec = static_cast<long>(sleep_until % 1000000000LL);
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
    }
  }
}

void stop_wall_thread() {
  if (g_bus.thread.joinable()) {
    g_bus.stop.store(true);
    g_bus.thread.join();
  }
  g_bus.stop.store(false);
}

struct AtExit {
  ~AtExit() {
    stop_wall_thread();
    if (g_bus.log != nullptr) std::fclose(g_bus.log);
    g_bus.log = nullptr;
  }
} g_at_exit;

// -- configuration --

bool parse_hex(const std::string& s, std::uint64_t* out) {
  std::string t = s;
  if (t.size() > 2 && t[0] == '0' && (t[1] == 'x' || t[1] == 'X')) t = t.substr(2);
  if (t.empty() || t.size() > 16) return false;
  char* end = nullptr;
  errno = 0;
  const unsigned long long v = std::strtoull(t.c_str(), &end, 16);
  if (errno != 0 || end == nullptr || *end != '\0') return false;
  *out = v;
  return true;
}

bool parse_number(const std::string& s, double* out) {
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(s.c_str(), &end);
  if (errno != 0 || end == nullptr || *end != '\0' || s.empty() || !std::isfinite(v)) {
    return false;
  }
  *out = v;
  return true;
}

bool parse_triple(const std::string& s, double out[3]) {
  std::size_t a = s.find('/');
  std::size_t b = a == std::string::npos ? a : s.find('/', a + 1);
  if (b == std::string::npos) return false;
  return parse_number(s.substr(0, a), &out[0]) &&
         parse_number(s.substr(a + 1, b - a - 1), &out[1]) &&
         parse_number(s.substr(b + 1), &out[2]);
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::size_t from = 0;
  for (;;) {
    const std::size_t at = s.find(sep, from);
    std::string item = s.substr(from, at - from);
    // trim blanks
    const std::size_t a = item.find_first_not_of(" \t\n");
    const std::size_t b = item.find_last_not_of(" \t\n");
    item = a == std::string::npos ? std::string() : item.substr(a, b - a + 1);
    if (!item.empty()) out.push_back(item);
    if (at == std::string::npos) break;
    from = at + 1;
  }
  return out;
}

// configures g_bus from text (g_mu held, no thread running); false with
// g_bus.error set
bool configure_locked(const std::string& text) {
  Bus fresh;
  const auto fail = [&](const std::string& what) {
    g_bus.error = "fwsim: " + what;
    return false;
  };
  std::vector<std::string> reset_items;
  for (const std::string& item : split(text, ';')) {
    const std::size_t eq = item.find('=');
    const std::string key = item.substr(0, eq);
    const std::string value = eq == std::string::npos ? "" : item.substr(eq + 1);
    if (key == "clock") {
      if (value != "virtual" && value != "wall") return fail("clock must be virtual or wall: " + item);
      fresh.wall = value == "wall";
    } else if (key == "port") {
      Port p;
      p.name = value.empty() ? "fwsim" + std::to_string(fresh.ports.size()) : value;
      fresh.ports.push_back(p);
    } else if (key == "omni" || key == "node") {
      if (fresh.ports.empty()) {
        Port p;
        p.name = "fwsim0";
        fresh.ports.push_back(p);
      }
      const std::vector<std::string> parts = split(value, ',');
      Node n;
      n.omni = key == "omni";
      if (parts.empty() || !parse_hex(parts[0], &n.guid)) return fail("bad GUID in " + item);
      if (n.omni) {
        n.has_vendor = true;
        n.vendor_quadlet = kOmniVendorQuadlet;
        // the drivers' packing of "11122334444" style serials: a made-up
        // one per GUID, bits 31 and 0 set
        n.serial_quadlet = 0x80000001u | ((static_cast<std::uint32_t>(n.guid) & 0x1fffu) << 1) |
                           (static_cast<std::uint32_t>((n.guid >> 13) & 0x7u) << 23);
      }
      for (std::size_t i = 1; i < parts.size(); ++i) {
        const std::size_t e = parts[i].find('=');
        const std::string k = parts[i].substr(0, e);
        const std::string v = e == std::string::npos ? "" : parts[i].substr(e + 1);
        std::uint64_t h = 0;
        double d = 0;
        double t3[3];
        if (k == "vendor" && parse_hex(v, &h)) {
          n.has_vendor = true;
          n.vendor_quadlet = static_cast<std::uint32_t>(h);
        } else if (k == "serial" && parse_hex(v, &h)) {
          n.serial_quadlet = static_cast<std::uint32_t>(h);
        } else if (k == "rate" && parse_number(v, &d) && d > 0 && d <= 8000) {
          n.rate_hz = d;
        } else if (k == "counts" && parse_triple(v, t3)) {
          for (int j = 0; j < 3; ++j) n.synth.counts0[j] = t3[j];
        } else if (k == "speed" && parse_triple(v, t3)) {
          for (int j = 0; j < 3; ++j) n.synth.speed[j] = t3[j];
        } else if (k == "pots" && parse_triple(v, t3)) {
          for (int j = 0; j < 3; ++j) n.synth.pots[j] = static_cast<int>(t3[j]);
        } else if (k == "docked" && (v == "0" || v == "1")) {
          n.synth.docked = v == "1";
        } else if (k == "buttons" && parse_number(v, &d)) {
          n.synth.buttons = static_cast<int>(d);
        } else if (k == "program" && v == "calibrate") {
          n.synth.calibrate = true;
        } else if (k == "dock_s" && parse_number(v, &d) && d >= 0) {
          n.synth.dock_s = d;
        } else if (k == "sweep_lo" && parse_triple(v, t3)) {
          for (int j = 0; j < 3; ++j) n.synth.sweep_lo[j] = t3[j];
        } else if (k == "sweep_hi" && parse_triple(v, t3)) {
          for (int j = 0; j < 3; ++j) n.synth.sweep_hi[j] = t3[j];
        } else if (k == "keep_on_reset" && (v == "0" || v == "1")) {
          n.keep_on_reset = v == "1";
        } else if (k == "quirk" && v == "no-readback") {
          n.quirk_no_readback = true;
        } else if (k == "quirk" && v == "not-ready") {
          n.quirk_not_ready = true;
        } else {
          return fail("bad " + key + " setting '" + parts[i] + "' in " + item);
        }
      }
      Port& p = fresh.ports.back();
      n.phy = static_cast<int>(p.nodes.size());
      p.nodes.push_back(n);
      p.local_phy = static_cast<int>(p.nodes.size());
    } else if (key == "eagain") {
      double d = 0;
      if (!parse_number(value, &d) || d < 0) return fail("bad " + item);
      fresh.eagain_every = static_cast<int>(d);
    } else if (key == "eagain_next") {
      double d = 0;
      if (!parse_number(value, &d) || d < 0) return fail("bad " + item);
      fresh.eagain_next = static_cast<int>(d);
    } else if (key == "reset_at") {
      reset_items = split(value, ',');
    } else if (key == "reset_after_start") {
      for (const std::string& r : split(value, ',')) {
        double d = 0;
        if (!parse_number(r, &d) || d < 0) return fail("bad reset_after_start time '" + r + "'");
        fresh.resets_after_start_s.push_back(d);
      }
    } else if (key == "renumber") {
      fresh.renumber = value == "1";
    } else if (key == "log") {
      fresh.log_path = value;
    } else {
      return fail("unknown item '" + item + "'");
    }
  }
  for (const std::string& r : reset_items) {
    double d = 0;
    if (fresh.ports.empty() || !parse_number(r, &d) || d < 0) {
      return fail("bad reset_at time '" + r + "' (or no port)");
    }
    fresh.ports[0].resets_ns.push_back(static_cast<std::int64_t>(std::llround(d * 1e9)));
  }
  if (!fresh.ports.empty()) std::sort(fresh.ports[0].resets_ns.begin(), fresh.ports[0].resets_ns.end());
  if (g_bus.log != nullptr) std::fclose(g_bus.log);
  g_bus.log = nullptr;
  g_bus.configured = true;
  g_bus.wall = fresh.wall;
  g_bus.ports = fresh.ports;
  g_bus.renumber = fresh.renumber;
  g_bus.resets_after_start_s = fresh.resets_after_start_s;
  g_bus.streamed = false;
  g_bus.eagain_every = fresh.eagain_every;
  g_bus.eagain_next = fresh.eagain_next;
  g_bus.transactions = g_bus.eagain_count = g_bus.underruns = 0;
  g_bus.log_path = fresh.log_path;
  g_bus.log_entries.clear();
  g_bus.now_ns = 0;
  g_bus.next_cycle_ns = kCycleNs;
  g_bus.wall_t0_ns = mono_ns();
  if (!g_bus.log_path.empty()) g_bus.log = std::fopen(g_bus.log_path.c_str(), "a");
  return true;
}

void ensure_configured() {
  std::call_once(g_env_once, [] {
    const std::lock_guard<std::mutex> lock(g_mu);
    if (g_bus.configured) return;
    const char* env = std::getenv("VMH_FWSIM");
    if (!configure_locked(env != nullptr ? env : "")) {
      std::fprintf(stderr, "%s (VMH_FWSIM)\n", g_bus.error.c_str());
      configure_locked("");
    }
    if (g_bus.wall) g_bus.thread = std::thread(wall_thread);
  });
}

// virtual clock: nothing moves unless a test advances it; wall clock: the
// bus thread keeps it up to date, and a caller brings it to now
void catch_up() {
  if (g_bus.wall) run_until(mono_ns() - g_bus.wall_t0_ns);
}

// -- transactions --

void log_transaction(const raw1394_handle* h, int phy, std::uint64_t guid, char op,
                     std::uint64_t addr, std::size_t len, const std::uint8_t* data,
                     int error) {
  fwsim_transaction t{};
  t.t_ns = g_bus.now_ns;
  t.port = h->port;
  t.phy = phy;
  t.guid = guid;
  t.op = op;
  t.addr = addr;
  t.len = static_cast<std::uint32_t>(len);
  if (data != nullptr) std::memcpy(t.data, data, std::min<std::size_t>(len, 4));
  t.error = error;
  if (g_bus.log_entries.size() < 100000) g_bus.log_entries.push_back(t);
  if (g_bus.log != nullptr) {
    std::fprintf(g_bus.log,
                 "%lld %s port=%d node=%d guid=%016llx addr=0x%llx len=%u data=",
                 static_cast<long long>(t.t_ns), op == 'r' ? "read" : "write", t.port,
                 t.phy, static_cast<unsigned long long>(guid),
                 static_cast<unsigned long long>(addr), t.len);
    for (std::uint32_t i = 0; i < std::min<std::uint32_t>(t.len, 4); ++i) {
      std::fprintf(g_bus.log, "%02x", t.data[i]);
    }
    std::fprintf(g_bus.log, " %s\n", error == 0 ? "ok" : std::strerror(error));
    std::fflush(g_bus.log);
  }
}

// the node a transaction goes to, or an errno
int route(raw1394_handle* h, r::NodeId id, Port** port, Node** node) {
  if (h == nullptr || h->port < 0 ||
      h->port >= static_cast<int>(g_bus.ports.size())) {
    return EINVAL;
  }
  *port = &g_bus.ports[static_cast<std::size_t>(h->port)];
  ++g_bus.transactions;
  if (g_bus.eagain_next > 0) {
    --g_bus.eagain_next;
    ++g_bus.eagain_count;
    return EAGAIN;  // a busy acknowledge
  }
  if (g_bus.eagain_every > 0 && g_bus.transactions % g_bus.eagain_every == 0) {
    ++g_bus.eagain_count;
    return EAGAIN;
  }
  if (h->generation != (*port)->generation) return EAGAIN;  // a stale generation
  if ((id & 0xffc0) != r::kLocalBus) return EINVAL;
  *node = find_phy(**port, id & 0x3f);
  if (*node == nullptr) return EAGAIN;  // no acknowledge: a time-out
  return 0;
}

bool config_rom_quadlet(const Node& n, std::uint64_t addr, std::uint32_t* q) {
  if (addr < r::kConfigRomBase || addr >= r::kConfigRomBase + 20 || (addr & 3) != 0) {
    return false;
  }
  switch ((addr - r::kConfigRomBase) / 4) {
    case 0: *q = 0x04040000u; return true;  // info length 4, CRC length 4
    case 1: *q = 0x31333934u; return true;  // "1394"
    case 2: *q = 0x00ff2000u; return true;  // capabilities
    case 3: *q = static_cast<std::uint32_t>(n.guid >> 32); return true;
    default: *q = static_cast<std::uint32_t>(n.guid); return true;
  }
}

int node_read(Node& n, std::uint64_t addr, std::size_t len, std::uint8_t* out) {
  std::uint32_t q = 0;
  if (len % 4 == 0 && len > 0 && config_rom_quadlet(n, addr, &q)) {
    for (std::size_t i = 0; i < len; i += 4) {
      if (!config_rom_quadlet(n, addr + i, &q)) return EINVAL;
      put_be32(out + i, q);
    }
    return 0;
  }
  if (addr == 0x1006000c && n.has_vendor) {
    if (len != 4) return EPERM;
    put_be32(out, n.vendor_quadlet);
    return 0;
  }
  if (!n.omni) return EINVAL;
  if (addr == 0x10060010) {
    if (len != 4) return EPERM;
    put_be32(out, n.serial_quadlet);
    return 0;
  }
  std::uint8_t v = 0;
  switch (addr) {
    case 0x1000: v = n.r1000; break;
    case 0x1001: v = n.quirk_no_readback ? 0x3f : n.r1001; break;
    case 0x1082: v = 0x00; break;
    case 0x1083: v = n.quirk_not_ready ? 0x40 : 0xc0; break;
    case 0x1087: v = n.r1087; break;
    default: return EINVAL;
  }
  if (len != 1) return EPERM;
  out[0] = v;
  return 0;
}

int node_write(Node& n, std::uint64_t addr, std::size_t len, const std::uint8_t* in) {
  if (!n.omni) return EINVAL;
  if (addr == 0x20010) {
    if (len != 4) return EPERM;
    std::memcpy(n.r20010, in, 4);
    n.wrote_20010 = true;
    return 0;
  }
  if (addr != 0x1000 && addr != 0x1001 && addr != 0x1087) return EINVAL;
  if (len != 1) return EPERM;
  if (addr == 0x1000) n.r1000 = in[0];
  if (addr == 0x1001) n.r1001 = in[0];
  if (addr == 0x1087) n.r1087 = in[0];
  update_streaming(n);
  return 0;
}

raw1394_handle* make_handle(int port) {
  auto* h = new raw1394_handle;
  h->port = port;
  h->efd = eventfd(0, EFD_SEMAPHORE | EFD_NONBLOCK | EFD_CLOEXEC);
  h->reset_handler = [](raw1394_handle* hh, unsigned g) {
    hh->generation = g;  // raw1394_update_generation
    return 0;
  };
  if (port >= 0) h->generation = g_bus.ports[static_cast<std::size_t>(port)].generation;
  g_bus.handles.push_back(h);
  return h;
}

int iso_init(raw1394_handle* h, bool recv, r::IsoRecvHandler rh, r::IsoXmitHandler xh,
             unsigned buf_packets, unsigned max_packet, unsigned char channel, int irq) {
  if (h == nullptr || h->port < 0 || buf_packets == 0 || max_packet == 0 ||
      channel > 63) {
    errno = EINVAL;
    return -1;
  }
  if (h->iso.init) {
    errno = EBUSY;
    return -1;
  }
  IsoCtx& c = h->iso;
  c.init = true;
  c.started = false;
  c.recv = recv;
  c.rh = rh;
  c.xh = xh;
  c.channel = channel;
  c.buf_packets = buf_packets;
  c.max_packet = max_packet;
  c.irq = irq < 0 ? std::max(1u, buf_packets / 4) : std::max(1, irq);
  c.data.assign(static_cast<std::size_t>(buf_packets) * max_packet, 0);
  c.len.assign(buf_packets, 0);
  c.cycle.assign(buf_packets, 0);
  c.head = c.count = c.since_irq = 0;
  ++c.epoch;
  h->scratch.assign(static_cast<std::size_t>(buf_packets) * max_packet, 0);
  h->scratch_len.assign(buf_packets, 0);
  h->scratch_cycle.assign(buf_packets, 0);
  return 0;
}

// fills every free transmit slot with the handler (g_mu NOT held: the
// handler is the caller's code)
void fill_xmit(raw1394_handle* h) {
  unsigned free_slots = 0;
  std::uint32_t epoch = 0;
  r::IsoXmitHandler xh = nullptr;
  unsigned max_packet = 0;
  {
    const std::lock_guard<std::mutex> lock(g_mu);
    const IsoCtx& c = h->iso;
    if (!c.init || c.recv) return;
    free_slots = c.buf_packets - c.count;
    epoch = c.epoch;
    xh = c.xh;
    max_packet = c.max_packet;
  }
  for (unsigned i = 0; i < free_slots; ++i) {
    unsigned len = 0;
    unsigned char tag = 0, sy = 0;
    std::uint8_t* d = h->scratch.data() + static_cast<std::size_t>(i) * max_packet;
    if (xh != nullptr) xh(h, d, &len, &tag, &sy, -1, 0);
    h->scratch_len[i] = std::min(len, max_packet);
  }
  const std::lock_guard<std::mutex> lock(g_mu);
  IsoCtx& c = h->iso;
  if (!c.init || c.epoch != epoch) return;
  for (unsigned i = 0; i < free_slots && c.count < c.buf_packets; ++i) {
    const unsigned slot = (c.head + c.count) % c.buf_packets;
    std::memcpy(c.data.data() + static_cast<std::size_t>(slot) * c.max_packet,
                h->scratch.data() + static_cast<std::size_t>(i) * max_packet,
                h->scratch_len[i]);
    c.len[slot] = h->scratch_len[i];
    ++c.count;
  }
}

}  // namespace

// ---------------------------------------------------------------- libraw1394

FWSIM_EXPORT raw1394_handle* raw1394_new_handle() {
  ensure_configured();
  const std::lock_guard<std::mutex> lock(g_mu);
  return make_handle(-1);
}

FWSIM_EXPORT raw1394_handle* raw1394_new_handle_on_port(int port) {
  ensure_configured();
  const std::lock_guard<std::mutex> lock(g_mu);
  if (port < 0 || port >= static_cast<int>(g_bus.ports.size())) {
    errno = ENOENT;
    return nullptr;
  }
  return make_handle(port);
}

FWSIM_EXPORT void raw1394_destroy_handle(raw1394_handle* h) {
  if (h == nullptr) return;
  {
    const std::lock_guard<std::mutex> lock(g_mu);
    g_bus.handles.erase(std::remove(g_bus.handles.begin(), g_bus.handles.end(), h),
                        g_bus.handles.end());
  }
  if (h->efd >= 0) close(h->efd);
  delete h;
}

FWSIM_EXPORT int raw1394_get_port_info(raw1394_handle* h, r::PortInfo* info, int max) {
  (void)h;
  const std::lock_guard<std::mutex> lock(g_mu);
  const int n = static_cast<int>(g_bus.ports.size());
  for (int i = 0; i < n && i < max && info != nullptr; ++i) {
    const Port& p = g_bus.ports[static_cast<std::size_t>(i)];
    info[i].nodes = static_cast<int>(p.nodes.size()) + 1;
    std::snprintf(info[i].name, sizeof info[i].name, "%s", p.name.c_str());
  }
  return n;
}

FWSIM_EXPORT int raw1394_get_nodecount(raw1394_handle* h) {
  const std::lock_guard<std::mutex> lock(g_mu);
  if (h == nullptr || h->port < 0) return 0;
  return static_cast<int>(g_bus.ports[static_cast<std::size_t>(h->port)].nodes.size()) + 1;
}

FWSIM_EXPORT r::NodeId raw1394_get_local_id(raw1394_handle* h) {
  const std::lock_guard<std::mutex> lock(g_mu);
  if (h == nullptr || h->port < 0) return r::kLocalBus | 0x3f;
  return static_cast<r::NodeId>(
      r::kLocalBus | g_bus.ports[static_cast<std::size_t>(h->port)].local_phy);
}

FWSIM_EXPORT unsigned int raw1394_get_generation(raw1394_handle* h) {
  const std::lock_guard<std::mutex> lock(g_mu);
  return h != nullptr ? h->generation : ~0u;
}

FWSIM_EXPORT void raw1394_update_generation(raw1394_handle* h, unsigned int g) {
  const std::lock_guard<std::mutex> lock(g_mu);
  if (h != nullptr) h->generation = g;
}

FWSIM_EXPORT void raw1394_set_userdata(raw1394_handle* h, void* data) {
  if (h != nullptr) h->userdata = data;
}

FWSIM_EXPORT void* raw1394_get_userdata(raw1394_handle* h) {
  return h != nullptr ? h->userdata : nullptr;
}

FWSIM_EXPORT int raw1394_get_fd(raw1394_handle* h) { return h != nullptr ? h->efd : -1; }

FWSIM_EXPORT r::BusResetHandler raw1394_set_bus_reset_handler(raw1394_handle* h,
                                                              r::BusResetHandler fn) {
  const std::lock_guard<std::mutex> lock(g_mu);
  r::BusResetHandler old = h->reset_handler;
  h->reset_handler = fn;
  return old;
}

FWSIM_EXPORT int raw1394_busreset_notify(raw1394_handle* h, int on) {
  const std::lock_guard<std::mutex> lock(g_mu);
  h->notify = on;
  return 0;
}

FWSIM_EXPORT int raw1394_loop_iterate(raw1394_handle* h) {
  if (h == nullptr) {
    errno = EINVAL;
    return -1;
  }
  std::uint64_t v = 0;
  while (read(h->efd, &v, sizeof v) != static_cast<ssize_t>(sizeof v)) {
    if (errno != EAGAIN) return -1;
    bool wall = false;
    {
      const std::lock_guard<std::mutex> lock(g_mu);
      wall = g_bus.wall;
    }
    if (!wall) {
      errno = EAGAIN;  // a real one would block: nothing will come
      return -1;
    }
    pollfd fd{h->efd, POLLIN, 0};
    if (poll(&fd, 1, 1000) <= 0) {
      errno = EAGAIN;
      return -1;
    }
  }
  Event ev;
  r::BusResetHandler reset_handler = nullptr;
  unsigned n = 0;
  r::IsoRecvHandler rh = nullptr;
  int channel = 0;
  {
    const std::lock_guard<std::mutex> lock(g_mu);
    if (h->ev_count == 0) return 0;
    ev = h->events[h->ev_head];
    h->ev_head = (h->ev_head + 1) % kEvents;
    --h->ev_count;
    if (ev.type == EvType::kReset) {
      if (h->notify == r::kNotifyOn) reset_handler = h->reset_handler;
    } else {
      IsoCtx& c = h->iso;
      if (!c.init || !c.started || ev.epoch != c.epoch) return 0;
      if (c.recv) {
        // one interrupt: irq_interval packets
        n = std::min(c.irq, c.count);
        for (unsigned i = 0; i < n; ++i) {
          const unsigned slot = (c.head + i) % c.buf_packets;
          std::memcpy(h->scratch.data() + static_cast<std::size_t>(i) * c.max_packet,
                      c.data.data() + static_cast<std::size_t>(slot) * c.max_packet,
                      c.len[slot]);
          h->scratch_len[i] = c.len[slot];
          h->scratch_cycle[i] = c.cycle[slot];
        }
        c.head = (c.head + n) % c.buf_packets;
        c.count -= n;
        rh = c.rh;
        channel = c.channel;
      }
    }
  }
  if (ev.type == EvType::kReset) {
    return reset_handler != nullptr ? reset_handler(h, ev.generation) : 0;
  }
  if (rh != nullptr) {
    const unsigned max_packet = h->iso.max_packet;
    for (unsigned i = 0; i < n; ++i) {
      rh(h, h->scratch.data() + static_cast<std::size_t>(i) * max_packet,
         h->scratch_len[i], static_cast<unsigned char>(channel), 0, 0,
         h->scratch_cycle[i], 0);
    }
    return 0;
  }
  fill_xmit(h);  // a transmit interrupt
  return 0;
}

FWSIM_EXPORT int raw1394_read(raw1394_handle* h, r::NodeId id, r::NodeAddr addr,
                              std::size_t len, r::Quadlet* buf) {
  const std::lock_guard<std::mutex> lock(g_mu);
  catch_up();
  Port* p = nullptr;
  Node* n = nullptr;
  int e = route(h, id, &p, &n);
  std::uint8_t out[64] = {};
  if (e == 0 && (len == 0 || len > sizeof out)) e = EPERM;
  if (e == 0) e = node_read(*n, addr, len, out);
  if (e == 0) std::memcpy(buf, out, len);
  if (h != nullptr && h->port >= 0) {
    log_transaction(h, id & 0x3f, n != nullptr ? n->guid : 0, 'r', addr, len,
                    e == 0 ? out : nullptr, e);
  }
  if (e != 0) {
    errno = e;
    return -1;
  }
  return 0;
}

FWSIM_EXPORT int raw1394_write(raw1394_handle* h, r::NodeId id, r::NodeAddr addr,
                               std::size_t len, r::Quadlet* data) {
  const std::lock_guard<std::mutex> lock(g_mu);
  catch_up();
  Port* p = nullptr;
  Node* n = nullptr;
  int e = route(h, id, &p, &n);
  std::uint8_t in[64] = {};
  if (len > 0 && len <= sizeof in) std::memcpy(in, data, len);
  if (e == 0 && (len == 0 || len > sizeof in)) e = EPERM;
  if (e == 0) e = node_write(*n, addr, len, in);
  if (h != nullptr && h->port >= 0) {
    log_transaction(h, id & 0x3f, n != nullptr ? n->guid : 0, 'w', addr, len, in, e);
  }
  if (e != 0) {
    errno = e;
    return -1;
  }
  return 0;
}

FWSIM_EXPORT int raw1394_channel_modify(raw1394_handle* h, unsigned int channel,
                                        r::ModifyMode mode) {
  const std::lock_guard<std::mutex> lock(g_mu);
  if (h == nullptr || h->port < 0 || channel > 63) {
    errno = EINVAL;
    return -1;
  }
  Port& p = g_bus.ports[static_cast<std::size_t>(h->port)];
  const std::uint64_t bit = 1ull << channel;
  if (mode == r::kModifyAlloc) {
    if ((p.channels & bit) != 0) {
      errno = EAGAIN;  // taken: the resource manager's compare-swap fails
      return -1;
    }
    p.channels |= bit;
    return 0;
  }
  if ((p.channels & bit) == 0) {
    errno = EINVAL;
    return -1;
  }
  p.channels &= ~bit;
  return 0;
}

FWSIM_EXPORT int raw1394_iso_recv_init(raw1394_handle* h, r::IsoRecvHandler handler,
                                       unsigned int buf_packets,
                                       unsigned int max_packet_size,
                                       unsigned char channel, r::DmaRecvMode,
                                       int irq_interval) {
  const std::lock_guard<std::mutex> lock(g_mu);
  return iso_init(h, true, handler, nullptr, buf_packets, max_packet_size, channel,
                  irq_interval);
}

FWSIM_EXPORT int raw1394_iso_recv_start(raw1394_handle* h, int, int, int) {
  const std::lock_guard<std::mutex> lock(g_mu);
  if (h == nullptr || !h->iso.init || !h->iso.recv) {
    errno = EINVAL;
    return -1;
  }
  h->iso.started = true;
  return 0;
}

FWSIM_EXPORT int raw1394_iso_xmit_init(raw1394_handle* h, r::IsoXmitHandler handler,
                                       unsigned int buf_packets,
                                       unsigned int max_packet_size,
                                       unsigned char channel, r::Speed,
                                       int irq_interval) {
  const std::lock_guard<std::mutex> lock(g_mu);
  return iso_init(h, false, nullptr, handler, buf_packets, max_packet_size, channel,
                  irq_interval);
}

FWSIM_EXPORT int raw1394_iso_xmit_start(raw1394_handle* h, int, int) {
  {
    const std::lock_guard<std::mutex> lock(g_mu);
    if (h == nullptr || !h->iso.init || h->iso.recv) {
      errno = EINVAL;
      return -1;
    }
  }
  fill_xmit(h);  // the whole buffer before the first cycle, as libraw1394 does
  const std::lock_guard<std::mutex> lock(g_mu);
  h->iso.started = true;
  return 0;
}

FWSIM_EXPORT void raw1394_iso_stop(raw1394_handle* h) {
  const std::lock_guard<std::mutex> lock(g_mu);
  if (h == nullptr) return;
  h->iso.started = false;
  h->iso.head = h->iso.count = h->iso.since_irq = 0;
  ++h->iso.epoch;  // events already queued are stale
}

FWSIM_EXPORT void raw1394_iso_shutdown(raw1394_handle* h) {
  const std::lock_guard<std::mutex> lock(g_mu);
  if (h == nullptr) return;
  h->iso.init = h->iso.started = false;
  h->iso.head = h->iso.count = h->iso.since_irq = 0;
  ++h->iso.epoch;
  h->iso.data.clear();
}

FWSIM_EXPORT int raw1394_reset_bus(raw1394_handle* h) {
  const std::lock_guard<std::mutex> lock(g_mu);
  if (h == nullptr || h->port < 0) {
    errno = EINVAL;
    return -1;
  }
  do_reset(static_cast<std::size_t>(h->port));
  return 0;
}

// ------------------------------------------------------------------- control

FWSIM_EXPORT int fwsim_configure(const char* text) {
  std::call_once(g_env_once, [] {});  // the environment is not read after this
  stop_wall_thread();
  const std::lock_guard<std::mutex> lock(g_mu);
  if (!g_bus.handles.empty()) {
    g_bus.error = "fwsim: " + std::to_string(g_bus.handles.size()) +
                  " handle(s) still open";
    return -1;
  }
  if (!configure_locked(text != nullptr ? text : "")) return -1;
  if (g_bus.wall) g_bus.thread = std::thread(wall_thread);
  return 0;
}

FWSIM_EXPORT const char* fwsim_last_error() {
  static thread_local std::string copy;
  const std::lock_guard<std::mutex> lock(g_mu);
  copy = g_bus.error;
  return copy.c_str();
}

FWSIM_EXPORT std::int64_t fwsim_now_ns() {
  ensure_configured();
  const std::lock_guard<std::mutex> lock(g_mu);
  catch_up();
  return g_bus.now_ns;
}

FWSIM_EXPORT void fwsim_advance_ns(std::int64_t ns) {
  ensure_configured();
  const std::lock_guard<std::mutex> lock(g_mu);
  if (g_bus.wall || ns <= 0) return;
  run_until(g_bus.now_ns + ns);
}

FWSIM_EXPORT int fwsim_bus_reset(int port) {
  ensure_configured();
  const std::lock_guard<std::mutex> lock(g_mu);
  if (port < 0 || port >= static_cast<int>(g_bus.ports.size())) return -1;
  catch_up();
  do_reset(static_cast<std::size_t>(port));
  return 0;
}

FWSIM_EXPORT int fwsim_get_node(std::uint64_t guid, fwsim_node_info* out) {
  ensure_configured();
  const std::lock_guard<std::mutex> lock(g_mu);
  catch_up();
  int port = -1;
  const Node* n = find_guid(guid, &port);
  if (n == nullptr || out == nullptr) return -1;
  fwsim_node_info i{};
  i.guid = n->guid;
  i.port = port;
  i.phy = n->phy;
  i.omni = n->omni ? 1 : 0;
  i.streaming = n->streaming ? 1 : 0;
  i.reg_tx_channel = n->r1000;
  i.reg_rx_channel = n->r1001;
  i.reg_control = n->r1087;
  std::memcpy(i.reg_20010, n->r20010, 4);
  i.wrote_20010 = n->wrote_20010 ? 1 : 0;
  i.counter = n->counter;
  i.packets_sent = n->packets_sent;
  i.packets_received = n->packets_received;
  i.packets_dropped = n->packets_dropped;
  i.commands = n->commands;
  std::memcpy(i.last_command, n->last_command, 16);
  i.last_command_ns = n->last_command_ns;
  for (int j = 0; j < 3; ++j) i.encoder_counts[j] = n->counts[j];
  i.last_packet_ns = n->last_packet_ns;
  *out = i;
  return 0;
}

FWSIM_EXPORT int fwsim_set_encoder_speed(std::uint64_t guid, double s1, double s2,
                                         double s3) {
  ensure_configured();
  const std::lock_guard<std::mutex> lock(g_mu);
  catch_up();
  Node* n = find_guid(guid);
  if (n == nullptr) return -1;
  // the position goes on from where it is now
  const double t_s = 1e-9 * static_cast<double>(g_bus.now_ns);
  const double s[3] = {s1, s2, s3};
  for (int j = 0; j < 3; ++j) {
    n->synth.counts0[j] += (n->synth.speed[j] - s[j]) * t_s;
    n->synth.speed[j] = s[j];
  }
  return 0;
}

FWSIM_EXPORT int fwsim_set_docked(std::uint64_t guid, int docked) {
  ensure_configured();
  const std::lock_guard<std::mutex> lock(g_mu);
  catch_up();
  Node* n = find_guid(guid);
  if (n == nullptr) return -1;
  n->synth.docked = docked != 0;
  return 0;
}

FWSIM_EXPORT int fwsim_attach_device(std::uint64_t guid, const fwsim_device_ops* ops) {
  ensure_configured();
  const std::lock_guard<std::mutex> lock(g_mu);
  Node* n = find_guid(guid);
  if (n == nullptr || !n->omni) return -1;
  n->has_ops = ops != nullptr;
  n->ops = ops != nullptr ? *ops : fwsim_device_ops{};
  return 0;
}

FWSIM_EXPORT void fwsim_eagain(int every_nth, int next_k) {
  ensure_configured();
  const std::lock_guard<std::mutex> lock(g_mu);
  g_bus.eagain_every = std::max(0, every_nth);
  g_bus.eagain_next = std::max(0, next_k);
}

FWSIM_EXPORT long fwsim_eagain_count() {
  const std::lock_guard<std::mutex> lock(g_mu);
  return g_bus.eagain_count;
}

FWSIM_EXPORT long fwsim_underruns() {
  const std::lock_guard<std::mutex> lock(g_mu);
  return g_bus.underruns;
}

FWSIM_EXPORT long fwsim_log_size() {
  const std::lock_guard<std::mutex> lock(g_mu);
  return static_cast<long>(g_bus.log_entries.size());
}

FWSIM_EXPORT int fwsim_log_entry(long i, fwsim_transaction* out) {
  const std::lock_guard<std::mutex> lock(g_mu);
  if (i < 0 || i >= static_cast<long>(g_bus.log_entries.size()) || out == nullptr) {
    return -1;
  }
  *out = g_bus.log_entries[static_cast<std::size_t>(i)];
  return 0;
}

FWSIM_EXPORT void fwsim_log_clear() {
  const std::lock_guard<std::mutex> lock(g_mu);
  g_bus.log_entries.clear();
}
