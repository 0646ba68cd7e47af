#include "runtime/json_util.h"

#include <ctime>

namespace vmh {

namespace {

// true for a scalar, or an array whose items are all flat
bool flat(const Json& j) {
  if (j.is_object()) return false;
  if (!j.is_array()) return true;
  for (const Json& item : j) {
    if (item.is_object()) return false;
    if (item.is_array()) {
      for (const Json& x : item) {
        if (x.is_structured()) return false;
      }
    }
  }
  return true;
}

// compact text with a space after each comma, for one-line arrays
std::string one_line(const Json& j) {
  if (!j.is_array()) return j.dump();  // a scalar, or an empty object: {}
  std::string s = "[";
  bool first = true;
  for (const Json& item : j) {
    if (!first) s += ", ";
    s += one_line(item);
    first = false;
  }
  return s + "]";
}

void write(const Json& j, int indent, std::string* out) {
  if (flat(j) || j.empty()) {
    *out += one_line(j);
    return;
  }
  const std::string pad(static_cast<std::size_t>(indent + 2), ' ');
  const std::string close_pad(static_cast<std::size_t>(indent), ' ');
  const bool object = j.is_object();
  *out += object ? "{\n" : "[\n";
  bool first = true;
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (!first) *out += ",\n";
    *out += pad;
    if (object) *out += Json(it.key()).dump() + ": ";
    write(*it, indent + 2, out);
    first = false;
  }
  *out += "\n" + close_pad + (object ? "}" : "]");
}

}  // namespace

std::string dump_readable(const Json& j) {
  std::string out;
  write(j, 0, &out);
  return out;
}

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

}  // namespace vmh
