// The force mapping's check on a recorded run (compare_force_mapping,
// bringup/compare_force.h): does the torque the controller sent map to the
// force it meant, through J_r^T, at every tick.
#include "bringup/compare_force.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "controller/device_frame.h"
#include "controller/omni_params.h"
#include "output/number_text.h"
#include "output/output_file.h"
#include "output/svg_chart.h"
#include "sim/cases/case_catalogue.h"

namespace vmh::bringup {
namespace {

std::string mapping_fmt(double v, int digits = 3) {
  return output::significant(v, digits);
}

}  // namespace

CompareSection compare_force_mapping(const Recording& run) {
  CompareSection s;
  s.name = "force_mapping";
  const std::string name = "force_mapping.torque_angle_p95";
  if (!run.has("F_x_N") || !run.has("tau_1_Nm")) {
    s.skipped.push_back(
        {name, "the trace has no F_*_N (not a hw run)", run.dir});
    return s;
  }
  if (!run.has_jacobian()) {
    s.skipped.push_back(
        {name, "the device reports no Jacobian (dev_J_*)", run.dir});
    return s;
  }
  // four readings of the device's Jacobian: as stored or transposed, its
  // columns device joints t1..t3 or DH joints q1..q3
  const char* kReading[4] = {"stored, device joints",
                             "transposed, device joints", "stored, DH joints",
                             "transposed, DH joints"};
  std::vector<double> angles[4];
  for (std::size_t r : run.good_rows()) {
    const Vec3 F = run.vec3("F_", "_N", r, true);
    const Vec3 tau = run.tau_cmd_Nm(r);
    if (!F.allFinite() || F.norm() <= 0.1 || !tau.allFinite() ||
        tau.norm() < 1e-9) {
      continue;
    }
    const Eigen::Matrix<double, 6, 6> J = run.dev_J(r);
    if (!J.allFinite()) continue;
    for (int k = 0; k < 4; ++k) {
      const Mat3 Jl = (k % 2 == 0) ? Mat3(J.topLeftCorner<3, 3>())
                                   : Mat3(J.transpose().topLeftCorner<3, 3>());
      Vec3 t = 1e-3 * Jl.transpose() * F;  // mm/rad to m/rad: N m
      if (k >= 2) t = dh_to_motor_torques(t);
      const double c = t.dot(tau) / (t.norm() * tau.norm());
      angles[k].push_back(
          std::isfinite(c) ? std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / kPi
                           : 180.0);
    }
  }
  if (angles[0].empty()) {
    s.skipped.push_back(
        {name, "no good row with |F| > 0.1 N and a torque sent", run.dir});
    return s;
  }
  double p95[4];
  int best = 0;
  for (int k = 0; k < 4; ++k) {
    std::vector<double> a = angles[k];
    const std::size_t n = static_cast<std::size_t>(
                              std::ceil(0.95 * static_cast<double>(a.size()))) -
                          1;
    std::nth_element(a.begin(), a.begin() + static_cast<long>(n), a.end());
    p95[k] = a[n];
    if (p95[k] < p95[best]) best = k;
  }
  CompareCheck c = make_check(
      name, p95[best], 10.0, "deg", CompareCheck::kAtMost,
      "angle between tau_1..3_Nm (J_r^T F) and J_dev^T F, J_dev read " +
          std::string(kReading[best]) + ", over " +
          std::to_string(angles[0].size()) + " rows with |F| > 0.1 N");
  c.recording = run.dir;
  s.checks.push_back(c);
  nlohmann::ordered_json readings = nlohmann::ordered_json::object();
  for (int k = 0; k < 4; ++k) readings[kReading[k]] = p95[k];
  s.detail = {{"rows", static_cast<long>(angles[0].size())},
              {"best_reading", kReading[best]},
              {"p95_deg_by_reading", readings}};
  if (!c.pass) {
    s.faults.push_back({"force_mapping",
                        "p95 angle " + mapping_fmt(p95[best]) +
                            " deg between the project's and the device's J^T F",
                        run.dir});
  }
  return s;
}

}  // namespace vmh::bringup
