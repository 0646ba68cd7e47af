#include "hd/hd_config.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <system_error>
#include <filesystem>

namespace vmh::hd {
namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return {};
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return s;
}

std::string configured_list(const HdConfig& c) {
  std::string out = "default";
  for (const auto& [name, spec] : c.names) {
    if (lower(name) == "default") continue;
    out += ", " + name;
  }
  return out;
}

}  // namespace

DeviceSpec parse_device_spec(const std::string& spec) {
  DeviceSpec d;
  d.text = trim(spec);
  const auto q = d.text.find('?');
  d.device = trim(d.text.substr(0, q));
  if (d.device.empty()) {
    throw HdConfigError("device spec '" + spec +
                        "' names no backend (expected BACKEND[:ARGUMENT]"
                        "[?KEY=VALUE&...])");
  }
  if (q == std::string::npos) return d;
  std::stringstream rest(d.text.substr(q + 1));
  std::string item;
  while (std::getline(rest, item, '&')) {
    item = trim(item);
    if (item.empty()) continue;
    const auto eq = item.find('=');
    std::string key = trim(item.substr(0, eq));
    std::string value = eq == std::string::npos ? "" : trim(item.substr(eq + 1));
    if (key.empty()) {
      throw HdConfigError("device spec '" + spec + "': option '" + item +
                          "' has no key");
    }
    d.options.emplace_back(std::move(key), std::move(value));
  }
  return d;
}

bool is_default_name(const char* name) {
  if (name == nullptr) return true;
  static const char* const kDefaults[] = {
      "",           "default device", "default phantom", "phantom omni",
      "omni",       "default"};
  const std::string n = lower(trim(name));
  for (const char* d : kDefaults) {
    if (n == d) return true;
  }
  return false;
}

HdConfig parse_hd_config(const std::string& text, const std::string& file) {
  HdConfig c;
  c.file = file;
  std::stringstream in(text);
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const auto hash = line.find('#');
    line = trim(line.substr(0, hash));
    if (line.empty()) continue;
    const auto eq = line.find('=');
    const std::string where = file + ":" + std::to_string(number);
    if (eq == std::string::npos) {
      throw HdConfigError(where + ": expected 'NAME = SPEC', got '" + line + "'");
    }
    const std::string name = trim(line.substr(0, eq));
    const std::string spec = trim(line.substr(eq + 1));
    if (name.empty() || spec.empty()) {
      throw HdConfigError(where + ": expected 'NAME = SPEC', got '" + line + "'");
    }
    parse_device_spec(spec);  // malformed specs fail here, with the line
    for (const auto& [other, s] : c.names) {
      if (lower(other) == lower(name)) {
        throw HdConfigError(where + ": '" + name + "' is configured twice");
      }
    }
    c.names[name] = spec;
    if (is_default_name(name.c_str())) {
      c.default_spec = spec;
      c.default_from = where;
    }
  }
  return c;
}

HdConfig load_hd_config() {
  namespace fs = std::filesystem;
  HdConfig c;
  std::string file;
  bool must_exist = false;
  if (const char* f = std::getenv("VMH_HD_CONFIG"); f != nullptr && *f) {
    file = f;
    must_exist = true;
  } else if (const char* x = std::getenv("XDG_CONFIG_HOME"); x != nullptr && *x) {
    file = std::string(x) + "/vmhaptics/hd.conf";
  } else if (const char* h = std::getenv("HOME"); h != nullptr && *h) {
    file = std::string(h) + "/.config/vmhaptics/hd.conf";
  }
  std::error_code ec;
  if (!file.empty() && (must_exist || fs::exists(file, ec))) {
    std::ifstream in(file);
    if (!in) {
      throw HdConfigError("cannot read the HD configuration file '" + file +
                          "' (VMH_HD_CONFIG)");
    }
    std::stringstream text;
    text << in.rdbuf();
    c = parse_hd_config(text.str(), file);
  }
  if (const char* d = std::getenv("VMH_HD_DEVICE"); d != nullptr && *d) {
    parse_device_spec(d);
    c.default_spec = d;
    c.default_from = "VMH_HD_DEVICE";
  }
  return c;
}

std::string resolve_device_name(const HdConfig& config, const char* name) {
  if (is_default_name(name)) return config.default_spec;
  const std::string want = lower(trim(name));
  for (const auto& [n, spec] : config.names) {
    if (lower(n) == want) return spec;
  }
  throw HdConfigError(
      "no device is configured as '" + std::string(name) + "' (configured: " +
      configured_list(config) + "; " +
      (config.file.empty() ? std::string("no configuration file: write "
                                         "'NAME = SPEC' lines to "
                                         "$XDG_CONFIG_HOME/vmhaptics/hd.conf")
                           : "file " + config.file) +
      ")");
}

}  // namespace vmh::hd
