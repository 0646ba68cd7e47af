#include "runtime/calibration_store.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>

#include "output/output_file.h"

namespace vmh::runtime {
namespace {

namespace fs = std::filesystem;

// a stored calibration is a few hundred bytes; anything much larger is not
// one (and is not read into memory)
constexpr std::uintmax_t kMaxFileBytes = 1 << 20;

std::string joint_name(const char* field, int i) {
  const bool pot = std::string(field).rfind("pot", 0) == 0;
  return std::string(field) + "[" + std::to_string(i) + "] (t" +
         std::to_string(i + (pot ? 4 : 1)) + ")";
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::array<double, 3> triple(const Json& j, const char* key,
                             const std::string& path) {
  if (!j.contains(key)) {
    throw CalibrationError(path + ": '" + key + "' is missing");
  }
  const Json& v = j[key];
  if (!v.is_array() || v.size() != 3) {
    throw CalibrationError(path + ": '" + key +
                           "' must be an array of 3 numbers, got " +
                           v.type_name());
  }
  std::array<double, 3> out{};
  for (int i = 0; i < 3; ++i) {
    if (!v[i].is_number()) {
      throw CalibrationError(path + ": " + joint_name(key, i) +
                             " must be a number, got " + v[i].type_name());
    }
    out[static_cast<std::size_t>(i)] = v[i].get<double>();
  }
  return out;
}

// an optional array of three +1 / -1 (whole numbers in JSON)
std::array<int, 3> signs(const Json& j, const char* key, const std::string& path,
                         const std::array<int, 3>& fallback) {
  if (!j.contains(key)) return fallback;
  const Json& v = j[key];
  if (!v.is_array() || v.size() != 3) {
    throw CalibrationError(path + ": '" + key +
                           "' must be an array of 3 signs (+1 or -1), got " +
                           v.type_name());
  }
  std::array<int, 3> out{};
  for (int i = 0; i < 3; ++i) {
    if (!v[i].is_number_integer()) {
      throw CalibrationError(path + ": " + joint_name(key, i) +
                             " must be +1 or -1, got " + v[i].dump());
    }
    const auto x = v[i].get<long long>();
    if (x != 1 && x != -1) {
      throw CalibrationError(path + ": " + joint_name(key, i) + " = " +
                             std::to_string(x) + " is not +1 or -1");
    }
    out[static_cast<std::size_t>(i)] = static_cast<int>(x);
  }
  return out;
}

std::string text_field(const Json& j, const char* key,
                       const std::string& path, const std::string& fallback) {
  if (!j.contains(key)) return fallback;
  if (!j[key].is_string()) {
    throw CalibrationError(path + ": '" + key + "' must be a string, got " +
                           j[key].type_name());
  }
  return j[key].get<std::string>();
}

}  // namespace

void check_calibration(const hw::OmniCalibration& c, const std::string& where) {
  for (int i = 0; i < 3; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double e = c.encoder_offset_rad[k];
    if (!std::isfinite(e) || std::abs(e) > kMaxEncoderOffsetRad) {
      throw CalibrationError(where + ": " + joint_name("encoder_offset_rad", i) +
                             " = " + num(e) +
                             " rad is not a finite offset within +-pi");
    }
    const double g = c.pot_gain_rad[k];
    if (!std::isfinite(g) || std::abs(g) < kMinPotGainRad ||
        std::abs(g) > kMaxPotGainRad) {
      throw CalibrationError(where + ": " + joint_name("pot_gain_rad", i) +
                             " = " + num(g) +
                             " rad per code is not a pot's gain (|gain| in "
                             "[1e-4, 1e-2])");
    }
    const double o = c.pot_offset_rad[k];
    const double far = o + g * 4095.0;
    if (!std::isfinite(o) || std::abs(o) > kMaxPotAngleRad ||
        std::abs(far) > kMaxPotAngleRad) {
      throw CalibrationError(where + ": " + joint_name("pot_offset_rad", i) +
                             " = " + num(o) +
                             " rad puts the pot's codes at angles beyond "
                             "+-4 pi");
    }
    const int sg = c.encoder_sign[k];
    if (sg != 1 && sg != -1) {
      throw CalibrationError(where + ": " + joint_name("encoder_sign", i) +
                             " = " + std::to_string(sg) +
                             " is not +1 or -1");
    }
    const double ink = c.inkwell_t123_rad[k];
    if (!std::isfinite(ink) || std::abs(ink) > kMaxEncoderOffsetRad) {
      throw CalibrationError(where + ": " + joint_name("inkwell_t123_rad", i) +
                             " = " + num(ink) +
                             " rad is not a finite angle within +-pi");
    }
  }
}

std::string calibration_dir() {
  const char* xdg = std::getenv("XDG_CONFIG_HOME");
  fs::path base;
  if (xdg != nullptr && xdg[0] != '\0') {
    base = xdg;
  } else {
    const char* home = std::getenv("HOME");
    base = fs::path(home != nullptr ? home : ".") / ".config";
  }
  return (base / "vmhaptics" / "calibration").string();
}

std::string calibration_path(const std::string& serial) {
  std::string name;
  for (char ch : serial) {
    const bool ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
                    (ch >= '0' && ch <= '9') || ch == '-' || ch == '_' ||
                    ch == '.';
    name += ok ? ch : '_';
  }
  if (name.empty() || name == "." || name == "..") name = "unknown";
  return (fs::path(calibration_dir()) / (name + ".json")).string();
}

std::optional<StoredCalibration> load_calibration(const std::string& serial) {
  const std::string path = calibration_path(serial);
  // only a regular file (a FIFO would block the read for ever, a device
  // would never end), and a small one: read as a recording's files are,
  // without blocking and within the bound
  bool missing = false;
  std::string text;
  try {
    text = output::read_regular_file(path, kMaxFileBytes, &missing);
  } catch (const std::runtime_error& e) {
    throw CalibrationError(std::string(e.what()) + " (not a calibration)");
  }
  if (missing) return std::nullopt;
  Json j;
  try {
    j = Json::parse(text);
  } catch (const std::exception& e) {
    throw CalibrationError(path + ": not JSON (" + e.what() + ")");
  }
  if (!j.is_object()) throw CalibrationError(path + ": not a JSON object");
  StoredCalibration c;
  c.calibration.encoder_offset_rad = triple(j, "encoder_offset_rad", path);
  c.calibration.pot_gain_rad = triple(j, "pot_gain_rad", path);
  c.calibration.pot_offset_rad = triple(j, "pot_offset_rad", path);
  // written since the signs became data; a file from before has the
  // nominal ones (its offsets were fitted with the signs of that time:
  // docs/hardware.md, "Calibration")
  c.calibration.encoder_sign =
      signs(j, "encoder_sign", path, hw::kNominalEncoderSign);
  if (j.contains("inkwell_t123_rad")) {
    c.calibration.inkwell_t123_rad = triple(j, "inkwell_t123_rad", path);
  }
  check_calibration(c.calibration, path);
  c.serial = text_field(j, "serial", path, serial);
  c.backend = text_field(j, "backend", path, "");
  c.date_utc = text_field(j, "date_utc", path, "");
  if (j.contains("details")) c.details = j["details"];
  return c;
}

std::string save_calibration(const StoredCalibration& c) {
  const std::string path = calibration_path(c.serial);
  check_calibration(c.calibration, "the fit for " + path);
  Json j{{"serial", c.serial},
         {"backend", c.backend},
         {"date_utc", c.date_utc},
         {"encoder_offset_rad", c.calibration.encoder_offset_rad},
         {"encoder_sign", c.calibration.encoder_sign},
         {"inkwell_t123_rad", c.calibration.inkwell_t123_rad},
         {"pot_gain_rad", c.calibration.pot_gain_rad},
         {"pot_offset_rad", c.calibration.pot_offset_rad},
         {"details", c.details}};
  fs::create_directories(fs::path(path).parent_path());
  output::write_file_atomically(path, dump_readable(j) + "\n");
  return path;
}

}  // namespace vmh::runtime
