// docs/bringup.md runs: every ```sh block of the page, in order, as one
// bash script against the emulator, with `vmhaptics` the built program.
// So the procedure a user follows is the one CI ran.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/cli_run.h"

namespace {

namespace fs = std::filesystem;

const std::string kDoc = std::string(VMH_SOURCE_DIR) + "/docs/bringup.md";

std::vector<std::string> sh_blocks(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> blocks;
  std::string line, block;
  bool inside = false;
  while (std::getline(in, line)) {
    if (!inside && line == "```sh") {
      inside = true;
      block.clear();
    } else if (inside && line == "```") {
      inside = false;
      blocks.push_back(block);
    } else if (inside) {
      block += line + "\n";
    }
  }
  return blocks;
}

nlohmann::json read_json(const fs::path& p) {
  std::ifstream in(p);
  return nlohmann::json::parse(in);
}

// the order: list, probe, calibrate, record, compare, motor-test,
// compare, identify, hw run at 0.2 gains, hw run at full gains
TEST(BringupDoc, StepsComeInTheProceduresOrder) {
  std::string all;
  for (const std::string& b : sh_blocks(kDoc)) all += b;
  std::size_t at = 0;
  for (const char* step :
       {"vmhaptics hw list", "vmhaptics hw probe", "vmhaptics hw calibrate",
        "vmhaptics hw record", "vmhaptics compare bringup/record ",
        "vmhaptics hw motor-test", "vmhaptics compare bringup/record bringup/motor1",
        "vmhaptics identify", "--gain-scale 0.2", "vmhaptics hw run case1 --device \"$DEVICE\" --out bringup/run-full"}) {
    const std::size_t next = all.find(step, at);
    ASSERT_NE(next, std::string::npos) << "step missing or out of order: " << step;
    at = next;
  }
}

TEST(BringupDoc, RunsEndToEndOnTheEmulator) {
  const fs::path dir = vmh::testing::fresh_dir("bringup_doc_", "run");
  fs::create_directories(dir / "bin");
  fs::create_symlink(VMH_CLI_PATH, dir / "bin" / "vmhaptics");
  std::ofstream script(dir / "bringup.sh");
  script << "set -euo pipefail\n";
  for (const std::string& b : sh_blocks(kDoc)) script << b;
  script.close();
  const std::string cmd = "cd " + dir.string() + " && PATH=" + (dir / "bin").string() +
                          ":$PATH DEVICE=emulator XDG_CONFIG_HOME=" +
                          (dir / "config").string() + " bash bringup.sh > log.txt 2>&1";
  const int status = std::system(cmd.c_str());
  ASSERT_EQ(status, 0) << "the procedure failed; its output:\n"
                       << vmh::testing::read_file(dir / "log.txt");

  // what each step left behind says what the page says it shows
  const fs::path b = dir / "bringup";
  EXPECT_NEAR(read_json(b / "probe.json")["rate_Hz"].get<double>(), 1000.0, 200.0);
  for (const char* c : {"compare-kinematics", "compare-force", "compare-run"}) {
    const nlohmann::json j = read_json(b / c / "compare.json");
    EXPECT_TRUE(j["pass"].get<bool>()) << c;
    EXPECT_TRUE(j["suspected_faults"].empty()) << c << ": " << j["suspected_faults"];
    EXPECT_FALSE(j["checks"].empty()) << c;
  }
  const nlohmann::json id = read_json(b / "identify" / "identify.json");
  EXPECT_TRUE(fs::exists(b / "omni-calibrated.xml"));
  EXPECT_FALSE(id.empty());
  EXPECT_TRUE(fs::exists(b / "run-full" / "trace.csv"));
}

}  // namespace
