// The emulator's seeded faults (sim/emulator.h, SeededFaults): their text
// form and their effect on the reported joint angles.
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <utility>

#include "sim/emulator.h"

namespace vmh::sim {
namespace {

constexpr const char* kKnown =
    "joint<N>_sign (N 1..6), gimbal_swap, link_length_<P>pct, delay_<M>ms, "
    "motor3_relative, motor<N>_sign (N 1..3), torque_units_Nm, "
    "torque_units_mNm, mass_x<K>, friction_x<K>, damping_x<K>";

[[noreturn]] void bad(const std::string& item, const std::string& why) {
  throw std::invalid_argument("seeded emulator fault '" + item + "': " + why +
                              " (known: " + kKnown + ")");
}

bool starts_with(const std::string& s, const char* prefix) {
  return s.rfind(prefix, 0) == 0;
}
bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// the text between `prefix` and `suffix` of item, if it has both
bool middle(const std::string& item, const std::string& prefix,
            const std::string& suffix, std::string* out) {
  if (item.size() <= prefix.size() + suffix.size() ||
      !starts_with(item, prefix.c_str()) || !ends_with(item, suffix)) {
    return false;
  }
  *out = item.substr(prefix.size(), item.size() - prefix.size() - suffix.size());
  return true;
}

double number(const std::string& text, const std::string& item) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(v)) {
    bad(item, "'" + text + "' is not a number");
  }
  return v;
}

// 1..n from a one-digit index text
int index(const std::string& text, const std::string& item, int n) {
  if (text.size() != 1 || text[0] < '1' || text[0] > '0' + n) {
    bad(item, "the index must be 1.." + std::to_string(n));
  }
  return text[0] - '0';
}

}  // namespace

SeededFaults parse_seeded_faults(const std::string& text) {
  SeededFaults f;
  std::string item;
  std::string kinds_seen = ",";  // each kind once: a second would be unclear
  auto once = [&](const std::string& kind) {
    if (kinds_seen.find("," + kind + ",") != std::string::npos) {
      bad(item, kind + " given twice");
    }
    kinds_seen += kind + ",";
  };
  auto one = [&]() {
    std::string x;
    if (item == "gimbal_swap") {
      once(item);
      f.gimbal_swap = true;
    } else if (item == "motor3_relative") {
      once(item);
      f.edit.motor3_relative = true;
    } else if (item == "torque_units_Nm" || item == "torque_units_mNm") {
      once("torque_units");
      f.torque_scale = item == "torque_units_Nm" ? 1000.0 : 0.001;
    } else if (middle(item, "joint", "_sign", &x)) {
      const int n = index(x, item, 6);
      once(item);
      f.joint_sign[static_cast<std::size_t>(n - 1)] = true;
    } else if (middle(item, "motor", "_sign", &x)) {
      const int n = index(x, item, 3);
      once(item);
      f.edit.motor_gain[n - 1] = -1.0;
    } else if (middle(item, "link_length_", "pct", &x)) {
      once("link_length");
      const double p = number(x, item);
      if (!(p > -50.0 && p < 100.0)) bad(item, "P must be in (-50, 100) %");
      f.edit.link1_scale = 1.0 + p / 100.0;
    } else if (middle(item, "delay_", "ms", &x)) {
      once("delay");
      const double m = number(x, item);
      if (!(m > 0.0)) bad(item, "M must be > 0 ms");
      f.delay_ms = m;
    } else if (middle(item, "mass_x", "", &x) ||
               middle(item, "friction_x", "", &x) ||
               middle(item, "damping_x", "", &x)) {
      const std::string kind = item.substr(0, item.find("_x"));
      once(kind);
      const double k = number(x, item);
      if (!(k > 0.0)) bad(item, "K must be > 0");
      (kind == "mass"       ? f.edit.mass_scale
       : kind == "friction" ? f.edit.friction_scale
                            : f.edit.damping_scale) = k;
    } else {
      bad(item, "unknown name");
    }
    f.items.push_back(item);
  };
  std::string cur;
  for (char c : text + ",") {
    if (c == ' ') continue;
    if (c != ',') {
      cur += c;
      continue;
    }
    item = std::exchange(cur, {});
    if (item.empty()) {
      if (text.find_first_not_of(" ,") == std::string::npos) continue;
      bad(item, "empty item in '" + text + "'");
    }
    one();
  }
  return f;
}

void apply_seeded_readings(const SeededFaults& seeded,
                           Joints* q_device_rad) noexcept {
  if (seeded.gimbal_swap) std::swap((*q_device_rad)[4], (*q_device_rad)[5]);
  for (int i = 0; i < 6; ++i) {
    if (seeded.joint_sign[static_cast<std::size_t>(i)]) {
      (*q_device_rad)[i] = -(*q_device_rad)[i];
    }
  }
}

}  // namespace vmh::sim
