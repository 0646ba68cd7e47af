// `--emulator-fault` and `--model`, as a user runs them: the emulator's
// seeded faults recorded only as its hidden setup in meta.json, the
// device's own kinematics in the trace, bad names and files refused with
// exit 2 and one line naming them; `run --model`. hw record runs in real
// time: half a second each.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/support/cli_run.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using vmh::testing::run;

// a private calibration store, so that no test reads another's
const std::string kEnv =
    "XDG_CONFIG_HOME=" + ::testing::TempDir() + "vmh_emufault_cfg ";
const std::string kOmni = std::string(VMH_MODELS_DIR) + "/omni/omni.xml";

fs::path fresh_dir(const std::string& name) {
  return vmh::testing::fresh_dir("vmh_emufault_", name);
}


int lines(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n' ? 1 : 0;
  return n;
}

TEST(HwEmulatorFault, RecordKeepsTheFaultsHiddenInMeta) {
  const fs::path out = fresh_dir("record");
  const auto r = run("hw record --duration 0.5 --quiet --out " + out.string() +
                         " --emulator-fault joint1_sign,gimbal_swap --model " + kOmni,
                     kEnv);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json meta = json::parse(vmh::testing::read_file(out / "meta.json"));
  const json& emu = meta.at("emulator");
  EXPECT_EQ(emu.at("seeded_faults"), json({"joint1_sign", "gimbal_swap"}));
  EXPECT_EQ(emu.at("hand"), "tour");
  EXPECT_EQ(emu.at("model"), fs::absolute(kOmni).string());
  const fs::path scene = emu.at("scene").get<std::string>();
  EXPECT_TRUE(scene.is_absolute()) << scene;
  EXPECT_TRUE(fs::exists(scene)) << scene;
  EXPECT_EQ(scene.filename(), "case1.xml");
  // the device's own kinematics are in the trace; the faults are not in
  // the trace or on stdout
  const std::string trace = vmh::testing::read_file(out / "trace.csv");
  const std::string header = trace.substr(0, trace.find('\n'));
  for (const char* c : {"dev_p_x_mm", "dev_R_33", "dev_v_z_mm_s", "dev_J_11", "dev_J_66"}) {
    EXPECT_NE(header.find(c), std::string::npos) << c;
  }
  EXPECT_GT(lines(trace), 100);
  for (const std::string& text : {trace, r.out, r.err}) {
    EXPECT_EQ(text.find("joint1_sign"), std::string::npos);
    EXPECT_EQ(text.find("gimbal_swap"), std::string::npos);
  }
}

TEST(HwEmulatorFault, WithoutFaultsMetaHasTheSetupAndAnEmptyList) {
  const fs::path out = fresh_dir("plain");
  const auto r = run("hw record --duration 0.5 --quiet --out " + out.string(), kEnv);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json emu = json::parse(vmh::testing::read_file(out / "meta.json")).at("emulator");
  EXPECT_TRUE(emu.at("seeded_faults").empty());
  EXPECT_TRUE(emu.at("model").is_null());
}

TEST(HwEmulatorFault, BadNameIsRefusedNamingIt) {
  const fs::path out = fresh_dir("bad");
  const auto r = run("hw record --duration 0.5 --out " + out.string() +
                         " --emulator-fault joint1_sign,joint9_sign",
                     kEnv);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("joint9_sign"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out / "meta.json"));
  // a delay that is not whole periods, on another verb
  const auto d = run("hw probe --emulator-fault delay_2.5ms", kEnv);
  EXPECT_EQ(d.exit_code, 2);
  EXPECT_NE(d.err.find("delay_2.5ms"), std::string::npos) << d.err;
  EXPECT_NE(d.err.find("servo periods"), std::string::npos) << d.err;
}

TEST(HwEmulatorFault, OnlyTheEmulatorTakesThem) {
  for (const std::string& flags :
       {std::string("--emulator-fault joint1_sign"), "--model " + kOmni}) {
    const auto r = run("hw record --duration 0.5 --device openhaptics " + flags, kEnv);
    EXPECT_EQ(r.exit_code, 2) << flags;
    EXPECT_EQ(lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(flags.substr(0, flags.find(' '))), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("emulator"), std::string::npos) << r.err;
  }
}

TEST(HwEmulatorFault, MissingOrBadModelFileIsNamed) {
  const fs::path dir = fresh_dir("badmodel");
  fs::create_directories(dir);
  const fs::path bad = dir / "broken.xml";
  std::ofstream(bad) << "<mujoco><worldbody><body";
  for (const std::string& file : {std::string("/nonexistent.xml"), bad.string()}) {
    for (const std::string verb :
         {"hw record --duration 0.5", "hw run case1 --duration 0.5", "run case1"}) {
      const auto r = run(verb + " --model " + file, kEnv);
      EXPECT_EQ(r.exit_code, 2) << verb << " " << file;
      EXPECT_EQ(lines(r.err), 1) << r.err;
      EXPECT_NE(r.err.find(file), std::string::npos) << verb << ": " << r.err;
    }
  }
}

// the scene's own Omni as --model: the same parameters, so the same run
TEST(RunModel, SameOmniGivesTheSameRun) {
  const fs::path with = fresh_dir("run_model");
  const fs::path without = fresh_dir("run_plain");
  const auto a = run("run case1 --model " + kOmni + " --out " + with.string());
  ASSERT_EQ(a.exit_code, 0) << a.err;
  const auto b = run("run case1 --out " + without.string());
  ASSERT_EQ(b.exit_code, 0) << b.err;
  const json sa = json::parse(vmh::testing::read_file(with / "case1" / "summary.json"));
  const json sb = json::parse(vmh::testing::read_file(without / "case1" / "summary.json"));
  EXPECT_EQ(sa.at("model"), fs::absolute(kOmni).string());
  EXPECT_TRUE(sb.at("model").is_null());
  EXPECT_EQ(sa.at("metrics"), sb.at("metrics"));
}

}  // namespace
