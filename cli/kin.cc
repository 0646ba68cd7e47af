// `vmhaptics kin ...`: forward kinematics, Jacobian, inverse kinematics and
// the device parameters of the PHANTOM Omni, as one JSON object on stdout.
// The field names and units are a contract documented in docs/outputs.md.
#include "cli/kin.h"

#include <Eigen/SVD>
#include <cmath>
#include <iostream>
#include <memory>
#include <string>

#include "cli/args.h"
#include "runtime/json_util.h"
#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "controller/omni_params.h"

namespace vmh::cli {

namespace {

struct KinOptions {
  std::string q;
  std::string convention = "dh";
  std::string tool_offset_mm = "0";
  std::string p_device_mm;
  std::string p_base_m;
  std::string near;
  std::string R_base;
};

Joints to_joints(const std::vector<double>& v) {
  Joints q;
  for (int i = 0; i < kOmniJoints; ++i) q[i] = v[static_cast<std::size_t>(i)];
  return q;
}

// joint angles given on the command line, converted to the DH convention
Joints read_joints(const std::string& option, const std::string& text,
                   const std::string& convention) {
  const Joints q = to_joints(parse_list(option, text, kOmniJoints));
  return convention == "device" ? device_to_dh_joints(q) : q;
}

OmniParams read_params(const KinOptions& o) {
  OmniParams p;
  p.tool_offset_m =
      parse_number("--tool-offset-mm", o.tool_offset_mm) / kMmPerM;
  return p;
}

// fields shared by `kin fk` and `kin jac`
Json pose_json(const OmniParams& p, const Joints& q_dh) {
  OmniFrames frames;
  omni_frames(p, q_dh, &frames);
  const OmniPose pose{frames.T_base[kOmniJoints].translation(),
                      frames.T_base[kOmniJoints].linear()};
  const Vec3 tool = omni_tool_point(p, pose);
  const Mat3 R_dev = base_to_device_rotation(pose.R_base);

  Json out;
  out["q_dh"] = to_json_vector(q_dh);
  out["q_device"] = to_json_vector(dh_to_device_joints(q_dh));
  out["within_limits"] = omni_within_limits(p, q_dh);
  out["p_base_m"] = to_json_vector(pose.p_base_m);
  out["R_base"] = to_json_rows(pose.R_base);
  out["p_device_mm"] = to_json_vector(base_to_device_mm(p, pose.p_base_m));
  out["R_device"] = to_json_rows(R_dev);
  out["axis_device"] = to_json_vector(R_dev.col(2));
  out["tool_offset_mm"] = p.tool_offset_m * kMmPerM;
  out["p_tool_base_m"] = to_json_vector(tool);
  out["p_tool_device_mm"] = to_json_vector(base_to_device_mm(p, tool));
  Json list = Json::array();
  for (int i = 0; i <= kOmniJoints; ++i) {
    list.push_back(
        {{"frame", i},
         {"p_base_m", to_json_vector(frames.T_base[i].translation())},
         {"R_base", to_json_rows(frames.T_base[i].linear())}});
  }
  out["frames"] = std::move(list);
  return out;
}

void run_fk(const KinOptions& o, bool with_jacobian) {
  const OmniParams p = read_params(o);
  const Joints q = read_joints("--q", o.q, o.convention);
  Json out = pose_json(p, q);
  if (with_jacobian) {
    const Mat6 J = omni_jacobian(p, q);
    out["J_base"] = to_json_rows(J);
    out["J_tool_base"] = to_json_rows(omni_jacobian_at(p, q, p.tool_offset_m));
    // conditioning of the actuated position block (joints 1-3 to v)
    const Eigen::JacobiSVD<Mat3> svd(J.block<3, 3>(0, 0));
    const Vec3 sv = svd.singularValues();
    out["J_pos_singular_values"] = to_json_vector(sv);
    out["J_pos_condition"] = sv[2] > 0 ? Json(sv[0] / sv[2]) : Json(nullptr);
  }
  std::cout << dump_readable(out) << '\n';
}

Mat3 read_rotation(const std::string& text) {
  const std::vector<double> v = parse_list("--R-base", text, 9);
  Mat3 R;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c)
      R(r, c) = v[static_cast<std::size_t>(3 * r + c)];
  }
  const double ortho = (R.transpose() * R - Mat3::Identity()).norm();
  if (ortho > 1e-6 || R.determinant() < 0) {
    throw UsageError(
        "--R-base: expected a proper rotation (orthonormal rows, det +1), "
        "got |R^T R - I| = " +
        std::to_string(ortho) + ", det = " + std::to_string(R.determinant()));
  }
  return R;
}

