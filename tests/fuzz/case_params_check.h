// The properties a loaded CaseParams must have, whichever way it was read
// (--set, ctl options, a scene's <custom> fields): shared by
// case_params_fuzz.cc and scene_fuzz.cc.
#ifndef VMHAPTICS_TESTS_FUZZ_CASE_PARAMS_CHECK_H_
#define VMHAPTICS_TESTS_FUZZ_CASE_PARAMS_CHECK_H_

#include <cmath>
#include <cstring>
#include <exception>
#include <stdexcept>
#include <string>

#include "controller/controller.h"
#include "sim/cases/case_params.h"
#include "sim/cases/case_params_detail.h"
#include "tests/fuzz/fuzz_check.h"

namespace vmh::fuzz {

// Every row of the table set, of its size, finite (or +inf where the row
// allows it), within its row's rule, and a text among its row's words; the
// tick count a run is bounded by (docs: duration_s / servo_period_s below
// kMaxTicksPerRun); and the controller made from the settings either built
// or refused with std::invalid_argument.
inline void check_loaded(const sim::CaseParams& c) {
  const auto& table = sim::case_fields();
  FUZZ_CHECK(c.values.size() == table.size(), "one value per table row");
  for (const sim::ParamSpec& f : table) {
    const sim::ParamValue& v = c.value(f);
    const std::string ctx = std::string("field ") + f.name;
    FUZZ_CHECK(v.set, "unset after loading: " + ctx);
    if (f.is_text) {
      FUZZ_CHECK(sim::detail::word_index(f.words, v.text) >= 0,
                 "text not among its words: " + ctx + " = '" + v.text + "'");
      continue;
    }
    FUZZ_CHECK(static_cast<int>(v.numbers.size()) == f.size,
               "wrong size: " + ctx);
    for (double x : v.numbers) {
      FUZZ_CHECK(std::isfinite(x) || (f.allow_inf && x > 0.0),
                 "non-finite value accepted: " + ctx);
      try {
        sim::check_param_number(f, x, "fuzz");
      } catch (const sim::ParamError& e) {
        fail(__FILE__, __LINE__, "accepted value out of its row's range",
             ctx + ": " + e.what());
      }
    }
  }
  FUZZ_CHECK(c.sim.duration_s > 0.0 && c.controller.servo_period_s > 0.0,
             "duration and servo period positive");
  FUZZ_CHECK(c.sim.duration_s / c.controller.servo_period_s <=
                 static_cast<double>(sim::kMaxTicksPerRun),
             "the ranges let the tick count pass kMaxTicksPerRun");
  FUZZ_CHECK(c.sim.fault_joint >= 1 && c.sim.fault_joint <= 6, "fault_joint");
  FUZZ_CHECK(std::isfinite(c.script.dir.norm()) && c.script.dir.norm() >= 1e-9,
             "script_dir zero or non-finite");
  try {
    Controller controller(sim::controller_params(c));
  } catch (const std::invalid_argument& e) {
    FUZZ_CHECK(std::strlen(e.what()) > 0, "empty validate message");
  }
}

// A refusal: a message that says something.
inline void check_refusal(const std::exception& e) {
  FUZZ_CHECK(std::strlen(e.what()) > 0, "refused without a message");
}

}  // namespace vmh::fuzz

#endif  // VMHAPTICS_TESTS_FUZZ_CASE_PARAMS_CHECK_H_
