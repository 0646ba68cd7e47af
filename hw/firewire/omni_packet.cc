// The FireWire Omni's packets as bytes <-> fields (omni_packet.h says the
// layout and where it comes from: docs/sources.md §9.2).
#include "hw/firewire/omni_packet.h"

#include <cmath>

namespace vmh::hw::fw {

namespace {

// little-endian loads and stores, byte by byte (no alignment, any host)
std::uint16_t load_u16(const std::uint8_t* p) noexcept {
  return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}
std::uint32_t load_u32(const std::uint8_t* p) noexcept {
  return static_cast<std::uint32_t>(p[0]) |
         (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) |
         (static_cast<std::uint32_t>(p[3]) << 24);
}
std::int16_t load_i16(const std::uint8_t* p) noexcept {
  const std::uint16_t u = load_u16(p);
  // two's complement, spelled out (the conversion of an out-of-range value
  // to a signed type is implementation-defined before C++20)
  return u >= 0x8000u ? static_cast<std::int16_t>(static_cast<int>(u) - 0x10000)
                      : static_cast<std::int16_t>(u);
}
void store_u16(std::uint8_t* p, std::uint16_t v) noexcept {
  p[0] = static_cast<std::uint8_t>(v & 0xffu);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}
void store_u32(std::uint8_t* p, std::uint32_t v) noexcept {
  p[0] = static_cast<std::uint8_t>(v & 0xffu);
  p[1] = static_cast<std::uint8_t>((v >> 8) & 0xffu);
  p[2] = static_cast<std::uint8_t>((v >> 16) & 0xffu);
  p[3] = static_cast<std::uint8_t>(v >> 24);
}
void store_i16(std::uint8_t* p, std::int16_t v) noexcept {
  store_u16(p, static_cast<std::uint16_t>(v < 0 ? static_cast<int>(v) + 0x10000
                                                : static_cast<int>(v)));
}

PacketError check_size(const std::uint8_t* data, std::size_t size,
                       std::size_t expected, const void* out) noexcept {
  if (data == nullptr || out == nullptr) return PacketError::kNull;
  if (size < expected) return PacketError::kTooShort;
  if (size > expected) return PacketError::kTooLong;
  return PacketError::kOk;
}

// byte offsets of the state packet (omni_packet.h)
constexpr std::size_t kOffMagic = 0;
constexpr std::size_t kOffEncoders = 4;
constexpr std::size_t kOffGimbalA = 10;
constexpr std::size_t kOffUnknown16 = 16;
constexpr std::size_t kOffPacketNumber = 18;
constexpr std::size_t kOffStatus = 19;
constexpr std::size_t kOffUnknown20 = 20;
constexpr std::size_t kOffGimbalB = 22;
constexpr std::size_t kOffUnknown28 = 28;
constexpr std::size_t kOffCounter = 32;
constexpr std::size_t kOffUnknown36 = 36;
constexpr std::size_t kOffTime = 40;
static_assert(kOffTime + 4 == kStatePacketBytes, "state packet layout");

// and of the command packet
constexpr std::size_t kOffMotor = 0;
constexpr std::size_t kOffCommandStatus = 6;
constexpr std::size_t kOffZero = 8;
static_assert(kOffZero + 8 == kCommandPacketBytes, "command packet layout");

// the motor word's zero and its half-ranges: 2047 counts below zero and
// 2048 above (12 bits, 0x07ff in the middle)
constexpr double kWordsBelowZero = kMotorWordZero;                  // 2047
constexpr double kWordsAboveZero = kMotorWordMax - kMotorWordZero;  // 2048

}  // namespace

const char* packet_error_name(PacketError e) noexcept {
  switch (e) {
    case PacketError::kOk: return "ok";
    case PacketError::kTooShort: return "too_short";
    case PacketError::kTooLong: return "too_long";
    case PacketError::kNull: return "null";
  }
  return "unknown";
}

PacketError decode_state(const std::uint8_t* data, std::size_t size,
                         StatePacket* out) noexcept {
  const PacketError e = check_size(data, size, kStatePacketBytes, out);
  if (e != PacketError::kOk) return e;
  StatePacket p;
  p.magic = load_u32(data + kOffMagic);
  for (std::size_t i = 0; i < 3; ++i) {
    p.encoders[i] = load_i16(data + kOffEncoders + 2 * i);
    p.gimbal_a[i] = load_u16(data + kOffGimbalA + 2 * i);
    p.gimbal_b[i] = load_u16(data + kOffGimbalB + 2 * i);
  }
  p.unknown16 = load_u16(data + kOffUnknown16);
  p.packet_number = data[kOffPacketNumber];
  p.status = data[kOffStatus];
  p.unknown20 = load_u16(data + kOffUnknown20);
  for (std::size_t i = 0; i < 2; ++i) {
    p.unknown28[i] = load_u16(data + kOffUnknown28 + 2 * i);
    p.unknown36[i] = load_u16(data + kOffUnknown36 + 2 * i);
  }
  p.counter = load_u32(data + kOffCounter);
  p.time = load_u32(data + kOffTime);
  *out = p;
  return PacketError::kOk;
}

void encode_state(const StatePacket& p,
                  std::uint8_t out[kStatePacketBytes]) noexcept {
  store_u32(out + kOffMagic, p.magic);
  for (std::size_t i = 0; i < 3; ++i) {
    store_i16(out + kOffEncoders + 2 * i, p.encoders[i]);
    store_u16(out + kOffGimbalA + 2 * i, p.gimbal_a[i]);
    store_u16(out + kOffGimbalB + 2 * i, p.gimbal_b[i]);
  }
  store_u16(out + kOffUnknown16, p.unknown16);
  out[kOffPacketNumber] = p.packet_number;
  out[kOffStatus] = p.status;
  store_u16(out + kOffUnknown20, p.unknown20);
  for (std::size_t i = 0; i < 2; ++i) {
    store_u16(out + kOffUnknown28 + 2 * i, p.unknown28[i]);
    store_u16(out + kOffUnknown36 + 2 * i, p.unknown36[i]);
  }
  store_u32(out + kOffCounter, p.counter);
  store_u32(out + kOffTime, p.time);
}

PacketError decode_command(const std::uint8_t* data, std::size_t size,
                           CommandPacket* out) noexcept {
  const PacketError e = check_size(data, size, kCommandPacketBytes, out);
  if (e != PacketError::kOk) return e;
  CommandPacket c;
  for (std::size_t i = 0; i < 3; ++i) {
    c.motor[i] = load_u16(data + kOffMotor + 2 * i);
  }
  c.status = load_u16(data + kOffCommandStatus);
  *out = c;
  return PacketError::kOk;
}

void encode_command(const CommandPacket& p,
                    std::uint8_t out[kCommandPacketBytes]) noexcept {
  for (std::size_t i = 0; i < 3; ++i) {
    store_u16(out + kOffMotor + 2 * i, p.motor[i]);
  }
  store_u16(out + kOffCommandStatus, p.status);
  store_u32(out + kOffZero, 0u);
  store_u32(out + kOffZero + 4, 0u);
}

// §9.2 gives word = (u + 1)/2 * 4095, whose zero falls between two words
// (2047.5). Here zero is exactly kMotorWordZero and each half of the range
// is scaled to reach its end (-1 -> 0x0000, +1 -> 0x0fff), which is within
// one count of the source's line everywhere and inverts exactly.
std::uint16_t motor_word_from_unit(double u) noexcept {
  if (std::isnan(u)) return kMotorWordZero;
  if (u >= 1.0) return kMotorWordMax;  // also +inf
  if (u <= -1.0) return 0;             // also -inf
  const double w = u >= 0.0 ? kWordsBelowZero + std::round(u * kWordsAboveZero)
                            : kWordsBelowZero + std::round(u * kWordsBelowZero);
  return static_cast<std::uint16_t>(w);
}

double unit_from_motor_word(std::uint16_t word) noexcept {
  const int w = word & kMotorWordMax;
  const int d = w - static_cast<int>(kMotorWordZero);
  return d >= 0 ? d / kWordsAboveZero : d / kWordsBelowZero;
}

std::int32_t pot_code(std::uint16_t a, std::uint16_t b) noexcept {
  constexpr int kShift = 16 - kPotValidBits;
  const std::int64_t ra = a >> kShift;
  const std::int64_t rb = b >> kShift;
  const std::int64_t sum = ra + rb;
  if (sum == 0) return -1;
  // round(ra / sum * kPotCodeMax) in integers: (2 ra max + sum) / (2 sum)
  const std::int64_t code = (2 * ra * kPotCodeMax + sum) / (2 * sum);
  return static_cast<std::int32_t>(code);
}

void pot_words_from_code(std::int32_t code, std::uint16_t* a,
                         std::uint16_t* b) noexcept {
  constexpr int kShift = 16 - kPotValidBits;
  if (code < 0) code = 0;
  if (code > kPotCodeMax) code = kPotCodeMax;
  if (a != nullptr) *a = static_cast<std::uint16_t>(code << kShift);
  if (b != nullptr) {
    *b = static_cast<std::uint16_t>((kPotCodeMax - code) << kShift);
  }
}

std::int32_t unwrap_encoder(std::int32_t previous, std::int16_t raw) noexcept {
  // the step from previous's low 16 bits to raw, taken modulo 65536 into
  // [-32768, 32767]
  const auto prev_low = static_cast<std::uint16_t>(
      static_cast<std::uint32_t>(previous) & 0xffffu);
  const auto raw_u = static_cast<std::uint16_t>(
      raw < 0 ? static_cast<int>(raw) + 0x10000 : static_cast<int>(raw));
  const auto diff = static_cast<std::uint16_t>(raw_u - prev_low);
  const std::int32_t step =
      diff >= 0x8000u ? static_cast<std::int32_t>(diff) - 0x10000
                      : static_cast<std::int32_t>(diff);
  // wraps (defined) in uint32 should a count ever pass 2^31
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(previous) +
                                   static_cast<std::uint32_t>(step));
}

}  // namespace vmh::hw::fw
