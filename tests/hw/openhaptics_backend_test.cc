// hw/openhaptics/openhaptics_backend.h against the test libHD.so
// (tests/hw/fake_libhd/), loaded through VMH_LIBHD: identification, the
// scheduler path (the loop ticks on the scheduler's thread between
// hdBeginFrame and hdEndFrame), units, signs and frames checked against the
// test library's own kinematics, the HD error paths, and that nothing in
// the servo callback allocates.
#include "hw/openhaptics/openhaptics_backend.h"

#include <dlfcn.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <string>
#include <thread>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "tests/hw/fake_libhd/fake_hd_hooks.h"
#include "tests/support/alloc_counter.h"

namespace vmh::hw {
namespace {

// The test library's hooks, from the same loaded copy the backend uses (a
// second dlopen of one path returns the same object).
struct Hooks {
  void* handle = nullptr;
  FakeHdCountersFn counters = nullptr;
  FakeHdVec3Fn joint_torque_mNm = nullptr;
  FakeHdVec3Fn force_N = nullptr;
  FakeHdVec3Fn applied_Nm = nullptr;
  FakeHdVec3Fn position_mm = nullptr;
  FakeHdJointsFn joints_rad = nullptr;
  FakeHdInFrameFn in_frame = nullptr;
  FakeHdTrueJointsFn true_q_dh = nullptr;

  static const Hooks& get() {
    static const Hooks h = [] {
      Hooks k;
      k.handle = dlopen(VMH_FAKE_LIBHD, RTLD_NOW | RTLD_LOCAL);
      if (k.handle == nullptr) return k;
      auto sym = [&](const char* n) { return dlsym(k.handle, n); };
      k.counters = reinterpret_cast<FakeHdCountersFn>(sym("fake_hd_counters"));
      k.joint_torque_mNm =
          reinterpret_cast<FakeHdVec3Fn>(sym("fake_hd_last_joint_torque_mNm"));
      k.force_N = reinterpret_cast<FakeHdVec3Fn>(sym("fake_hd_last_force_N"));
      k.applied_Nm = reinterpret_cast<FakeHdVec3Fn>(sym("fake_hd_applied_torque_Nm"));
      k.position_mm = reinterpret_cast<FakeHdVec3Fn>(sym("fake_hd_position_mm"));
      k.joints_rad = reinterpret_cast<FakeHdJointsFn>(sym("fake_hd_model_joints_rad"));
      k.in_frame = reinterpret_cast<FakeHdInFrameFn>(sym("fake_hd_in_frame"));
      k.true_q_dh =
          reinterpret_cast<FakeHdTrueJointsFn>(sym("fake_hd_true_q_dh_rad"));
      return k;
    }();
    return h;
  }
  Vec3 vec(FakeHdVec3Fn f) const {
    double v[3];
    f(v);
    return Vec3(v[0], v[1], v[2]);
  }
  FakeHdCounters count() const {
    FakeHdCounters c{};
    counters(&c);
    return c;
  }
};

// what the loop does with the motor torques
enum class Drive { kConstantTorque, kDeviceForce };

// A loop doing what servo_tick does with a device: read the state once,
// write a torque; it records what it saw for the test to check.
class RecordingLoop final : public ServoLoop {
 public:
  HapticDevice* device = nullptr;
  Drive drive = Drive::kConstantTorque;
  Vec3 tau_Nm = Vec3::Zero();      // kConstantTorque
  Vec3 force_device_N = Vec3::Zero();  // kDeviceForce: tau = J^T F
  long stop_after = -1;            // return false after this many ticks
  bool allocate = false;           // allocate once per tick (a control)
  OmniParams omni;

  std::atomic<long> ticks{0};
  std::atomic<long> out_of_frame{0};
  std::atomic<long> read_errors{0};
  std::atomic<int> last_error{0};
  DeviceState first;  // read after stop()
  DeviceState last;

