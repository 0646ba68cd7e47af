// MuJoCo's errors and warnings, handled by the project instead of MuJoCo's
// defaults. Left alone, MuJoCo 2.2.2 prints a warning on stdout (into a
// verb's JSON) and appends it to MUJOCO_LOG.TXT in the current directory;
// an error is printed on stdout and logged the same way, then MuJoCo waits
// for a key on stdin and calls exit(1).
//
// install_mujoco_handlers() puts the project's handlers in place (main()
// calls it first, load_model() calls it before every load):
//
// - mju_user_warning counts each warning by kind, deduplicated (the text
//   with its numbers masked: "Time = 0.0030" and "Time = 0.0040" are one
//   kind), in a tally for the process and in every MujocoWarningScope open
//   on the calling thread. Nothing is printed and nothing is logged:
//   `vmhaptics` prints the process's tally on stderr as it exits
//   (mujoco_warning_lines), and `run` puts each run's in summary.json.
// - mju_user_error throws MujocoError with MuJoCo's message. MuJoCo calls
//   the handler as its last act (mju_error tail-calls it) and, if it
//   returned, would carry on with the state it had just found broken, so it
//   must not return. It throws rather than exits: MuJoCo 2.2.2's own model
//   compiler installs a (thread-local) handler that throws a C++ exception
//   through the same C frames, libmujoco.so carries the unwind tables for
//   them (.eh_frame), and an exception lets `run --all` fail one case with
//   a named message while the others finish; tests/sim/mujoco_messages_test
//   raises a real mju_error inside mj_step and catches it. The mjData the
//   error came from is left mid-step (its stack unrestored): drop it.
//
// Neither handler ever writes MUJOCO_LOG.TXT: MuJoCo writes that file only
// from its default handlers.
#ifndef VMHAPTICS_SIM_MUJOCO_MESSAGES_H_
#define VMHAPTICS_SIM_MUJOCO_MESSAGES_H_

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace vmh::sim {

// An error MuJoCo raised (mju_error): "MuJoCo error: <its message>", one
// line. Not a SimError: it is a failure of the run (exit 1), not bad input.
class MujocoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Installs the project's mju_user_error and mju_user_warning unless a
// handler is installed already (a test's guard, say, which then keeps
// MuJoCo's messages to itself). Thread-safe; cheap after the first call.
void install_mujoco_handlers();
// whether the project's handlers are the ones installed now
bool mujoco_handlers_installed();

// The name of one of MuJoCo's per-step warnings (mjtWarning, counted in
// mjData::warning[]): inertia, contactfull, cnstrfull, vgeomfull, badqpos,
// badqvel, badqacc, badctrl; "other" out of range.
const char* mujoco_warning_name(int warning);
// The kind of a warning's text: one of mujoco_warning_name's, or "other".
const char* mujoco_warning_kind(const std::string& text);

// Warnings deduplicated by their text with the numbers masked.
struct MujocoWarningTally {
  struct Entry {
    std::string kind;   // mujoco_warning_kind
    std::string text;   // the first of them, as MuJoCo wrote it
    std::int64_t count = 0;
  };
  std::vector<Entry> entries;  // in the order first seen

  void add(const std::string& text);
  // adds every entry of `other` (its counts), as if its texts came here
  void merge(const MujocoWarningTally& other);
  // an entry's count to the entry of the same text (numbers masked), or
  // the entry itself when there is none
  void add(const Entry& entry);
  std::int64_t total() const;
  // how many of a kind
  std::int64_t count(const std::string& kind) const;
};

// The warnings the handler sees on this thread while the scope is open
// (scopes nest; each sees every warning of its lifetime). Open it on the
// thread that steps the model: MuJoCo warns on the calling thread.
class MujocoWarningScope {
 public:
  MujocoWarningScope();
  ~MujocoWarningScope();
  MujocoWarningScope(const MujocoWarningScope&) = delete;
  MujocoWarningScope& operator=(const MujocoWarningScope&) = delete;

  const MujocoWarningTally& tally() const { return tally_; }

 private:
  friend void record_mujoco_warning(const char* text);
  MujocoWarningScope* parent_;
  MujocoWarningTally tally_;
};

// What the warning handler does with one message (the handler calls it;
// public for tests): counted in the process's tally and the open scopes.
void record_mujoco_warning(const char* text);

// Every warning seen in this process so far, and a reset for tests.
MujocoWarningTally mujoco_warnings_so_far();
void clear_mujoco_warnings();

// One line per kind for stderr, "MuJoCo warning (badqacc, 3 times): <the
// first text>"; none when there were none.
std::vector<std::string> mujoco_warning_lines(const MujocoWarningTally& tally);

}  // namespace vmh::sim

#endif  // VMHAPTICS_SIM_MUJOCO_MESSAGES_H_
