// vmhaptics hw decode firewire-state HEX...
// vmhaptics hw decode firewire-command HEX...
// vmhaptics hw encode firewire-command --motor-unit u1,u2,u3 [--motors-on]
// vmhaptics hw encode firewire-state [--encoders ...] [--pot-codes ...] ...
//
// The FireWire Omni's packets by hand, for debugging a capture or checking
// what the driver would send: the codec of hw/firewire/omni_packet.h, no
// device. HEX is the packet's bytes in order as hex digits (44 bytes for a
// state packet, 16 for a command), in one word or several, white space
// anywhere ignored ("0b 99 00 ..." as a capture tool prints it, quoted or
// not, works too). Each prints one JSON object on stdout. A packet of the
// wrong length, a non-hex digit or a value that is not a number: exit 2 and
// one line naming it.
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "cli/args.h"
#include "cli/hw.h"
#include "runtime/json_util.h"
#include "hw/firewire/omni_packet.h"

namespace vmh::cli {
namespace {

namespace fw = hw::fw;

std::string hex_of(const std::uint8_t* data, std::size_t n) {
  static const char kDigits[] = "0123456789abcdef";
  std::string s;
  for (std::size_t i = 0; i < n; ++i) {
    s += kDigits[data[i] >> 4];
    s += kDigits[data[i] & 0xf];
  }
  return s;
}

std::string hex_word(unsigned v, int digits) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%0*x", digits, v);
  return buf;
}

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// The words joined, as exactly `bytes` bytes. `verb` names the command.
std::vector<std::uint8_t> parse_hex(const std::vector<std::string>& words,
                                    std::size_t bytes, const std::string& verb,
                                    const char* what) {
  // white space anywhere is a separator, as a capture tool prints the
  // bytes, also inside one quoted word ("0b 99 00 ...")
  std::string text;
  for (const std::string& w : words) {
    for (char ch : w) {
      if (!std::isspace(static_cast<unsigned char>(ch))) text += ch;
    }
  }
  if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) {
    text = text.substr(2);
  }
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (hex_digit(text[i]) < 0) {
      throw UsageError(verb + ": '" + text + "' has a non-hex digit '" +
                       std::string(1, text[i]) + "' at position " +
                       std::to_string(i + 1));
    }
  }
  if (text.size() % 2 != 0) {
    throw UsageError(verb + ": '" + text + "' is " + std::to_string(text.size()) +
                     " hex digits, an odd number (" + what + ": " +
                     std::to_string(2 * bytes) + " digits, " +
                     std::to_string(bytes) + " bytes)");
  }
  if (text.size() != 2 * bytes) {
    throw UsageError(verb + ": '" + text + "' is " + std::to_string(text.size() / 2) +
                     " bytes; " + what + " is " + std::to_string(bytes) +
                     " bytes (" + std::to_string(2 * bytes) + " hex digits)");
  }
  std::vector<std::uint8_t> out(bytes);
  for (std::size_t i = 0; i < bytes; ++i) {
    out[i] = static_cast<std::uint8_t>(hex_digit(text[2 * i]) * 16 +
                                       hex_digit(text[2 * i + 1]));
  }
  return out;
}

template <typename T, std::size_t N>
Json array_json(const std::array<T, N>& a) {
  Json j = Json::array();
  for (const T& v : a) j.push_back(v);
  return j;
}

Json state_json(const fw::StatePacket& p, const std::uint8_t* bytes) {
  std::array<std::int32_t, 3> codes{};
  for (std::size_t i = 0; i < 3; ++i) codes[i] = fw::pot_code(p.gimbal_a[i], p.gimbal_b[i]);
  return Json{{"hex", hex_of(bytes, fw::kStatePacketBytes)},
              {"magic", hex_word(p.magic, 8)},
              {"encoders", array_json(p.encoders)},
              {"gimbal_a", array_json(p.gimbal_a)},
              {"gimbal_b", array_json(p.gimbal_b)},
              {"pot_codes", array_json(codes)},
              {"pot_codes_note", "round(a/(a+b) * 2047) of the words' top 11 bits; "
                                 "-1: an open pot (a + b = 0)"},
              {"status", p.status},
              {"status_hex", hex_word(p.status, 2)},
              {"buttons_pressed", {p.button1_pressed(), p.button2_pressed()}},
              {"docked", p.docked()},
              {"packet_number", p.packet_number},
              {"counter", p.counter},
              {"time", p.time},
              {"unknown16", p.unknown16},
              {"unknown20", p.unknown20},
              {"unknown28", array_json(p.unknown28)},
              {"unknown36", array_json(p.unknown36)}};
}

