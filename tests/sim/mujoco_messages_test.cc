// sim/mujoco_messages.h: the project's MuJoCo warning and error handlers.
// Warnings are counted by kind and deduplicated, never printed on stdout and
// never logged to MUJOCO_LOG.TXT; an error (mju_error, also one raised
// inside mj_step) becomes a MujocoError that unwinds through MuJoCo's C
// frames to the caller.
#include "sim/mujoco_messages.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "sim/mujoco_util.h"

namespace vmh::sim {
namespace {

namespace fs = std::filesystem;

const char kQacc0[] =
    "Nan, Inf or huge value in QACC at DOF 0. The simulation is unstable. "
    "Time = 0.0010.";
const char kQacc3[] =
    "Nan, Inf or huge value in QACC at DOF 3. The simulation is unstable. "
    "Time = 0.0520.";

// The project's handlers in place of whatever was there (MuJoCo's defaults
// in a fresh test process), in a fresh temporary working directory, with
// the process's tally cleared; everything put back afterwards.
class MujocoMessagesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    old_error_ = mju_user_error;
    old_warning_ = mju_user_warning;
    mju_user_error = nullptr;
    mju_user_warning = nullptr;
    install_mujoco_handlers();
    clear_mujoco_warnings();
    old_cwd_ = fs::current_path();
    cwd_ = fs::path(::testing::TempDir()) /
           ("vmh_mujoco_messages_" +
            std::string(::testing::UnitTest::GetInstance()
                            ->current_test_info()
                            ->name()));
    fs::remove_all(cwd_);
    fs::create_directories(cwd_);
    fs::current_path(cwd_);
  }
  void TearDown() override {
    fs::current_path(old_cwd_);
    mju_user_error = old_error_;
    mju_user_warning = old_warning_;
  }

  // a model file in the working directory
  std::string write_model(const std::string& xml) {
    const fs::path p = cwd_ / "model.xml";
    std::ofstream(p) << xml;
    return p.string();
  }

  fs::path cwd_, old_cwd_;
  void (*old_error_)(const char*) = nullptr;
  void (*old_warning_)(const char*) = nullptr;
};

// a ball on a slide joint, and an actuator
const char kBall[] = R"(<mujoco>
  <worldbody>
    <body><joint name="x" type="slide"/><geom size="0.1" mass="1"/></body>
  </worldbody>
  <actuator><motor joint="x"/></actuator>
</mujoco>)";

TEST(MujocoWarningTally, CountsByKindWithTheNumbersMasked) {
  MujocoWarningTally t;
  t.add(kQacc0);
  t.add(kQacc3);
  t.add("Pre-allocated contact buffer is full. Increase nconmax above 100.");
  t.add("something else 12");
  ASSERT_EQ(t.entries.size(), 3u);
  EXPECT_EQ(t.entries[0].kind, "badqacc");
  EXPECT_EQ(t.entries[0].text, kQacc0);  // the first, as written
  EXPECT_EQ(t.entries[0].count, 2);
  EXPECT_EQ(t.entries[1].kind, "contactfull");
  EXPECT_EQ(t.entries[2].kind, "other");
  EXPECT_EQ(t.total(), 4);
  EXPECT_EQ(t.count("badqacc"), 2);
  EXPECT_EQ(t.count("badqpos"), 0);

  const std::vector<std::string> lines = mujoco_warning_lines(t);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0], std::string("MuJoCo warning (badqacc, 2 times): ") + kQacc0);
  EXPECT_EQ(lines[2], "MuJoCo warning (other, 1 time): something else 12");
  EXPECT_TRUE(mujoco_warning_lines(MujocoWarningTally{}).empty());
}

TEST(MujocoWarningTally, NamesEveryPerStepKind) {
  for (int k = 0; k < mjNWARNING; ++k) {
    // MuJoCo's own text for each kind is classified as that kind
    EXPECT_STREQ(mujoco_warning_kind(mju_warningText(k, 2)),
                 mujoco_warning_name(k))
        << k;
  }
  EXPECT_STREQ(mujoco_warning_name(mjWARN_BADQACC), "badqacc");
  EXPECT_STREQ(mujoco_warning_name(-1), "other");
  EXPECT_STREQ(mujoco_warning_name(mjNWARNING), "other");
}

