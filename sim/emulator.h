// The emulator: the MuJoCo Omni (a scene ClosedLoop loads, models/omni with
// the hand) stepped in real time in its own thread behind HapticDevice, so
// that every `hw` command runs without hardware.
//
// Clocks. On the wall clock (the default) the physics runs in a thread of
// its own, described next. In lockstep (EmulatorOptions::lockstep) there
// is no thread: advance() runs one servo period on the caller's thread
// (the session's, through device/lockstep.h), and the emulator's clock is
// the number of periods advanced times the period; every time the
// emulator reads (staleness, the device watchdog, time stamps) is on that
// clock, so the same settings give the same readings to the last bit.
//
// Threads. The physics thread (start()/stop()) runs one servo period
// (the case's servo_period_s) at a time: it sets the hand's target from the
// hand program at emulator time, applies the latest motor command through
// SimDevice (its clamps and delay line), runs the period's mj_step calls
// (h = the scene's timestep), publishes a snapshot, and sleeps to an
// absolute deadline (clock_nanosleep, TIMER_ABSTIME, CLOCK_MONOTONIC). When
// it falls more than kMaxCatchUpPeriods behind it drops the missed periods
// instead of racing to catch up, and counts them (EmulatorTruth::
// lag_periods). Emulator time (t_sim_s) is the simulated time: it stops
// while the physics is stalled or dropping periods, as a device's would.
//
// read_state / read_joints / write_motor_torques are for one servo thread
// (or calls serialised with it): noexcept, no allocation, no lock (Seqlock
// and atomics). press_buttons, set_hand_program, inject and truth may be
// called from any thread; set_calibration from one thread at a time.
//
// Readings. Joints in the device convention through the sensor model, as
// SimDevice's (encoders whole counts of 15000 per revolution; gimbal pots
// 2^11 levels over each joint's range, docs/sources.md §6), then turned
// into raw values with the emulator's hidden "factory" calibration and
// back to angles with the current calibration (hw/omni_calibration.h).
// The factory encoder offsets are whole counts and the factory pots are
// the sensor model's levels, so with the factory calibration the reported
// angles equal SimDevice's to rounding (1e-15 rad). The pots therefore
// read 11-bit codes, not §9.2's example 10-bit ones: a 10-bit pot on top of
// the sensor model would quantise twice. The emulator always quantises,
// whatever the case's `quantize`.
//
// The device-side watchdog: if no write arrived for device_watchdog_s of
// wall time (after the first write), the physics thread holds zero torque,
// as a device's firmware does, until the next write.
//
// Torque sign: positive motor torque on t1 turns t1 positively (device
// convention), through SimDevice and the model's actuators.
//
// The device's own kinematics (kStateTransform, kStateVelocity,
// kStateJacobian, as OpenHaptics's HD_CURRENT_TRANSFORM, _VELOCITY and
// _JACOBIAN), computed from the TRUE MuJoCo state at the end of the period
// (sim/emulator_kinematics.h), not from controller/ code, so that a
// comparison with the project's own kinematics is a real check. The DH
// base frame is the MuJoCo world frame of models/omni; the device frame is
// controller/device_frame.h's, placed with the scene's nominal OmniParams.
//   transform_mm: the site "wrist" (the wrist centre, the stylus body's
//     origin). Translation (0..2, 3): base_to_device_mm(site_xpos), mm.
//     Rotation (0..2, 0..2): base_to_device_rotation(site_xmat): its
//     columns are the DH stylus frame's axes (frame 6; z along the stylus)
//     in the device frame. Stored in Eigen's (column-major) order, so
//     transform_mm(r, c) is row r, column c. OpenHaptics's own stylus
//     rotation is a fixed rotation away from this one (unverified on a
//     device).
//   velocity_mm_s: the wrist site's linear velocity (mj_jacSite times
//     qvel), device frame, mm/s.
//   jacobian(r, c) = d x_r / d t_c: rows v_x, v_y, v_z (mm/rad) then
//     w_x, w_y, w_z (rad/rad), device frame; columns the DEVICE joints
//     t1..t6 (t3 the absolute forearm angle). By the chain rule through
//     q_dh = device_to_dh_joints(t) (q1 = -t1, q3 = t3 - t2, q4 = -t4,
//     q6 = -t6) the columns are mj_jacSite's DH columns (-J1, J2 - J3, J3,
//     -J4, J5, -J6), rotated into the device frame.
// They are part of the published snapshot, so a late reading is late in
// every field. Seeded faults (SeededFaults) leave them true: they are what
// the device itself computes from its own sensors.
#ifndef VMHAPTICS_SIM_EMULATOR_H_
#define VMHAPTICS_SIM_EMULATOR_H_

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "device/device_backend.h"
#include "device/haptic_device.h"
#include "device/seqlock.h"
#include "device/tick_record.h"
#include "hw/omni_calibration.h"
#include "sim/emulator_faults.h"
#include "sim/hand.h"
#include "sim/hand_script.h"

