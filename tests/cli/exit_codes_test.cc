// docs/cli.md's exit-code table, walked verb by verb (issue 34, item 7).
//
// The verbs come from the binary's own help, not from a list here: a verb
// added later without a row below fails ExitCodes.EveryVerbHasItsRow. Each
// leaf verb is run with --help (0), an option it does not have (2), and the
// input of its own that the table names for exit 2 (a value out of its
// range, a case or a file that is not there); where a success or a failure
// (1) is cheap to reach it is run too. The signals' row (130, 143) is
// walked by tests/cli/interrupt_cli_test.cc and the run's and hw verbs'
// own signal tests, which need a process in flight.
//
// Every refusal must be one line on stderr, "vmhaptics: error: ...", that
// names its cause (the option, the value or the file).
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/cli_run.h"

namespace {

using vmh::testing::CliRun;
using vmh::testing::run;

// the names under "Subcommands:" in `vmhaptics <prefix> --help`
std::vector<std::string> subcommands(const std::string& prefix) {
  const CliRun r = run(prefix + " --help");
  std::vector<std::string> out;
  std::istringstream in(r.out);
  std::string line;
  bool in_list = false;
  while (std::getline(in, line)) {
    if (line.rfind("Subcommands:", 0) == 0) {
      in_list = true;
      continue;
    }
    if (!in_list) continue;
    // "  name   description": two spaces, then the name
    if (line.size() > 2 && line[0] == ' ' && line[1] == ' ' && line[2] != ' ') {
      out.push_back(line.substr(2, line.find(' ', 2) - 2));
    }
  }
  return out;
}

// every leaf verb under `prefix` ("kin fk", "hw run", "hw decode
// firewire-state", "run", ...)
void add_leaves(const std::string& prefix, std::vector<std::string>* out) {
  const std::vector<std::string> sub = subcommands(prefix);
  if (sub.empty()) {
    out->push_back(prefix);
    return;
  }
  for (const std::string& s : sub) add_leaves(prefix.empty() ? s : prefix + " " + s, out);
}
std::vector<std::string> leaf_verbs() {
  static const std::vector<std::string> verbs = [] {
    std::vector<std::string> out;
    add_leaves("", &out);
    return out;
  }();
  return verbs;
}

struct Row {
  std::vector<std::pair<std::string, std::string>> refused;  // args, cause named
  std::string succeeds;  // args that exit 0 quickly ("" if none here)
  std::string fails;     // args that exit 1 ("" if none here)
};

// the table's rows for each verb: exit 2 with what the message must name
const std::map<std::string, Row>& rows() {
  static const std::map<std::string, Row> r = {
      {"kin fk",
       {{{"--q 1,2", "expected 6 comma-separated numbers"},
         {"--qq 0,0,0,0,0,0", "has no option --qq"}},  // not "--q is required"
        "--q 0,0,0,0,0,0",
        ""}},
      {"kin jac", {{{"--q nan,0,0,0,0,0", "'nan' is not a finite number"}}, "--q 0,0,0,0,0,0", ""}},
      {"kin ik", {{{"--p-mm 1,2", "--p-mm"}}, "", ""}},
      {"kin params", {{{"extra", "extra"}}, "", ""}},
      {"ctl",
       {{{"--q 0,0,0,0,0,0 --vm bogus", "unknown value 'bogus'"}},
        "--q 0,0,0,0,0,0",
        "--kornt 0.5 --q=0.1,nan,0.3,0,0,0"}},
      {"run",
       {{{"case9", "'case9' is neither a case"},
         {"case1 --duration 0", "must be > 0 and <= 3600, got 0"},
         {"/nonexistent/scene.xml", "/nonexistent/scene.xml"}},
        "",
        "case1 --duration 0.5"}},
      {"params", {{{"bogus", "bogus"}}, "", ""}},
      {"study extremes", {{{"--only bogus", "unknown extreme scenario 'bogus'"}}, "", ""}},
      {"study precision", {{{"--case case9", "'case9' is neither a case"}}, "", ""}},
      {"study leanness", {{{"--case case9", "'case9' is neither a case"}}, "", ""}},
      {"study stability",
       {{{"--mass 0 --damping 1 --servo-period 0.001", "--mass: the slider's mass must be > 0 kg"},
         {"--damping 1 --servo-period 0.001", "--mass is required"}},
        "",
        ""}},
      {"study sensitivity", {{{"--shard 3/2", "'3/2' is not K/N"}}, "", ""}},
      {"study merge", {{{"--out OUT /nonexistent", "/nonexistent: cannot read"}}, "", ""}},
      {"compare", {{{"/nonexistent", "/nonexistent/meta.json: no such file"}}, "", ""}},
      {"identify",
       {{{"/nonexistent", "/nonexistent is not a directory"},
         // an option after a positional argument is still named
         {"/nonexistent --scene x", "has no option --scene"}},
        "",
        ""}},
      {"report", {{{"--out /proc/vmh_no/x", "/proc/vmh_no/x"}}, "", ""}},
      {"render",
       {{{"case1 --t 1e6 --out OUT", "--t: time 1e+06 s is past the scene's duration_s"}},
        "",
        ""}},
      {"view", {{{"case9", "'case9' is neither a case"}}, "", ""}},
      {"hw list", {{{"extra", "extra"}}, "", ""}},
      {"hw probe", {{{"--seconds 1e9", "--seconds must be > 0 and <= 3600 s"}}, "", ""}},
      {"hw record", {{{"--duration -1", "--duration must be > 0 and <= 86400 s"}}, "", ""}},
      {"hw motor-test",
       {{{"--motor 4 --torque-mNm 1 --ms 10", "--motor must be 1, 2 or 3"}}, "", ""}},
      {"hw run", {{{"case1 --duration 4000", "--duration must be > 0 and <= 3600 s"}}, "", ""}},
      {"hw calibrate", {{{"--sweep-s 0.5", "--sweep-s must be > 1 and <= 600 s"}}, "", ""}},
      {"hw decode firewire-state", {{{"zz", "'zz' has a non-hex digit"}}, "", ""}},
      {"hw decode firewire-command",
       {{{"0000", "'0000' is 2 bytes"}}, "00000000000000000000000000000000", ""}},
      {"hw encode firewire-command", {{{"", "is required"}}, "", ""}},
      {"hw encode firewire-state", {{{"--pot-codes 1,2,9999", "--pot-codes"}}, "", ""}},
      {"hw capture", {{{"--duration 1e9 --out OUT", "--duration"}}, "", ""}},
  };
  return r;
}

// one line on stderr, the error's
void expect_one_error_line(const CliRun& r, const std::string& what) {
  EXPECT_EQ(r.err.rfind("vmhaptics: error: ", 0), 0u) << what << ": " << r.err;
  ASSERT_FALSE(r.err.empty()) << what;
  EXPECT_EQ(r.err.back(), '\n') << what;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << what << ": more than one line: " << r.err;
}

std::string with_out(std::string args, const std::string& verb) {
  const std::string out = vmh::testing::fresh_dir("vmh_exit_", verb).string();
  for (std::size_t at; (at = args.find("OUT")) != std::string::npos;) {
    args.replace(at, 3, out);
  }
  return args;
}

TEST(ExitCodes, EveryVerbHasItsRow) {
  const std::vector<std::string> verbs = leaf_verbs();
  // the help lists the verbs docs/cli.md documents: at least these
  for (const char* v : {"kin fk", "ctl", "run", "hw run", "compare", "identify"}) {
    EXPECT_NE(std::find(verbs.begin(), verbs.end(), v), verbs.end()) << v;
  }
  for (const std::string& v : verbs) {
    EXPECT_EQ(rows().count(v), 1u) << "no exit-code row for '" << v << "'";
  }
}

TEST(ExitCodes, HelpIsZeroAndAnUnknownOptionTwo) {
  for (const std::string& v : leaf_verbs()) {
    const CliRun help = run(v + " --help");
    EXPECT_EQ(help.exit_code, 0) << v;
    EXPECT_NE(help.out.find("vmhaptics " + v + " [OPTIONS]"), std::string::npos) << v;
    const CliRun bad = run(v + " --no-such-option-here");
    EXPECT_EQ(bad.exit_code, 2) << v << ": " << bad.err;
    expect_one_error_line(bad, v);
    EXPECT_NE(bad.err.find("--no-such-option-here"), std::string::npos) << v << ": " << bad.err;
  }
}

TEST(ExitCodes, EachVerbsOwnBadInputIsTwoAndNamed) {
  for (const std::string& v : leaf_verbs()) {
    const auto it = rows().find(v);
    if (it == rows().end()) continue;  // EveryVerbHasItsRow says so
    for (const auto& [args, cause] : it->second.refused) {
      const std::string a = with_out(args, "refused");
      const CliRun r = run(v + " " + a);
      EXPECT_EQ(r.exit_code, 2) << v << " " << a << ": " << r.err;
      expect_one_error_line(r, v + " " + a);
      EXPECT_NE(r.err.find(cause), std::string::npos)
          << v << " " << a << ": the message does not name '" << cause << "': " << r.err;
      EXPECT_TRUE(r.out.empty()) << v << " " << a << " printed a result: " << r.out;
    }
  }
}

TEST(ExitCodes, SuccessIsZeroAndAFailureOne) {
  for (const auto& [v, row] : rows()) {
    if (!row.succeeds.empty()) {
      const CliRun r = run(v + " " + row.succeeds);
      EXPECT_EQ(r.exit_code, 0) << v << " " << row.succeeds << ": " << r.err;
      EXPECT_FALSE(r.out.empty()) << v;
    }
    if (!row.fails.empty()) {
      const CliRun r = run(v + " " + row.fails);
      EXPECT_EQ(r.exit_code, 1) << v << " " << row.fails << ": " << r.err;
      EXPECT_NE(r.err.find("vmhaptics: error: "), std::string::npos) << v << ": " << r.err;
    }
  }
}

}  // namespace
