// `vmhaptics render` as a user runs it, under a display (Xvfb): the JSON on
// stdout names PNG files that exist, bad input is exit 2 with one line
// naming the bad value, no display is exit 1 naming it; nothing is written
// for either.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <string>

#include "tests/support/cli_run.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using vmh::testing::run;

fs::path fresh_dir(const std::string& name) {
  return vmh::testing::fresh_dir("vmh_render_cli_", name);
}

std::string head(const fs::path& p, std::size_t n) {
  std::ifstream in(p, std::ios::binary);
  std::string s(n, '\0');
  in.read(s.data(), static_cast<std::streamsize>(n));
  s.resize(static_cast<std::size_t>(in.gcount()));
  return s;
}

int lines(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n' ? 1 : 0;
  return n;
}

TEST(RenderCli, WritesTheImagesItNames) {
  const fs::path out = fresh_dir("ok");
  const auto r = run("render case1 --t 1,0.5 --width 200 --height 150 --out " +
                     out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j.at("case"), "case1");
  EXPECT_EQ(fs::path(j.at("scene").get<std::string>()).filename(), "case1.xml");
  EXPECT_EQ(j.at("width_px"), 200);
  EXPECT_EQ(j.at("height_px"), 150);
  EXPECT_EQ(j.at("camera"), "default");
  const json& images = j.at("images");
  ASSERT_EQ(images.size(), 2u);
  // in increasing time, whatever the order given
  EXPECT_EQ(images[0].at("t_s"), 0.5);
  EXPECT_EQ(images[1].at("t_s"), 1.0);
  for (const json& im : images) {
    const fs::path p = im.at("path").get<std::string>();
    EXPECT_EQ(p.parent_path(), out);
    ASSERT_TRUE(fs::exists(p)) << p;
    EXPECT_EQ(head(p, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << p;
    // IHDR: width and height, big-endian, after the signature and the
    // chunk's length and type
    const std::string ihdr = head(p, 24);
    ASSERT_EQ(ihdr.size(), 24u);
    EXPECT_EQ(ihdr.substr(12, 4), "IHDR");
    EXPECT_EQ(static_cast<unsigned char>(ihdr[19]), 200);
    EXPECT_EQ(static_cast<unsigned char>(ihdr[23]), 150);
    EXPECT_GE(im.at("sim_t_s").get<double>(), im.at("t_s").get<double>());
  }
  EXPECT_EQ(fs::path(images[0].at("path").get<std::string>()).filename(),
            "case1_t000500ms.png");
  // no temporary file is left behind
  int files = 0;
  for (const auto& e : fs::directory_iterator(out)) {
    EXPECT_EQ(e.path().extension(), ".png") << e.path();
    ++files;
  }
  EXPECT_EQ(files, 2);
}

// each bad input: exit 2, one line on stderr naming the value, no folder
void expect_refused(const std::string& args, const std::string& named) {
  const fs::path out = fresh_dir("bad");
  const auto r = run("render " + args + " --out " + out.string());
  EXPECT_EQ(r.exit_code, 2) << args << ": " << r.err;
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_EQ(r.err.rfind("vmhaptics: error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(named), std::string::npos)
      << args << ": '" << named << "' not in: " << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_FALSE(fs::exists(out)) << args << " wrote " << out;
}

TEST(RenderCli, BadInputIsExit2NamingIt) {
  expect_refused("case1 --t -1", "'-1'");
  expect_refused("case1 --t x", "'x'");
  expect_refused("case1 --t 0.5,nan", "nan");
  expect_refused("case9 --t 1", "'case9'");
  expect_refused("case1 --t 1 --width 3", "--width: 3");
  expect_refused("case1 --t 1 --height 9000", "--height: 9000");
  expect_refused("case1 --t 1 --camera nosuchcam", "'nosuchcam'");
  expect_refused("case1 --t 1 --set nosuchfield=1", "nosuchfield");
}

// without a display: exit 1 (not bad input), the cause named, nothing
// written
TEST(RenderCli, NoDisplayIsExit1NamingIt) {
  const fs::path out = fresh_dir("nodisplay");
  const auto r = run("render case1 --t 0.5 --out " + out.string(),
                     "env -u DISPLAY -u WAYLAND_DISPLAY ");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("no OpenGL context"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("xvfb-run"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST(RenderCli, HelpNamesTheOptions) {
  const auto r = run("render --help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* opt : {"--t", "--out", "--width", "--height", "--camera",
                          "--set", "--no-overlay", "xvfb-run"}) {
    EXPECT_NE(r.out.find(opt), std::string::npos) << opt;
  }
}

}  // namespace