namespace vmh::sim {

class ClosedLoop;

// What the hand does while nobody holds the device. Device frame, mm.
enum class HandProgram {
  // the scene's own script (HandScript) from t = 0 at start(), then its
  // last target held still
  kCase,
  // a closed tour of the workspace, period kTourPeriod_s: the wrist centre
  // on a 3-D Lissajous curve of +-kTourAmplitude_mm (frequencies 1, 2, 3
  // per period) about the case's start point; the stylus axis circles a
  // cone of 0.5 rad about its start direction and rolls +-0.6 rad about
  // itself, so all six joints move
  kTour,
  // the hand lets go: before each physics step its target is put on the
  // grip's present pose and velocity, so its spring and damper exert
  // nothing at the step's start (exactly zero with Euler; RK4's inner
  // stages see the grip moved by part of a step: about 0.02 N at the
  // speeds of the tests). The device moves under its motors (and gravity,
  // off in the thesis scenes). The hand's mass stays on the grip (SimHand
  // adds it to the model; removing it would need a second model)
  kNone,
  // the stylus into the inkwell (kInkwellDevice_rad) and held there; the
  // target is corrected by the remaining error, as an eye would guide it
  kDock,
  // for calibration: the arm held at the start pose while each gimbal joint
  // t4, t5, t6 in turn is turned to one end of its range, to the other and
  // back (kSweepLeg_s per leg), the target 0.15 rad past the end so that
  // the hand's rotational spring presses it against the joint limit
  kGimbalSweep,
  // a hand another thread moves (Emulator::set_manual_hand: a viewer's
  // mouse): while held, the hand's spring pulls the grip toward the target
  // given; while not held it lets go, as kNone
  kManual,
};
const char* hand_program_name(HandProgram p);  // "case", "tour", ...
// throws std::invalid_argument naming the unknown program
HandProgram parse_hand_program(const std::string& name);

inline constexpr double kTourPeriod_s = 8.0;
inline constexpr double kTourAmplitude_mm = 50.0;
inline constexpr double kSweepLeg_s = 1.0;

// The inkwell (dock) pose: hw::kInkwellDevice_rad (hw/omni_calibration.h),
// which `hw calibrate` fits the encoder offsets to.
using hw::kInkwellDevice_rad;
// the inkwell switch closes when the true wrist centre is within this of
// the inkwell's and the stylus axis within this angle of the inkwell's
inline constexpr double kDockRadius_mm = 5.0;
inline constexpr double kDockAngle_deg = 15.0;

struct EmulatorOptions {
  // lockstep: no physics thread; advance() runs each period (see above)
  bool lockstep = false;
  // a scene ClosedLoop can load; empty: models/cases/case1.xml of the
  // models directory the build was configured with
  std::string scene;
  std::vector<std::string> overrides;
  HandProgram hand = HandProgram::kTour;
  double realtime_factor = 1.0;  // simulated s per wall s (> 0)
  // run the physics thread under SCHED_FIFO at this priority when the
  // system allows it (a device's firmware does not wait for the host's
  // scheduler either); 0: normal scheduling
  int realtime_priority = 70;
  std::string serial = "EMU-0001";
  std::vector<EmulatorFault> faults;
  double device_watchdog_s = 0.05;  // <= 0: no device watchdog
  // a calibrated Omni MJCF whose parameters replace the scene's Omni's
  // (sim::omni_model_hook; `--model FILE`); empty: the scene's own
  std::string model_file;
  SeededFaults seeded;  // the device's hidden built-in mistakes
};

// Ground truth of the last period. Its PlantTruth part describes the
// period as the simulated closed loop's record describes a tick
// (device/tick_record.h): the true joint angles and wrist centre at the
// period's start, the hand's target and the motors' torque over it, the
// energies, the hand's force and the state's finiteness at its end. The
// rest is the emulator's own. Device frame, mm, unless named.
struct EmulatorTruth : PlantTruth {
  double t_sim_s = 0.0;       // emulator time at the end of the period
  double wall_s = 0.0;        // the emulator's clock when published
  long periods = 0;           // periods stepped since start()
  long lag_periods = 0;       // periods dropped to stay in real time
  Joints q_end_dh = Joints::Zero();   // MuJoCo's joint angles at the end
  Vec3 p_end_mm = Vec3::Zero();       // the true wrist centre at the end
  Vec3 stylus_axis = Vec3::UnitZ();   // true stylus axis at the end, unit
  HandProgram program = HandProgram::kTour;
  bool docked = false;
  bool manual_held = false;  // kManual: the hand holds the stylus
  bool device_watchdog_fired = false;  // zero held: no write in time
  bool invalid_command = false;        // the last write was not finite
  bool unplugged = false;
  bool stalled = false;  // (seen only after a stall: the thread was frozen)
  bool late = false;
  int drops_pending = 0;
};

class Emulator final : public HapticDevice {
 public:
  // Loads the scene with options.model_file and the seeded faults' model
  // edit applied (throws SimError naming the file and field) and checks
  // the options (std::invalid_argument naming the field; a seeded delay
  // that is not a whole number of servo periods). Does not start.
  explicit Emulator(const EmulatorOptions& options);
  ~Emulator() override;
  Emulator(const Emulator&) = delete;
  Emulator& operator=(const Emulator&) = delete;

