#include "runtime/recording_meta.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "runtime/recording_detail.h"
#include "runtime/recording_reader.h"

namespace vmh::runtime {
namespace {

// the largest finite double: a bound that only says "finite"
constexpr double kHuge = std::numeric_limits<double>::max();

using recording_detail::shown;

// The checks a key's value goes through, naming the file and the key
class MetaChecker {
 public:
  MetaChecker(const Json& j, std::string path) : j_(j), path_(std::move(path)) {}

  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw RecordingError(path_ + ": key '" + key + "': " + what);
  }
  // the value at a dotted key's last part, or nullptr
  static const Json* child(const Json& o, const char* key) {
    const auto it = o.find(key);
    return it == o.end() ? nullptr : &*it;
  }
  std::string text(const Json& o, const char* key, const std::string& name,
                   bool nullable = false) const {
    const Json* v = child(o, key);
    if (v == nullptr || (nullable && v->is_null())) return {};
    if (!v->is_string()) fail(name, std::string("must be a string, not ") + v->type_name());
    return v->get<std::string>();
  }
  // a finite number in [lo, hi] (lo excluded when open_lo), or NaN when
  // the key is not there
  double number(const Json& o, const char* key, const std::string& name,
                double lo, double hi, bool open_lo = false) const {
    const Json* v = child(o, key);
    if (v == nullptr) return std::nan("");
    if (!v->is_number()) fail(name, std::string("must be a number, not ") + v->type_name());
    const double x = v->get<double>();
    if (!std::isfinite(x) || x < lo || x > hi || (open_lo && x == lo)) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "%s is not a finite number in %s%g, %g]",
                    v->dump().substr(0, 40).c_str(), open_lo ? "(" : "[", lo, hi);
      fail(name, buf);
    }
    return x;
  }
  // a whole number in [lo, hi], or `absent` when the key is not there
  long long integer(const Json& o, const char* key, const std::string& name,
                    long long lo, long long hi, long long absent) const {
    const Json* v = child(o, key);
    if (v == nullptr) return absent;
    if (!v->is_number_integer()) {
      fail(name, v->dump().substr(0, 40) + " is not a whole number in [" +
                     std::to_string(lo) + ", " + std::to_string(hi) + "]");
    }
    // a uint64 beyond int64 reads as negative: check it as unsigned first
    if (v->is_number_unsigned() && v->get<unsigned long long>() >
                                       static_cast<unsigned long long>(hi)) {
      fail(name, v->dump() + " is not in [" + std::to_string(lo) + ", " +
                     std::to_string(hi) + "]");
    }
    const long long x = v->get<long long>();
    if (x < lo || x > hi) {
      fail(name, std::to_string(x) + " is not in [" + std::to_string(lo) + ", " +
                     std::to_string(hi) + "]");
    }
    return x;
  }
  const Json* object(const Json& o, const char* key, const std::string& name) const {
    const Json* v = child(o, key);
    if (v == nullptr) return nullptr;
    if (!v->is_object()) fail(name, std::string("must be an object, not ") + v->type_name());
    return v;
  }
  void only_for(const char* key, const std::string& verb, const char* owner) const {
    if (child(j_, key) != nullptr && verb != owner) {
      fail(key, "a '" + verb + "' recording has no " + key + " (only '" + owner +
                    "' writes it): meta.json does not belong to this recording");
    }
  }

 private:
  const Json& j_;
  std::string path_;
};

// "verb": there, a string, and one of the verbs that write a recording
std::string meta_verb(const MetaChecker& c, const Json& j,
                      const std::string& path) {
  const Json* verb = MetaChecker::child(j, "verb");
  if (verb == nullptr) {
    throw RecordingError(path + ": no key 'verb' (not written by vmhaptics hw)");
  }
  if (!verb->is_string()) c.fail("verb", std::string("must be a string, not ") + verb->type_name());
  std::string name = verb->get<std::string>();
  bool known = false;
  for (const char* v : kRecordingVerbs) known |= name == v;
  if (!known) {
    c.fail("verb", "'" + shown(name) +
                       "' is not a verb that writes a recording (hw record, hw "
                       "motor-test, hw run)");
  }
  return name;
}

// "recording_format" (this reader's when absent), "software" (vmhaptics,
// a version string) and "date_utc": what wrote the recording
void check_writer(const MetaChecker& c, const Json& j) {
  const long long format = c.integer(j, "recording_format", "recording_format",
                                     0, 1'000'000, kRecordingFormat);
  if (format != kRecordingFormat) {
    c.fail("recording_format",
           std::to_string(format) + " is a format this reader does not know "
           "(it reads " + std::to_string(kRecordingFormat) +
           "): read it with the vmhaptics that wrote it");
  }
  if (const Json* s = c.object(j, "software", "software")) {
    if (MetaChecker::child(*s, "name") != nullptr &&
        c.text(*s, "name", "software.name") != "vmhaptics") {
      c.fail("software.name", "'" + shown(c.text(*s, "name", "software.name")) +
                                  "' is not vmhaptics");
    }
    c.text(*s, "version", "software.version");
  }
  c.text(j, "date_utc", "date_utc");
}

