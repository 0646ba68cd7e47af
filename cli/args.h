// Parsing and checking of the command line's numeric arguments.
//
// Every function throws vmh::cli::UsageError with a one-line message that
// names the option and what was wrong with it; main() prints it and exits 2.
#ifndef VMHAPTICS_CLI_ARGS_H_
#define VMHAPTICS_CLI_ARGS_H_

#include <stdexcept>
#include <string>
#include <vector>

namespace CLI {
class App;
class Option;
}  // namespace CLI

namespace vmh::cli {

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Parses "a,b,c" into exactly `count` finite numbers. `option` (e.g. "--q")
// is named in the error message.
std::vector<double> parse_list(const std::string& option,
                               const std::string& text, int count);

// `s` without its leading and trailing blanks (spaces and tabs)
std::string trim(const std::string& s);

// Parses one finite number. Subnormal numbers (1e-320) are numbers; a
// value that overflows to inf (1e999) is not.
double parse_number(const std::string& option, const std::string& text);

// Gives every numeric option of `app` and its sub-verbs (CLI11's FLOAT, INT
// and UINT options, not flags) a check that refuses an empty value: CLI11
// would read "" as 0, i.e. as the option's default. The help is unchanged.
void refuse_empty_numbers(CLI::App* app);

// The same check on one option of any type: for a text option whose empty
// value would otherwise mean "not given" (study precision --steps "" ran the
// whole default ladder).
void refuse_empty(CLI::Option* option, const std::string& give = "a value");

}  // namespace vmh::cli

#endif  // VMHAPTICS_CLI_ARGS_H_
