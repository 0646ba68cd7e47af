#include "bringup/compare_jacobian.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <limits>
#include <vector>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "controller/omni_params.h"
#include "output/output_file.h"
#include "output/svg_chart.h"

namespace vmh::bringup {
namespace {

constexpr std::size_t kMatrixSamples = 2000;
constexpr double kAngularWeightMmPerRad = 100.0;
constexpr std::size_t kMinSamples = 10;

double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// the project's Jacobian, rows (v mm/rad; w rad/rad) in the device frame,
// columns DH joints
Mat6 project_jacobian_dh_columns(const OmniParams& params, const Joints& q_dh) {
  const Mat6 Jb = omni_jacobian(params, q_dh);
  const Mat3 R = R_device_base();
  Mat6 J;
  J.topRows<3>() = R * Jb.topRows<3>() * kMmPerM;
  J.bottomRows<3>() = R * Jb.bottomRows<3>();
  return J;
}

// d q_dh / d t_device: the joint map is linear, so its columns are the
// images of the unit vectors
Mat6 dh_per_device_joint() {
  Mat6 M;
  for (int j = 0; j < 6; ++j) M.col(j) = device_to_dh_joints(Joints::Unit(j));
  return M;
}

std::string jac_fmt(const char* f, double a) {
  char buf[160];
  std::snprintf(buf, sizeof buf, f, a);
  return buf;
}

// The checks whose data the recording lacks, skipped: the matrix without
// dev_J, the velocity without dev_v, the finite differences without dev_p.
// False when all three are.
bool skip_missing_jacobian_data(const Recording& rec, CompareSection* sec) {
  const bool has_p = rec.has_transform();
  if (!rec.has_jacobian()) {
    sec->skipped.push_back({"jacobian.matrix_rel_error",
                            "the recording has no device Jacobian (dev_J_rc)",
                            rec.dir});
  }
  if (!rec.has_velocity()) {
    sec->skipped.push_back(
        {"jacobian.velocity_rel_error",
         "the recording has no device velocity (dev_v_*_mm_s)", rec.dir});
  }
  if (!has_p) {
    sec->skipped.push_back({"jacobian.fd_velocity_rel_error",
                            "the recording has no device position (dev_p_*_mm)",
                            rec.dir});
  }
  return rec.has_jacobian() || rec.has_velocity() || has_p;
}

// The good rows, their times and the true DH angles (the recorded ones
// read through the reading map)
struct JacobianSamples {
  std::vector<std::size_t> rows;
  std::vector<double> t_s;
  std::vector<Joints> q_true;
};

JacobianSamples jacobian_samples(const Recording& rec,
                                 const ReadingMap& readings) {
  JacobianSamples s;
  s.rows = rec.good_rows();
  for (std::size_t r : s.rows) {
    s.t_s.push_back(rec.t_s(r));
    s.q_true.push_back(device_to_dh_joints(
        readings.true_from_reported(dh_to_device_joints(rec.q_dh_rad(r)))));
  }
  return s;
}

// (a) the matrix in each layout: the device's Jacobian as stored and
// transposed, its columns device or DH joints, against the project's at
// up to kMatrixSamples samples; the check on the best layout's median
// relative (weighted Frobenius) error
void check_jacobian_matrix(const Recording& rec, const JacobianSamples& s,
                           CompareSection* sec) {
  const OmniParams params;
  const Mat6 M = dh_per_device_joint();
  const char* kNames[4] = {"as_stored_device_joints",
                           "transposed_device_joints", "as_stored_dh_joints",
                           "transposed_dh_joints"};
  std::array<std::vector<double>, 4> errors;
  Mat6 W = Mat6::Identity();
  W.bottomRightCorner<3, 3>() *= kAngularWeightMmPerRad;
  const std::size_t n = std::min(s.rows.size(), kMatrixSamples);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = k * s.rows.size() / n;
    const Mat6 Jd = rec.dev_J(s.rows[i]);
    if (!Jd.allFinite()) continue;
    const Mat6 Jq = project_jacobian_dh_columns(params, s.q_true[i]);
    const Mat6 Jt = Jq * M;
    const Mat6 cand[4] = {Jd, Jd.transpose(), Jd, Jd.transpose()};
    for (int c = 0; c < 4; ++c) {
      const Mat6& Jp = c < 2 ? Jt : Jq;
      errors[c].push_back((W * (cand[c] - Jp)).norm() / (W * Jp).norm());
    }
  }
  if (errors[0].empty()) {
    sec->skipped.push_back(
        {"jacobian.matrix_rel_error", "no finite dev_J rows", rec.dir});
    return;
  }
  nlohmann::ordered_json layouts = nlohmann::ordered_json::object();
  int best = 0;
  std::array<double, 4> med;
  for (int c = 0; c < 4; ++c) {
    med[c] = median(errors[c]);
    layouts[kNames[c]] = med[c];
    if (med[c] < med[best]) best = c;
  }
  sec->detail["layout"] = kNames[best];
  sec->detail["layout_median_rel_error"] = layouts;
  sec->detail["matrix_samples"] = errors[0].size();
  sec->checks.push_back(
      make_check("jacobian.matrix_rel_error", med[best],
                 kJacobianRelErrorThreshold, "ratio", CompareCheck::kAtMost,
                 std::string("median relative Frobenius error, best layout ") +
                     kNames[best]));
}

// (b) J(q) qdot, qdot a central difference over +-kVelocityHalfWindowS,
// at each sample where one is possible: the two speeds for the figure, and
// the relative errors against the device's velocity and against its
// positions' differences where the device moves faster than
// kVelocityMinSpeedMmS
struct VelocitySamples {
  std::vector<double> t_moving_s, speed_project_mm_s, speed_device_mm_s, rel_v,
      rel_fd;
};

VelocitySamples velocity_samples(const Recording& rec,
                                 const JacobianSamples& s) {
  const OmniParams params;
  const bool has_p = rec.has_transform();
  const std::vector<double>& t_s = s.t_s;
  VelocitySamples out;
  for (std::size_t i = 0; i < s.rows.size(); ++i) {
    const auto hi =
        std::lower_bound(t_s.begin(), t_s.end(), t_s[i] + kVelocityHalfWindowS);
    auto lo =
        std::upper_bound(t_s.begin(), t_s.end(), t_s[i] - kVelocityHalfWindowS);
    if (hi == t_s.end() || lo == t_s.begin()) continue;
    --lo;
    const std::size_t j = hi - t_s.begin(), k = lo - t_s.begin();
    const double dt = t_s[j] - t_s[k];
    // a gap in the good rows: no central difference here
    if (!(dt > 0) || dt > 3 * kVelocityHalfWindowS) continue;
    const Joints qdot = (s.q_true[j] - s.q_true[k]) / dt;
    const Vec3 v =
        project_jacobian_dh_columns(params, s.q_true[i]).topRows<3>() * qdot;
    out.t_moving_s.push_back(t_s[i]);
    out.speed_project_mm_s.push_back(v.norm());
    double dev_speed = std::numeric_limits<double>::quiet_NaN();
    if (rec.has_velocity()) {
      const Vec3 dv = rec.dev_v_mm_s(s.rows[i]);
      dev_speed = dv.norm();
      if (dv.allFinite() && dev_speed > kVelocityMinSpeedMmS) {
        out.rel_v.push_back((v - dv).norm() / dev_speed);
      }
    }
    out.speed_device_mm_s.push_back(dev_speed);
    if (has_p) {
      const Vec3 fd = (rec.dev_p_mm(s.rows[j]) - rec.dev_p_mm(s.rows[k])) / dt;
      if (fd.allFinite() && fd.norm() > kVelocityMinSpeedMmS) {
        out.rel_fd.push_back((v - fd).norm() / fd.norm());
      }
    }
  }
  return out;
}

// a velocity check on the median of rel (|J qdot - against| / |against|),
// skipped with fewer than kMinSamples samples
void add_velocity_check(const char* name, const std::vector<double>& rel,
                        const std::string& against, const std::string& dir,
                        CompareSection* sec) {
  if (rel.size() < kMinSamples) {
    sec->skipped.push_back(
        {name,
         std::to_string(rel.size()) + " samples move faster than " +
             jac_fmt("%.0f mm/s", kVelocityMinSpeedMmS) + ", at least " +
             std::to_string(kMinSamples) + " needed",
         dir});
    return;
  }
  sec->checks.push_back(
      make_check(name, median(rel), kVelocityRelErrorThreshold, "ratio",
                 CompareCheck::kAtMost,
                 "median |J qdot - " + against + "| / |" + against + "| over " +
                     std::to_string(rel.size()) + " samples faster than " +
                     jac_fmt("%.0f mm/s", kVelocityMinSpeedMmS)));
}

// jacobian_velocity.svg: the project's speed and the device's over time
void write_velocity_figure(const Recording& rec, const VelocitySamples& v,
                           const std::string& figure_dir, CompareSection* sec) {
  output::Chart c;
  c.title = "Project J(q) qdot vs the device's velocity";
  c.subtitle = "recording " + rec.dir + ", device frame";
  c.x.label = "time (s)";
  c.y.label = "wrist speed (mm/s)";
  c.series.push_back({"|J(q) qdot|", v.t_moving_s, v.speed_project_mm_s, "",
                      true, false, false});
  if (rec.has_velocity()) {
    c.series.push_back(
        {"|dev_v|", v.t_moving_s, v.speed_device_mm_s, "", true, false, true});
  }
  sec->figures.push_back(output::write_file_in(
      figure_dir, "jacobian_velocity.svg", output::chart_svg(c)));
}

}  // namespace

