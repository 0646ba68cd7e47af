// `vmhaptics report` as a user runs it: --quick writes one self-contained
// page and prints its JSON (about 20 s on two cores); a second run with
// --reuse takes every case and study from the first one's files, and a
// third runs only what was removed; bad options are refused with exit 2
// and one line.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/cli_run.h"
#include "tests/support/svg_check.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using vmh::testing::run;
using vmh::testing::read_file;

const std::vector<std::string> kCases = {"case1", "case2", "case3", "case4",
                                         "case5", "case6", "case7"};

TEST(ReportCliTest, QuickWritesThePageAndReuseTakesItsFiles) {
  const fs::path dir = vmh::testing::fresh_dir("vmh_report_cli_", "quick");
  const auto first = run("report --quick --out " + dir.string());
  const json j = json::parse(first.out);
  // 0 exactly when no claim failed on every side (a claim that holds on
  // some sides only (of the pivot, or of the path's distance) is listed in claims_partial); 1 otherwise,
  // the page still written
  EXPECT_EQ(first.exit_code,
            j.at("claims_passed").get<int>() +
                        static_cast<int>(j.at("claims_partial").size()) ==
                    j.at("claims_total").get<int>()
                ? 0
                : 1)
      << first.err;
  EXPECT_EQ(j.at("report").get<std::string>(), (dir / "report.html").string());
  EXPECT_EQ(j.at("cases").get<std::vector<std::string>>(), kCases);
  EXPECT_GT(j.at("claims_total").get<int>(), 0);
  EXPECT_TRUE(j.at("reused").empty());
  for (const char* ran : {"case1", "case6", "extremes", "stability_map", "precision"}) {
    EXPECT_NE(std::find(j.at("ran").begin(), j.at("ran").end(), ran),
              j.at("ran").end()) << ran;
  }
  EXPECT_GT(j.at("wall_s").get<double>(), 0.0);
  // the stderr bar is for terminals: none here
  EXPECT_EQ(first.err.find('\r'), std::string::npos);

  const std::string html = read_file(dir / "report.html");
  EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_NE(html.find("</html>"), std::string::npos);
  EXPECT_EQ(vmh::testing::count(html, "<svg"), vmh::testing::count(html, "</svg>"));
  for (const std::string& c : kCases) {
    EXPECT_NE(html.find("<section id=\"" + c + "\">"), std::string::npos) << c;
    EXPECT_TRUE(fs::exists(dir / c / "summary.json")) << c;
  }
  for (const char* id : {"runtime", "precision", "stability", "extremes"}) {
    EXPECT_NE(html.find(std::string("<section id=\"") + id + "\">"),
              std::string::npos) << id;
  }
  // one render per case, inline: "iVBORw0KGgo" is the base64 of the PNG
  // signature. Registered under Xvfb where the build has the renderer
  // (VMH_EXPECT_RENDERS); elsewhere each case must say why it has none.
#ifdef VMH_EXPECT_RENDERS
  EXPECT_EQ(vmh::testing::count(html, "src=\"data:image/png;base64,iVBORw0KGgo"),
            7) << first.err;
  EXPECT_EQ(html.find("render unavailable"), std::string::npos);
  for (const std::string& c : kCases) {
    EXPECT_FALSE(fs::is_empty(dir / c / "render")) << c;
  }
#else
  EXPECT_EQ(vmh::testing::count(html, "render unavailable: "), 7);
#endif
  for (const char* f : {"precision.svg", "stability_map.svg", "extremes.json"}) {
    EXPECT_TRUE(fs::exists(dir / "study" / f)) << f;
  }

  const auto second = run("report --reuse --quick --out " + dir.string());
  const json k = json::parse(second.out);
  EXPECT_EQ(second.exit_code, first.exit_code) << second.err;
  std::vector<std::string> reused_cases;
  for (const json& r : k.at("reused")) {
    const std::string name = r.get<std::string>();
    if (name.rfind("case", 0) == 0) reused_cases.push_back(name);
  }
  EXPECT_EQ(reused_cases, kCases);
  EXPECT_TRUE(k.at("ran").empty()) << k.dump();
  EXPECT_EQ(k.at("claims_passed"), j.at("claims_passed"));

  // what is missing runs, and only that: case 3 written again by `run`
  // (whose files --reuse takes as its own), the precision study's figure
  // removed (a study runs again when any of its files is missing)
  fs::remove_all(dir / "case3");
  ASSERT_TRUE(fs::remove(dir / "study" / "precision.svg"));
  ASSERT_EQ(run("run case3 --out " + dir.string()).exit_code, 0);
  const auto third = run("report --reuse --quick --out " + dir.string());
  const json t = json::parse(third.out);
  EXPECT_EQ(third.exit_code, first.exit_code) << third.err;
  EXPECT_EQ(t.at("ran"), json::array({"precision"})) << t.dump();
  std::vector<std::string> reused_again;
  for (const json& r : t.at("reused")) {
    const std::string name = r.get<std::string>();
    if (name.rfind("case", 0) == 0) reused_again.push_back(name);
  }
  EXPECT_EQ(reused_again, kCases);
  EXPECT_TRUE(fs::exists(dir / "study" / "precision.svg"));
  EXPECT_EQ(t.at("claims_passed"), j.at("claims_passed"));
}

TEST(ReportCliTest, BadOptionsAreRefusedWithOneLine) {
  for (const char* args : {"report --jobs -1", "report --jobs x",
                           "report --out ''", "report --frobnicate"}) {
    const auto r = run(args);
    EXPECT_EQ(r.exit_code, 2) << args;
    EXPECT_EQ(r.out, "") << args;
    EXPECT_EQ(r.err.rfind("vmhaptics: error: ", 0), 0u) << args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
}

}  // namespace
