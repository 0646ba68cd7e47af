// What the three parts of the bus code share, not part of the public
// interface: the finding of Omnis (raw1394_discovery.cc), the transport's
// handles and per-tick I/O (raw1394_transport.cc), and its start, stop and
// recovery sequences (raw1394_sequences.cc). raw1394_transport.h says what
// each does.
#ifndef VMHAPTICS_HW_FIREWIRE_RAW1394_TRANSPORT_DETAIL_H_
#define VMHAPTICS_HW_FIREWIRE_RAW1394_TRANSPORT_DETAIL_H_

#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

#include "hw/firewire/raw1394_api.h"
#include "hw/firewire/raw1394_transport.h"

namespace vmh::hw::fw {

namespace detail {

inline std::string errno_text(int e) { return std::strerror(e); }

inline double now_s() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) +
         1e-9 * static_cast<double>(ts.tv_nsec);
}

inline void sleep_s(double s) noexcept {
  if (!(s > 0.0)) return;
  timespec ts{};
  ts.tv_sec = static_cast<std::time_t>(s);
  ts.tv_nsec = static_cast<long>((s - static_cast<double>(ts.tv_sec)) * 1e9);
  while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {
  }
}

inline std::uint32_t from_bus(r1394::Quadlet q) noexcept {
  // bus data is big-endian: the first byte is the most significant
  unsigned char b[4];
  std::memcpy(b, &q, 4);
  return (static_cast<std::uint32_t>(b[0]) << 24) |
         (static_cast<std::uint32_t>(b[1]) << 16) |
         (static_cast<std::uint32_t>(b[2]) << 8) | b[3];
}

// One register transaction, tried again while it fails with EAGAIN (a busy
// node, a transaction cut by a bus reset, a generation that moved on), at
// most `tries` times in all. phantom-drivers' rev-eng/easy-com.c retries
// without bound; a node that has gone answers EAGAIN for ever, hence the
// bound.
template <typename F>
bool with_retries(const Raw1394Options& o, std::atomic<std::uint64_t>* retries,
                  F&& transaction) noexcept {
  for (int i = 0;; ++i) {
    errno = 0;
    if (transaction() == 0) return true;
    if (errno != EAGAIN || i + 1 >= o.eagain_tries) return false;
    if (retries != nullptr) retries->fetch_add(1, std::memory_order_relaxed);
    sleep_s(o.eagain_delay_s);
  }
}

inline bool read_quadlet_on(const r1394::Api& a, r1394::Handle h,
                            const Raw1394Options& o,
                            std::atomic<std::uint64_t>* retries,
                            r1394::NodeId node, r1394::NodeAddr addr,
                            std::uint32_t* out) noexcept {
  r1394::Quadlet q = 0;
  if (!with_retries(o, retries, [&] { return a.read(h, node, addr, 4, &q); })) {
    return false;
  }
  *out = from_bus(q);
  return true;
}

// Every port's nodes looked at (raw1394_discovery.cc), for list_omni_nodes
// and the transport's constructor.
struct PortScan {
  int ports = 0;
  int nodes = 0;  // remote nodes looked at
  std::vector<NodeInfo> omnis;
  // SensAble's OUI in the vendor quadlet, but not the whole quadlet the
  // drivers know: "port 0 node 2: 0x000b9901"
  std::vector<std::string> other_sensable;
  std::string error;  // a port that could not be opened
};

// every node of every port (only options.port's if it is >= 0)
PortScan scan(const r1394::Api& a, const Raw1394Options& o);
// no port: say why in one line
std::string no_adapter_message();
// no Omni among the nodes scanned (with that GUID if `guid` is non-zero)
std::string not_found_message(const PortScan& s, std::uint64_t guid);

}  // namespace detail

struct Raw1394Transport::Handles {
  r1394::Handle ctrl = nullptr;  // registers, bus-reset events
  r1394::Handle rx = nullptr;    // iso receive
  r1394::Handle tx = nullptr;    // iso transmit
};

// libraw1394's callbacks (raw1394_transport.cc): plain C functions that get
// only the handle and find their transport from it
struct Raw1394Callbacks {
  static int bus_reset(r1394::Handle h, unsigned int generation);
  static r1394::Disposition received(r1394::Handle h, unsigned char* data,
                                     unsigned int len, unsigned char,
                                     unsigned char, unsigned char,
                                     unsigned int cycle, unsigned int);
  static r1394::Disposition transmit(r1394::Handle h, unsigned char* data,
                                     unsigned int* len, unsigned char* tag,
                                     unsigned char* sy, int, unsigned int);
};

}  // namespace vmh::hw::fw

#endif  // VMHAPTICS_HW_FIREWIRE_RAW1394_TRANSPORT_DETAIL_H_
