// libFuzzer harness: the FireWire Omni's packet codec
// (hw/firewire/omni_packet.h), pure functions on bytes.
//
// The whole input is offered as a state packet and as a command packet;
// then the input is read as numbers for the motor-word, pot and encoder
// helpers. Checks:
//  - a packet of the wrong size is refused (too_short / too_long) and the
//    output left as it was; one of the right size decodes, and encoding it
//    gives back the same bytes (the command's reserved zero words aside);
//  - every PacketError has a name from the documented set;
//  - motor_word_from_unit: a word in [0, 0x0fff], zero torque for NaN and 0,
//    saturation (never wrap) out of [-1, 1], monotone in u;
//    unit_from_motor_word: in [-1, 1] and inverted exactly by
//    motor_word_from_unit;
//  - pot_code: -1 or a code in [0, 2047]; pot_words_from_code's pair reads
//    back as the (clamped) code;
//  - unwrap_encoder: the low 16 bits are the raw count, and the step from
//    the previous count (modulo 2^32, as documented) is in [-32768, 32767].
#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>

#include "hw/firewire/omni_packet.h"
#include "tests/fuzz/fuzz_check.h"

namespace {

using namespace vmh::hw::fw;

bool valid_name(PacketError e) {
  const std::string n = packet_error_name(e);
  return n == "ok" || n == "too_short" || n == "too_long" || n == "null";
}

void check_packets(const std::uint8_t* data, std::size_t size) {
  StatePacket state;
  state.magic = 0x12345678u;
  const PacketError es = decode_state(data, size, &state);
  FUZZ_CHECK(valid_name(es), "state error without a name");
  if (size != kStatePacketBytes) {
    FUZZ_CHECK(es == (size < kStatePacketBytes ? PacketError::kTooShort
                                                : PacketError::kTooLong),
               "state packet of " + std::to_string(size) + " bytes");
    FUZZ_CHECK(state.magic == 0x12345678u, "refused packet changed the output");
  } else {
    FUZZ_CHECK(es == PacketError::kOk, "44-byte state packet refused");
    std::uint8_t again[kStatePacketBytes];
    encode_state(state, again);
    FUZZ_CHECK(std::memcmp(again, data, kStatePacketBytes) == 0,
               "state packet does not round-trip");
  }

  CommandPacket cmd;
  cmd.status = 0xbeef;
  const PacketError ec = decode_command(data, size, &cmd);
  FUZZ_CHECK(valid_name(ec), "command error without a name");
  if (size != kCommandPacketBytes) {
    FUZZ_CHECK(ec != PacketError::kOk && cmd.status == 0xbeef,
               "command packet of " + std::to_string(size) + " bytes");
  } else {
    FUZZ_CHECK(ec == PacketError::kOk, "16-byte command packet refused");
    std::uint8_t again[kCommandPacketBytes];
    encode_command(cmd, again);
    FUZZ_CHECK(std::memcmp(again, data, 8) == 0,
               "command packet does not round-trip");
    for (std::size_t i = 8; i < kCommandPacketBytes; ++i) {
      FUZZ_CHECK(again[i] == 0, "command's reserved words not zero");
    }
  }
  FUZZ_CHECK(decode_state(nullptr, size, &state) == PacketError::kNull, "null");
}

double any_double(FuzzedDataProvider& in) {
  if (in.ConsumeBool()) return in.ConsumeFloatingPointInRange(-1.5, 1.5);
  const auto bits = in.ConsumeIntegral<std::uint64_t>();
  double d;
  std::memcpy(&d, &bits, sizeof d);
  return d;
}

void check_motor_words(FuzzedDataProvider& in) {
  const double u = any_double(in), v = any_double(in);
  const std::uint16_t w = motor_word_from_unit(u);
  FUZZ_CHECK(w <= kMotorWordMax, "motor word above 0x0fff");
  if (std::isnan(u) || u == 0.0) {
    FUZZ_CHECK(w == kMotorWordZero, "NaN or 0 not zero torque");
  }
  if (u >= 1.0) FUZZ_CHECK(w == kMotorWordMax, "u >= 1 not saturated");
  if (u <= -1.0) FUZZ_CHECK(w == 0, "u <= -1 not saturated");
  if (!std::isnan(u) && !std::isnan(v) && u <= v) {
    FUZZ_CHECK(w <= motor_word_from_unit(v), "motor word not monotone");
  }
  const std::uint16_t raw = in.ConsumeIntegral<std::uint16_t>();
  const double back = unit_from_motor_word(raw);
  FUZZ_CHECK(back >= -1.0 && back <= 1.0, "unit out of [-1, 1]");
  FUZZ_CHECK(motor_word_from_unit(back) == (raw & kMotorWordMax),
             "unit_from_motor_word not inverted on word " + std::to_string(raw));
}

void check_pots(FuzzedDataProvider& in) {
  const auto a = in.ConsumeIntegral<std::uint16_t>();
  const auto b = in.ConsumeIntegral<std::uint16_t>();
  const std::int32_t code = pot_code(a, b);
  FUZZ_CHECK(code == -1 || (code >= 0 && code <= kPotCodeMax),
             "pot code out of range");
  const std::int32_t want = in.ConsumeIntegral<std::int32_t>();
  std::uint16_t pa = 0, pb = 0;
  pot_words_from_code(want, &pa, &pb);
  FUZZ_CHECK(pot_code(pa, pb) == std::clamp(want, 0, kPotCodeMax),
             "pot words do not read back as their code");
}

void check_encoder(FuzzedDataProvider& in) {
  const auto previous = in.ConsumeIntegral<std::int32_t>();
  const auto raw = in.ConsumeIntegral<std::int16_t>();
  const std::int32_t now = unwrap_encoder(previous, raw);
  FUZZ_CHECK(static_cast<std::int16_t>(static_cast<std::uint16_t>(
                 static_cast<std::uint32_t>(now) & 0xffffu)) == raw,
             "unwrapped count's low 16 bits are not the raw count");
  // modulo 2^32: the count wraps (documented) should it ever pass 2^31
  const auto step = static_cast<std::int32_t>(
      static_cast<std::uint32_t>(now) - static_cast<std::uint32_t>(previous));
  FUZZ_CHECK(step >= -32768 && step <= 32767,
             "unwrapped step over half the wrap: " + std::to_string(previous) +
                 " -> " + std::to_string(now));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data,
                                      std::size_t size) {
  check_packets(data, size);
  FuzzedDataProvider in(data, size);
  while (in.remaining_bytes() > 0) {
    switch (in.ConsumeIntegralInRange<int>(0, 2)) {
      case 0: check_motor_words(in); break;
      case 1: check_pots(in); break;
      default: check_encoder(in); break;
    }
  }
  return 0;
}
