// The report's page: well formed (every element closed in order), every
// figure present (each <img> a base64 PNG, each inline <svg> balanced),
// every case and every claim of its summary.json on it, failing claims
// marked, and the summary's count right. Once on real runs of the seven cases
// and once on made-up inputs with a failing claim and a render.
#include "thesis/report_html.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <atomic>
#include <filesystem>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include "thesis/run_case.h"
#include "tests/support/svg_check.h"

namespace vmh::thesis {
namespace {

namespace fs = std::filesystem;

const char kPngSignature[] = "\x89PNG\r\n\x1a\n";

// HTML's void elements, which the page writes self-closed
bool is_void(const std::string& name) {
  for (const char* v : {"meta", "img", "br", "hr", "link", "input"}) {
    if (name == v) return true;
  }
  return false;
}

// "" when, after the DOCTYPE, every element is closed in order under one
// <html> root and void elements are self-closed; else what is wrong
std::string html_problems(const std::string& s) {
  const std::string doctype = "<!DOCTYPE html>";
  if (s.compare(0, doctype.size(), doctype) != 0) return "no DOCTYPE";
  std::vector<std::string> open;
  std::size_t i = doctype.size();
  bool root_seen = false;
  while (true) {
    const std::size_t lt = s.find('<', i);
    if (lt == std::string::npos) break;
    const std::size_t gt = s.find('>', lt);
    if (gt == std::string::npos) return "unclosed '<' at " + std::to_string(lt);
    const std::string tag = s.substr(lt + 1, gt - lt - 1);
    if (tag.find('<') != std::string::npos) return "'<' inside a tag at " + std::to_string(lt);
    if (std::count(tag.begin(), tag.end(), '"') % 2 != 0) return "unpaired quote in <" + tag + ">";
    if (tag.empty()) return "empty tag";
    if (tag[0] == '/') {
      const std::string name = tag.substr(1);
      if (open.empty() || open.back() != name) {
        return "</" + name + "> closes " + (open.empty() ? "nothing" : "<" + open.back() + ">");
      }
      open.pop_back();
    } else {
      const std::string name = tag.substr(0, tag.find_first_of(" \n/"));
      if (open.empty()) {
        if (root_seen || name != "html") return "root is not one <html>";
        root_seen = true;
      }
      if (tag.back() != '/') {
        if (is_void(name)) return "<" + name + "> not self-closed";
        open.push_back(name);
      }
    }
    i = gt + 1;
  }
  if (!open.empty()) return "<" + open.back() + "> never closed";
  return root_seen ? "" : "no <html>";
}

// base64 decoded by table, independently of the writer's encoder
std::string unbase64(const std::string& in) {
  const std::string alphabet =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  unsigned acc = 0;
  int bits = 0;
  for (char c : in) {
    if (c == '=') break;
    const std::size_t v = alphabet.find(c);
    if (v == std::string::npos) return "<bad base64>";
    acc = (acc << 6) | static_cast<unsigned>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += static_cast<char>((acc >> bits) & 0xFF);
    }
  }
  return out;
}

// every check the page must pass; returns the number of <img> seen
int check_page(const std::string& html) {
  EXPECT_EQ(html_problems(html), "");
  // found by hand: std::regex recurses per character and overflows the
  // stack on figures of a megabyte
  int svgs = 0;
  for (std::size_t p = html.find("<svg"); p != std::string::npos;
       p = html.find("<svg", p + 1), ++svgs) {
    const std::size_t end = html.find("</svg>", p);
    EXPECT_NE(end, std::string::npos);
    if (end == std::string::npos) break;
    EXPECT_EQ(testing::tag_problems(html.substr(p, end + 6 - p)), "")
        << "inline svg " << svgs;
  }
  EXPECT_GT(svgs, 0);
  int imgs = 0;
  for (std::size_t p = html.find("<img "); p != std::string::npos;
       p = html.find("<img ", p + 1), ++imgs) {
    const std::size_t a = html.find(" src=\"", p) + 6;
    const std::string src = html.substr(a, html.find('"', a) - a);
    const std::string prefix = "data:image/png;base64,";
    EXPECT_EQ(src.compare(0, prefix.size(), prefix), 0) << "an <img> not inline";
    if (src.compare(0, prefix.size(), prefix) != 0) continue;
    EXPECT_EQ(unbase64(src.substr(prefix.size())).substr(0, 8),
              std::string(kPngSignature, 8));
  }
  // nothing outside the file
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(html.find("href=\"http"), std::string::npos);
  EXPECT_EQ(html.find(" src=\"http"), std::string::npos);
  return imgs;
}

TEST(ReportHtmlTest, Base64MatchesRfc4648) {
  EXPECT_EQ(base64(""), "");
  EXPECT_EQ(base64("f"), "Zg==");
  EXPECT_EQ(base64("fo"), "Zm8=");
  EXPECT_EQ(base64("foo"), "Zm9v");
  EXPECT_EQ(base64("foobar"), "Zm9vYmFy");
  EXPECT_EQ(unbase64(base64(std::string("\x00\xff\x10\x80", 4))),
            std::string("\x00\xff\x10\x80", 4));
}

TEST(ReportHtmlTest, InlineSvgDropsTheProlog) {
  EXPECT_EQ(inline_svg("<?xml version=\"1.0\"?>\n<svg a=\"1\"></svg>\n"),
            "<svg a=\"1\"></svg>\n");
}

// the seven cases run for real (20 s each, about half a second of wall time
// each), loaded from their files as `report --reuse` loads them
TEST(ReportHtmlTest, RealRunsOfTheSevenCasesAreAllOnThePage) {
  const fs::path dir = fs::path(::testing::TempDir()) / "vmh_report_html_cases";
  fs::remove_all(dir);
  std::vector<CaseJob> jobs;
  for (const sim::CaseEntry& c : sim::case_catalogue()) {
    std::string name;
    jobs.push_back({c.name, sim::resolve_scene(c.name, &name), {}, {}, false});
  }
  // the progress callback, called from the two workers, ends at 7 of 7
  std::atomic<std::size_t> last_done{0}, calls{0};
  run_cases(&jobs, {}, dir.string(), 2, "",
            [&](std::size_t done, std::size_t total) {
              EXPECT_EQ(total, 7u);
              ++calls;
              std::size_t seen = last_done.load();
              while (done > seen && !last_done.compare_exchange_weak(seen, done)) {
              }
            });
  EXPECT_EQ(calls.load(), 7u);
  EXPECT_EQ(last_done.load(), 7u);
  ReportInputs in;
  in.header.version = "test";
  for (const CaseJob& j : jobs) {
    ASSERT_EQ(j.error, "") << j.name;
    in.cases.push_back(load_report_case(dir.string(), j.name, RenderFn{}));
  }
  const std::string html = report_html(in);
  EXPECT_EQ(check_page(html), 0);  // no renderer: no image
  int total = 0, passed = 0, failed = 0;
  for (const CaseJob& j : jobs) {
    EXPECT_NE(html.find("<section id=\"" + j.name + "\">"), std::string::npos) << j.name;
    const nlohmann::json summary = nlohmann::json::parse(
        read_file_text((dir / j.name / "summary.json").string()));
    for (const nlohmann::json& c : summary.at("claims")) {
      const std::string name = c.at("name");
      EXPECT_NE(html.find("id=\"" + j.name + "-claim-" + name + "\"><td>" + name + "</td>"),
                std::string::npos) << name;
      ++total;
      passed += c.at("pass") == true ? 1 : 0;
      failed += c.at("pass") == false ? 1 : 0;
    }
  }
  EXPECT_GT(total, 0);
  EXPECT_NE(html.find("Claims passed: <span class=\"" +
                      std::string(failed == 0 ? "pass" : "fail") + "\">" +
                      std::to_string(passed) + "/" + std::to_string(total)),
            std::string::npos);
  EXPECT_EQ(testing::count(html, "render unavailable: no renderer in this build"), 7u);
  // the force field of every case: one panel for the circles (cases 1-4)
  // and the line (7), three for the spheres (5, 6)
  EXPECT_EQ(testing::count(html, "-force-field-ff-xy\""), 7u);
  EXPECT_EQ(testing::count(html, "-force-field-ff-zy\""), 2u);
  // every id on the page once: the figures' own ids are prefixed per figure
  std::map<std::string, int> ids;
  const std::regex id_attr(R"re(\sid="([^"]*)")re");
  for (auto it = std::sregex_iterator(html.begin(), html.end(), id_attr);
       it != std::sregex_iterator(); ++it) {
    ++ids[(*it)[1].str()];
  }
  EXPECT_GT(ids.size(), 50u);
  for (const auto& [id, n] : ids) EXPECT_EQ(n, 1) << id;
}

TEST(ReportHtmlTest, InlineSvgPrefixesItsIdsAndTheirReferences) {
  const std::string svg =
      "<svg><defs><clipPath id=\"plot-clip\"><rect/></clipPath></defs>"
      "<g clip-path=\"url(#plot-clip)\" data-id=\"keep\"><use href=\"#m\"/>"
      "<use xlink:href=\"#m\"/><a href=\"https://x\"/></g>\n<path\nid=\"m\"/></svg>";
  EXPECT_EQ(inline_svg(svg, "f1-"),
            "<svg><defs><clipPath id=\"f1-plot-clip\"><rect/></clipPath></defs>"
            "<g clip-path=\"url(#f1-plot-clip)\" data-id=\"keep\"><use href=\"#f1-m\"/>"
            "<use xlink:href=\"#f1-m\"/><a href=\"https://x\"/></g>\n<path\nid=\"f1-m\"/></svg>");
  EXPECT_EQ(inline_svg(svg), svg);
}

TEST(ReportHtmlTest, LoadNamesAMissingSummary) {
  const fs::path dir = fs::path(::testing::TempDir()) / "vmh_report_html_empty";
  fs::create_directories(dir / "case1");
  try {
    load_report_case(dir.string(), "case1", RenderFn{});
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("summary.json"), std::string::npos) << e.what();
  }
}

nlohmann::json claim(const std::string& name, double value, bool pass) {
  return {{"name", name}, {"value", value}, {"comparison", "<="},
          {"threshold", 1.0}, {"unit", "mm"}, {"pass", pass},
          {"statement", "a < b & c > d"}, {"window", "hold"}};
}

TEST(ReportHtmlTest, AFailingClaimIsMarkedAndARenderEmbedded) {
  ReportInputs in;
  in.header.command_line = "vmhaptics report --out <x>";  // escaped
  const std::string svg = "<svg xmlns=\"http://www.w3.org/2000/svg\"><g><line x1=\"0\"/></g></svg>\n";
  for (int k = 1; k <= 2; ++k) {
    ReportCase c;
    c.name = "case" + std::to_string(k);
    c.summary = {{"thesis_case", k},
                 {"claims", {claim("held_near", 0.5, true),
                             claim(k == 2 ? "drifts_far" : "stays", 3.0, k != 2)}}};
    c.views_svg = svg;
    c.history_svg = svg;
    c.force_field_svg = svg;
    if (k == 1) {
      c.render_png = std::string(kPngSignature, 8) + std::string("IHDR-and-more", 13);
    } else {
      c.render_note = "no GL context";
    }
    in.cases.push_back(c);
  }
  in.studies.extremes = {{"scenarios", {{{"name", "gain_x100"}, {"pass", false},
                                         {"outcome", "failed:force"}}}}};
  const std::string html = report_html(in);
  EXPECT_EQ(check_page(html), 1);
  EXPECT_NE(html.find("render unavailable: no GL context"), std::string::npos);
  // the failing claim's row, and nothing else, is marked
  const std::regex fail_row(R"(<tr class="fail" id="case2-claim-drifts_far"><td>drifts_far</td>[\s\S]*?FAIL</td>)");
  EXPECT_TRUE(std::regex_search(html, fail_row));
  EXPECT_EQ(html.find("<tr class=\"fail\" id=\"case1-claim-held_near\">"), std::string::npos);
  // the first screen: the matrix before any case's section, its failing
  // cell linked to the claim's row; the build's details at the end
  const std::size_t matrix = html.find("<table class=\"matrix\">");
  ASSERT_NE(matrix, std::string::npos);
  EXPECT_LT(matrix, html.find("<section id=\"case1\">"));
  EXPECT_LT(html.find("<table class=\"runtime\">"), html.find("<section id=\"case1\">"));
  EXPECT_NE(html.find("<td class=\"fail\"><a href=\"#case2-claim-drifts_far\">FAIL</a></td>"),
            std::string::npos);
  EXPECT_GT(html.find("<table class=\"header\">"), html.find("<section id=\"extremes\">"));
  EXPECT_NE(html.find("<tr class=\"fail\"><td>gain_x100</td>"), std::string::npos);
  EXPECT_NE(html.find("3/4"), std::string::npos);
  EXPECT_NE(html.find("case2:drifts_far"), std::string::npos);
  EXPECT_NE(html.find("&lt;x&gt;"), std::string::npos);
  const ClaimTally t = tally_claims(in.cases);
  EXPECT_EQ(t.passed, 3);
  EXPECT_EQ(t.total, 4);
}

// An SVG read back from a folder (report --reuse) that would run or load
// something is not inlined: the page promises no scripts (issue 34). The
// note names the file and what it holds; the clean figure beside it is
// inlined as before.
TEST(ReportHtmlTest, AFigureWithActiveContentIsNotInlined) {
  const std::string clean =
      "<svg xmlns=\"http://www.w3.org/2000/svg\"><g><line x1=\"0\"/></g></svg>\n";
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"<svg><script>alert(1)</script></svg>", "a <script> element"},
      {"<svg><SCRIPT src=\"x.js\"/></svg>", "a <script> element"},
      {"<svg onload=\"alert(1)\"><g/></svg>", "an event handler (onload=)"},
      {"<svg><g\n ONCLICK = \"x()\"/></svg>", "an event handler (ONCLICK =)"},
      {"<svg><a href=\"javascript:alert(1)\"><text>x</text></a></svg>",
       "a javascript: link"},
      {"<svg><foreignObject><iframe/></foreignObject></svg>",
       "a <foreignobject> element"},
  };
  for (const auto& [svg, what] : bad) {
    ReportInputs in;
    ReportCase c;
    c.name = "case1";
    c.summary = {{"thesis_case", 1}, {"claims", {claim("held_near", 0.5, true)}}};
    c.views_svg = svg;
    c.history_svg = clean;
    in.cases.push_back(c);
    const std::string html = report_html(in);
    EXPECT_EQ(html.find("alert(1)"), std::string::npos) << svg;
    EXPECT_EQ(html.find("x.js"), std::string::npos) << svg;
    EXPECT_NE(html.find("case1/views.svg: not shown: it holds " +
                        std::string(what == "a <script> element"
                                        ? "a &lt;script&gt; element"
                                        : what == "a <foreignobject> element"
                                              ? "a &lt;foreignobject&gt; element"
                                              : what)),
              std::string::npos)
        << svg;
    // the clean figure is still on the page
    EXPECT_NE(html.find("<line x1=\"0\"/>"), std::string::npos) << svg;
  }
  // the words alone, outside an attribute or element, are no handler
  ReportInputs in;
  ReportCase c;
  c.name = "case1";
  c.summary = {{"thesis_case", 1}, {"claims", {claim("held_near", 0.5, true)}}};
  c.views_svg = "<svg><text x=\"1\">on path, on=off</text></svg>";
  in.cases.push_back(c);
  EXPECT_NE(report_html(in).find("on path, on=off"), std::string::npos);
}

