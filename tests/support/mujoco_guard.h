// Test support for MuJoCo: a guard that records every MuJoCo error and
// warning instead of letting the default handlers print and exit, so that a
// test can fail with the message (MuJoCo's own test/fixture.h does the same).
//
// Install one guard per test (a fixture member or a local); it restores the
// previous handlers when it goes out of scope. An error handler that returns
// leaves MuJoCo in an undefined state, so the handler throws: gtest reports
// the exception as a failure of the running test.
#ifndef VMHAPTICS_TESTS_SUPPORT_MUJOCO_GUARD_H_
#define VMHAPTICS_TESTS_SUPPORT_MUJOCO_GUARD_H_

#include <mujoco/mujoco.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace vmh::testing {

inline std::vector<std::string>& mujoco_warnings() {
  static std::vector<std::string> messages;
  return messages;
}

class MujocoGuard {
 public:
  MujocoGuard() : old_error_(mju_user_error), old_warning_(mju_user_warning) {
    mujoco_warnings().clear();
    mju_user_error = [](const char* msg) {
      throw std::runtime_error(std::string("mujoco error: ") + msg);
    };
    mju_user_warning = [](const char* msg) {
      mujoco_warnings().push_back(std::string("mujoco warning: ") + msg);
    };
  }
  ~MujocoGuard() {
    mju_user_error = old_error_;
    mju_user_warning = old_warning_;
  }
  MujocoGuard(const MujocoGuard&) = delete;
  MujocoGuard& operator=(const MujocoGuard&) = delete;

  // every warning seen since the guard was made, one per line ("" if none)
  static std::string warnings() {
    std::string all;
    for (const std::string& m : mujoco_warnings()) all += m + "\n";
    return all;
  }

  // the warnings MuJoCo counted in d->warning (instabilities, bad contacts,
  // ...): "name: count" per kind seen, "" if none
  static std::string data_warnings(const mjData* d) {
    static const char* const kNames[mjNWARNING] = {
        "inertia",   "contactfull", "cnstrfull", "vgeomfull",
        "badqpos",   "badqvel",     "badqacc",   "badctrl"};
    std::string all;
    for (int i = 0; i < mjNWARNING; ++i) {
      if (d->warning[i].number > 0) {
        all += std::string(kNames[i]) + ": " +
               std::to_string(d->warning[i].number) + "\n";
      }
    }
    return all;
  }

 private:
  void (*old_error_)(const char*);
  void (*old_warning_)(const char*);
};

}  // namespace vmh::testing

#endif  // VMHAPTICS_TESTS_SUPPORT_MUJOCO_GUARD_H_
