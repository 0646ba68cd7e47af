// Which device a configuration name opens (docs/libhd.md, "Devices").
//
// OpenHaptics programs name the device they want: hdInitDevice(NULL) or a
// name from the vendor's setup tool ("Default Device", "Default PHANToM",
// "Phantom Omni", "Phantom2"...). Here a name maps to a device spec of the
// project's backend registry (runtime/backend_registry.h), with options:
//
//   SPEC      = BACKEND[:ARGUMENT][?KEY[=VALUE][&KEY[=VALUE]]...]
//   e.g.        emulator:case1?hand=none
//               emulator:firewire
//               firewire:0x000b990012345678
//               replay:/path/to/recording
//
// Where the map comes from, first match wins:
//   1. VMH_HD_DEVICE=SPEC           the default device (NULL and the default
//                                   names below)
//   2. the file $VMH_HD_CONFIG, else $XDG_CONFIG_HOME/vmhaptics/hd.conf
//      (~/.config/... when XDG_CONFIG_HOME is unset): lines "NAME = SPEC",
//      '#' comments; "default = SPEC" sets the default device
//   3. built in: the default device is "emulator" (the MuJoCo Omni at
//      case 1's start pose, nothing holding the stylus)
// The default names are "Default Device", "Default PHANToM",
// "Default Phantom", "Phantom Omni", "PHANToM Omni", "Omni", "" and NULL
// (case-insensitive); any other name must be in the file.
//
// Pure: no device is opened here. Errors are HdConfigError naming the name,
// the file and line, and the names that are configured.
#ifndef VMHAPTICS_HD_HD_CONFIG_H_
#define VMHAPTICS_HD_HD_CONFIG_H_

#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace vmh::hd {

struct HdConfigError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A device spec split into what the registry opens and its options.
struct DeviceSpec {
  std::string device;  // BACKEND[:ARGUMENT], as the registry resolves it
  // KEY=VALUE options in order of appearance (a bare KEY has value "")
  std::vector<std::pair<std::string, std::string>> options;
  std::string text;    // the spec as written
};

// Splits SPEC at its first '?' and the options at '&'. Throws HdConfigError
// for an empty spec or an option with an empty key.
DeviceSpec parse_device_spec(const std::string& spec);

// the default names, lower-cased
bool is_default_name(const char* name);

struct HdConfig {
  // name (as written) -> spec; "default" for the default device
  std::map<std::string, std::string> names;
  std::string default_spec = "emulator";
  std::string default_from = "built in";  // for messages
  std::string file;                       // the file read ("" for none)
};

// Parses the text of a configuration file (`file` names it in errors).
// Throws HdConfigError naming the file and line of a malformed line or a
// name given twice.
HdConfig parse_hd_config(const std::string& text, const std::string& file);

// The configuration from the environment: VMH_HD_CONFIG or the XDG file if
// it exists, then VMH_HD_DEVICE. Throws HdConfigError for a file that
// cannot be read or parsed (a missing default file is not an error).
HdConfig load_hd_config();

// The spec a name opens. Throws HdConfigError: "no device is configured as
// 'NAME' (configured: A, B; file F)".
std::string resolve_device_name(const HdConfig& config, const char* name);

}  // namespace vmh::hd

#endif  // VMHAPTICS_HD_HD_CONFIG_H_
