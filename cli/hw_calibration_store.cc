#include "cli/hw_calibration_store.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "report/output_file.h"

namespace vmh::cli {
namespace {

namespace fs = std::filesystem;

std::array<double, 3> triple(const Json& j, const char* key,
                             const std::string& path) {
  if (!j.contains(key) || !j[key].is_array() || j[key].size() != 3) {
    throw std::runtime_error(path + ": '" + key +
                             "' must be an array of 3 numbers");
  }
  std::array<double, 3> v{};
  for (int i = 0; i < 3; ++i) {
    if (!j[key][i].is_number()) {
      throw std::runtime_error(path + ": '" + key + "' must hold numbers");
    }
    v[i] = j[key][i].get<double>();
  }
  return v;
}

}  // namespace

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
  std::ifstream in(path);
  if (!in) return std::nullopt;
  std::stringstream ss;
  ss << in.rdbuf();
  Json j;
  try {
    j = Json::parse(ss.str());
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": not JSON (" + e.what() + ")");
  }
  StoredCalibration c;
  c.calibration.encoder_offset_rad = triple(j, "encoder_offset_rad", path);
  c.calibration.pot_gain_rad = triple(j, "pot_gain_rad", path);
  c.calibration.pot_offset_rad = triple(j, "pot_offset_rad", path);
  try {
    c.calibration.validate();
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
  c.serial = j.value("serial", serial);
  c.backend = j.value("backend", "");
  c.date_utc = j.value("date_utc", "");
  if (j.contains("details")) c.details = j["details"];
  return c;
}

std::string save_calibration(const StoredCalibration& c) {
  const std::string path = calibration_path(c.serial);
  Json j{{"serial", c.serial},
         {"backend", c.backend},
         {"date_utc", c.date_utc},
         {"encoder_offset_rad", c.calibration.encoder_offset_rad},
         {"pot_gain_rad", c.calibration.pot_gain_rad},
         {"pot_offset_rad", c.calibration.pot_offset_rad},
         {"details", c.details}};
  fs::create_directories(fs::path(path).parent_path());
  report::write_file_atomically(path, dump_readable(j) + "\n");
  return path;
}

}  // namespace vmh::cli
