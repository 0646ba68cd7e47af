#include "cli/args.h"

#include <CLI/CLI.hpp>

#include <cerrno>
#include <cmath>
#include <cstdlib>

namespace vmh::cli {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

namespace {

// one item of a list; `where` says which item for the message
double to_number(const std::string& option, const std::string& raw,
                 const std::string& where) {
  const std::string item = trim(raw);
  if (item.empty()) {
    throw UsageError(option + ": " + where + " is empty");
  }
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(item.c_str(), &end);
  if (end == item.c_str() || *end != '\0') {
    throw UsageError(option + ": " + where + " '" + item + "' is not a number");
  }
  // strtod sets ERANGE for a subnormal result too (1e-320), which is a
  // number; only an overflow to inf is refused
  if (!std::isfinite(v)) {
    throw UsageError(option + ": " + where + " '" + item +
                     "' is not a finite number");
  }
  return v;
}

}  // namespace

std::vector<double> parse_list(const std::string& option,
                               const std::string& text, int count) {
  std::vector<std::string> items;
  std::string::size_type start = 0;
  while (true) {
    const auto comma = text.find(',', start);
    items.push_back(text.substr(start, comma - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (static_cast<int>(items.size()) != count) {
    throw UsageError(option + ": expected " + std::to_string(count) +
                     " comma-separated numbers, got " +
                     std::to_string(items.size()));
  }
  std::vector<double> out;
  out.reserve(items.size());
  for (std::size_t i = 0; i < items.size(); ++i) {
    out.push_back(to_number(option, items[i], "item " + std::to_string(i + 1)));
  }
  return out;
}

double parse_number(const std::string& option, const std::string& text) {
  return to_number(option, text, "value");
}

void refuse_empty(CLI::Option* option, const std::string& give) {
  option->check(CLI::Validator(
      [give](std::string& value) {
        return value.find_first_not_of(" \t") == std::string::npos
                   ? "the value is empty; give " + give
                   : std::string();
      },
      "", "NON_EMPTY"));
}

void refuse_empty_numbers(CLI::App* app) {
  for (CLI::Option* opt : app->get_options()) {
    const std::string type = opt->get_type_name();
    if (opt->get_type_size_max() > 0 &&
        (type == "FLOAT" || type == "INT" || type == "UINT")) {
      refuse_empty(opt, "a number");
    }
  }
  for (CLI::App* sub : app->get_subcommands([](CLI::App*) { return true; })) {
    refuse_empty_numbers(sub);
  }
}

}  // namespace vmh::cli
