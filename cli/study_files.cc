#include "cli/study_files.h"

#include "cli/args.h"
#include "device/stop_signal.h"
#include "sim/mujoco_util.h"
#include "thesis/run_case.h"

namespace vmh::cli {

std::string study_scene(const std::string& option, const std::string& value,
                        std::string* name) {
  std::string target = value;
  if (value.size() == 1 && value[0] >= '1' && value[0] <= '9') {
    target = "case" + value;
  }
  try {
    return sim::resolve_scene(target, name);
  } catch (const sim::SimError& e) {
    throw UsageError(option + ": " + e.what());
  }
}

std::vector<double> parse_number_list(const std::string& option,
                                      const std::string& text) {
  std::vector<double> out;
  std::string::size_type start = 0;
  int item = 1;
  while (true) {
    const auto comma = text.find(',', start);
    out.push_back(parse_number(option + " item " + std::to_string(item),
                               text.substr(start, comma - start)));
    if (comma == std::string::npos) break;
    start = comma + 1;
    ++item;
  }
  return out;
}

runtime::StopFn study_stop() {
  return [] { return stop_requested(); };
}

void throw_if_stopped_after_writing(const std::string& verb,
                                    const std::string& out) {
  runtime::throw_if_stopped(
      verb, out.empty() ? "; nothing written"
                        : "; its files in " + out + " were already written whole");
}

}  // namespace vmh::cli