  bool tick(double) noexcept override {
    const long n = ticks.load(std::memory_order_relaxed) + 1;
    if (Hooks::get().in_frame() == 0) out_of_frame.fetch_add(1);
    if (allocate) {
      // a direct call: a new-expression's allocation may be elided
      void* volatile p = ::operator new(16);
      ::operator delete(p);
    }
    const DeviceError e = device->read_state(&state_);
    if (e != DeviceError::kOk) {
      read_errors.fetch_add(1);
      last_error.store(static_cast<int>(e));
      device->write_motor_torques(Vec3::Zero());
    } else {
      if (n == 1) first = state_;
      last = state_;
      Vec3 tau = tau_Nm;
      if (drive == Drive::kDeviceForce) {
        // the motor torques a device-frame force needs, by the controller's
        // kinematics: tau_dh = J_v^T F_base, then to the motors
        const Joints q_dh = device_to_dh_joints(state_.q_device_rad);
        const Mat3 Jv = omni_jacobian(omni, q_dh).topLeftCorner<3, 3>();
        tau = dh_to_motor_torques(Jv.transpose() *
                                  device_to_base_vector(force_device_N));
      }
      device->write_motor_torques(tau);
    }
    ticks.store(n, std::memory_order_release);
    return stop_after < 0 || n < stop_after;
  }