  // Launches the physics thread (emulator time 0); in lockstep, only
  // resets to time 0. With `resume`, an emulator that has run before goes
  // on from where stop() left it (pose, velocities, emulator time, the
  // periods and energies counted), as a device does when its host's loop
  // is restarted; its first start is fresh either way. Throws
  // DeviceOpenError if it is already running or cannot be started.
  void start(bool resume = false);
  // lockstep only: one servo period (the last command held), then the
  // clock moves on by the period. No allocation, no exception, no sleep.
  void advance() noexcept;
  bool lockstep() const noexcept { return options_.lockstep; }
  // The emulator's clock, s: CLOCK_MONOTONIC, or in lockstep the periods
  // advanced times the period.
  double clock_s() const noexcept;
  // When reads time out because the physics thread fell behind the wall
  // clock (a busy host, not an injected fault): why, in one line; empty
  // otherwise (and always in lockstep).
  std::string stall_cause() const;
  // Joins the physics thread; idempotent.
  void stop() noexcept;
  bool running() const noexcept { return running_.load(); }

  DeviceError read_joints(Joints* q_device_rad) noexcept override;
  DeviceError read_state(DeviceState* state) noexcept override;
  DeviceError write_motor_torques(const Vec3& tau_motor_Nm) noexcept override;

  EmulatorTruth truth() const noexcept { return truth_.read(); }
  DeviceIdentity identity() const;

  // kManual's hand: the grip's target (world = DH base frame, SI, as
  // SimHand::set_target takes it) and whether the hand holds the stylus;
  // used from the next period. Any thread; no allocation.
  void set_manual_hand(const HandTargetState& target, bool held) noexcept {
    manual_.write(ManualHand{target, held});
  }

  // A copy of the physics for a viewer: enable_mirror() (before start())
  // makes the physics thread copy its mjData into a mirror every
  // kMirrorPeriods periods (skipping a copy rather than waiting when a
  // reader holds it); copy_mirror() copies the mirror into d (made for
  // loop().model()), false before the first copy. Any thread.
  static constexpr int kMirrorPeriods = 4;
  void enable_mirror();
  bool copy_mirror(mjData* d) const;

  void press_buttons(std::uint32_t mask) noexcept { buttons_.store(mask); }
  void set_hand_program(HandProgram p) noexcept {
    program_.store(static_cast<int>(p));
  }
  // Schedules a fault (at max(at_s, now)); any thread. Throws
  // std::invalid_argument for a bad fault, std::length_error past
  // kMaxFaults faults in all.
  void inject(const EmulatorFault& fault);
  static constexpr int kMaxFaults = 64;

  // The calibration readings are decoded with (validated; throws
  // std::invalid_argument naming the field).
  void set_calibration(const hw::OmniCalibration& cal);
  hw::OmniCalibration calibration() const noexcept { return cal_.read(); }
  // the hidden truth: what an ideal calibration would find
  const hw::OmniCalibration& factory_calibration() const noexcept {
    return factory_;
  }

