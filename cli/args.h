// Parsing and checking of the command line's numeric arguments.
//
// Every function throws vmh::cli::UsageError with a one-line message that
// names the option and what was wrong with it; main() prints it and exits 2.
#ifndef VMHAPTICS_CLI_ARGS_H_
#define VMHAPTICS_CLI_ARGS_H_

#include <stdexcept>
#include <string>
#include <vector>

namespace vmh::cli {

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Parses "a,b,c" into exactly `count` finite numbers. `option` (e.g. "--q")
// is named in the error message.
std::vector<double> parse_list(const std::string& option,
                               const std::string& text, int count);

// Parses one finite number.
double parse_number(const std::string& option, const std::string& text);

}  // namespace vmh::cli

#endif  // VMHAPTICS_CLI_ARGS_H_