 private:
  DeviceState state_;
};

template <typename F>
bool wait_until(F done, double timeout_s = 10.0) {
  const auto until = std::chrono::steady_clock::now() +
                     std::chrono::duration<double>(timeout_s);
  while (!done()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

ServoOptions test_servo() {
  ServoOptions o;
  o.realtime = false;  // no mlockall in a test process
  return o;
}

class OpenHapticsBackendTest : public ::testing::Test {
 protected:
  void SetUp() override {
    setenv("VMH_LIBHD", VMH_FAKE_LIBHD, 1);
    ASSERT_NE(Hooks::get().handle, nullptr) << dlerror();
    ASSERT_NE(Hooks::get().in_frame, nullptr);
  }

  std::unique_ptr<OpenHapticsBackend> open(const std::string& config,
                                           OpenHapticsOptions::HdCommand cmd =
                                               OpenHapticsOptions::kJointTorque) {
    OpenHapticsOptions o;
    o.config = config;
    o.command = cmd;
    return std::make_unique<OpenHapticsBackend>(o);
  }

  // runs `loop` until it ticked `ticks` times
  void run(OpenHapticsBackend* b, RecordingLoop* loop, long ticks) {
    loop->device = b->device();
    b->start(loop, test_servo());
    ASSERT_TRUE(wait_until([&] { return loop->ticks.load() >= ticks; }))
        << "the loop ticked " << loop->ticks.load() << " times";
  }
};

std::string open_error(const std::string& config) {
  try {
    OpenHapticsOptions o;
    o.config = config;
    OpenHapticsBackend b(o);
  } catch (const DeviceOpenError& e) {
    return e.what();
  }
  return "";
}

TEST_F(OpenHapticsBackendTest, IdentificationComesThrough) {
  auto b = open("");
  const DeviceIdentity id = b->identity();
  EXPECT_EQ(id.backend, "openhaptics");
  EXPECT_EQ(id.config, "");
  EXPECT_EQ(id.model, "PHANTOM Omni (test libHD)");
  EXPECT_EQ(id.vendor, "vmhaptics tests");
  EXPECT_EQ(id.serial, "TEST-00001");
  EXPECT_EQ(id.driver_version, "test-driver 1.0");
  EXPECT_EQ(id.firmware_version, "test-firmware 0.1");
  EXPECT_EQ(id.api_version, "3.0.0 (vmhaptics test libHD)");
  EXPECT_EQ(id.input_dof, 6);
  EXPECT_EQ(id.output_dof, 3);
  EXPECT_TRUE(b->has_encoders());
  EXPECT_TRUE(b->has_inkwell());
  EXPECT_EQ(b->calibration_state(), CalibrationState::kOk);
  EXPECT_FALSE(b->running());
}

TEST_F(OpenHapticsBackendTest, UnknownDeviceNamesTheConfiguration) {
  for (const std::string cfg : {"missing", "no_such_device"}) {
    const std::string msg = open_error(cfg);
    ASSERT_FALSE(msg.empty()) << cfg;
    EXPECT_NE(msg.find("\"" + cfg + "\""), std::string::npos) << msg;
    EXPECT_NE(msg.find("0x303 comm_config_error"), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
}

TEST_F(OpenHapticsBackendTest, MissingLibraryNamesThePath) {
  setenv("VMH_LIBHD", "/nonexistent/libHD.so", 1);
  const std::string msg = open_error("");
  EXPECT_NE(msg.find("/nonexistent/libHD.so"), std::string::npos) << msg;
}

TEST_F(OpenHapticsBackendTest, LoopRunsInsideSchedulerFrames) {
  auto b = open("");
  RecordingLoop loop;
  run(b.get(), &loop, 200);
  EXPECT_TRUE(b->running());
  b->stop();
  EXPECT_FALSE(b->running());
  const FakeHdCounters c = Hooks::get().count();
  EXPECT_EQ(loop.out_of_frame.load(), 0);
  EXPECT_EQ(c.illegal_frames, 0);
  EXPECT_EQ(c.sets_outside_frame, 0);
  // one command per servo frame and one for stop()'s zero
  EXPECT_GE(c.sets_in_frame, loop.ticks.load() + 1);
  EXPECT_EQ(c.async_scheduled, 1);
  EXPECT_EQ(c.max_priority, 65535);
  EXPECT_EQ(c.enables_force, 1);
  EXPECT_EQ(c.scheduler_running, 0);
  EXPECT_EQ(c.disables, 1);
  EXPECT_GE(b->timing().ticks, 200);
  EXPECT_EQ(loop.read_errors.load(), 0);
  // the state the loop read carries everything the library reports
  for (DeviceStateField f : {kStateJoints, kStateButtons, kStateInkwell,
                             kStateTimestamp, kStateTransform, kStateVelocity,
                             kStateJacobian, kStateEncoders}) {
    EXPECT_TRUE(loop.last.has(f)) << f;
  }
}

TEST_F(OpenHapticsBackendTest, MotorTorqueArrivesInMilliNewtonMetres) {
  auto b = open("");
  RecordingLoop loop;
  loop.tau_Nm = Vec3(0.1, 0.0, 0.0);
  run(b.get(), &loop, 20);
  const Vec3 sent = Hooks::get().vec(Hooks::get().joint_torque_mNm);
  EXPECT_DOUBLE_EQ(sent[0], 100.0);
  EXPECT_DOUBLE_EQ(sent[1], 0.0);
  EXPECT_DOUBLE_EQ(sent[2], 0.0);
  b->stop();
  // stop() leaves zero at the device
  EXPECT_EQ(Hooks::get().vec(Hooks::get().joint_torque_mNm), Vec3::Zero());
  EXPECT_EQ(Hooks::get().vec(Hooks::get().applied_Nm), Vec3::Zero());
}

TEST_F(OpenHapticsBackendTest, JointAnglesPassThroughWithJoint3Absolute) {
  auto b = open("");
  RecordingLoop loop;
  run(b.get(), &loop, 5);
  // nobody holds it and no torque goes out: the model is at rest, so its
  // state now is its state at the last reading
  double q_dh[6];
  const bool truth = Hooks::get().true_q_dh(q_dh) == 1;
  b->stop();
  const DeviceState& s = loop.last;
  // the device's own transform (its formula, t3 absolute) is what the
  // controller's kinematics give for the angles the backend read
  const OmniParams omni;
  const OmniPose pose = omni_fk(omni, device_to_dh_joints(s.q_device_rad));
  const Vec3 p_mm = base_to_device_mm(omni, pose.p_base_m);
  EXPECT_LT((s.transform_mm.topRightCorner<3, 1>() - p_mm).norm(), 1e-9)
      << s.transform_mm << "\nvs " << p_mm.transpose();
  EXPECT_LT((s.transform_mm.topLeftCorner<3, 3>() -
             base_to_device_rotation(pose.R_base))
                .norm(),
            1e-9);
  // joint 3 arrives absolute: t3 = q2 + q3 of the model's own DH state
  // (MuJoCo's, over the emulator; the rigid model's known pose otherwise),
  // to the encoders' resolution
  if (truth) {
    const double count = 2.0 * 3.14159265358979323846 / 15000.0;
    EXPECT_NEAR(s.q_device_rad[2], q_dh[1] + q_dh[2], 2.0 * count);
    EXPECT_NEAR(s.q_device_rad[1], q_dh[1], 2.0 * count);
    EXPECT_NEAR(s.q_device_rad[0], -q_dh[0], 2.0 * count);
  } else {
    // the rigid model's pose has t3 = 0.7 rad with t2 = 0.2: an elbow
    // angle of 0.5 rad in DH terms
    EXPECT_NEAR(s.q_device_rad[2], 0.7, 1e-3);
    EXPECT_NEAR(device_to_dh_joints(s.q_device_rad)[2], 0.5, 1e-3);
  }
}

TEST_F(OpenHapticsBackendTest, PositiveMotorTorqueTurnsTheJointPositive) {
  auto b = open("");
  RecordingLoop loop;
  loop.tau_Nm = Vec3(0.05, -0.05, 0.05);
  run(b.get(), &loop, 150);
  b->stop();
  const Joints dq = loop.last.q_device_rad - loop.first.q_device_rad;
  EXPECT_GT(dq[0], 0.01) << dq.transpose();
  EXPECT_LT(dq[1], -0.01) << dq.transpose();
  EXPECT_GT(dq[2], 0.01) << dq.transpose();
}

// +x in the device frame, sent as motor torques: in force mode the backend
// turns them back into HD_CURRENT_FORCE, and the test library's own
// Jacobian and position formula must move the stylus toward +x.
void expect_force_moves_toward(OpenHapticsBackendTest* t,
                               OpenHapticsOptions::HdCommand cmd, double sign) {
  (void)t;
  OpenHapticsOptions o;
  o.command = cmd;
  OpenHapticsBackend b(o);
  RecordingLoop loop;
  loop.drive = Drive::kDeviceForce;
  loop.force_device_N = Vec3(0.5 * sign, 0.0, 0.0);
  loop.device = b.device();
  const Vec3 p0 = Hooks::get().vec(Hooks::get().position_mm);
  b.start(&loop, test_servo());
  ASSERT_TRUE(wait_until([&] { return loop.ticks.load() >= 150; }));
  if (cmd == OpenHapticsOptions::kForce) {
    // the force the backend sent is the one the loop asked for
    const Vec3 F = Hooks::get().vec(Hooks::get().force_N);
    EXPECT_LT((F - loop.force_device_N).norm(), 1e-3) << F.transpose();
    EXPECT_EQ(Hooks::get().vec(Hooks::get().joint_torque_mNm), Vec3::Zero());
  }
  b.stop();
  const Vec3 p1 = Hooks::get().vec(Hooks::get().position_mm);
  EXPECT_GT(sign * (p1[0] - p0[0]), 1.0)
      << hd_command_name(cmd) << ": " << p0.transpose() << " -> "
      << p1.transpose();
  if (cmd == OpenHapticsOptions::kForce) {
    EXPECT_EQ(Hooks::get().vec(Hooks::get().force_N), Vec3::Zero());
  }
}

TEST_F(OpenHapticsBackendTest, ForceModePushesAlongTheDeviceFrame) {
  expect_force_moves_toward(this, OpenHapticsOptions::kForce, +1.0);
  expect_force_moves_toward(this, OpenHapticsOptions::kForce, -1.0);
}

TEST_F(OpenHapticsBackendTest, JointTorqueModeAgreesWithForceMode) {
  expect_force_moves_toward(this, OpenHapticsOptions::kJointTorque, +1.0);
  expect_force_moves_toward(this, OpenHapticsOptions::kJointTorque, -1.0);
}

void expect_warning_keeps_torque(const std::string& config, const char* name) {
  OpenHapticsOptions o;
  o.config = config;
  OpenHapticsBackend b(o);
  RecordingLoop loop;
  loop.tau_Nm = Vec3(0.0, 0.05, 0.0);
  loop.device = b.device();
  b.start(&loop, test_servo());
  ASSERT_TRUE(wait_until([&] { return b.last_errors().warnings > 0; }))
      << config;
  const long at = loop.ticks.load();
  ASSERT_TRUE(wait_until([&] { return loop.ticks.load() > at + 20; }));
  const HdErrorReport r = b.last_errors();
  EXPECT_EQ(r.last_name, name);
  EXPECT_EQ(r.fatal, 0);
  ASSERT_EQ(r.counts.size(), 1u);
  EXPECT_EQ(r.counts[0].name, name);
  EXPECT_EQ(r.counts[0].count, 1);
  EXPECT_EQ(loop.read_errors.load(), 0);
  EXPECT_TRUE(b.running());
  const Vec3 sent = Hooks::get().vec(Hooks::get().joint_torque_mNm);
  EXPECT_DOUBLE_EQ(sent[1], 50.0) << "the torque still goes out";
  b.stop();
}

TEST_F(OpenHapticsBackendTest, WarmMotorsIsRecordedAndTorqueStillSent) {
  expect_warning_keeps_torque("warm_motors@50", "warm_motors");
}

TEST_F(OpenHapticsBackendTest, ExceededVelocityIsRecordedAsAWarning) {
  expect_warning_keeps_torque("exceeded_velocity@30", "exceeded_max_velocity");
}

TEST_F(OpenHapticsBackendTest, CommErrorFailsTheReadAndSendsZero) {
  auto b = open("comm_error@50");
  RecordingLoop loop;
  loop.tau_Nm = Vec3(0.05, 0.0, 0.0);
  loop.device = b->device();
  b->start(&loop, test_servo());
  ASSERT_TRUE(wait_until([&] { return loop.read_errors.load() >= 10; }));
  EXPECT_EQ(static_cast<DeviceError>(loop.last_error.load()), DeviceError::kIo);
  EXPECT_EQ(Hooks::get().vec(Hooks::get().joint_torque_mNm), Vec3::Zero());
  // a write after the fault is refused with the same error
  EXPECT_EQ(b->device()->write_motor_torques(Vec3(0.1, 0, 0)), DeviceError::kIo);
  const HdErrorReport r = b->last_errors();
  EXPECT_EQ(r.last_name, "comm_error");
  EXPECT_GE(r.fatal, 1);
  // the trace up to the fault was good: the ticks before frame 50 read fine
  EXPECT_GE(loop.ticks.load() - loop.read_errors.load(), 40);
  b->stop();
  EXPECT_EQ(Hooks::get().vec(Hooks::get().joint_torque_mNm), Vec3::Zero());
}

TEST_F(OpenHapticsBackendTest, LoopEndingSendsZeroAndStopsTheCallback) {
  auto b = open("");
  RecordingLoop loop;
  loop.tau_Nm = Vec3(0.0, 0.0, 0.08);
  loop.stop_after = 30;
  loop.device = b->device();
  b->start(&loop, test_servo());
  ASSERT_TRUE(wait_until([&] { return !b->running(); }));
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(loop.ticks.load(), 30);
  EXPECT_EQ(Hooks::get().vec(Hooks::get().joint_torque_mNm), Vec3::Zero());
  b->stop();
}

TEST_F(OpenHapticsBackendTest, InkwellButtonsAndEncodersFromTheConfiguration) {
  {
    auto b = open("docked,button1");
    RecordingLoop loop;
    run(b.get(), &loop, 3);
    b->stop();
    EXPECT_TRUE(loop.last.docked);
    EXPECT_EQ(loop.last.buttons, kButton1);
  }
  {
    auto b = open("no_encoders");
    EXPECT_FALSE(b->has_encoders());
    RecordingLoop loop;
    run(b.get(), &loop, 3);
    b->stop();
    EXPECT_FALSE(loop.last.docked);
    EXPECT_EQ(loop.last.buttons, 0u);
    EXPECT_FALSE(loop.last.has(kStateEncoders));
    EXPECT_TRUE(loop.last.has(kStateJoints));
    EXPECT_EQ(b->last_errors().warnings, 0) << "the probe's error is not logged";
  }
}

TEST_F(OpenHapticsBackendTest, CalibrationUpdatesWithTheDevicesStyle) {
  auto b = open("uncalibrated");
  EXPECT_EQ(b->calibration_state(), CalibrationState::kNeedsUpdate);
  EXPECT_EQ(b->update_calibration(), CalibrationState::kOk);
  RecordingLoop loop;
  run(b.get(), &loop, 3);
  // while running, the check goes through the scheduler
  EXPECT_EQ(b->calibration_state(), CalibrationState::kOk);
  b->stop();
  EXPECT_EQ(Hooks::get().count().illegal_frames, 0);
}

TEST_F(OpenHapticsBackendTest, StartIsRefusedWhenItCannotRun) {
  auto b = open("");
  RecordingLoop loop;
  loop.device = b->device();
  ServoOptions slow = test_servo();
  slow.period_s = 2e-3;
  try {
    b->start(&loop, slow);
    FAIL() << "a 2 ms period was accepted";
  } catch (const DeviceOpenError& e) {
    EXPECT_NE(std::string(e.what()).find("period_s"), std::string::npos);
  }
  b->start(&loop, test_servo());
  EXPECT_THROW(b->start(&loop, test_servo()), DeviceOpenError);
  b->stop();
  EXPECT_THROW(b->start(&loop, test_servo()), DeviceOpenError);
  EXPECT_EQ(parse_hd_command("force"), OpenHapticsOptions::kForce);
  EXPECT_EQ(parse_hd_command("joint_torque"), OpenHapticsOptions::kJointTorque);
  try {
    parse_hd_command("torque");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("\"torque\""), std::string::npos);
  }
}

// Everything in the process while the servo runs (the backend's callback,
// the loop's read and write, force mode's map, the test library's
// scheduler) allocates nothing: the counter is armed while the test thread
// only sleeps.
std::size_t allocations_while_running(OpenHapticsBackend* b,
                                      RecordingLoop* loop, long* ticks) {
  loop->device = b->device();
  b->start(loop, test_servo());
  EXPECT_TRUE(wait_until([&] { return loop->ticks.load() >= 10; }));
  std::size_t allocations = 0;
  {
    testing::AllocationScope scope;
    const long t0 = loop->ticks.load();
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    *ticks = loop->ticks.load() - t0;
    allocations = scope.count();
  }
  b->stop();
  return allocations;
}

TEST_F(OpenHapticsBackendTest, AllocationCounterSeesTheSchedulerThread) {
  // the control for the test below: one allocation per tick on the
  // scheduler's thread is counted
  auto b = open("");
  RecordingLoop loop;
  loop.allocate = true;
  long ticks = 0;
  const std::size_t n = allocations_while_running(b.get(), &loop, &ticks);
  EXPECT_GT(ticks, 10);
  EXPECT_GE(n, static_cast<std::size_t>(ticks));
}

TEST_F(OpenHapticsBackendTest, ServoCallbackAllocatesNothing) {
  for (auto cmd : {OpenHapticsOptions::kJointTorque, OpenHapticsOptions::kForce}) {
    auto b = open("", cmd);
    RecordingLoop loop;
    loop.drive = Drive::kDeviceForce;
    loop.force_device_N = Vec3(0.2, 0.1, -0.1);
    long ticks_during = 0;
    const std::size_t allocations =
        allocations_while_running(b.get(), &loop, &ticks_during);
    EXPECT_GT(ticks_during, 10) << "the servo ran while counting";
    EXPECT_EQ(allocations, 0u) << hd_command_name(cmd);
  }
}

}  // namespace
}  // namespace vmh::hw
