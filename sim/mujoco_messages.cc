#include "sim/mujoco_messages.h"

#include <mujoco/mujoco.h>

#include <cctype>
#include <cstring>
#include <mutex>

namespace vmh::sim {
namespace {

// the process's tally and the install, under one lock
std::mutex& messages_mutex() {
  static std::mutex m;
  return m;
}
MujocoWarningTally& process_tally() {
  static MujocoWarningTally tally;
  return tally;
}

thread_local MujocoWarningScope* t_innermost_scope = nullptr;

// MuJoCo's messages may span lines; ours are one line
std::string one_line(const char* text) {
  std::string s = text != nullptr ? text : "";
  for (char& ch : s) {
    if (ch == '\n' || ch == '\r') ch = ' ';
  }
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

// the text with each number ("3", "0.0010.") as '#': the warning's kind
// without its DOF or time
std::string masked(const std::string& text) {
  std::string out;
  for (std::size_t i = 0; i < text.size();) {
    if (std::isdigit(static_cast<unsigned char>(text[i])) != 0) {
      while (i < text.size() &&
             (std::isdigit(static_cast<unsigned char>(text[i])) != 0 ||
              text[i] == '.')) {
        ++i;
      }
      out += '#';
    } else {
      out += text[i++];
    }
  }
  return out;
}

void on_warning(const char* text) {
  // a warning must not unwind into MuJoCo: a failed allocation loses it
  try {
    record_mujoco_warning(text);
  } catch (...) {
  }
}

[[noreturn]] void on_error(const char* text) {
  throw MujocoError("MuJoCo error: " + one_line(text));
}

}  // namespace

void install_mujoco_handlers() {
  std::lock_guard<std::mutex> lock(messages_mutex());
  if (mju_user_warning == nullptr && mju_user_error == nullptr) {
    mju_user_warning = on_warning;
    mju_user_error = on_error;
  }
}

bool mujoco_handlers_installed() {
  std::lock_guard<std::mutex> lock(messages_mutex());
  return mju_user_warning == on_warning && mju_user_error == on_error;
}

const char* mujoco_warning_name(int warning) {
  static const char* const kNames[mjNWARNING] = {
      "inertia", "contactfull", "cnstrfull", "vgeomfull",
      "badqpos", "badqvel",     "badqacc",   "badctrl"};
  return warning >= 0 && warning < mjNWARNING ? kNames[warning] : "other";
}

const char* mujoco_warning_kind(const std::string& text) {
  // the starts of mju_warningText's messages (MuJoCo 2.2.2), in mjtWarning
  // order
  static const char* const kTexts[mjNWARNING] = {
      "Inertia matrix is too close to singular",
      "Pre-allocated contact buffer is full",
      "Pre-allocated constraint buffer is full",
      "Pre-allocated visual geom buffer is full",
      "Nan, Inf or huge value in QPOS",
      "Nan, Inf or huge value in QVEL",
      "Nan, Inf or huge value in QACC",
      "Nan, Inf or huge value in CTRL"};
  for (int i = 0; i < mjNWARNING; ++i) {
    if (text.rfind(kTexts[i], 0) == 0) return mujoco_warning_name(i);
  }
  return "other";
}

void MujocoWarningTally::add(const std::string& text) {
  add(Entry{mujoco_warning_kind(text), text, 1});
}

void MujocoWarningTally::merge(const MujocoWarningTally& other) {
  for (const Entry& o : other.entries) add(o);
}

void MujocoWarningTally::add(const Entry& entry) {
  const std::string key = masked(entry.text);
  for (Entry& e : entries) {
    if (masked(e.text) == key) {
      e.count += entry.count;
      return;
    }
  }
  entries.push_back(entry);
}

std::int64_t MujocoWarningTally::total() const {
  std::int64_t n = 0;
  for (const Entry& e : entries) n += e.count;
  return n;
}

std::int64_t MujocoWarningTally::count(const std::string& kind) const {
  std::int64_t n = 0;
  for (const Entry& e : entries) {
    if (e.kind == kind) n += e.count;
  }
  return n;
}

MujocoWarningScope::MujocoWarningScope() : parent_(t_innermost_scope) {
  t_innermost_scope = this;
}

MujocoWarningScope::~MujocoWarningScope() { t_innermost_scope = parent_; }

void record_mujoco_warning(const char* text) {
  const std::string line = one_line(text);
  for (MujocoWarningScope* s = t_innermost_scope; s != nullptr; s = s->parent_) {
    s->tally_.add(line);
  }
  std::lock_guard<std::mutex> lock(messages_mutex());
  process_tally().add(line);
}

MujocoWarningTally mujoco_warnings_so_far() {
  std::lock_guard<std::mutex> lock(messages_mutex());
  return process_tally();
}

void clear_mujoco_warnings() {
  std::lock_guard<std::mutex> lock(messages_mutex());
  process_tally() = MujocoWarningTally{};
}

std::vector<std::string> mujoco_warning_lines(const MujocoWarningTally& tally) {
  std::vector<std::string> lines;
  for (const MujocoWarningTally::Entry& e : tally.entries) {
    lines.push_back("MuJoCo warning (" + e.kind + ", " +
                    std::to_string(e.count) +
                    (e.count == 1 ? " time): " : " times): ") + e.text);
  }
  return lines;
}

}  // namespace vmh::sim