// A claim that holds on one side only: its verdict names the side where it
// fails, and every side is listed with its value and prediction, the
// failing one marked; the value, threshold and prediction share one cell.
TEST(ReportHtmlTest, APartialClaimNamesItsFailingSide) {
  ReportInputs in;
  ReportCase c;
  c.name = "case2";
  nlohmann::json k = claim("bends", 0.7, true);
  k["pass"] = "partial";
  k["prediction"] = 0.72;
  k["matches_prediction"] = true;
  k["sides"] = {{{"where", "left of the pivot"}, {"value", 0.95}, {"pass", true},
                 {"prediction", 0.96}, {"matches_prediction", true}},
                {{"where", "right of the pivot"}, {"value", 0.41}, {"pass", false},
                 {"prediction", 0.4}, {"matches_prediction", true}}};
  c.summary = {{"thesis_case", 2}, {"claims", {k}}};
  in.cases.push_back(c);
  const std::string html = report_html(in);
  EXPECT_NE(html.find("<td class=\"partial\"><a href=\"#case2-claim-bends\">"
                      "partial: fails right of the pivot</a></td>"),
            std::string::npos);
  EXPECT_NE(html.find("<td>0.7 &lt;= 1 mm (law: 0.72, agrees)</td>"), std::string::npos);
  EXPECT_NE(html.find("<li>left of the pivot: 0.95 &lt;= 1 mm (law: 0.96, agrees), holds</li>"),
            std::string::npos);
  EXPECT_NE(html.find("<li class=\"fail\">right of the pivot: 0.41 &lt;= 1 mm (law: 0.4, "
                      "agrees), FAILS</li>"),
            std::string::npos);
}

}  // namespace
// What --reuse reads is read as untrusted input: a FIFO in a file's place
// is refused by its type (reading it would wait for a writer for ever),
// a device is refused before it is read; a missing file is "".
TEST(ReportReuse, OnlyRegularFilesAreRead) {
  const std::string dir = ::testing::TempDir() + "vmh_report_reuse";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  EXPECT_EQ(read_file_text(dir + "/none.svg"), "");
  const std::string fifo = dir + "/views.svg";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  try {
    (void)read_file_text(fifo);
    ADD_FAILURE() << "a FIFO was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("views.svg is a FIFO"), std::string::npos) << e.what();
  }
  std::filesystem::remove(fifo);
  std::filesystem::create_symlink("/dev/zero", fifo);
  EXPECT_THROW((void)read_file_text(fifo), std::runtime_error);
  std::filesystem::remove_all(dir);
}

}  // namespace vmh::thesis
