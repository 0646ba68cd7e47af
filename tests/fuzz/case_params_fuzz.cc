// libFuzzer harness: the case-parameter loader (sim/cases/case_params.h) as the
// command line drives it.
//
// The input is text, one item a line. If the first line is "ctl", the
// other lines are `vmhaptics ctl` options, "--option value"
// (sim::ctl_inputs); otherwise every line is a `--set name=value` item
// (sim::set_inputs). The items are loaded with load_case_params. It must
// either refuse with a sim::ParamError that has a message (no other
// exception) or accept with every value within its table row's documented
// range (case_params_check.h).
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "sim/cases/case_params.h"
#include "tests/fuzz/case_params_check.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data,
                                      std::size_t size) {
  using namespace vmh;
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> lines;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t nl = text.find('\n', start);
    lines.push_back(text.substr(start, nl == std::string::npos
                                           ? std::string::npos
                                           : nl - start));
    if (nl == std::string::npos) break;
    start = nl + 1;
  }
  if (!lines.empty() && lines.back().empty()) lines.pop_back();
  // each line is one argument: a C string, which ends at its first NUL
  for (std::string& l : lines) l = l.c_str();

  try {
    std::vector<sim::ParamInput> inputs;
    std::string source = "fuzz.xml";
    if (!lines.empty() && lines.front() == "ctl") {
      std::vector<std::pair<std::string, std::string>> given;
      for (std::size_t i = 1; i < lines.size(); ++i) {
        const std::size_t sp = lines[i].find(' ');
        given.emplace_back(lines[i].substr(0, sp),
                           sp == std::string::npos ? ""
                                                   : lines[i].substr(sp + 1));
      }
      inputs = sim::ctl_inputs(given);
      source = "ctl";
    } else {
      // a scene's required fields first, as a scene would give them
      inputs.push_back({"vm_kind", "circle", sim::ValueSource::kScene, source});
      for (sim::ParamInput& in : sim::set_inputs(lines)) {
        inputs.push_back(std::move(in));
      }
    }
    const sim::CaseParams c = sim::load_case_params(source, inputs);
    fuzz::check_loaded(c);
  } catch (const sim::ParamError& e) {
    fuzz::check_refusal(e);
  }
  return 0;
}
