// The backend registry (runtime/backend_registry.h): a spec resolves to the
// longest registered name, unknown ones are named with the grammars, an
// option the backend does not take is refused naming those that take it,
// a backend without a servo loop is refused for one, and `hw list` carries
// every backend's own row.
#include <gtest/gtest.h>

#include "runtime/backend_registry.h"

namespace vmh::runtime {
namespace {

// a backend that records how it was opened
struct Opened {
  std::string name;
  OpenRequest request;
};

BackendInfo fake(const std::string& name, std::vector<BackendOption> options,
                 Opened* seen, bool servo = true) {
  BackendInfo b;
  b.name = name;
  b.grammar = name + "[:ARG]";
  b.summary = "a test backend";
  b.options = std::move(options);
  b.servo = servo;
  b.list = [name] { return Json{{"available", true}, {"found", name + " here"}}; };
  if (servo) {
    b.open = [seen, name](const OpenRequest& rq) {
      seen->name = name;
      seen->request = rq;
      return OpenedDevice{};
    };
  } else {
    b.probe = [](const std::string& a) { return Json{{"probed", a}}; };
  }
  return b;
}

class RegistryTest : public ::testing::Test {
 protected:
  void SetUp() override {
    reg.add(fake("emu", {{"hand", "h"}, {"fault", "f"}}, &seen));
    reg.add(fake("emu:wire", {{"hand", "h"}, {"fault", "f"}}, &seen));
    reg.add(fake("dev", {{"cmd", "c"}}, &seen));
    reg.add(fake("usbish", {}, &seen, /*servo=*/false));
  }
  BackendRegistry reg;
  Opened seen;
};

TEST_F(RegistryTest, ASpecResolvesToTheLongestName) {
  std::string arg;
  EXPECT_EQ(reg.resolve("emu", &arg).name, "emu");
  EXPECT_EQ(arg, "");
  EXPECT_EQ(reg.resolve("emu:case2", &arg).name, "emu");
  EXPECT_EQ(arg, "case2");
  EXPECT_EQ(reg.resolve("emu:wire", &arg).name, "emu:wire");
  EXPECT_EQ(arg, "");
  EXPECT_EQ(reg.resolve("emu:wire:case3", &arg).name, "emu:wire");
  EXPECT_EQ(arg, "case3");
  // a name is matched whole, not as a prefix of a word
  EXPECT_THROW(reg.resolve("emulator", &arg), RequestError);
}

TEST_F(RegistryTest, AnUnknownBackendIsNamedWithTheGrammars) {
  std::string arg;
  try {
    reg.resolve("nosuch:x", &arg);
    FAIL();
  } catch (const RequestError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("'nosuch'"), std::string::npos) << m;
    EXPECT_NE(m.find("emu:wire[:ARG]"), std::string::npos) << m;
  }
}

TEST_F(RegistryTest, OpenPassesTheArgumentAndOptions) {
  OpenRequest rq;
  rq.options["hand"] = "tour";
  reg.open("emu:wire:scene.xml", rq);
  EXPECT_EQ(seen.name, "emu:wire");
  EXPECT_EQ(seen.request.argument, "scene.xml");
  EXPECT_EQ(seen.request.option("hand"), "tour");
}

TEST_F(RegistryTest, AnOptionTheBackendDoesNotTakeIsRefusedNamingWhoDoes) {
  OpenRequest rq;
  rq.options["fault"] = "drop@1:5";
  try {
    reg.open("dev", rq);
    FAIL();
  } catch (const RequestError& e) {
    EXPECT_EQ(std::string(e.what()),
              "--fault: only emu, emu:wire take it, not --device dev");
  }
  rq.options = {{"bogus", "1"}};
  EXPECT_THROW(reg.open("emu", rq), RequestError);
}

TEST_F(RegistryTest, DefaultsApplyOnlyWhereNotGiven) {
  OpenRequest rq;
  rq.defaults["hand"] = "case";
  EXPECT_EQ(rq.option("hand"), "case");
  rq.options["hand"] = "none";
  EXPECT_EQ(rq.option("hand"), "none");
  EXPECT_EQ(rq.option("fault"), "");
}

TEST_F(RegistryTest, ABackendWithoutAServoLoopIsRefusedForOne) {
  EXPECT_THROW(reg.open("usbish", OpenRequest{}), RequestError);
}

TEST_F(RegistryTest, TheListHasEveryBackendsOwnRowInOrder) {
  const Json j = reg.list();
  ASSERT_EQ(j.at("backends").size(), 4u);
  EXPECT_EQ(j["backends"][0]["name"], "emu");
  EXPECT_EQ(j["backends"][0]["device"], "emu[:ARG]");
  EXPECT_EQ(j["backends"][0]["found"], "emu here");
  EXPECT_EQ(j["backends"][3]["name"], "usbish");
}

TEST_F(RegistryTest, OptionUsesNameTheBackendsThatTakeEachKey) {
  const auto uses = reg.option_uses();
  ASSERT_EQ(uses.size(), 3u);
  EXPECT_EQ(uses[0].key, "hand");
  EXPECT_EQ(uses[0].backends, "emu, emu:wire");
  EXPECT_EQ(uses[2].key, "cmd");
}

TEST_F(RegistryTest, ABackendIsRegisteredOnce) {
  Opened other;
  EXPECT_THROW(reg.add(fake("dev", {}, &other)), std::logic_error);
  BackendInfo nameless;
  EXPECT_THROW(reg.add(nameless), std::logic_error);
}

}  // namespace
}  // namespace vmh::runtime