  // the scene's loop (model, script, path): read-only use while running
  const ClosedLoop& loop() const { return *loop_; }
  double servo_period_s() const noexcept { return period_s_; }
  // the seeded delay in servo periods (EmulatorOptions::seeded.delay_ms)
  int delay_periods() const noexcept { return delay_periods_; }
  // the inkwell's wrist centre (mm) and stylus axis, device frame
  Vec3 inkwell_mm() const noexcept;
  Vec3 inkwell_axis() const noexcept;

 private:
  // a reading and when it was published (wall clock: a stalled physics
  // thread is told from a late reading, whose own timestamp is old)
  struct Published {
    DeviceState state;
    double publish_wall_s = 0.0;
    bool finite = true;
  };
  struct Command {
    Vec3 tau_Nm = Vec3::Zero();
    double wall_s = 0.0;
    std::uint64_t count = 0;  // writes so far
    bool invalid = false;
  };
  struct ManualHand {
    HandTargetState target;
    bool held = false;
  };
  struct FaultSlot {
    std::atomic<bool> ready{false};
    std::atomic<bool> taken{false};  // the physics thread has acted on it
    EmulatorFault fault;
  };

  void run() noexcept;
  // one servo period; returns the seconds to freeze for (a stall), else 0
  double step_period() noexcept;
  // how far apart two of the clock's times may be and still be equal
  double time_tolerance_s() const noexcept;
  double apply_faults(double t_s) noexcept;
  Vec3 motor_command(double now_s) noexcept;
  // the period's snapshot and truth: publish() measures (read_sensors),
  // hands the servo thread the reading or a late one (publish_reading)
  // and fills the truth (fill_truth)
  void publish(double now_s) noexcept;
  // the sensors quantised, as raw values and decoded angles with the
  // seeded faults, the inkwell switch (the true wrist centre and stylus
  // axis into *truth) and the device's own kinematics
  void read_sensors(const Joints& q_dh, DeviceState* state,
                    EmulatorTruth* truth) noexcept;
  // the reading into the late ring, and the one due now into state_
  void publish_reading(const Published& p, double now_s) noexcept;
  // the truth of the period just ended (all but `docked`, from the reading)
  void fill_truth(const Joints& q_dh, double now_s,
                  EmulatorTruth* truth) noexcept;

  EmulatorOptions options_;
  std::unique_ptr<ClosedLoop> loop_;
  double period_s_ = 1e-3;
  int substeps_ = 1;
  int delay_periods_ = 0;
  hw::OmniCalibration factory_;

  std::thread thread_;
  std::atomic<bool> running_{false};
  bool started_before_ = false;  // start(resume) goes on from here
  std::atomic<bool> stop_{false};

  // shared with the servo thread and others
  Seqlock<hw::OmniCalibration> cal_;
  Seqlock<Command> command_;
  Seqlock<EmulatorTruth> truth_;
  Seqlock<Published> state_;
  Seqlock<ManualHand> manual_;
  // the viewer's mirror (enable_mirror)
  mutable std::mutex mirror_mutex_;
  mjData* mirror_ = nullptr;
  bool mirror_filled_ = false;  // under mirror_mutex_
  std::atomic<std::uint32_t> buttons_{0};
  std::atomic<int> program_{0};
  std::atomic<int> drops_{0};
  std::atomic<bool> unplugged_{false};
  std::atomic<std::uint64_t> writes_{0};  // the servo thread's count
  std::atomic<double> start_wall_s_{0.0};
  std::atomic<double> t_sim_now_s_{0.0};
  // lockstep: the clock (periods advanced), and a stall's end on it
  std::atomic<long> lockstep_periods_{0};
  double frozen_until_s_ = -1.0;
  std::atomic<bool> frozen_{false};  // the physics thread is in a stall
  // reads that timed out because the physics was behind, not by a fault
  std::atomic<long> starved_reads_{0};
  FaultSlot faults_[kMaxFaults];
  std::atomic<int> fault_count_{0};

  // the physics thread's own
  struct PhysicsState;
  std::unique_ptr<PhysicsState> ps_;
};

}  // namespace vmh::sim

#endif  // VMHAPTICS_SIM_EMULATOR_H_
