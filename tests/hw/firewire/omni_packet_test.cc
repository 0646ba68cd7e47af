// The FireWire Omni's packet codec against packets written out byte by byte
// (hw/firewire/omni_packet.h gives the layout; docs/sources.md §9.2).
#include "hw/firewire/omni_packet.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

namespace vmh::hw::fw {
namespace {

// A state packet with a different value in every field, little-endian.
constexpr std::uint8_t kGoldenState[44] = {
    0x78, 0x56, 0x34, 0x12,  //  0 magic 0x12345678
    0xe8, 0x03,              //  4 encoder t1 = 1000
    0xfe, 0xff,              //  6 encoder t2 = -2
    0xff, 0x7f,              //  8 encoder t3 = 32767
    0x00, 0x40,              // 10 gimbal_a t4 = 0x4000
    0x20, 0x80,              // 12 gimbal_a t5 = 0x8020
    0xe0, 0xff,              // 14 gimbal_a t6 = 0xffe0
    0xef, 0xbe,              // 16 unknown16 = 0xbeef
    0x2a,                    // 18 packet_number = 42
    0x05,                    // 19 status: b1 released, b2 pressed, undocked
    0x22, 0x11,              // 20 unknown20 = 0x1122
    0xe0, 0xbf,              // 22 gimbal_b t4 = 0xbfe0
    0xc0, 0x7f,              // 24 gimbal_b t5 = 0x7fc0
    0x00, 0x00,              // 26 gimbal_b t6 = 0
    0x44, 0x33, 0x66, 0x55,  // 28 unknown28 = {0x3344, 0x5566}
    0x04, 0x03, 0x02, 0x01,  // 32 counter 0x01020304
    0x88, 0x77, 0xaa, 0x99,  // 36 unknown36 = {0x7788, 0x99aa}
    0xef, 0xbe, 0xad, 0xde,  // 40 time 0xdeadbeef
};

TEST(FirewirePacket, GoldenStateDecodes) {
  StatePacket p;
  ASSERT_EQ(decode_state(kGoldenState, sizeof kGoldenState, &p),
            PacketError::kOk);
  EXPECT_EQ(p.magic, 0x12345678u);
  EXPECT_EQ(p.encoders[0], 1000);
  EXPECT_EQ(p.encoders[1], -2);
  EXPECT_EQ(p.encoders[2], 32767);
  EXPECT_EQ(p.gimbal_a[0], 0x4000);
  EXPECT_EQ(p.gimbal_a[1], 0x8020);
  EXPECT_EQ(p.gimbal_a[2], 0xffe0);
  EXPECT_EQ(p.unknown16, 0xbeef);
  EXPECT_EQ(p.packet_number, 42);
  EXPECT_EQ(p.status, 0x05);
  EXPECT_EQ(p.unknown20, 0x1122);
  EXPECT_EQ(p.gimbal_b[0], 0xbfe0);
  EXPECT_EQ(p.gimbal_b[1], 0x7fc0);
  EXPECT_EQ(p.gimbal_b[2], 0x0000);
  EXPECT_EQ(p.unknown28[0], 0x3344);
  EXPECT_EQ(p.unknown28[1], 0x5566);
  EXPECT_EQ(p.counter, 0x01020304u);
  EXPECT_EQ(p.unknown36[0], 0x7788);
  EXPECT_EQ(p.unknown36[1], 0x99aa);
  EXPECT_EQ(p.time, 0xdeadbeefu);
  // status 0x05: bit 0 set (button 1 up), bit 1 clear (button 2 down),
  // bit 2 set (out of the inkwell)
  EXPECT_FALSE(p.button1_pressed());
  EXPECT_TRUE(p.button2_pressed());
  EXPECT_FALSE(p.docked());
}

TEST(FirewirePacket, GoldenStateReencodesByteIdentical) {
  StatePacket p;
  ASSERT_EQ(decode_state(kGoldenState, 44, &p), PacketError::kOk);
  std::uint8_t out[kStatePacketBytes];
  std::memset(out, 0xa5, sizeof out);
  encode_state(p, out);
  for (std::size_t i = 0; i < 44; ++i) {
    EXPECT_EQ(out[i], kGoldenState[i]) << "byte " << i;
  }
}

TEST(FirewirePacket, StatusBitsOfTheSwitches) {
  StatePacket p;
  p.status = 0x00;  // both buttons down, in the inkwell
  EXPECT_TRUE(p.button1_pressed());
  EXPECT_TRUE(p.button2_pressed());
  EXPECT_TRUE(p.docked());
  p.status = 0x07;  // none down, out of the inkwell
  EXPECT_FALSE(p.button1_pressed());
  EXPECT_FALSE(p.button2_pressed());
  EXPECT_FALSE(p.docked());
  p.status = 0xfa;  // bit 0 clear only among the three: button 1 down, docked
  EXPECT_TRUE(p.button1_pressed());
  EXPECT_FALSE(p.button2_pressed());
  EXPECT_TRUE(p.docked());
}

TEST(FirewirePacket, ShortAndLongStatePacketsAreRefusedUntouched) {
  StatePacket p;
  p.magic = 0xcafef00d;
  p.counter = 77;
  EXPECT_EQ(decode_state(kGoldenState, 43, &p), PacketError::kTooShort);
  EXPECT_EQ(p.magic, 0xcafef00du);
  EXPECT_EQ(p.counter, 77u);
  std::uint8_t longer[45] = {};
  std::memcpy(longer, kGoldenState, 44);
  EXPECT_EQ(decode_state(longer, 45, &p), PacketError::kTooLong);
  EXPECT_EQ(p.magic, 0xcafef00du);
  EXPECT_EQ(p.counter, 77u);
  EXPECT_EQ(decode_state(nullptr, 44, &p), PacketError::kNull);
  EXPECT_EQ(decode_state(kGoldenState, 44, nullptr), PacketError::kNull);
  EXPECT_EQ(p.magic, 0xcafef00du);
}

// zero torque on t1, full positive on t2, full negative on t3, motors on
constexpr std::uint8_t kGoldenCommand[16] = {
    0xff, 0x07,              //  0 motor t1 = 0x07ff (zero)
    0xff, 0x0f,              //  2 motor t2 = 0x0fff (+1)
    0x00, 0x00,              //  4 motor t3 = 0x0000 (-1)
    0xc8, 0x53,              //  6 status 0x53c8 = 0x53c0 | motors on
    0x00, 0x00, 0x00, 0x00,  //  8 zero
    0x00, 0x00, 0x00, 0x00,  // 12 zero
};

TEST(FirewirePacket, GoldenCommandDecodesAndReencodes) {
  CommandPacket c;
  ASSERT_EQ(decode_command(kGoldenCommand, 16, &c), PacketError::kOk);
  EXPECT_EQ(c.motor[0], 0x07ff);
  EXPECT_EQ(c.motor[1], 0x0fff);
  EXPECT_EQ(c.motor[2], 0x0000);
  EXPECT_EQ(c.status, 0x53c8);
  EXPECT_TRUE(c.motors_on());
  std::uint8_t out[kCommandPacketBytes];
  std::memset(out, 0xa5, sizeof out);
  encode_command(c, out);
  for (std::size_t i = 0; i < 16; ++i) {
    EXPECT_EQ(out[i], kGoldenCommand[i]) << "byte " << i;
  }
}

TEST(FirewirePacket, DefaultCommandIsZeroWithMotorsOff) {
  std::uint8_t out[kCommandPacketBytes];
  encode_command(CommandPacket{}, out);
  const std::uint8_t expected[16] = {0xff, 0x07, 0xff, 0x07, 0xff, 0x07,
                                     0xc0, 0x53, 0, 0, 0, 0, 0, 0, 0, 0};
  for (std::size_t i = 0; i < 16; ++i) EXPECT_EQ(out[i], expected[i]) << i;
  EXPECT_FALSE(CommandPacket{}.motors_on());
}

TEST(FirewirePacket, ShortAndLongCommandPacketsAreRefusedUntouched) {
  CommandPacket c;
  c.motor[0] = 0x0123;
  EXPECT_EQ(decode_command(kGoldenCommand, 15, &c), PacketError::kTooShort);
  std::uint8_t longer[17] = {};
  EXPECT_EQ(decode_command(longer, 17, &c), PacketError::kTooLong);
  EXPECT_EQ(c.motor[0], 0x0123);
  EXPECT_EQ(c.status, kCommandStatusInitial);
}

TEST(FirewirePacket, MotorWordsAtTheEndsAndZero) {
  EXPECT_EQ(motor_word_from_unit(0.0), 0x07ff);
  EXPECT_EQ(motor_word_from_unit(-0.0), 0x07ff);
  EXPECT_EQ(motor_word_from_unit(1.0), 0x0fff);
  EXPECT_EQ(motor_word_from_unit(-1.0), 0x0000);
  // half scale: 2047 + 0.5 * 2048 = 3071; 2047 - 0.5 * 2047 = 1023.5 -> 1023
  // (rounded away from zero)
  EXPECT_EQ(motor_word_from_unit(0.5), 0x0bff);
  EXPECT_EQ(motor_word_from_unit(-0.5), 0x03ff);
  // one word either side of zero
  EXPECT_EQ(motor_word_from_unit(1.0 / 2048), 0x0800);
  EXPECT_EQ(motor_word_from_unit(-1.0 / 2047), 0x07fe);
}

TEST(FirewirePacket, MotorWordsSaturateAndNeverWrap) {
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(motor_word_from_unit(5.0), 0x0fff);
  EXPECT_EQ(motor_word_from_unit(-5.0), 0x0000);
  EXPECT_EQ(motor_word_from_unit(1.0000001), 0x0fff);
  EXPECT_EQ(motor_word_from_unit(-1.0000001), 0x0000);
  EXPECT_EQ(motor_word_from_unit(inf), 0x0fff);
  EXPECT_EQ(motor_word_from_unit(-inf), 0x0000);
  EXPECT_EQ(motor_word_from_unit(1e300), 0x0fff);
  EXPECT_EQ(motor_word_from_unit(-1e300), 0x0000);
  EXPECT_EQ(motor_word_from_unit(std::nan("")), 0x07ff);
}

TEST(FirewirePacket, MotorWordsFollowTheSourcesLine) {
  // §9.2: word = (u + 1)/2 * 4095; ours is within one word of it and
  // monotonic
  int previous = -1;
  for (int k = -1000; k <= 1000; ++k) {
    const double u = k / 1000.0;
    const int w = motor_word_from_unit(u);
    EXPECT_LE(std::fabs(w - (u + 1.0) / 2.0 * 4095.0), 1.0) << "u " << u;
    EXPECT_GE(w, previous) << "u " << u;
    previous = w;
  }
}

TEST(FirewirePacket, UnitFromMotorWord) {
  EXPECT_EQ(unit_from_motor_word(0x07ff), 0.0);
  EXPECT_EQ(unit_from_motor_word(0x0fff), 1.0);
  EXPECT_EQ(unit_from_motor_word(0x0000), -1.0);
  EXPECT_DOUBLE_EQ(unit_from_motor_word(0x0bff), 0.5);      // 1024 / 2048
  EXPECT_DOUBLE_EQ(unit_from_motor_word(0x03ff), -1024.0 / 2047.0);
  EXPECT_EQ(unit_from_motor_word(0xf7ff), 0.0);  // bits above 12 ignored
  // every word survives the round trip
  for (int w = 0; w <= 0x0fff; ++w) {
    EXPECT_EQ(motor_word_from_unit(
                  unit_from_motor_word(static_cast<std::uint16_t>(w))),
              w);
  }
}

TEST(FirewirePacket, PotCodeOfComplementaryWords) {
  // the golden packet's pairs: top 11 bits 512/1535, 1025/1022, 2047/0
  EXPECT_EQ(pot_code(0x4000, 0xbfe0), 512);
  EXPECT_EQ(pot_code(0x8020, 0x7fc0), 1025);
  EXPECT_EQ(pot_code(0xffe0, 0x0000), 2047);
  EXPECT_EQ(pot_code(0x0000, 0xffe0), 0);
  // the low 5 bits are not part of the reading
  EXPECT_EQ(pot_code(0x401f, 0xbfff), 512);
  // not complementary: a = 100, b = 300 (top bits) -> 2047 * 0.25 = 511.75
  EXPECT_EQ(pot_code(100 << 5, 300 << 5), 512);
  // an open pot
  EXPECT_EQ(pot_code(0, 0), -1);
  EXPECT_EQ(pot_code(0x001f, 0x001f), -1);
}

TEST(FirewirePacket, PotWordsFromCode) {
  std::uint16_t a = 0, b = 0;
  pot_words_from_code(512, &a, &b);
  EXPECT_EQ(a, 0x4000);
  EXPECT_EQ(b, 0xbfe0);
  pot_words_from_code(-5, &a, &b);  // clamped to 0
  EXPECT_EQ(a, 0x0000);
  EXPECT_EQ(b, 0xffe0);
  pot_words_from_code(5000, &a, &b);  // clamped to 2047
  EXPECT_EQ(a, 0xffe0);
  EXPECT_EQ(b, 0x0000);
  for (std::int32_t code = 0; code <= kPotCodeMax; ++code) {
    pot_words_from_code(code, &a, &b);
    EXPECT_EQ(pot_code(a, b), code);
  }
}

TEST(FirewirePacket, UnwrapEncoderAcrossTheInt16Boundary) {
  // upward through +32767 -> -32768
  EXPECT_EQ(unwrap_encoder(32767, -32768), 32768);
  EXPECT_EQ(unwrap_encoder(32760, -32766), 32770);  // +10
  // downward through -32768 -> +32767
  EXPECT_EQ(unwrap_encoder(-32768, 32767), -32769);
  EXPECT_EQ(unwrap_encoder(-32766, 32760), -32776);  // -10
  // small steps away from the boundary
  EXPECT_EQ(unwrap_encoder(0, 100), 100);
  EXPECT_EQ(unwrap_encoder(0, -100), -100);
  // far from zero: 100000 has low bits 34464, i.e. int16 -31072
  EXPECT_EQ(unwrap_encoder(100000, -31070), 100002);
  EXPECT_EQ(unwrap_encoder(-100000, 31070), -100002);
  // the largest step either way
  EXPECT_EQ(unwrap_encoder(0, 32767), 32767);
  EXPECT_EQ(unwrap_encoder(0, -32768), -32768);
}

TEST(FirewirePacket, ErrorNames) {
  EXPECT_STREQ(packet_error_name(PacketError::kOk), "ok");
  EXPECT_STREQ(packet_error_name(PacketError::kTooShort), "too_short");
  EXPECT_STREQ(packet_error_name(PacketError::kTooLong), "too_long");
  EXPECT_STREQ(packet_error_name(PacketError::kNull), "null");
}

}  // namespace
}  // namespace vmh::hw::fw
