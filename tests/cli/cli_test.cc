// The command line as a user runs it: its JSON contract and its errors.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "tests/support/cli_run.h"
#include "tests/support/openhaptics_reference.h"

namespace vmh {
namespace {

using nlohmann::json;

using testing::CliRun;
using testing::run;

Vec3 vec3(const json& j) { return Vec3(j[0], j[1], j[2]); }

Mat3 mat3(const json& j) {
  Mat3 m;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m(r, c) = j[r][c];
  }
  return m;
}

Joints joints(const json& j) {
  Joints q;
  for (int i = 0; i < 6; ++i) q[i] = j[i];
  return q;
}

TEST(CliKin, FkPrintsTheDocumentedFields) {
  const CliRun r = run("kin fk --q 0.1,0.2,0.3,0.4,0.5,0.6");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json j = json::parse(r.out);
  for (const char* key : {"q_dh", "q_device", "p_base_m", "R_base",
                          "p_device_mm", "axis_device", "frames"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_EQ(j["q_dh"].size(), 6u);
  EXPECT_EQ(j["frames"].size(), 7u);
  // the OpenHaptics reference at the same pose in device joint angles
  Joints t;
  t << -0.1, 0.2, 0.5, -0.4, 0.5, -0.6;
  const Vec3 expect = testing::openhaptics_wrist_mm(t, 133.35, 133.35);
  EXPECT_LE((vec3(j["p_device_mm"]) - expect).norm(), 1e-9);
  const Mat3 R_dev = testing::openhaptics_stylus_rotation(t);
  EXPECT_LE((mat3(j["R_device"]) - R_dev).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LE((vec3(j["axis_device"]) - R_dev.col(2)).norm(), 1e-12);
  EXPECT_LE((joints(j["q_device"]) - t).norm(), 1e-15);
  const Mat3 R = mat3(j["R_base"]);
  EXPECT_LE((R_device_base() * R - R_dev).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(CliKin, DeviceConventionConvertsJointThree) {
  const CliRun r = run("kin fk --convention device --q 0.1,0.2,0.5,0,0,0");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json j = json::parse(r.out);
  const Joints q = joints(j["q_dh"]);
  EXPECT_NEAR(q[0], -0.1, 1e-15);
  EXPECT_NEAR(q[2], 0.3, 1e-15);
}

TEST(CliKin, JacobianMatchesTheLibrary) {
  const CliRun r =
      run("kin jac --q 0.1,0.2,0.3,0.4,0.5,0.6 --tool-offset-mm -20");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json j = json::parse(r.out);
  Joints q;
  q << 0.1, 0.2, 0.3, 0.4, 0.5, 0.6;
  const OmniParams p;
  const Mat6 J = omni_jacobian(p, q), Jt = omni_jacobian_at(p, q, -0.02);
  ASSERT_EQ(j["J_base"].size(), 6u);
  for (int r6 = 0; r6 < 6; ++r6) {
    ASSERT_EQ(j["J_base"][r6].size(), 6u);
    for (int c = 0; c < 6; ++c) {
      EXPECT_DOUBLE_EQ(j["J_base"][r6][c].get<double>(), J(r6, c) + 0.0);
      EXPECT_DOUBLE_EQ(j["J_tool_base"][r6][c].get<double>(), Jt(r6, c) + 0.0);
    }
  }
}

TEST(CliKin, IkSolutionsReachTheTargetAndNearestIsTheSource) {
  // device frame target made from a known configuration
  const OmniParams p;
  Joints q;
  q << 0.2, 0.3, 0.4, 0, 0, 0;
  const Vec3 target_mm = base_to_device_mm(p, omni_fk(p, q).p_base_m);
  std::ostringstream args;
  args.precision(17);
  args << "kin ik --p-device-mm " << target_mm[0] << "," << target_mm[1] << ","
       << target_mm[2] << " --near 0.2,0.3,0.4,0,0,0";
  const CliRun r = run(args.str());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["status"], "ok");
  ASSERT_EQ(j["solutions"].size(), 4u);
  for (const json& s : j["solutions"]) {
    const Vec3 got = base_to_device_mm(p, omni_fk(p, joints(s)).p_base_m);
    EXPECT_LE((got - target_mm).norm(), 1e-9);
  }
  EXPECT_LE((joints(j["nearest"]) - q).norm(), 1e-9);
}

TEST(CliKin, UnreachableTargetIsReportedNotNaN) {
  const CliRun r = run("kin ik --p-device-mm 0,0,400");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["status"], "unreachable");
  EXPECT_TRUE(j["solutions"].empty());
  EXPECT_TRUE(j["nearest"].is_null());
  EXPECT_GT(j["reach_excess_mm"].get<double>(), 0.0);
}

// bad input: one line on stderr naming what was wrong, nothing on stdout,
// exit code 2
void expect_usage_error(const std::string& args, const std::string& needle) {
  const CliRun r = run(args);
  EXPECT_EQ(r.exit_code, 2) << args;
  EXPECT_TRUE(r.out.empty()) << args << " printed " << r.out;
  EXPECT_NE(r.err.find("vmhaptics: error:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(needle), std::string::npos)
      << args << ": '" << r.err << "' lacks '" << needle << "'";
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "not one line: " << r.err;
}

TEST(CliErrors, BadInputIsOneLineNamingTheProblem) {
  expect_usage_error("kin fk --q 0.1,0.2,0.3", "expected 6");
  expect_usage_error("kin fk --q 0.1,0.2,x,0.4,0.5,0.6",
                     "item 3 'x' is not a number");
  expect_usage_error("kin fk --q 0.1,0.2,nan,0.4,0.5,0.6",
                     "not a finite number");
  expect_usage_error("kin fk --q 0.1,0.2,0.3,0.4,0.5,inf",
                     "not a finite number");
  expect_usage_error("kin fk --q 0.1,,0.3,0.4,0.5,0.6", "item 2 is empty");
  expect_usage_error("kin fk", "--q");
  expect_usage_error("kin fk --q 0,0,0,0,0,0 --convention xyz", "--convention");
  expect_usage_error("kin ik", "--p-device-mm");
  expect_usage_error("kin ik --p-device-mm 1,2", "--p-device-mm: expected 3");
  // a hint so large that whole turns cannot be told apart (it returned
  // "ok" with q1 = 1e17, 86 mm from the target)
  expect_usage_error("kin ik --p-device-mm 0,-65.51,-88.11 --near 1e17,0,0,0,0,0",
                     "--near: q1 = 1e+17 rad is beyond");
  expect_usage_error("kin ik --p-device-mm 0,0,0 --R-base 1,0,0,0,1,0,0,0,2",
                     "--R-base");
  expect_usage_error("kin jac --q 0,0,0,0,0,0 --tool-offset-mm abc",
                     "--tool-offset-mm");
  expect_usage_error("nosuchverb", "unknown verb 'nosuchverb'");
  expect_usage_error("kin fkk --q 0,0,0,0,0,0",
                     "unknown verb 'fkk' for 'vmhaptics kin'");
}

TEST(CliErrors, NegativeNumbersAreAccepted) {
  const CliRun r = run("kin fk --q=-0.1,-0.2,0.3,0.4,0.5,0.6");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_DOUBLE_EQ(json::parse(r.out)["q_dh"][0].get<double>(), -0.1);
}

// strtod sets ERANGE for a subnormal result too: such a number was refused
// as "not a finite number"; an overflow to inf still is (issue 17)
TEST(CliErrors, SubnormalNumbersAreAccepted) {
  const CliRun r = run("kin fk --q 1e-320,0.2,0.3,0.4,0.5,0.6");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(json::parse(r.out)["q_dh"][0].get<double>(), 1e-320);
  expect_usage_error("kin fk --q 1e999,0.2,0.3,0.4,0.5,0.6",
                     "item 1 '1e999' is not a finite number");
}

// CLI11 reads an empty value of a numeric option as 0, which for most
// options is their default: refused instead, on every verb
TEST(CliErrors, AnEmptyNumberIsRefused) {
  expect_usage_error("study stability --mass '' --damping 2",
                     "--mass: the value is empty");
  expect_usage_error("run case1 --jobs ''", "--jobs: the value is empty");
  expect_usage_error("run case1 --duration ' '", "--duration");
  expect_usage_error("ctl --ticks '' --q 0,0,0,0,0,0", "--ticks");
}

TEST(CliHelp, HelpExitsZero) {
  const CliRun r = run("--help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("kin"), std::string::npos);
}

}  // namespace
}  // namespace vmh