Json command_json(const fw::CommandPacket& c, const std::uint8_t* bytes) {
  std::array<double, 3> units{};
  for (std::size_t i = 0; i < 3; ++i) units[i] = fw::unit_from_motor_word(c.motor[i]);
  bool zero_tail = true;
  for (std::size_t i = 8; i < fw::kCommandPacketBytes; ++i) zero_tail &= bytes[i] == 0;
  return Json{{"hex", hex_of(bytes, fw::kCommandPacketBytes)},
              {"motor_words", array_json(c.motor)},
              {"motor_unit", array_json(units)},
              {"status", c.status},
              {"status_hex", hex_word(c.status, 4)},
              {"motors_on", c.motors_on()},
              {"led_flash", (c.status & fw::kCommandLedFlash) != 0},
              {"led_fast_flash", (c.status & fw::kCommandLedFastFlash) != 0},
              {"tail_zero", zero_tail}};
}

struct PacketOptions {
  std::vector<std::string> hex;
  // encode firewire-command
  std::string motor_unit;
  bool motors_on = false;
  // encode firewire-state
  std::string encoders = "0,0,0";
  std::string pot_codes = "1023,1023,1023";
  std::string buttons_pressed = "0,0";
  bool docked = false;
  double counter = 0.0;
  double time = 0.0;
  std::string magic = "0";
};

void decode_state(const PacketOptions& o) {
  const auto bytes = parse_hex(o.hex, fw::kStatePacketBytes,
                               "hw decode firewire-state", "a state packet");
  fw::StatePacket p;
  fw::decode_state(bytes.data(), bytes.size(), &p);
  std::cout << dump_readable(state_json(p, bytes.data())) << '\n';
}

void decode_command(const PacketOptions& o) {
  const auto bytes = parse_hex(o.hex, fw::kCommandPacketBytes,
                               "hw decode firewire-command", "a command packet");
  fw::CommandPacket c;
  fw::decode_command(bytes.data(), bytes.size(), &c);
  std::cout << dump_readable(command_json(c, bytes.data())) << '\n';
}

void encode_command(const PacketOptions& o) {
  const std::vector<double> u = parse_list("--motor-unit", o.motor_unit, 3);
  fw::CommandPacket c;
  Json saturated = Json::array();
  for (std::size_t i = 0; i < 3; ++i) {
    c.motor[i] = fw::motor_word_from_unit(u[i]);
    saturated.push_back(std::abs(u[i]) > 1.0);
  }
  c.status = o.motors_on
                 ? static_cast<std::uint16_t>(fw::kCommandStatusInitial | fw::kCommandMotorsOn)
                 : static_cast<std::uint16_t>(fw::kCommandStatusInitial & ~fw::kCommandMotorsOn);
  std::uint8_t bytes[fw::kCommandPacketBytes];
  fw::encode_command(c, bytes);
  Json out = command_json(c, bytes);
  out["motor_unit_asked"] = u;
  out["saturated"] = saturated;
  std::cout << dump_readable(out) << '\n';
}

std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

// a whole number in [lo, hi], or a usage error naming the option and item
long whole_in(const std::string& option, double v, const std::string& where,
              double lo, double hi) {
  if (v != std::floor(v) || v < lo || v > hi) {
    throw UsageError(option + ": " + where + " '" + number_text(v) +
                     "' is not a whole number in [" + number_text(lo) + ", " +
                     number_text(hi) + "]");
  }
  return static_cast<long>(v);
}