// "device": the identity of the device recorded
void read_device(const MetaChecker& c, const Json& d, DeviceIdentity* device) {
  device->backend = c.text(d, "backend", "device.backend");
  device->config = c.text(d, "config", "device.config");
  device->model = c.text(d, "model", "device.model");
  device->vendor = c.text(d, "vendor", "device.vendor");
  device->serial = c.text(d, "serial", "device.serial");
  device->driver_version = c.text(d, "driver_version", "device.driver_version");
  device->firmware_version =
      c.text(d, "firmware_version", "device.firmware_version");
  device->api_version = c.text(d, "api_version", "device.api_version");
  device->input_dof =
      static_cast<int>(c.integer(d, "input_dof", "device.input_dof", 0, 6, 0));
  device->output_dof = static_cast<int>(
      c.integer(d, "output_dof", "device.output_dof", 0, 6, 0));
}

// "session": its duration, ticks and nominal period
void read_session(const MetaChecker& c, const Json& s, RecordingMeta* m) {
  m->duration_s = c.number(s, "duration_s", "session.duration_s", 0.0, 1e7);
  c.integer(s, "ticks", "session.ticks", 0, 1'000'000'000'000LL, 0);
  if (const Json* t = c.object(s, "timing", "session.timing")) {
    const double us =
        c.number(*t, "nominal_period_us", "session.timing.nominal_period_us",
                 0.0, 1e6, true);
    if (std::isfinite(us)) m->nominal_period_s = 1e-6 * us;
  }
}

// the keys only one verb writes: refused in another verb's recording
void check_verb_keys(const MetaChecker& c, const std::string& verb) {
  c.only_for("motor", verb, "hw motor-test");
  c.only_for("torque_asked_mNm", verb, "hw motor-test");
  c.only_for("pulse_ms", verb, "hw motor-test");
  c.only_for("sets", verb, "hw run");
  c.only_for("gain_scale", verb, "hw run");
  c.only_for("case", verb, "hw run");
}

// hw motor-test's keys: the motor pulsed (required), the torque asked for,
// the pulse's length
void read_motor_test(const MetaChecker& c, const Json& j, RecordingMeta* m) {
  m->motor = static_cast<int>(c.integer(j, "motor", "motor", 1, 3, 0));
  if (m->motor == 0) {
    c.fail("motor", "missing: a motor test's meta.json names the motor it "
                    "pulsed (1, 2 or 3)");
  }
  m->torque_asked_mNm =
      c.number(j, "torque_asked_mNm", "torque_asked_mNm", -kHuge, kHuge);
  m->pulse_ms = c.number(j, "pulse_ms", "pulse_ms", 0.0, 1e4, true);
}

// hw run's keys: the case, its scene, its --set overrides, the gain scale
void read_run(const MetaChecker& c, const Json& j, RecordingMeta* m) {
  m->case_name = c.text(j, "case", "case");
  m->scene = c.text(j, "scene", "scene");
  if (const Json* s = MetaChecker::child(j, "sets")) {
    if (!s->is_array()) c.fail("sets", std::string("must be an array of strings, not ") + s->type_name());
    for (std::size_t i = 0; i < s->size(); ++i) {
      if (!(*s)[i].is_string()) {
        c.fail("sets[" + std::to_string(i) + "]",
               std::string("must be a string, not ") + (*s)[i].type_name());
      }
      m->sets.push_back((*s)[i].get<std::string>());
    }
  }
  m->gain_scale = c.number(j, "gain_scale", "gain_scale", 0.0, kHuge);
}

}  // namespace

RecordingMeta parse_recording_meta(const Json& j, const std::string& path) {
  if (!j.is_object()) {
    throw RecordingError(path + ": not a JSON object (a recording's meta.json "
                         "is one)");
  }
  const MetaChecker c(j, path);
  RecordingMeta m;
  m.json = j;
  m.verb = meta_verb(c, j, path);
  check_writer(c, j);
  if (const Json* d = c.object(j, "device", "device")) {
    read_device(c, *d, &m.device);
  }
  if (const Json* s = c.object(j, "session", "session")) {
    read_session(c, *s, &m);
  }
  check_verb_keys(c, m.verb);
  if (m.verb == "hw motor-test") read_motor_test(c, j, &m);
  if (m.verb == "hw run") {
    read_run(c, j, &m);
  } else if (MetaChecker::child(j, "scene") != nullptr) {
    c.text(j, "scene", "scene");
  }
  if (const Json* e = MetaChecker::child(j, "emulator"); e != nullptr && !e->is_null()) {
    if (!e->is_object()) c.fail("emulator", std::string("must be an object, not ") + e->type_name());
    m.emulator_scene = c.text(*e, "scene", "emulator.scene", true);
    c.text(*e, "hand", "emulator.hand", true);
  }
  return m;
}

}  // namespace vmh::runtime
