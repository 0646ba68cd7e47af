// `vmhaptics ctl` as a user runs it: its JSON contract, its errors, and the
// control law checked against formulas written out here (the nearest point
// of a circle, eq. 3.11 for a 1-DOF VM, tau = J^T F) rather than against
// the controller's own code.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "controller/controller.h"
#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "tests/support/cli_run.h"
#include "tests/support/constants.h"

namespace vmh {
namespace {

using nlohmann::json;
using testing::CliRun;
using testing::run;

using vmh::testing::kPi;

Vec3 ctl_vec3(const json& j) { return Vec3(j[0], j[1], j[2]); }

Vec6 vec6(const json& j) {
  Vec6 v;
  for (int i = 0; i < 6; ++i) v[i] = j[i];
  return v;
}

std::string list(const Eigen::VectorXd& v) {
  std::ostringstream s;
  s.precision(17);
  for (Eigen::Index i = 0; i < v.size(); ++i) s << (i ? "," : "") << v[i];
  return s.str();
}

// `--q=...` (the = lets the list start with a minus sign)
std::string q_arg(const Joints& q) { return "--q=" + list(q); }

// the arm angles that put the wrist centre at p_device_mm, the wrist angles
// q4..q6 given; through the project's IK, nearest the zero arm pose
Joints joints_at(const Vec3& p_device_mm, const Vec3& wrist) {
  const OmniParams p;
  Joints near = Joints::Zero();
  near.tail<3>() = wrist;
  const IkSolutions s =
      omni_ik_position(p, device_mm_to_base(p, p_device_mm), near);
  const int k = omni_ik_nearest(s, near);
  EXPECT_GE(k, 0) << "unreachable: " << p_device_mm.transpose();
  return k >= 0 ? s.q_dh[static_cast<std::size_t>(k)] : near;
}

// a successful run's JSON
json ctl(const std::string& args) {
  const CliRun r = run("ctl " + args);
  EXPECT_EQ(r.exit_code, 0) << args << ": " << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  return r.out.empty() ? json::object() : json::parse(r.out);
}

// Case 1 of the thesis (kornt 0) on a circle of L = 50 mm about a pivot off
// the origin: the wrist centre 2 mm outside the circle and 2 mm off its
// plane, where the force stays inside every limit.
const Vec3 kPivot(-5.0, -10.0, 0.0);
const std::string kPivotArg = "--pivot-mm=-5,-10,0";
const double kAngle = kPi / 3;
Vec3 case1_target() {
  return kPivot + 52.0 * Vec3(std::cos(kAngle), std::sin(kAngle), 0.0) +
         Vec3(0, 0, 2.0);
}
Joints case1_q() { return joints_at(case1_target(), Vec3(0.3, 0.8, 0.0)); }

// Case 2 (kornt 0.5) with the wrist centre on the circle about the origin
// and the stylus turned away from the radial direction.
Joints case2_q() {
  return joints_at(Vec3(30.0, 40.0, 0.0), Vec3(0.3, 0.8, 0.0));
}

TEST(CtlJson, EveryVmPrintsTheDocumentedKeysInOrder) {
  const std::vector<std::string> keys = {"vm",
                                         "q_dh",
                                         "q_device",
                                         "error_formulation",
                                         "placement",
                                         "length_unit_mm",
                                         "gains",
                                         "p_rm_mm",
                                         "axis_rm",
                                         "theta_v",
                                         "theta_r",
                                         "x_v_mm",
                                         "x_r_mm",
                                         "e",
                                         "e_units",
                                         "e_dot",
                                         "f_motion",
                                         "f_motion_units",
                                         "force_device_N",
                                         "force_base_N",
                                         "tau_Nm",
                                         "tau_motor_Nm",
                                         "placement_iterations",
                                         "placement_cost",
                                         "vm_rcond",
                                         "status",
                                         "status_code"};
  const struct {
    const char* vm;
    std::size_t dof;
  } vms[] = {{"circle", 1}, {"sphere", 3}, {"surface", 5}};
  for (const auto& c : vms) {
    const CliRun r = run(std::string("ctl --vm ") + c.vm +
                         " --kornt 0.5 --q 0.1,0.2,0.3,0.4,0.5,0.6");
    ASSERT_EQ(r.exit_code, 0) << c.vm << ": " << r.err;
    const auto j = nlohmann::ordered_json::parse(r.out);
    std::vector<std::string> got;
    for (auto it = j.begin(); it != j.end(); ++it) got.push_back(it.key());
    EXPECT_EQ(got, keys) << c.vm;
    EXPECT_EQ(j["vm"], c.vm);
    EXPECT_EQ(j["theta_v"].size(), c.dof) << c.vm;
    EXPECT_EQ(j["theta_r"].size(), c.dof) << c.vm;
    for (const char* k : {"q_dh", "q_device", "e", "e_units", "e_dot",
                          "f_motion", "f_motion_units"}) {
      EXPECT_EQ(j[k].size(), 6u) << c.vm << " " << k;
    }
    for (const char* k :
         {"p_rm_mm", "axis_rm", "x_v_mm", "x_r_mm", "force_device_N",
          "force_base_N", "tau_Nm", "tau_motor_Nm"}) {
      EXPECT_EQ(j[k].size(), 3u) << c.vm << " " << k;
    }
    EXPECT_EQ(j["gains"].size(), 4u);
    EXPECT_EQ(j["error_formulation"], "thesis");
    EXPECT_EQ(j["placement"], "gauss-newton");
    // the status names are the set bits of status_code
    const auto code = j["status_code"].get<std::uint32_t>();
    std::uint32_t from_names = 0;
    for (const auto& name : j["status"]) {
      int bit = -1;
      for (int b = 0; b < kStatusFlagCount; ++b) {
        if (name == status_flag_name(1u << b)) bit = b;
      }
      if (name == "ok") {
        EXPECT_EQ(code, 0u);
        EXPECT_EQ(j["status"].size(), 1u);
      } else {
        ASSERT_GE(bit, 0) << name;
        from_names |= 1u << bit;
      }
    }
    EXPECT_EQ(from_names, code) << c.vm;
    // one tick: no previous error, so no rate
    EXPECT_EQ(vec6(j["e_dot"]), Vec6::Zero()) << c.vm;
  }
}

TEST(CtlJson, GainsFollowEq328) {
  const json j =
      ctl("--length-mm 40 --kpos 0.3 --kornt 0.5 --kv 0.002 "
          "--q 0.1,0.2,0.3,0.4,0.5,0.6");
  const json& g = j["gains"];
  EXPECT_DOUBLE_EQ(g["k_pos_N_per_mm"].get<double>(), 0.3);
  EXPECT_NEAR(g["k_ornt_Nmm_per_rad"].get<double>(), 0.5 * 2 * kPi * 40, 1e-12);
  EXPECT_DOUBLE_EQ(g["k_vel_Ns_per_mm"].get<double>(), 0.002);
  // --kv is the position rows' K_v only, as a scene's k_vel_Ns_per_mm (it
  // used to set the orientation rows to kv x 2 pi L as well)
  EXPECT_EQ(g["k_vel_ornt_Nmms_per_rad"].get<double>(), 0.0);
}

// The orientation rows' K_v is its own option, in N mm s/rad; the old --kv
// behaviour is --kv-ornt = kv x 2 pi L.
TEST(CtlJson, OrientationDampingIsItsOwnOption) {
  const double kv = 0.002, L = 40.0;
  std::ostringstream args;
  args.precision(17);
  args << "--length-mm " << L << " --kv " << kv << " --kv-ornt "
       << kv * 2 * kPi * L << " --q 0.1,0.2,0.3,0.4,0.5,0.6";
  const json j = ctl(args.str());
  const json& g = j["gains"];
  EXPECT_DOUBLE_EQ(g["k_vel_Ns_per_mm"].get<double>(), kv);
  EXPECT_NEAR(g["k_vel_ornt_Nmms_per_rad"].get<double>(), kv * 2 * kPi * L,
              1e-15);
  const json o = ctl("--kv-ornt 3 --q 0.1,0.2,0.3,0.4,0.5,0.6");
  const json& only = o["gains"];
  EXPECT_EQ(only["k_vel_Ns_per_mm"].get<double>(), 0.0);
  EXPECT_EQ(only["k_vel_ornt_Nmms_per_rad"].get<double>(), 3.0);
}

// The controller settings ctl gained from the table change what it computes:
// the force limit saturates, the servo period is accepted.
TEST(CtlOptions, ForceLimitFromTheTable) {
  const std::string q = " --q 0.1,0.2,0.3,0.4,0.5,0.6";
  const json free = ctl("--kpos 2" + q);
  const double f = ctl_vec3(free["force_device_N"]).norm();
  ASSERT_GT(f, 0.2);
  const json capped = ctl("--kpos 2 --force-limit-N 0.1" + q);
  EXPECT_NEAR(ctl_vec3(capped["force_device_N"]).norm(), 0.1, 1e-12);
  EXPECT_NE(std::find(capped["status"].begin(), capped["status"].end(),
                      "force_saturated"),
            capped["status"].end());
  EXPECT_NO_THROW(ctl("--servo-period-s 0.002 --projection-weights "
                      "1,1,1,2,2,2" + q));
}

TEST(CtlCircle, CaseOneForceIsKposTimesTheErrorToTheNearestPoint) {
  const Joints q = case1_q();
  const json j = ctl(kPivotArg + " --kpos 0.2 " + q_arg(q));
  ASSERT_EQ(j["status"], json::array({"ok"})) << j.dump();
  // the RM is the forward kinematics of q
  const OmniParams p;
  EXPECT_LE((ctl_vec3(j["p_rm_mm"]) - case1_target()).norm(), 1e-9);
  EXPECT_LE((ctl_vec3(j["p_rm_mm"]) - base_to_device_mm(p, omni_fk(p, q).p_base_m))
                .norm(),
            1e-12);
  // X(theta_V) is the nearest point of the circle: the pivot plus L along
  // the RM's projection into the plane
  const Vec3 x_v = ctl_vec3(j["x_v_mm"]);
  const Vec3 expect_x_v =
      kPivot + 50.0 * Vec3(std::cos(kAngle), std::sin(kAngle), 0.0);
  EXPECT_LE((x_v - expect_x_v).norm(), 1e-8);
  EXPECT_NEAR(j["theta_v"][0].get<double>(), kAngle, 1e-9);
  // with no orientation gain the error is normal to the path, so eq. 3.11
  // passes K_pos e through unchanged
  const Vec3 F = ctl_vec3(j["force_device_N"]);
  const Vec3 expect_F = 0.2 * (x_v - ctl_vec3(j["p_rm_mm"]));
  EXPECT_LE((F - expect_F).norm(), 1e-9) << F.transpose();
  EXPECT_NEAR(F.norm(), 0.2 * std::sqrt(8.0), 1e-8);
  EXPECT_LE((vec6(j["f_motion"]).head<3>() - expect_F).norm(), 1e-9);
  EXPECT_LE(vec6(j["f_motion"]).tail<3>().norm(), 1e-9);
}

// eq. 3.12: tau = J_r^T F with the wrist-centre Jacobian's linear rows and
// the force in the base frame
void expect_tau_is_jacobian_transpose_force(const json& j, const Joints& q) {
  const OmniParams p;
  const Vec3 F = ctl_vec3(j["force_device_N"]);
  const Vec3 F_base = device_to_base_vector(F);
  EXPECT_LE((ctl_vec3(j["force_base_N"]) - F_base).norm(), 1e-12);
  const Mat6 J = omni_jacobian(p, q);
  const Vec3 tau = J.topLeftCorner<3, 3>().transpose() * F_base;
  EXPECT_LE((ctl_vec3(j["tau_Nm"]) - tau).norm(), 1e-12) << tau.transpose();
  EXPECT_GT(tau.norm(), 1e-3);  // not trivially zero
}

TEST(CtlCircle, TorqueIsJacobianTransposeTimesForce) {
  const Joints q1 = case1_q();
  expect_tau_is_jacobian_transpose_force(
      ctl(kPivotArg + " --kpos 0.2 " + q_arg(q1)), q1);
  // also where the motor limits scale the force down
  const Joints q2 = case2_q();
  const json j = ctl("--kornt 0.5 " + q_arg(q2));
  EXPECT_EQ(j["status"], json::array({"torque_saturated"})) << j.dump();
  expect_tau_is_jacobian_transpose_force(j, q2);
}

TEST(CtlConvention, DeviceAnglesGiveTheSameTick) {
  Joints q;
  q << 0.1, 0.2, 0.3, 0.4, 0.5, 0.6;
  const Joints t = dh_to_device_joints(q);
  for (const char* vm : {"circle", "sphere", "surface"}) {
    const std::string common = std::string("--vm ") + vm + " --kornt 0.5 ";
    const json a = ctl(common + q_arg(q));
    const json b = ctl(common + "--convention device " + q_arg(t));
    EXPECT_LE((vec6(b["q_dh"]) - q).norm(), 1e-15) << vm;
    EXPECT_LE((vec6(b["q_device"]) - t).norm(), 1e-15) << vm;
    for (const char* k : {"p_rm_mm", "x_v_mm", "x_r_mm", "force_device_N",
                          "tau_Nm", "tau_motor_Nm"}) {
      EXPECT_LE((ctl_vec3(a[k]) - ctl_vec3(b[k])).norm(), 1e-9) << vm << " " << k;
    }
    EXPECT_LE((vec6(a["f_motion"]) - vec6(b["f_motion"])).norm(), 1e-9) << vm;
    EXPECT_EQ(a["status"], b["status"]) << vm;
  }
}

TEST(CtlUnits, LengthUnitChangesTheProjectionButNotCaseOne) {
  // case 2 on the path: e has only the orientation row, and eq. 3.11 for
  // the circle's J_V = (L t, n) gives, with J_V^T J_V = L^2 + 1 in the
  // controller's unit, f = g - J_V (K e_z) / (L^2 + 1)
  const Joints q2 = case2_q();
  const double K_Nmm = 0.5 * 2 * kPi * 50;
  Vec3 f_pos[2];
  int n = 0;
  for (const double u : {1.0, 1000.0}) {
    std::ostringstream args;
    args << "--kornt 0.5 --length-unit-mm " << u << " " << q_arg(q2);
    const json j = ctl(args.str());
    const Vec6 e = vec6(j["e"]), f = vec6(j["f_motion"]);
    ASSERT_LE(e.head<5>().norm(), 1e-9) << "not on the path: " << e.transpose();
    ASSERT_GT(std::abs(e[5]), 0.1) << "no orientation error";
    const double L = 50.0 / u, K = K_Nmm / u;
    const double th = j["theta_v"][0];
    const Vec3 t(-std::sin(th), std::cos(th), 0.0);
    EXPECT_LE((f.head<3>() + L * t * K * e[5] / (L * L + 1)).norm(), 1e-9)
        << "u = " << u;
    EXPECT_NEAR(f[5], K * e[5] * L * L / (L * L + 1), 1e-9 * K);
    EXPECT_EQ(j["e_units"][0], u == 1.0 ? "mm" : "m");
    EXPECT_EQ(j["f_motion_units"][5], u == 1.0 ? "N*mm" : "N*m");
    f_pos[n++] = f.head<3>();
  }
  // the thesis's unit study: in metres the position force nearly vanishes
  EXPECT_GT(f_pos[0].norm(), 100 * f_pos[1].norm());

  // case 1: no orientation gain, so the unit changes nothing physical
  const Joints q1 = case1_q();
  const json mm = ctl(kPivotArg + " --kpos 0.2 " + q_arg(q1));
  const json m =
      ctl(kPivotArg + " --kpos 0.2 --length-unit-mm 1000 " + q_arg(q1));
  EXPECT_LE((ctl_vec3(mm["force_device_N"]) - ctl_vec3(m["force_device_N"])).norm(),
            1e-9);
  EXPECT_GT(ctl_vec3(mm["force_device_N"]).norm(), 0.1);
  EXPECT_LE((ctl_vec3(mm["x_v_mm"]) - ctl_vec3(m["x_v_mm"])).norm(), 1e-9);
  EXPECT_LE((vec6(mm["e"]).head<3>() / 1000 - vec6(m["e"]).head<3>()).norm(),
            1e-12);
  EXPECT_DOUBLE_EQ(m["length_unit_mm"].get<double>(), 1000.0);

  // any other unit is named as a multiple of the mm
  const json x = ctl("--length-unit-mm 2.5 --q 0.1,0.2,0.3,0.4,0.5,0.6");
  EXPECT_EQ(x["e_units"][0], "x2.5mm");
  EXPECT_EQ(x["f_motion_units"][3], "N*x2.5mm");
}

TEST(CtlOptions, ClosedFormPlacementAgreesWithGaussNewton) {
  const Joints q = case1_q();
  const json gn = ctl(kPivotArg + " --kpos 0.2 " + q_arg(q));
  const json cf = ctl(kPivotArg + " --kpos 0.2 --placement closed " + q_arg(q));
  EXPECT_EQ(cf["placement"], "closed");
  EXPECT_EQ(cf["placement_iterations"], 0);
  EXPECT_GE(gn["placement_iterations"].get<int>(), 1);
  EXPECT_NEAR(cf["theta_v"][0].get<double>(), gn["theta_v"][0].get<double>(),
              1e-9);
}

TEST(CtlOptions, OrientationWeightsPlaceTheVmAlongTheStylus) {
  // W_o (eq. 3.17): the placed VM is the aligned one, theta_V = theta_R
  const Joints q = case2_q();
  const json j = ctl("--weights 0,0,0,1,1,1 " + q_arg(q));
  const json plain = ctl(q_arg(q));
  const double tv = j["theta_v"][0], tr = j["theta_r"][0];
  EXPECT_NEAR(wrap_angle(tv - tr), 0.0, 1e-8);
  // with the default W_p they differ (the stylus is not radial here)
  EXPECT_GT(std::abs(wrap_angle(plain["theta_v"][0].get<double>() - tr)), 0.1);
}

TEST(CtlOptions, GeometricErrorIsTheRotationFromStylusToLink) {
  const std::string q = "--q 0.1,0.2,0.3,0.4,0.5,0.6";
  const json g = ctl("--vm sphere --error geometric " + q);
  const json t = ctl("--vm sphere " + q);
  EXPECT_EQ(g["error_formulation"], "geometric");
  const Vec3 a = ctl_vec3(g["axis_rm"]);
  const Vec3 link = ctl_vec3(g["x_v_mm"]).normalized();  // pivot at the origin
  const Vec3 c = a.cross(link);
  const Vec3 expect = std::atan2(c.norm(), a.dot(link)) * c.normalized();
  EXPECT_LE((vec6(g["e"]).tail<3>() - expect).norm(), 1e-9)
      << vec6(g["e"]).transpose();
  EXPECT_GT((vec6(g["e"]).tail<3>() - vec6(t["e"]).tail<3>()).norm(), 1e-3);
}

TEST(CtlOptions, SurfaceFrictionAndLiftOff) {
  const std::string q = "--q 0.1,0.2,0.3,0.4,0.5,0.6";
  const auto has = [](const json& j, const char* flag) {
    for (const auto& s : j["status"]) {
      if (s == flag) return true;
    }
    return false;
  };
  // mu = 0: the contact point is free (5-DOF VM); small mu: it is held,
  // the force leaves the friction cone and it slides (the same answer);
  // mu = inf: it is held, so J_V loses its two sliding columns
  const json free = ctl("--vm surface " + q);
  const json slips = ctl("--vm surface --mu 0.01 " + q);
  const json stuck = ctl("--vm surface --mu inf " + q);
  EXPECT_FALSE(has(free, "contact_sliding"));
  EXPECT_TRUE(has(slips, "contact_sliding")) << slips["status"];
  EXPECT_FALSE(has(stuck, "contact_sliding")) << stuck["status"];
  EXPECT_LE((vec6(free["f_motion"]) - vec6(slips["f_motion"])).norm(), 1e-9);
  EXPECT_GT((vec6(free["f_motion"]) - vec6(stuck["f_motion"])).norm(), 1.0);
  // the free VM matches the wrist position in the plane: no tangential
  // force. Here it pulls the stylus toward the plane; a unilateral plane
  // cannot pull, so the contact opens and the force is zero
  EXPECT_LE(vec6(free["f_motion"]).head<2>().norm(), 1e-6);
  ASSERT_LT(vec6(free["f_motion"])[2], -1.0);
  const json open = ctl("--vm surface --unilateral " + q);
  EXPECT_TRUE(has(open, "contact_open")) << open["status"];
  EXPECT_FALSE(has(free, "contact_open"));
  EXPECT_EQ(ctl_vec3(open["force_device_N"]), Vec3::Zero());
  EXPECT_EQ(vec6(open["f_motion"]), Vec6::Zero());
}

TEST(CtlOptions, RepeatedTicksReuseTheWarmStart) {
  const Joints q = case1_q();
  const json one = ctl(kPivotArg + " --kpos 0.2 " + q_arg(q));
  const json five = ctl(kPivotArg + " --kpos 0.2 --ticks 5 " + q_arg(q));
  // converged on the first tick: the later ones start at the answer
  EXPECT_LE(five["placement_iterations"].get<int>(), 1);
  EXPECT_LE((ctl_vec3(one["force_device_N"]) - ctl_vec3(five["force_device_N"])).norm(),
            1e-9);
  EXPECT_LE(vec6(five["e_dot"]).norm(), 1e-6);
  // a held contact that slid on the first tick has reached the point where
  // the force is inside the friction cone, so on the second it sticks
  const std::string surface =
      "--vm surface --mu 0.5 --q 0.1,0.2,0.3,0.4,0.5,0.6";
  const json first = ctl(surface);
  const json second = ctl(surface + " --ticks 2");
  EXPECT_NE(first["status"].dump().find("contact_sliding"), std::string::npos)
      << first["status"];
  EXPECT_EQ(second["status"].dump().find("contact_sliding"), std::string::npos)
      << second["status"];
  EXPECT_LE(std::hypot(first["theta_v"][0].get<double>() -
                           second["theta_v"][0].get<double>(),
                       first["theta_v"][1].get<double>() -
                           second["theta_v"][1].get<double>()),
            1e-9);
}

// bad input: one line on stderr naming what was wrong, nothing on stdout,
// exit code 2
void expect_ctl_usage_error(const std::string& args, const std::string& needle) {
  const CliRun r = run(args);
  EXPECT_EQ(r.exit_code, 2) << args;
  EXPECT_TRUE(r.out.empty()) << args << " printed " << r.out;
  EXPECT_NE(r.err.find("vmhaptics: error:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(needle), std::string::npos)
      << args << ": '" << r.err << "' lacks '" << needle << "'";
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "not one line: " << r.err;
}

TEST(CtlErrors, BadInputIsAUsageErrorNamingTheOption) {
  const std::string q = " --q 0,0,0,0,0,0";
  expect_ctl_usage_error("ctl --vm cube" + q,
                     "--vm: unknown value 'cube' (expected one of: circle, "
                     "sphere, surface, line)");
  expect_ctl_usage_error("ctl --q 0,0,0,0,0", "--q: expected 6");
  expect_ctl_usage_error("ctl --q 0,0,x,0,0,0", "item 3 'x' is not a number");
  expect_ctl_usage_error("ctl", "--q");
  expect_ctl_usage_error("ctl --length-mm 0" + q, "--length-mm");
  expect_ctl_usage_error("ctl --length-mm=-5" + q,
                     "--length-mm: field 'vm_length_mm' must be > 0");
  expect_ctl_usage_error("ctl --error foo" + q,
                     "--error: unknown value 'foo' (expected one of: thesis, "
                     "geometric)");
  expect_ctl_usage_error("ctl --placement newton" + q,
                     "--placement: unknown value 'newton'");
  expect_ctl_usage_error("ctl --kpos=-1" + q, "--kpos");
  expect_ctl_usage_error("ctl --kornt=-1" + q, "--kornt");
  expect_ctl_usage_error("ctl --kv abc" + q, "--kv");
  expect_ctl_usage_error("ctl --vm surface --mu=-0.5" + q, "--mu");
  expect_ctl_usage_error("ctl --weights 0,0,0,0,0,0" + q, "--weights");
  expect_ctl_usage_error("ctl --weights 1,1,1" + q,
                     "--weights: field 'placement_weights' expects 6");
  expect_ctl_usage_error("ctl --kv-ornt=-1" + q, "--kv-ornt");
  expect_ctl_usage_error("ctl --vm surface --mu=-inf" + q, "--mu");
  expect_ctl_usage_error("ctl --kpos inf" + q, "not finite");
  expect_ctl_usage_error("ctl --projection-weights 1,1,1,1,1,0" + q,
                     "--projection-weights");
  expect_ctl_usage_error("ctl --force-limit-N 0" + q, "--force-limit-N");
  expect_ctl_usage_error("ctl --length-unit-mm 0" + q, "--length-unit-mm");
  expect_ctl_usage_error("ctl --pivot-mm 1,2" + q, "--pivot-mm");
  expect_ctl_usage_error("ctl --ticks 0" + q, "--ticks");
  expect_ctl_usage_error("ctl --ticks 1.5" + q, "--ticks");
  expect_ctl_usage_error("ctl --convention xyz" + q, "--convention");
  expect_ctl_usage_error("ctl --q 0,0,0,0,0,1e999", "not a finite number");
}

TEST(CtlErrors, NonFiniteJointIsAFaultWithZeroForce) {
  for (const char* bad : {"nan", "inf", "-inf"}) {
    const CliRun r =
        run(std::string("ctl --kornt 0.5 --q=0.1,") + bad + ",0.3,0,0,0");
    EXPECT_EQ(r.exit_code, 1) << bad;
    ASSERT_FALSE(r.out.empty()) << bad << ": " << r.err;
    const json j = json::parse(r.out);
    EXPECT_EQ(j["status"], json::array({"invalid_input"})) << bad;
    EXPECT_EQ(j["status_code"], kStatusInvalidInput);
    EXPECT_EQ(ctl_vec3(j["force_device_N"]), Vec3::Zero());
    EXPECT_EQ(ctl_vec3(j["tau_Nm"]), Vec3::Zero());
    EXPECT_EQ(vec6(j["f_motion"]), Vec6::Zero());
    EXPECT_TRUE(j["q_dh"][1].is_null());  // JSON has no NaN
    EXPECT_TRUE(j["theta_v"].is_null());
    EXPECT_TRUE(j["x_v_mm"].is_null());
    EXPECT_NE(r.err.find("vmhaptics: error:"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("invalid_input"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "not one line: " << r.err;
  }
}

// |F|^2 overflows (K_pos 1e155 N/mm, ~3 mm off the circle): a numerical
// fault with zero force, not a zero force flagged force_saturated (issue 17)
TEST(CtlErrors, AnOverflowingForceIsANumericalFault) {
  const CliRun r = run("ctl --kpos 1e155 " + kPivotArg + " " + q_arg(case1_q()));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  ASSERT_FALSE(r.out.empty()) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["status"], json::array({"numerical_fault"})) << r.out;
  EXPECT_EQ(j["status_code"], kStatusNumericalFault);
  EXPECT_EQ(ctl_vec3(j["force_device_N"]), Vec3::Zero());
  EXPECT_EQ(ctl_vec3(j["tau_Nm"]), Vec3::Zero());
  EXPECT_EQ(ctl_vec3(j["tau_motor_Nm"]), Vec3::Zero());
  EXPECT_NE(r.err.find("numerical_fault"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("force_saturated"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "not one line: " << r.err;
}

// strtod's ERANGE for a subnormal result is no reason to refuse it
TEST(CtlOptions, SubnormalNumbersAreNumbers) {
  const json j = ctl("--kpos 1e-320 --q 1e-320,0.1,0.2,0,0,0");
  EXPECT_EQ(j["q_dh"][0].get<double>(), 1e-320);
  EXPECT_EQ(j["gains"]["k_pos_N_per_mm"].get<double>(), 1e-320);
}

TEST(CtlHelp, TopLevelHelpListsCtl) {
  const CliRun r = run("--help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("ctl"), std::string::npos);
  const CliRun c = run("ctl --help");
  EXPECT_EQ(c.exit_code, 0);
  EXPECT_NE(c.out.find("--kornt"), std::string::npos);
  EXPECT_NE(c.out.find("--kv-ornt"), std::string::npos);
  // each option names the scene's parameter it is
  EXPECT_NE(c.out.find("k_vel_ornt_Nmms_per_rad"), std::string::npos);
  // the flag is described too
  const auto flag = c.out.find("--unilateral");
  ASSERT_NE(flag, std::string::npos);
  EXPECT_NE(c.out.find("the plane only pushes", flag), std::string::npos);
}

// `vmhaptics params` prints the parameter table; docs/parameters.md is that
// output, verbatim, so it cannot drift from the code.
TEST(Params, DocsFileIsWhatTheProgramPrints) {
  const CliRun r = run("params");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  const std::string doc = std::string(VMH_MODELS_DIR) + "/../docs/parameters.md";
  ASSERT_TRUE(std::filesystem::is_regular_file(doc)) << doc;
  EXPECT_EQ(r.out, vmh::testing::read_file(doc))
      << "regenerate: build/vmhaptics params > docs/parameters.md";
  for (const char* row : {"| `k_vel_ornt_Nmms_per_rad` | `--kv-ornt` |",
                          "| `friction_mu` | `--mu` |",
                          "| `unilateral` | `--unilateral` |",
                          "| `duration_s` | - |"}) {
    EXPECT_NE(r.out.find(row), std::string::npos) << row;
  }
}

}  // namespace
}  // namespace vmh