CompareSection compare_jacobian(const Recording& rec,
                                const ReadingMap& readings,
                                const std::string& figure_dir) {
  CompareSection sec;
  sec.name = "jacobian";
  if (!skip_missing_jacobian_data(rec, &sec)) return sec;

  if (!readings.is_identity()) {
    sec.detail["explained_by"] = readings.name;
    sec.detail["note"] = "angles read through the readings map " +
                         readings.name +
                         " (compare_kinematics) before the project's Jacobian";
  }
  const JacobianSamples s = jacobian_samples(rec, readings);
  if (rec.has_jacobian() && !s.rows.empty()) {
    check_jacobian_matrix(rec, s, &sec);
  }

  const VelocitySamples v = velocity_samples(rec, s);
  if (rec.has_velocity()) {
    add_velocity_check("jacobian.velocity_rel_error", v.rel_v, "dev_v", rec.dir,
                       &sec);
  }
  if (rec.has_transform()) {
    add_velocity_check("jacobian.fd_velocity_rel_error", v.rel_fd,
                       "d(dev_p)/dt", rec.dir, &sec);
  }
  sec.detail["velocity_half_window_s"] = kVelocityHalfWindowS;
  sec.detail["velocity_min_speed_mm_s"] = kVelocityMinSpeedMmS;
  for (CompareCheck& c : sec.checks) c.recording = rec.dir;

  if (!figure_dir.empty() && !v.t_moving_s.empty()) {
    write_velocity_figure(rec, v, figure_dir, &sec);
  }
  return sec;
}

}  // namespace vmh::bringup