void encode_state(const PacketOptions& o) {
  fw::StatePacket p;
  const auto enc = parse_list("--encoders", o.encoders, 3);
  const auto pots = parse_list("--pot-codes", o.pot_codes, 3);
  const auto btn = parse_list("--buttons-pressed", o.buttons_pressed, 2);
  for (std::size_t i = 0; i < 3; ++i) {
    const std::string item = "item " + std::to_string(i + 1);
    p.encoders[i] = static_cast<std::int16_t>(
        whole_in("--encoders", enc[i], item, -32768.0, 32767.0));
    fw::pot_words_from_code(static_cast<std::int32_t>(whole_in(
                                "--pot-codes", pots[i], item, 0.0, fw::kPotCodeMax)),
                            &p.gimbal_a[i], &p.gimbal_b[i]);
  }
  std::uint8_t status = 0;
  if (whole_in("--buttons-pressed", btn[0], "item 1", 0.0, 1.0) == 0) {
    status |= fw::kStateButton1Released;
  }
  if (whole_in("--buttons-pressed", btn[1], "item 2", 0.0, 1.0) == 0) {
    status |= fw::kStateButton2Released;
  }
  if (!o.docked) status |= fw::kStateUndocked;
  p.status = status;
  p.counter = static_cast<std::uint32_t>(whole_in("--counter", o.counter, "value", 0.0, 4294967295.0));
  p.packet_number = static_cast<std::uint8_t>(p.counter & 0xffu);
  p.time = static_cast<std::uint32_t>(whole_in("--time", o.time, "value", 0.0, 4294967295.0));
  {
    std::string m = o.magic;
    if (m.size() > 2 && m[0] == '0' && (m[1] == 'x' || m[1] == 'X')) m = m.substr(2);
    bool ok = !m.empty() && m.size() <= 8;
    for (char ch : m) ok &= hex_digit(ch) >= 0;
    if (!ok) throw UsageError("--magic: '" + o.magic + "' is not up to 8 hex digits");
    p.magic = static_cast<std::uint32_t>(std::stoul(m, nullptr, 16));
  }
  std::uint8_t bytes[fw::kStatePacketBytes];
  fw::encode_state(p, bytes);
  std::cout << dump_readable(state_json(p, bytes)) << '\n';
}

}  // namespace

void register_hw_packet(CLI::App* hw) {
  auto o = std::make_shared<PacketOptions>();
  CLI::App* dec = hw->add_subcommand(
      "decode",
      "a FireWire Omni packet's bytes (hex) as fields: firewire-state (44 "
      "bytes) or firewire-command (16 bytes)");
  dec->require_subcommand(1);
  CLI::App* ds = dec->add_subcommand(
      "firewire-state",
      "a device -> host state packet: encoders, pot words and codes, "
      "buttons, inkwell, counter, time");
  ds->add_option("hex", o->hex, "88 hex digits, in one word or several")->required();
  ds->callback([o]() { decode_state(*o); });
  CLI::App* dc = dec->add_subcommand(
      "firewire-command",
      "a host -> device command packet: motor words and units, status bits");
  dc->add_option("hex", o->hex, "32 hex digits, in one word or several")->required();
  dc->callback([o]() { decode_command(*o); });

  CLI::App* enc = hw->add_subcommand(
      "encode", "a FireWire Omni packet from fields, as hex: firewire-command "
                "or firewire-state");
  enc->require_subcommand(1);
  CLI::App* ec = enc->add_subcommand(
      "firewire-command",
      "a command packet from motor commands u in [-1, 1] (full scale); "
      "outside it they saturate, and \"saturated\" says which");
  ec->add_option("--motor-unit", o->motor_unit, "u1,u2,u3 (t1..t3)")->required();
  ec->add_flag("--motors-on", o->motors_on,
               "set the motors-on bit (default: off, as the drivers start)");
  ec->callback([o]() { encode_command(*o); });
  CLI::App* es = enc->add_subcommand(
      "firewire-state",
      "a state packet from fields (pots as complementary a/b words)");
  es->add_option("--encoders", o->encoders, "e1,e2,e3: int16 counts (default 0,0,0)");
  es->add_option("--pot-codes", o->pot_codes,
                 "c4,c5,c6: codes 0..2047 (default 1023,1023,1023)");
  es->add_option("--buttons-pressed", o->buttons_pressed,
                 "b1,b2: 1 pressed, 0 not (default 0,0)");
  es->add_flag("--docked", o->docked, "the stylus in the inkwell (default: out)");
  es->add_option("--counter", o->counter,
                 "packet counter, 0..2^32-1 (the packet number is its low byte)");
  es->add_option("--time", o->time, "time word, 0..2^32-1");
  es->add_option("--magic", o->magic, "magic word, hex (default 0)");
  es->callback([o]() { encode_state(*o); });
}

}  // namespace vmh::cli
