// libFuzzer harness: the command line's argument parsing (CLI11 with
// cli/args.h's checks) on the verbs that need no scene: kin, ctl, params.
//
// The input is the argument list, one argument a line (argv[0] is
// "vmhaptics"). The real verbs are registered as in cli/main.cc, with
// refuse_empty_numbers, and the arguments are parsed, which runs the verb.
// The outcome must be one of main()'s:
//  - success: what the verb wrote on stdout is one JSON object (kin, ctl)
//    whose numbers are all finite (no null but where docs/outputs.md
//    documents one), or the parameter table (params);
//  - bad usage (exit 2): a CLI::ParseError or a vmh::cli::UsageError with a
//    one-line message;
//  - a run failure (exit 1): only ctl's "controller fault", with a message.
// No other exception may escape. An argument that is empty or blank is
// never taken for a number (CLI11 would read "" as 0).
// parse_number and parse_list are also called directly on each argument:
// they accept a finite number (subnormals too) or refuse with a message that
// names the option.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "cli/args.h"
#include "cli/ctl.h"
#include "cli/kin.h"
#include "cli/params.h"
#include "tests/fuzz/fuzz_check.h"

namespace {

// every number of a JSON document finite. nlohmann writes a NaN or inf as
// null, so null is refused too, except under the keys docs/outputs.md
// documents as null: kin ik's `nearest` when no solution is there, kin's
// `J_pos_condition` at a singular pose
bool all_finite(const nlohmann::json& j, const std::string& key = "") {
  if (j.is_null()) return key == "nearest" || key == "J_pos_condition";
  if (j.is_number_float()) return std::isfinite(j.get<double>());
  if (j.is_object()) {
    for (const auto& [k, v] : j.items()) {
      if (!all_finite(v, k)) return false;
    }
  } else if (j.is_array()) {
    for (const auto& v : j) {
      if (!all_finite(v)) return false;
    }
  }
  return true;
}

void check_direct(const std::string& arg) {
  using vmh::cli::UsageError;
  try {
    const double v = vmh::cli::parse_number("--x", arg);
    FUZZ_CHECK(std::isfinite(v), "parse_number accepted a non-finite value: " + arg);
    FUZZ_CHECK(arg.find_first_not_of(" \t") != std::string::npos,
               "parse_number accepted a blank value");
  } catch (const UsageError& e) {
    FUZZ_CHECK(std::string(e.what()).rfind("--x: ", 0) == 0,
               std::string("message does not name the option: ") + e.what());
  }
  try {
    const std::vector<double> v = vmh::cli::parse_list("--q", arg, 3);
    FUZZ_CHECK(v.size() == 3, "parse_list returned the wrong count: " + arg);
    for (double x : v) FUZZ_CHECK(std::isfinite(x), "parse_list non-finite: " + arg);
  } catch (const UsageError& e) {
    FUZZ_CHECK(std::string(e.what()).rfind("--q: ", 0) == 0,
               std::string("message does not name the option: ") + e.what());
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data,
                                      std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> args{"vmhaptics"};
  std::size_t start = 0;
  while (start < text.size() && args.size() < 40) {
    const std::size_t nl = text.find('\n', start);
    args.push_back(text.substr(start, nl == std::string::npos ? std::string::npos
                                                              : nl - start));
    if (nl == std::string::npos) break;
    start = nl + 1;
  }
  for (std::size_t i = 1; i < args.size(); ++i) check_direct(args[i]);
  // a C string ends at the first NUL, as an argv entry would
  for (std::string& a : args) a = a.c_str();
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());

  CLI::App app{"vmhaptics (fuzz)"};
  app.require_subcommand(1);
  vmh::cli::register_kin(&app);
  vmh::cli::register_ctl(&app);
  vmh::cli::register_params(&app);
  vmh::cli::refuse_empty_numbers(&app);

  std::ostringstream out;
  std::streambuf* saved = std::cout.rdbuf(out.rdbuf());
  std::string verb;
  bool ok = false;
  try {
    app.parse(static_cast<int>(argv.size()), argv.data());
    ok = true;
  } catch (const CLI::Success&) {
    // --help, --help-all: printed nothing here (app.exit would)
  } catch (const CLI::ParseError& e) {
    FUZZ_CHECK(std::string(e.what()).size() > 0, "empty parse error");
  } catch (const vmh::cli::UsageError& e) {
    const std::string m = e.what();
    FUZZ_CHECK(!m.empty(), "empty usage error");
    FUZZ_CHECK(m.find('\n') == std::string::npos, "usage error of two lines: " + m);
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    FUZZ_CHECK(m.rfind("ctl: controller fault", 0) == 0,
               "an exception main() would report as a run failure (exit 1): " + m);
  }
  std::cout.rdbuf(saved);
  if (!ok) return 0;

  for (CLI::App* sub : app.get_subcommands()) verb = sub->get_name();
  const std::string printed = out.str();
  if (verb == "params") {
    FUZZ_CHECK(printed.find("force_limit_N") != std::string::npos,
               "params printed no table");
    return 0;
  }
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(printed);
  } catch (const nlohmann::json::exception& e) {
    vmh::fuzz::fail(__FILE__, __LINE__, "stdout is not JSON",
                    std::string(e.what()) + ": " + printed.substr(0, 200));
  }
  FUZZ_CHECK(j.is_object(), "stdout is not a JSON object");
  FUZZ_CHECK(all_finite(j), "a non-finite number (or null) on stdout: " +
                                printed.substr(0, 400));
  return 0;
}