void run_ik(const KinOptions& o) {
  const OmniParams p = read_params(o);
  if (o.p_device_mm.empty() == o.p_base_m.empty()) {
    throw UsageError("kin ik: give exactly one of --p-device-mm, --p-base-m");
  }
  Vec3 target_base_m;
  if (!o.p_device_mm.empty()) {
    const std::vector<double> v = parse_list("--p-device-mm", o.p_device_mm, 3);
    target_base_m = device_mm_to_base(p, Vec3(v[0], v[1], v[2]));
  } else {
    const std::vector<double> v = parse_list("--p-base-m", o.p_base_m, 3);
    target_base_m = Vec3(v[0], v[1], v[2]);
  }
  const Joints near = o.near.empty()
                          ? Joints::Zero().eval()
                          : read_joints("--near", o.near, o.convention);
  for (int i = 0; i < kOmniJoints; ++i) {
    if (std::abs(near[i]) > kIkMaxHintRad) {
      char msg[160];
      std::snprintf(msg, sizeof msg,
                    "--near: q%d = %g rad is beyond +-%g rad, where whole "
                    "turns can no longer be told apart",
                    i + 1, near[i], kIkMaxHintRad);
      throw UsageError(msg);
    }
  }
  const IkSolutions s =
      o.R_base.empty()
          ? omni_ik_position(p, target_base_m, near)
          : omni_ik_pose(p, target_base_m, read_rotation(o.R_base), near);
  const int best = omni_ik_nearest(s, near);

  Json out;
  out["status"] = ik_status_name(s.status);
  out["p_base_m"] = to_json_vector(target_base_m);
  out["p_device_mm"] = to_json_vector(base_to_device_mm(p, target_base_m));
  out["near_dh"] = to_json_vector(near);
  out["orientation_given"] = !o.R_base.empty();
  Json sol = Json::array(), sol_dev = Json::array(), lim = Json::array();
  for (int k = 0; k < s.count; ++k) {
    sol.push_back(to_json_vector(s.q_dh[k]));
    sol_dev.push_back(to_json_vector(dh_to_device_joints(s.q_dh[k])));
    lim.push_back(static_cast<bool>(s.within_limits[k]));
  }
  out["solutions"] = std::move(sol);
  out["solutions_device"] = std::move(sol_dev);
  out["within_limits"] = std::move(lim);
  out["nearest_index"] = best;
  out["nearest"] = best >= 0 ? to_json_vector(s.q_dh[best]) : Json(nullptr);
  out["reach_excess_mm"] = s.reach_excess_m * kMmPerM;
  out["shoulder_singular"] = s.shoulder_singular;
  out["elbow_singular"] = s.elbow_singular;
  out["wrist_singular"] = s.wrist_singular;
  std::cout << dump_readable(out) << '\n';
}

void run_params() {
  const OmniParams p;
  Json out;
  out["l0_m"] = p.l0_m;
  out["l1_m"] = p.l1_m;
  out["l2_m"] = p.l2_m;
  out["tool_offset_m"] = p.tool_offset_m;
  out["joint_lower_rad"] = p.joint_lower_rad;
  out["joint_upper_rad"] = p.joint_upper_rad;
  out["motor_torque_limit_Nm"] = p.motor_torque_limit_Nm;
  out["max_force_N"] = p.max_force_N;
  out["continuous_force_N"] = p.continuous_force_N;
  out["encoder_counts_per_rev"] = p.encoder_counts_per_rev;
  out["gimbal_pot_bits"] = p.gimbal_pot_bits;
  Json dh = Json::array();
  for (const DhRow& r : omni_dh_table(p)) {
    dh.push_back({{"a_m", r.a_m},
                  {"alpha_rad", r.alpha_rad},
                  {"d_m", r.d_m},
                  {"theta_offset_rad", r.theta_offset_rad}});
  }
  out["dh_table"] = std::move(dh);
  out["R_device_base"] = to_json_rows(R_device_base());
  std::cout << dump_readable(out) << '\n';
}

void add_convention(CLI::App* cmd, KinOptions* o) {
  cmd->add_option("--convention", o->convention,
                  "joint angles given and read as 'dh' (thesis Table B.1, "
                  "q3 relative) or 'device' (OpenHaptics, joint 3 absolute)")
      ->check(CLI::IsMember({"dh", "device"}));
  cmd->add_option("--tool-offset-mm", o->tool_offset_mm,
                  "tool point on the stylus axis z6, signed, from the wrist "
                  "centre (mm)");
}

}  // namespace

void register_kin(CLI::App* app) {
  auto opts = std::make_shared<KinOptions>();
  CLI::App* kin = app->add_subcommand(
      "kin", "kinematics of the PHANTOM Omni (Appendix B), JSON on stdout");
  kin->require_subcommand(1);

  // fk and jac take the same options; jac adds the Jacobian to the output
  const auto add_fk_verb = [&](const char* name, const char* help,
                               bool with_jacobian) {
    CLI::App* cmd = kin->add_subcommand(name, help);
    cmd->add_option("--q", opts->q, "six joint angles q1,...,q6 (rad)")
        ->required();
    add_convention(cmd, opts.get());
    cmd->callback([opts, with_jacobian] { run_fk(*opts, with_jacobian); });
  };
  add_fk_verb("fk", "forward kinematics of every frame", false);
  add_fk_verb("jac", "forward kinematics and the 6x6 geometric Jacobian", true);

  CLI::App* ik = kin->add_subcommand(
      "ik", "every joint solution for a wrist-centre position (Pieper)");
  ik->add_option("--p-device-mm", opts->p_device_mm,
                 "wrist centre x,y,z in the device frame (mm)");
  ik->add_option("--p-base-m", opts->p_base_m,
                 "wrist centre x,y,z in the DH base frame (m)");
  ik->add_option("--near", opts->near,
                 "configuration q1,...,q6 to pick the nearest solution and "
                 "to supply free angles (rad; default 0)");
  ik->add_option("--R-base", opts->R_base,
                 "stylus frame rotation, 9 numbers row by row, DH base frame; "
                 "solves the wrist angles too");
  add_convention(ik, opts.get());
  ik->callback([opts] { run_ik(*opts); });

  CLI::App* params = kin->add_subcommand(
      "params", "the Omni's parameters and DH table (SI units)");
  params->callback([] { run_params(); });
}

}  // namespace vmh::cli
