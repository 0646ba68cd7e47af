// The FireWire PHANTOM Omni's isochronous packets as pure functions: bytes
// <-> typed fields. No I/O, no allocation, no exceptions; every function is
// safe to call from the servo thread.
//
// The layout is reverse-engineered, not published by the vendor
// (docs/sources.md §9.2: Y. Tsutano's raw Omni driver and
// scottsharris/phantom-drivers' PhantomSpec.h). NOT YET VERIFIED ON A DEVICE
// BY THIS PROJECT: every field below is as those sources give it.
//
// Device -> host, 44 bytes, little-endian (byte offsets):
//    0 u32 magic            4 i16 encoder[3]        10 u16 gimbal_a[3]
//   16 u16 (unknown)       18 u8 packet_number      19 u8 status
//   20 u16 (unknown)       22 u16 gimbal_b[3]       28 u16 (unknown)[2]
//   32 u32 counter         36 u16 (unknown)[2]      40 u32 time
//   status: bit 0 button 1, bit 1 button 2 (both active-low: 0 = pressed),
//           bit 2 set when the stylus is OUT of the inkwell.
//
// Host -> device, 16 bytes, little-endian (the byte order of the command
// packet is not stated by the sources; taken as the state packet's):
//    0 u16 motor[3]         6 u16 status            8 u32 zero[2]
//   motor: 12-bit offset binary, 0x07ff = zero torque, word = (u+1)/2*4095
//          for u in [-1, 1] (the sign of u is the device convention's sign of
//          the motor's torque, unverified);
//   status: bit 0 / bit 1 dock LED flash / fast flash, bit 3 motors on; the
//          drivers start from 0x53c0 and set bit 3 to enable the motors.
#ifndef VMHAPTICS_HW_FIREWIRE_OMNI_PACKET_H_
#define VMHAPTICS_HW_FIREWIRE_OMNI_PACKET_H_

#include <array>
#include <cstddef>
#include <cstdint>

namespace vmh::hw::fw {

inline constexpr std::size_t kStatePacketBytes = 44;
inline constexpr std::size_t kCommandPacketBytes = 16;

// motor words (12-bit offset binary)
inline constexpr std::uint16_t kMotorWordZero = 0x07ff;
inline constexpr std::uint16_t kMotorWordMax = 0x0fff;

// command status word
inline constexpr std::uint16_t kCommandStatusInitial = 0x53c0;
inline constexpr std::uint16_t kCommandLedFlash = 1u << 0;
inline constexpr std::uint16_t kCommandLedFastFlash = 1u << 1;
inline constexpr std::uint16_t kCommandMotorsOn = 1u << 3;

// state status byte
inline constexpr std::uint8_t kStateButton1Released = 1u << 0;  // active-low
inline constexpr std::uint8_t kStateButton2Released = 1u << 1;  // active-low
inline constexpr std::uint8_t kStateUndocked = 1u << 2;

// The potentiometer words carry 11 valid bits at the top of 16 (§9.2).
inline constexpr int kPotValidBits = 11;
inline constexpr std::int32_t kPotCodeMax = (1 << kPotValidBits) - 1;  // 2047

// What went wrong with a packet's bytes.
enum class PacketError : int { kOk = 0, kTooShort, kTooLong, kNull };
// "ok", "too_short", "too_long", "null"
const char* packet_error_name(PacketError e) noexcept;

// One device -> host packet, every field as sent (raw words).
struct StatePacket {
  std::uint32_t magic = 0;
  std::array<std::int16_t, 3> encoders{};   // motors t1..t3, counts
  std::array<std::uint16_t, 3> gimbal_a{};  // pots t4..t6, word a
  std::uint16_t unknown16 = 0;              // offset 16
  std::uint8_t packet_number = 0;
  std::uint8_t status = kStateButton1Released | kStateButton2Released;
  std::uint16_t unknown20 = 0;              // offset 20
  std::array<std::uint16_t, 3> gimbal_b{};  // pots t4..t6, word b
  std::array<std::uint16_t, 2> unknown28{};
  std::uint32_t counter = 0;                // +1 per packet
  std::array<std::uint16_t, 2> unknown36{};
  std::uint32_t time = 0;

  bool button1_pressed() const noexcept {
    return (status & kStateButton1Released) == 0;
  }
  bool button2_pressed() const noexcept {
    return (status & kStateButton2Released) == 0;
  }
  // in the inkwell (bit 2 clear)
  bool docked() const noexcept { return (status & kStateUndocked) == 0; }
};

// One host -> device packet.
struct CommandPacket {
  std::array<std::uint16_t, 3> motor{kMotorWordZero, kMotorWordZero,
                                     kMotorWordZero};
  std::uint16_t status = kCommandStatusInitial;
  bool motors_on() const noexcept { return (status & kCommandMotorsOn) != 0; }
};

// Bytes -> packet. Exactly kStatePacketBytes are accepted; anything else is
// refused (kTooShort / kTooLong) and *out is left as it was.
PacketError decode_state(const std::uint8_t* data, std::size_t size,
                         StatePacket* out) noexcept;
void encode_state(const StatePacket& p,
                  std::uint8_t out[kStatePacketBytes]) noexcept;

PacketError decode_command(const std::uint8_t* data, std::size_t size,
                           CommandPacket* out) noexcept;
void encode_command(const CommandPacket& p,
                    std::uint8_t out[kCommandPacketBytes]) noexcept;

// u in [-1, 1] -> motor word. Out-of-range u, +-inf included, saturates at
// 0x0000 / 0x0fff (never wraps); NaN gives kMotorWordZero. Zero is exactly
// 0x07ff and each half-range is scaled to reach its end (2047 words below
// zero, 2048 above): within one word of the sources' (u+1)/2*4095, and
// unit_from_motor_word inverts it exactly on every word.
std::uint16_t motor_word_from_unit(double u) noexcept;
// motor word -> u (0x07ff -> 0 exactly, 0x0000 -> -1, 0x0fff -> +1; bits
// above the 12th ignored)
double unit_from_motor_word(std::uint16_t word) noexcept;

// The pot reading of one gimbal joint as the ratio r = a/(a+b) of the top
// kPotValidBits of each word, as an integer code round(r * kPotCodeMax) in
// [0, kPotCodeMax]; -1 when a + b is zero (an open pot).
std::int32_t pot_code(std::uint16_t a, std::uint16_t b) noexcept;
// A complementary pair (a, b) whose pot_code is `code` (clamped to
// [0, kPotCodeMax]): a = code << 5, b = (kPotCodeMax - code) << 5.
void pot_words_from_code(std::int32_t code, std::uint16_t* a,
                         std::uint16_t* b) noexcept;

// Encoder counts arrive as int16 and wrap every 65536 counts (4.4 rev at
// 15000 counts/rev). The unwrapped count nearest `previous` whose low 16 bits
// are `raw` (a step of at most 32767 counts per packet either way).
std::int32_t unwrap_encoder(std::int32_t previous, std::int16_t raw) noexcept;

}  // namespace vmh::hw::fw

#endif  // VMHAPTICS_HW_FIREWIRE_OMNI_PACKET_H_
