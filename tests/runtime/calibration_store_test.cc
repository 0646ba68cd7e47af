// The calibration store (runtime/calibration_store.h): a stored fit reads
// back as written; a malformed or implausible file is refused naming the
// file and the field, never loaded; what is not a regular file is refused
// before it is read.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "runtime/calibration_store.h"

namespace vmh::runtime {
namespace {

namespace fs = std::filesystem;

// a plausible calibration: 11-bit pots over +-1.13 rad, offsets near the
// inkwell's
hw::OmniCalibration plausible() {
  hw::OmniCalibration c;
  c.encoder_offset_rad = {-0.23, 0.37, 0.0};
  c.pot_gain_rad = {2.5e-3, 1.1e-3, 2.5e-3};
  c.pot_offset_rad = {-2.6, -1.15, -2.6};
  return c;
}

class StoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::path(::testing::TempDir()) / ("vmh_store_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    setenv("XDG_CONFIG_HOME", dir.c_str(), 1);
  }
  void TearDown() override { fs::remove_all(dir); }
  void write(const std::string& serial, const std::string& text) {
    fs::create_directories(fs::path(calibration_path(serial)).parent_path());
    std::ofstream(calibration_path(serial)) << text;
  }
  std::string refusal(const std::string& serial) {
    try {
      load_calibration(serial);
    } catch (const CalibrationError& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir;
};

TEST_F(StoreTest, AStoredFitReadsBackAsWritten) {
  StoredCalibration c;
  c.calibration = plausible();
  c.serial = "EMU-0001";
  c.backend = "emulator";
  const std::string path = save_calibration(c);
  EXPECT_EQ(path, calibration_path("EMU-0001"));
  const auto back = load_calibration("EMU-0001");
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->calibration.pot_gain_rad, c.calibration.pot_gain_rad);
  EXPECT_EQ(back->calibration.encoder_offset_rad, c.calibration.encoder_offset_rad);
  EXPECT_EQ(back->backend, "emulator");
  EXPECT_EQ(back->calibration.encoder_sign, c.calibration.encoder_sign);
  EXPECT_EQ(back->calibration.inkwell_t123_rad, c.calibration.inkwell_t123_rad);
  EXPECT_FALSE(load_calibration("nobody").has_value());
  // signs and the inkwell pose other than the nominal ones come back too
  c.calibration.encoder_sign = {1, -1, -1};
  c.calibration.inkwell_t123_rad = {0.01, 0.23, -0.37};
  c.serial = "EMU-0002";
  save_calibration(c);
  const auto other = load_calibration("EMU-0002");
  ASSERT_TRUE(other.has_value());
  EXPECT_EQ(other->calibration.encoder_sign, (std::array<int, 3>{1, -1, -1}));
  EXPECT_EQ(other->calibration.inkwell_t123_rad,
            (std::array<double, 3>{0.01, 0.23, -0.37}));
}

TEST_F(StoreTest, AFileFromBeforeTheSignsHasTheNominalOnes) {
  // as `hw calibrate` wrote them before the signs and the inkwell pose
  // were stored
  write("old", "{\"serial\": \"old\", \"encoder_offset_rad\": [-0.2, 0.3, 0.1], "
               "\"pot_gain_rad\": [0.0025, -0.0025, 0.0023], "
               "\"pot_offset_rad\": [-2.7, 2.6, -2.4]}");
  const auto c = load_calibration("old");
  ASSERT_TRUE(c.has_value()) << refusal("old");
  EXPECT_EQ(c->calibration.encoder_sign, hw::kNominalEncoderSign);
  EXPECT_EQ(c->calibration.encoder_sign, (std::array<int, 3>{-1, -1, 1}));
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(c->calibration.inkwell_t123_rad[i], hw::kInkwellDevice_rad[i]) << i;
  }
  EXPECT_EQ(c->calibration.encoder_offset_rad, (std::array<double, 3>{-0.2, 0.3, 0.1}));
}

TEST_F(StoreTest, BadSignsAndInkwellPosesAreRefusedNamingTheJoint) {
  const std::string rest =
      "\"encoder_offset_rad\": [0, 0, 0], \"pot_gain_rad\": [0.001, 0.001, "
      "0.001], \"pot_offset_rad\": [0, 0, 0]";
  write("s0", "{" + rest + ", \"encoder_sign\": [-1, 0, 1]}");
  EXPECT_NE(refusal("s0").find("encoder_sign[1] (t2) = 0 is not +1 or -1"),
            std::string::npos) << refusal("s0");
  write("s2", "{" + rest + ", \"encoder_sign\": [-1, 1, 2]}");
  EXPECT_NE(refusal("s2").find("encoder_sign[2] (t3) = 2"), std::string::npos)
      << refusal("s2");
  write("sf", "{" + rest + ", \"encoder_sign\": [1.0, 1, 1]}");
  EXPECT_NE(refusal("sf").find("encoder_sign[0] (t1) must be +1 or -1"),
            std::string::npos) << refusal("sf");
  write("ss", "{" + rest + ", \"encoder_sign\": [-1, \"-1\", 1]}");
  EXPECT_NE(refusal("ss").find("encoder_sign[1] (t2) must be +1 or -1"),
            std::string::npos) << refusal("ss");
  write("sn", "{" + rest + ", \"encoder_sign\": -1}");
  EXPECT_NE(refusal("sn").find("'encoder_sign' must be an array of 3 signs"),
            std::string::npos) << refusal("sn");
  write("i4", "{" + rest + ", \"inkwell_t123_rad\": [0, 4, 0]}");
  EXPECT_NE(refusal("i4").find("inkwell_t123_rad[1] (t2) = 4 rad"),
            std::string::npos) << refusal("i4");
  write("ix", "{" + rest + ", \"inkwell_t123_rad\": [0, 0]}");
  EXPECT_NE(refusal("ix").find("'inkwell_t123_rad' must be an array of 3 numbers"),
            std::string::npos) << refusal("ix");
  // check_calibration refuses the same in memory, and nothing is stored
  hw::OmniCalibration c = plausible();
  c.encoder_sign[0] = 3;
  StoredCalibration s;
  s.calibration = c;
  s.serial = "badsign";
  try {
    save_calibration(s);
    ADD_FAILURE() << "a sign of 3 was stored";
  } catch (const CalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("encoder_sign[0] (t1) = 3"),
              std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(calibration_path("badsign")));
}

TEST_F(StoreTest, MalformedFilesAreRefusedNamingTheField) {
  write("a", "{\"encoder_offset_rad\": [0, 0, 0], \"pot_gain_rad\": [0.001, \"x\", "
             "0.001], \"pot_offset_rad\": [0, 0, 0]}");
  EXPECT_NE(refusal("a").find("pot_gain_rad[1] (t5) must be a number, got string"),
            std::string::npos) << refusal("a");
  write("b", "{\"encoder_offset_rad\": [0, 0, 0], \"pot_gain_rad\": [0.001, 0.001, "
             "0.001]}");
  EXPECT_NE(refusal("b").find("'pot_offset_rad' is missing"), std::string::npos);
  write("c", "[1, 2, 3]");
  EXPECT_NE(refusal("c").find("not a JSON object"), std::string::npos);
  write("d", "{not json");
  EXPECT_NE(refusal("d").find("not JSON"), std::string::npos);
  write("e", "{\"serial\": 5, \"encoder_offset_rad\": [0, 0, 0], \"pot_gain_rad\": "
             "[0.001, 0.001, 0.001], \"pot_offset_rad\": [0, 0, 0]}");
  EXPECT_NE(refusal("e").find("'serial' must be a string"), std::string::npos);
}

TEST_F(StoreTest, ImplausibleValuesAreRefusedNamingTheJoint) {
  const auto refused = [](hw::OmniCalibration c) {
    try {
      check_calibration(c, "f");
    } catch (const CalibrationError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(refused(plausible()), "");
  hw::OmniCalibration c = plausible();
  c.pot_gain_rad[1] = 0.0226;  // a sweep that covered 100 codes
  EXPECT_NE(refused(c).find("pot_gain_rad[1] (t5)"), std::string::npos);
  c = plausible();
  c.encoder_offset_rad[2] = 1e308;
  EXPECT_NE(refused(c).find("encoder_offset_rad[2] (t3)"), std::string::npos);
  c = plausible();
  c.pot_offset_rad[0] = std::nan("");
  EXPECT_NE(refused(c).find("pot_offset_rad[0] (t4)"), std::string::npos);
  c = plausible();
  c.pot_offset_rad[2] = 20.0;
  EXPECT_NE(refused(c).find("pot_offset_rad[2] (t6)"), std::string::npos);
  // and nothing implausible is stored
  StoredCalibration s;
  s.calibration.pot_gain_rad = {1, 1, 1};
  s.serial = "bad";
  EXPECT_THROW(save_calibration(s), CalibrationError);
  EXPECT_FALSE(fs::exists(calibration_path("bad")));
}

TEST_F(StoreTest, WhatIsNotARegularFileIsRefusedUnread) {
  const std::string path = calibration_path("fifo");
  fs::create_directories(fs::path(path).parent_path());
  ASSERT_EQ(mkfifo(path.c_str(), 0600), 0);
  EXPECT_NE(refusal("fifo").find("not a regular file"), std::string::npos);
  fs::remove(path);
  fs::create_directory(path);
  EXPECT_NE(refusal("fifo").find("not a regular file"), std::string::npos);
}

TEST_F(StoreTest, AHugeFileIsRefusedUnread) {
  write("big", std::string(2 << 20, ' '));
  EXPECT_NE(refusal("big").find("is 2 MiB, over the reader's bound of 1 MiB"),
            std::string::npos)
      << refusal("big");
}

TEST(CalibrationPath, ASerialCannotLeaveTheFolder) {
  const std::string p = calibration_path("../../../etc/passwd");
  EXPECT_EQ(fs::path(p).parent_path(), fs::path(calibration_dir()));
  EXPECT_EQ(fs::path(p).filename(), ".._.._.._etc_passwd.json");
}

}  // namespace
}  // namespace vmh::runtime
