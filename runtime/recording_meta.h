// meta.json's schema, as a recording is read back (runtime/recording_reader.h
// reads the file and includes this header): the verbs that write a
// recording, the format this reader knows, and what a valid meta.json
// holds. parse_recording_meta's refusals are RecordingErrors naming the
// file and the key.
#ifndef VMHAPTICS_RUNTIME_RECORDING_META_H_
#define VMHAPTICS_RUNTIME_RECORDING_META_H_

#include <limits>
#include <string>
#include <vector>

#include "device/device_backend.h"
#include "runtime/json_util.h"

namespace vmh::runtime {

// What meta.json's "recording_format" says (runtime/meta.cc writes it). A
// meta.json without the key predates it and is read as format 1, the
// layout it has; any other value is refused.
inline constexpr int kRecordingFormat = 1;

// The verbs whose sessions write a recording
inline constexpr const char* kRecordingVerbs[] = {"hw record", "hw motor-test",
                                                  "hw run"};

// meta.json after validation. The schema (every key optional unless said;
// a key that is there must have its type and range; other keys, such as a
// backend's own entries, are kept in `json` unread):
//   verb               required; one of kRecordingVerbs
//   recording_format   integer; kRecordingFormat
//   software           object; name "vmhaptics", version a string
//   date_utc           string
//   device             object; backend, config, model, vendor, serial,
//                      driver_version, firmware_version, api_version
//                      strings; input_dof, output_dof integers 0..6
//   session            object; duration_s finite >= 0, ticks integer >= 0,
//                      timing.nominal_period_us finite in (0, 1e6]
//   motor              "hw motor-test" only, and required there: 1, 2 or 3
//   torque_asked_mNm   "hw motor-test" only: finite
//   pulse_ms           "hw motor-test" only: finite in (0, 1e4]
//   case, scene        "hw run" only: strings
//   sets               "hw run" only: an array of strings
//   gain_scale         "hw run" only: finite and >= 0
//   emulator           object; scene and hand strings (or null)
struct RecordingMeta {
  std::string verb;
  DeviceIdentity device;
  double duration_s = std::numeric_limits<double>::quiet_NaN();
  double nominal_period_s = 0.0;  // 0 when not known
  int motor = 0;                  // 1..3 for a motor test, else 0
  double torque_asked_mNm = std::numeric_limits<double>::quiet_NaN();
  double pulse_ms = std::numeric_limits<double>::quiet_NaN();
  std::string case_name;          // hw run
  std::string scene;              // hw run: the case's scene
  std::vector<std::string> sets;  // hw run: its --set overrides
  double gain_scale = std::numeric_limits<double>::quiet_NaN();  // hw run
  std::string emulator_scene;     // the scene an emulator simulated, or ""
  Json json;                      // meta.json as written
};

// Validates a parsed meta.json against the schema; `path` names the file
// in messages ("<path>: key 'motor': 99 is not 1, 2 or 3").
RecordingMeta parse_recording_meta(const Json& j, const std::string& path);

}  // namespace vmh::runtime

#endif  // VMHAPTICS_RUNTIME_RECORDING_META_H_