TEST_F(MujocoMessagesTest, AWarningIsCountedNotPrintedNorLogged) {
  ASSERT_TRUE(mujoco_handlers_installed());
  ::testing::internal::CaptureStdout();
  {
    MujocoWarningScope outer;
    {
      MujocoWarningScope inner;
      mju_warning_i("Nan, Inf or huge value in QACC at DOF %d. The "
                    "simulation is unstable.", 3);
      EXPECT_EQ(inner.tally().count("badqacc"), 1);
    }
    mju_warning("a second kind");
    EXPECT_EQ(outer.tally().total(), 2);  // the inner scope's warning too
  }
  const std::string out = ::testing::internal::GetCapturedStdout();
  EXPECT_EQ(out, "");
  EXPECT_FALSE(fs::exists(cwd_ / "MUJOCO_LOG.TXT"));
  const MujocoWarningTally all = mujoco_warnings_so_far();
  EXPECT_EQ(all.total(), 2);
  EXPECT_EQ(all.count("other"), 1);
  // no scope open: the process's tally still counts it
  mju_warning("a third");
  EXPECT_EQ(mujoco_warnings_so_far().total(), 3);
}

TEST_F(MujocoMessagesTest, ABadStateInMjStepIsCountedOnce) {
  ModelPtr m = load_model(write_model(kBall));
  DataPtr d(mj_makeData(m.get()));
  ASSERT_TRUE(d);
  ::testing::internal::CaptureStdout();
  MujocoWarningScope scope;
  d->qvel[0] = std::nan("");
  mj_step(m.get(), d.get());  // mj_checkVel: warns, resets the state
  const std::string out = ::testing::internal::GetCapturedStdout();
  EXPECT_EQ(out, "");
  EXPECT_EQ(d->warning[mjWARN_BADQVEL].number, 1);
  EXPECT_TRUE(std::isfinite(d->qvel[0]));  // MuJoCo reset it
  EXPECT_EQ(scope.tally().count("badqvel"), 1);
  ASSERT_EQ(scope.tally().entries.size(), 1u);
  EXPECT_NE(scope.tally().entries[0].text.find("QVEL"), std::string::npos);
  EXPECT_FALSE(fs::exists(cwd_ / "MUJOCO_LOG.TXT"));
}

TEST_F(MujocoMessagesTest, AnErrorThrowsWithItsMessage) {
  try {
    mju_error_i("Test error %d", 7);
    FAIL() << "mju_error returned";
  } catch (const MujocoError& e) {
    EXPECT_STREQ(e.what(), "MuJoCo error: Test error 7");
  }
  EXPECT_FALSE(fs::exists(cwd_ / "MUJOCO_LOG.TXT"));
}

TEST_F(MujocoMessagesTest, AnErrorInsideMjStepUnwindsToTheCaller) {
  // a stack far too small for one step (set after compiling, which steps
  // too): mj_stackAlloc raises mju_error deep inside mj_step, and the
  // exception must come out through MuJoCo's frames
  ModelPtr m = load_model(write_model(kBall));
  m->nstack = 8;
  DataPtr d(mj_makeData(m.get()));
  ASSERT_TRUE(d);
  ::testing::internal::CaptureStdout();
  bool thrown = false;
  try {
    mj_step(m.get(), d.get());
  } catch (const MujocoError& e) {
    thrown = true;
    EXPECT_EQ(std::string(e.what()).rfind("MuJoCo error: Stack overflow", 0), 0u)
        << e.what();
  }
  const std::string out = ::testing::internal::GetCapturedStdout();
  EXPECT_TRUE(thrown);
  EXPECT_EQ(out, "");
  EXPECT_FALSE(fs::exists(cwd_ / "MUJOCO_LOG.TXT"));
}

TEST_F(MujocoMessagesTest, AnotherHandlerIsLeftInPlace) {
  static int seen = 0;
  seen = 0;
  mju_user_warning = [](const char*) { ++seen; };
  mju_user_error = [](const char*) { throw std::runtime_error("theirs"); };
  install_mujoco_handlers();  // a guard's handlers stay
  EXPECT_FALSE(mujoco_handlers_installed());
  mju_warning("to the other handler");
  EXPECT_EQ(seen, 1);
  EXPECT_EQ(mujoco_warnings_so_far().total(), 0);
}

TEST_F(MujocoMessagesTest, LoadingAModelInstallsThem) {
  mju_user_error = nullptr;
  mju_user_warning = nullptr;
  ModelPtr m = load_model(write_model(kBall));
  EXPECT_TRUE(mujoco_handlers_installed());
}

}  // namespace
}  // namespace vmh::sim
