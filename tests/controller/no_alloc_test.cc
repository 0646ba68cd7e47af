// The servo loop allocates nothing and throws nothing: the kinematics,
// Controller::tick for every mechanism and option, and servo_tick() around
// it.
//
// The controller and device libraries are the build's own (-O3, NDEBUG),
// and every heap allocation is counted while a scope is armed: operator new
// and the C allocator that Eigen's dynamic matrices use
// (tests/support/alloc_counter.h). The first tests show that the counter
// does see each kind of allocation, so a zero below means something. The
// controller's Eigen assertions run live in the fuzz build instead
// (tests/fuzz/, controller_tick_fuzz), where every one that fails stops
// the fuzzer.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <random>
#include <utility>
#include <vector>

#include "controller/controller.h"
#include "controller/device_frame.h"
#include "device/safety.h"
#include "device/servo_tick.h"
#include "controller/omni_kinematics.h"
#include "tests/support/alloc_counter.h"

namespace vmh {
namespace {

using testing::AllocationScope;
using testing::keep_alive;

std::vector<Joints> random_configurations(int n) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  std::vector<Joints> out(static_cast<std::size_t>(n));
  for (Joints& q : out) {
    for (int i = 0; i < 6; ++i) q[i] = u(rng);
  }
  return out;
}

TEST(NoAllocDetectors, CounterCatchesOperatorNew) {
  std::size_t n = 0;
  {
    AllocationScope scope;
    std::vector<double> v(16, 1.0);
    keep_alive(v.data());
    n = scope.count();
    EXPECT_EQ(v.size(), 16u);
  }
  EXPECT_GE(n, 1u);
}

TEST(NoAllocDetectors, CounterCatchesEigensDynamicMatrices) {
  if (!testing::kCountsMalloc) GTEST_SKIP() << "malloc is AddressSanitizer's";
  std::size_t n = 0;
  {
    AllocationScope scope;
    Eigen::MatrixXd m(8, 8);
    m.setZero();
    keep_alive(m.data());
    n = scope.count();
  }
  EXPECT_GE(n, 1u);
}

TEST(NoAllocDetectors, CounterCatchesTheCAllocator) {
  if (!testing::kCountsMalloc) GTEST_SKIP() << "malloc is AddressSanitizer's";
  std::size_t n = 0;
  {
    AllocationScope scope;
    void* a = std::malloc(64);
    keep_alive(a);
    void* b = std::calloc(4, 16);
    keep_alive(b);
    void* c = std::realloc(a, 128);
    keep_alive(c);
    void* d = nullptr;
    EXPECT_EQ(posix_memalign(&d, 64, 64), 0);
    keep_alive(d);
    n = scope.count();
    std::free(b);
    std::free(c);
    std::free(d);
  }
  EXPECT_EQ(n, 4u);
}

// runs f over many configurations with both detectors armed and asserts that
// it counted nothing and nothing threw
template <typename F>
void expect_no_alloc(F f) {
  const std::vector<Joints> qs = random_configurations(200);
  std::size_t allocations = 0;
  {
    AllocationScope scope;
    for (const Joints& q : qs) {
      EXPECT_NO_THROW(f(q));
    }
    allocations = scope.count();
  }
  EXPECT_EQ(allocations, 0u);
}

TEST(NoAlloc, ForwardKinematics) {
  const OmniParams p;
  double sink = 0;
  expect_no_alloc([&](const Joints& q) {
    OmniFrames frames;
    omni_frames(p, q, &frames);
    const OmniPose pose = omni_fk(p, q);
    sink += pose.p_base_m.sum() + omni_tool_point(p, pose).sum() +
            frames.T_base[3].translation().x();
  });
  EXPECT_TRUE(std::isfinite(sink));
}

TEST(NoAlloc, Jacobian) {
  const OmniParams p;
  double sink = 0;
  expect_no_alloc([&](const Joints& q) {
    sink += omni_jacobian(p, q).sum() + omni_jacobian_at(p, q, -0.03).sum();
  });
  EXPECT_TRUE(std::isfinite(sink));
}

TEST(NoAlloc, OnePassKinematics) {
  const OmniParams p;
  double sink = 0;
  expect_no_alloc([&](const Joints& q) {
    OmniPose pose;
    Mat6 J;
    omni_fk_jacobian(p, q, &pose, &J, -0.03);
    const OmniArmKinematics arm = omni_arm_kinematics(p, q);
    sink += pose.p_base_m.sum() + J.sum() + arm.Jv_arm.sum();
  });
  EXPECT_TRUE(std::isfinite(sink));
}

TEST(NoAlloc, InverseKinematics) {
  const OmniParams p;
  int found = 0;
  expect_no_alloc([&](const Joints& q) {
    const OmniPose pose = omni_fk(p, q);
    const IkSolutions a = omni_ik_position(p, pose.p_base_m, q);
    const IkSolutions b = omni_ik_pose(p, pose.p_base_m, pose.R_base, q);
    found += a.count + b.count + omni_ik_nearest(b, q);
  });
  EXPECT_GT(found, 0);
}

TEST(NoAlloc, DeviceFrameConversions) {
  const OmniParams p;
  double sink = 0;
  expect_no_alloc([&](const Joints& q) {
    const Joints t = dh_to_device_joints(q);
    const OmniPose pose = omni_fk(p, device_to_dh_joints(t));
    const Vec3 mm = base_to_device_mm(p, pose.p_base_m);
    sink += device_mm_to_base(p, mm).sum() +
            base_to_device_rotation(pose.R_base).sum() +
            base_to_device_vector(pose.R_base.col(2)).sum();
  });
  EXPECT_TRUE(std::isfinite(sink));
}

// every registered mechanism, error formulation and placement method, over random
// poses, the home pose (the RM at the pivot), the sphere's pole and
// non-finite samples, with the saturations active
TEST(NoAlloc, ControllerTick) {
  static_assert(noexcept(std::declval<Controller&>().tick(
                    std::declval<const Joints&>(),
                    std::declval<ControlOutput*>())),
                "tick() must be noexcept");
  std::vector<ControllerParams> variants;
  for (const VmDescriptor& d : vm_registry()) {
    const VmKind kind = d.kind;
    for (ErrorFormulation f :
         {ErrorFormulation::kThesis, ErrorFormulation::kGeometric}) {
      for (PlacementMethod m :
           {PlacementMethod::kGaussNewton, PlacementMethod::kClosedForm}) {
        ControllerParams p;
        p.vm.kind = kind;
        p.error = f;
        p.placement = m;
        p.gains.k_ornt_Nmm_per_rad = thesis_orientation_gain(0.5, 50.0);
        p.gains.k_vel_Ns_per_mm = 0.002;
        if (kind == VmKind::kSurface) {
          p.placement_options.weights = Vec6::Ones();
          p.vm.pivot_mm = Vec3(0, 0, -50);
          p.vm.friction_mu = 0.5;
          p.vm.unilateral = true;
        }
        variants.push_back(p);
      }
    }
  }
  std::vector<Joints> qs = random_configurations(200);
  qs.push_back(Joints::Zero());
  Joints nan_q = Joints::Zero();
  nan_q[2] = std::nan("");
  qs.push_back(nan_q);
  qs.push_back(Joints::Constant(1e300));
  int ticks = 0;
  for (const ControllerParams& p : variants) {
    Controller c(p);  // construction may allocate
    ControlOutput out;
    std::size_t allocations = 0;
    {
        AllocationScope scope;
      for (const Joints& q : qs) {
        EXPECT_NO_THROW(c.tick(q, &out));
        ++ticks;
      }
      c.reset();
      EXPECT_NO_THROW(c.tick(qs[0], &out));
      allocations = scope.count();
    }
    EXPECT_EQ(allocations, 0u) << vm_kind_name(p.vm.kind) << " "
                               << error_formulation_name(p.error) << " "
                               << placement_method_name(p.placement);
  }
  // four variants per mechanism, 203 poses each
  EXPECT_EQ(ticks, 4 * static_cast<int>(vm_registry().size()) * 203);
}

// A device that allocates nothing either: it hands out the angles it is
// given, fails a read or a write when told to, and keeps the last torque.
class ScriptedDevice final : public HapticDevice {
 public:
  DeviceError read_joints(Joints* q_device_rad) noexcept override {
    if (read_error != DeviceError::kOk) return read_error;
    *q_device_rad = q_device;
    return DeviceError::kOk;
  }
  DeviceError write_motor_torques(const Vec3& tau_motor_Nm) noexcept override {
    written_Nm = tau_motor_Nm;
    return write_error;
  }
  Joints q_device = Joints::Zero();
  DeviceError read_error = DeviceError::kOk;
  DeviceError write_error = DeviceError::kOk;
  Vec3 written_Nm = Vec3::Zero();
};

// servo_tick over random readings, failed reads (which reset the
// controller), failed writes and NaN readings, for the circle and the
// sphere
TEST(NoAlloc, ServoTick) {
  static_assert(noexcept(servo_tick(nullptr, nullptr, nullptr)),
                "servo_tick must be noexcept");
  const DeviceError errors[] = {DeviceError::kNotConnected, DeviceError::kIo,
                                DeviceError::kTimeout,
                                DeviceError::kSensorFault};
  int zeroed = 0, ticks = 0;
  for (VmKind kind : {VmKind::kCircle, VmKind::kSphere}) {
    ControllerParams p;
    p.vm.kind = kind;
    p.gains.k_ornt_Nmm_per_rad = thesis_orientation_gain(0.5, 50.0);
    p.gains.k_vel_Ns_per_mm = 0.002;
    Controller c(p);
    ScriptedDevice dev;
    ControlOutput out;
    std::vector<Joints> qs = random_configurations(200);
    qs[50][3] = std::nan("");
    std::size_t allocations = 0;
    {
        AllocationScope scope;
      for (std::size_t k = 0; k < qs.size(); ++k) {
        dev.q_device = qs[k];
        dev.read_error = k % 17 == 3 ? errors[(k / 17) % 4] : DeviceError::kOk;
        dev.write_error = k % 23 == 5 ? DeviceError::kIo : DeviceError::kOk;
        ServoTickResult r;
        EXPECT_NO_THROW(r = servo_tick(&dev, &c, &out));
        if (r.zeroed) ++zeroed;
        ++ticks;
      }
      allocations = scope.count();
    }
    EXPECT_EQ(allocations, 0u) << vm_kind_name(kind);
  }
  EXPECT_EQ(ticks, 400);
  // the error paths were taken: 12 failed reads, 9 failed writes and one
  // NaN per mechanism (some may coincide)
  EXPECT_GE(zeroed, 2 * 12);
}

// the same through the safety layer, every allocation counted:
// random readings (velocity cuts), failed reads (comm
// loss), slow and fast slews of the pose, every limit in play
TEST(NoAlloc, ServoTickThroughTheSafetyLayer) {
  ControllerParams p;
  p.gains.k_ornt_Nmm_per_rad = thesis_orientation_gain(0.5, 50.0);
  Controller c(p);
  ScriptedDevice dev;
  SafetyParams sp;
  sp.comm_lost_reads = 2;
  sp.comm_resume_reads = 5;
  sp.ramp_s = 0.01;
  SafetyLayer layer(&dev, sp);
  ControlOutput out;
  std::vector<Joints> qs = random_configurations(400);
  std::size_t allocations = 0;
  int cut = 0;
  {
    AllocationScope scope;
    for (std::size_t k = 0; k < qs.size(); ++k) {
      // long runs of one pose (force flows) between jumps (velocity cuts)
      dev.q_device = qs[(k / 40) * 40];
      dev.read_error = k % 41 == 7 ? DeviceError::kIo : DeviceError::kOk;
      layer.set_read_time(1e-3 * static_cast<double>(k));
      layer.set_inputs(k % 97 == 0, true);
      EXPECT_NO_THROW(servo_tick(&layer, &c, &out));
      layer.service_watchdog(1e-3 * static_cast<double>(k));
      if ((layer.status() & kSafetyCuts) != 0) ++cut;
    }
    allocations = scope.count();
  }
  EXPECT_EQ(allocations, 0u);
  // both paths were taken
  EXPECT_GT(cut, 10);
  EXPECT_LT(cut, 300);
}

}  // namespace
}  // namespace vmh
