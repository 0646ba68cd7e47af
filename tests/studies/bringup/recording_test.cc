// studies/bringup/recording: a trace written by hand, read back; a bad one
// refused with the file and the cause named.
#include "studies/bringup/recording.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

namespace vmh::bringup {
namespace {

namespace fs = std::filesystem;

fs::path make_dir(const std::string& name) {
  const fs::path d = fs::path(::testing::TempDir()) / ("rec_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

void write(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

const char* kHeader =
    "t_s,period_s,q1_rad,q2_rad,q3_rad,q4_rad,q5_rad,q6_rad,tau_sent_1_Nm,"
    "tau_sent_2_Nm,tau_sent_3_Nm,read_error,dev_p_x_mm,dev_p_y_mm,dev_p_z_mm\n";

TEST(Recording, ReadsNumbersTextAndNaN) {
  const fs::path d = make_dir("ok");
  write(d / "meta.json", R"({"verb": "hw record"})");
  write(d / "trace.csv", std::string(kHeader) +
                             "0,0,0.1,0.2,0.3,0.4,0.5,0.6,0,0,0.01,ok,1,2,3\n"
                             "0.001,0.001,nan,nan,nan,nan,nan,nan,0,0,0,timeout,nan,nan,nan\n"
                             "0.002,0.001,0.1,0.2,0.3,0.4,0.5,0.6,0,0,0.02,ok,1.5,2,3\n");
  const Recording r = load_recording(d.string());
  EXPECT_EQ(r.verb, "hw record");
  ASSERT_EQ(r.rows, 3u);
  EXPECT_DOUBLE_EQ(r.q_dh_rad(2)[5], 0.6);
  EXPECT_TRUE(std::isnan(r.col("q1_rad")[1]));
  EXPECT_EQ(r.text_col("read_error")[1], "timeout");
  EXPECT_EQ(r.good_rows(), (std::vector<std::size_t>{0, 2}));
  EXPECT_TRUE(r.has_transform());
  EXPECT_FALSE(r.has_jacobian());
  EXPECT_DOUBLE_EQ(r.dev_p_mm(2).x(), 1.5);
  EXPECT_DOUBLE_EQ(r.tau_sent_Nm(2)[2], 0.02);
  EXPECT_EQ(r.emulator_scene(), "");  // a device names no scene
}

TEST(Recording, TheEmulatorsSceneComesFromMeta) {
  const fs::path d = make_dir("emu");
  write(d / "meta.json", R"({"verb": "hw motor-test", "emulator": {"scene": "/m/case2.xml"}})");
  write(d / "trace.csv", std::string(kHeader) +
                             "0,0,0.1,0.2,0.3,0.4,0.5,0.6,0,0,0.01,ok,1,2,3\n");
  EXPECT_EQ(load_recording(d.string()).emulator_scene(), "/m/case2.xml");
}

TEST(Recording, ALastRowCutShortIsDropped) {
  const fs::path d = make_dir("cut");
  write(d / "meta.json", R"({"verb": "hw run"})");
  write(d / "trace.csv", std::string(kHeader) +
                             "0,0,0.1,0.2,0.3,0.4,0.5,0.6,0,0,0.01,ok,1,2,3\n"
                             "0.001,0.001,0.1,0.2\n");
  EXPECT_EQ(load_recording(d.string()).rows, 1u);
}

TEST(Recording, BadInputNamesTheFileAndTheCause) {
  auto message = [](const fs::path& d) {
    try {
      load_recording(d.string());
    } catch (const RecordingError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const fs::path none = make_dir("none");
  EXPECT_NE(message(none).find("meta.json"), std::string::npos);
  const fs::path bad = make_dir("bad");
  write(bad / "meta.json", R"({"verb": "hw record"})");
  write(bad / "trace.csv", std::string(kHeader) +
                               "0,0,0.1,x,0.3,0.4,0.5,0.6,0,0,0.01,ok,1,2,3\n"
                               "0,0,0.1,0.2,0.3,0.4,0.5,0.6,0,0,0.01,ok,1,2,3\n");
  EXPECT_NE(message(bad).find("'q2_rad': not a number"), std::string::npos) << message(bad);
  const fs::path nocol = make_dir("nocol");
  write(nocol / "meta.json", R"({"verb": "hw record"})");
  write(nocol / "trace.csv", "t_s,q1_rad\n0,0\n");
  EXPECT_NE(message(nocol).find("no column 'q6_rad'"), std::string::npos) << message(nocol);
  const fs::path nojson = make_dir("nojson");
  write(nojson / "meta.json", "{");
  EXPECT_NE(message(nojson).find("not valid JSON"), std::string::npos);
}

}  // namespace
}  // namespace vmh::bringup
