// The MuJoCo-free reader of a scene's <custom> fields (sim/cases/scene_fields.h)
// against MuJoCo's own compiler (mj_loadXML) on every scene of models/ and
// of the tests: the same fields, kinds and values, and the same case
// parameters; and the reader's refusals, each naming the file and what was
// wrong.
#include "sim/cases/scene_fields.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <map>
#include <sstream>

#include "sim/cases/case_config.h"
#include "sim/mujoco_util.h"
#include "tests/support/temp_mjcf.h"

namespace vmh::sim {
namespace {

namespace fs = std::filesystem;
using vmh::testing::TempMjcfDir;

std::vector<double> numbers(const std::string& text) {
  std::istringstream in(text);
  std::vector<double> v;
  double x;
  while (in >> x) v.push_back(x);
  return v;
}

// every MJCF file under models/ and tests/sim/scenes that MuJoCo compiles
// on its own (omni.xml and hand.xml are included fragments, not models)
std::vector<std::string> scenes() {
  std::vector<std::string> out;
  for (const char* dir : {VMH_MODELS_DIR, VMH_TEST_SCENES_DIR}) {
    for (const auto& e : fs::recursive_directory_iterator(dir)) {
      if (e.path().extension() != ".xml") continue;
      char err[1000] = "";
      mjModel* m = mj_loadXML(e.path().c_str(), nullptr, err, sizeof err);
      if (m == nullptr) continue;
      mj_deleteModel(m);
      out.push_back(e.path().string());
    }
  }
  return out;
}

TEST(SceneFields, AgreeWithMuJoCoOnEveryScene) {
  const std::vector<std::string> all = scenes();
  ASSERT_GE(all.size(), 7u);  // the six cases and more
  int with_fields = 0;
  for (const std::string& path : all) {
    ModelPtr m = load_model(path);
    std::map<std::string, std::vector<double>> mj_numeric;
    std::map<std::string, std::string> mj_text;
    for (int i = 0; i < m->nnumeric; ++i) {
      if (m->numeric_size[i] == 0) continue;
      mj_numeric[m->names + m->name_numericadr[i]] = std::vector<double>(
          m->numeric_data + m->numeric_adr[i],
          m->numeric_data + m->numeric_adr[i] + m->numeric_size[i]);
    }
    for (int i = 0; i < m->ntext; ++i) {
      mj_text[m->names + m->name_textadr[i]] = m->text_data + m->text_adr[i];
    }
    const std::vector<CustomField> fields = read_scene_fields(path);
    EXPECT_EQ(fields.size(), mj_numeric.size() + mj_text.size()) << path;
    for (const CustomField& f : fields) {
      if (f.is_text) {
        ASSERT_TRUE(mj_text.count(f.name)) << path << ": " << f.name;
        EXPECT_EQ(f.value, mj_text[f.name]) << path << ": " << f.name;
      } else {
        ASSERT_TRUE(mj_numeric.count(f.name)) << path << ": " << f.name;
        EXPECT_EQ(numbers(f.value), mj_numeric[f.name]) << path << ": " << f.name;
      }
    }
    with_fields += fields.empty() ? 0 : 1;
  }
  EXPECT_GE(with_fields, 7);
}

// the case parameters the two routes give, through the one loader
TEST(SceneFields, GiveTheCaseParametersMuJoCosFieldsGive) {
  for (int n = 1; n <= 6; ++n) {
    const std::string path =
        std::string(VMH_MODELS_DIR) + "/cases/case" + std::to_string(n) + ".xml";
    const std::vector<std::string> sets = {"k_pos_N_per_mm=0.25", "duration_s=3"};
    const CaseParams a = load_scene_params(path, sets);
    ModelPtr m = load_model(path);
    const CaseConfig b = CaseConfig::from_model(m.get(), path, sets);
    ASSERT_EQ(a.values.size(), b.values.size());
    for (std::size_t i = 0; i < a.values.size(); ++i) {
      EXPECT_EQ(a.values[i].text, b.values[i].text) << path << " " << case_fields()[i].name;
      EXPECT_EQ(a.values[i].numbers, b.values[i].numbers) << path << " " << case_fields()[i].name;
      EXPECT_EQ(a.values[i].source, b.values[i].source) << path << " " << case_fields()[i].name;
    }
    const ControllerParams pa = case_controller_params(a);
    const ControllerParams pb = case_controller_params(b);
    EXPECT_EQ(pa.gains.k_pos_N_per_mm, 0.25);
    EXPECT_EQ(pa.gains.k_ornt_Nmm_per_rad, pb.gains.k_ornt_Nmm_per_rad);
    EXPECT_EQ(pa.vm.kind, pb.vm.kind);
    EXPECT_EQ(pa.vm.length_mm, pb.vm.length_mm);
    EXPECT_EQ(pa.servo_period_s, pb.servo_period_s);
    EXPECT_EQ(a.sim.duration_s, 3.0);
    EXPECT_EQ(a.thesis_case, n);
  }
}

std::string refusal(const std::string& path) {
  try {
    read_scene_fields(path);
  } catch (const ParamError& e) {
    return e.what();
  }
  return "(read)";
}

TEST(SceneFields, IncludesResolveAgainstTheMainFilesFolder) {
  TempMjcfDir dir;
  fs::create_directories(dir.path() / "sub");
  dir.write("sub/one.xml", "<mujoco><include file=\"two.xml\"/></mujoco>");
  dir.write("two.xml",
            "<mujoco><custom><numeric name=\"x\" data=\"2\"/></custom></mujoco>");
  dir.write("sub/two.xml",
            "<mujoco><custom><numeric name=\"x\" data=\"1\"/></custom></mujoco>");
  // the include's children take its place: an include inside <custom>
  dir.write("in_custom.xml", "<mujoco><numeric name=\"y\" size=\"3\" data=\"4\"/></mujoco>");
  const std::string main = dir.write(
      "main.xml",
      "<?xml version=\"1.0\"?>\n<!-- a comment <custom> -->\n<mujoco model='m'>"
      "<include file=\"sub/one.xml\"/>"
      "<custom><include file=\"in_custom.xml\"/>"
      "<text name=\"t\" data=\"a &amp; b &#65;\"/></custom></mujoco>");
  const std::vector<CustomField> f = read_scene_fields(main);
  ASSERT_EQ(f.size(), 3u);
  EXPECT_EQ(f[0].name, "x");
  EXPECT_EQ(numbers(f[0].value), std::vector<double>{2});  // not sub/two.xml's 1
  EXPECT_EQ(f[1].name, "y");
  EXPECT_EQ(numbers(f[1].value), (std::vector<double>{4, 0, 0}));  // size pads
  EXPECT_EQ(f[2].value, "a & b A");
  // MuJoCo reads the same
  ModelPtr m = load_model(main);
  EXPECT_EQ(m->numeric_data[m->numeric_adr[0]], 2.0);
}

TEST(SceneFields, RefusalsNameTheFileAndWhat) {
  TempMjcfDir dir;
  const auto write = [&](const char* name, const char* xml) { return dir.write(name, xml); };
  EXPECT_NE(refusal(write("cycle.xml", "<mujoco><include file=\"cycle.xml\"/></mujoco>"))
                .find("includes itself"), std::string::npos);
  EXPECT_NE(refusal(write("missing.xml", "<mujoco><include file=\"nope.xml\"/></mujoco>"))
                .find("nope.xml: no such file"), std::string::npos);
  EXPECT_NE(refusal(write("open.xml", "<mujoco>\n<custom>\n</mujoco>")).find("line 3"),
            std::string::npos);
  EXPECT_NE(refusal(write("entity.xml",
                          "<mujoco><custom><text name=\"a\" data=\"&bogus;\"/></custom></mujoco>"))
                .find("unknown entity &bogus;"), std::string::npos);
  EXPECT_NE(refusal(write("much.xml",
                          "<mujoco><custom><numeric name=\"a\" size=\"1\" data=\"1 2\"/></custom></mujoco>"))
                .find("more data than its size"), std::string::npos);
  EXPECT_NE(refusal(write("dtd.xml", "<!DOCTYPE x><mujoco/>")).find("DTD"), std::string::npos);
  EXPECT_NE(refusal(write("quote.xml", "<mujoco model=m/>")).find("not quoted"),
            std::string::npos);
  const std::string fifo = (dir.path() / "fifo.xml").string();
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_NE(refusal(fifo).find("not a regular file"), std::string::npos);
  std::string deep = "<mujoco><include file=\"d0.xml\"/></mujoco>";
  for (int i = 0; i < 20; ++i) {
    dir.write("d" + std::to_string(i) + ".xml",
              "<mujoco><include file=\"d" + std::to_string(i + 1) + ".xml\"/></mujoco>");
  }
  EXPECT_NE(refusal(write("deep.xml", deep.c_str())).find("nested more than 16"),
            std::string::npos);
  // an unknown field is the loader's refusal, as with MuJoCo
  try {
    load_scene_params(write("unknown.xml",
                            "<mujoco><custom><numeric name=\"bogus\" data=\"1\"/></custom></mujoco>"),
                      {});
    FAIL();
  } catch (const ParamError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown <custom> field 'bogus'"), std::string::npos);
  }
}

// The loader bounds a scene before MuJoCo reads it (issue 34): MuJoCo's
// own reader would block on an included FIFO and would compile and step a
// scene of any size. Each refusal is a SimError naming the file and what
// was wrong, and comes before any compile.
TEST(SceneBounds, TheLoaderRefusesWhatMuJoCoWouldHangOrDrownOn) {
  TempMjcfDir dir;
  const auto refused = [](const std::string& path) {
    try {
      (void)load_model(path);
    } catch (const SimError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const auto has = [](const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
  };
  // an include that is a FIFO: refused by its type, never opened
  const std::string fifo = (dir.path() / "part.xml").string();
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  std::string m = refused(dir.write("with_fifo.xml", "<mujoco><include file=\"part.xml\"/></mujoco>"));
  EXPECT_TRUE(has(m, "<include file=\"part.xml\">: " + fifo + " is a FIFO, not a regular file")) << m;
  // a scene that includes itself
  m = refused(dir.write("self.xml", "<mujoco><include file=\"self.xml\"/></mujoco>"));
  EXPECT_TRUE(has(m, "includes itself (a cycle)")) << m;
  // more bodies than the bound (comments do not count)
  std::string many = "<mujoco><worldbody><!-- <body/> -->";
  for (int i = 0; i <= kMaxSceneBodies; ++i) many += "<body><geom size=\"0.1\"/></body>";
  m = refused(dir.write("many.xml", (many + "</worldbody></mujoco>").c_str()));
  EXPECT_TRUE(has(m, std::to_string(kMaxSceneBodies + 1) + " bodies with its includes")) << m;
  std::string enough = "<mujoco><worldbody>";
  for (int i = 0; i < kMaxSceneBodies; ++i) enough += "<body><geom size=\"0.1\"/></body>";
  EXPECT_EQ(refused(dir.write("enough.xml", (enough + "</worldbody></mujoco>").c_str())), "");
  // XML over the bound, counted over the scene and its includes together
  const std::string half(kMaxSceneBytes / 2 + 16, ' ');
  dir.write("half.xml", ("<mujoco>" + half + "</mujoco>").c_str());
  m = refused(dir.write("two_halves.xml", ("<mujoco><include file=\"half.xml\"/>" + half +
                                           "</mujoco>").c_str()));
  EXPECT_TRUE(has(m, "over the reader's bound")) << m;
  // an asset that is a FIFO or a folder
  const std::string mesh = (dir.path() / "m.stl").string();
  ASSERT_EQ(mkfifo(mesh.c_str(), 0600), 0);
  m = refused(dir.write("mesh.xml", "<mujoco><asset><mesh name=\"m\" file=\"m.stl\"/></asset></mujoco>"));
  EXPECT_TRUE(has(m, "asset 'm.stl' (" + mesh + ") is a FIFO, not a regular file")) << m;
  std::filesystem::create_directories(dir.path() / "tex" / "t.png");
  m = refused(dir.write("tex.xml", "<mujoco><compiler texturedir=\"tex\"/><asset>"
                                   "<texture name=\"t\" type=\"2d\" file=\"t.png\"/></asset></mujoco>"));
  EXPECT_TRUE(has(m, "asset 't.png'") && has(m, "is a folder")) << m;
  // the headless loader checks the same
  try {
    (void)load_model_headless((dir.path() / "with_fifo.xml").string());
    ADD_FAILURE() << "a scene including a FIFO was loaded headless";
  } catch (const SimError& e) {
    EXPECT_TRUE(has(e.what(), "is a FIFO")) << e.what();
  }
}

}  // namespace
}  // namespace vmh::sim
