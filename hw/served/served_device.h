// The served device, both ends (hw/served/README.md):
//   ServedServer   makes a HapticDevice of this process available under a
//                  name: a servo loop that publishes the device's reading
//                  each tick and applies the client's latest torque
//   ServedDevice   the client's HapticDevice over the region
//   ServedBackend  the client's DeviceBackend (`--device served:NAME`, and
//                  libHD.so's VMH_HD_DEVICE=served:NAME) on the project's
//                  servo thread, wall clock
//
// Safety at the seam. The server puts zero torque on its device when the
// client's command is older than the watchdog (50 ms by default: the
// client stopped, crashed or was suspended), before the first command,
// and when the server stops. The client's reads fail with kTimeout when
// the server's last reading is older than the staleness bound, and with
// kNotConnected once the server has stopped or its process is gone, so
// the client's own safety layer (reading guard, device/) zeroes its force.
//
// Real time: read_state, write_motor_torques and the server's tick take
// no lock and allocate nothing (sequence locks in the shared region).
#ifndef VMHAPTICS_HW_SERVED_SERVED_DEVICE_H_
#define VMHAPTICS_HW_SERVED_SERVED_DEVICE_H_

#include <atomic>
#include <memory>
#include <string>

#include "device/device_backend.h"
#include "device/haptic_device.h"
#include "device/servo_thread.h"
#include "hw/served/served_shm.h"

namespace vmh::hw::served {

inline constexpr double kDefaultWatchdog_s = 0.05;
inline constexpr double kDefaultStale_s = 0.05;

struct ServerOptions {
  double period_s = 1e-3;                  // the server's servo period
  double watchdog_s = kDefaultWatchdog_s;  // command age that zeroes torque
  bool realtime = false;                   // SCHED_FIFO for the server's loop
};

// What the server has seen, for a viewer's panel and tests.
struct ServerStats {
  long ticks = 0;
  std::uint64_t commands = 0;  // the client's write count last read
  CommandState command_state = CommandState::kNone;
  Vec3 tau_applied_Nm = Vec3::Zero();
  int client_pid = 0;          // 0: no client holds the device now
  int read_errors = 0;         // the device's failed reads so far
};

class ServedServer {
 public:
  // Creates the region (ShmRegion::create: DeviceOpenError naming the
  // cause) and fills its identity. `device` is not owned, must outlive
  // the server and is called only from the server's servo thread.
  ServedServer(const std::string& name, HapticDevice* device,
               const DeviceIdentity& identity, const ServerOptions& options);
  ~ServedServer();  // stop(), then the name is removed
  ServedServer(const ServedServer&) = delete;
  ServedServer& operator=(const ServedServer&) = delete;

  // Starts the servo loop (serving from its first tick). Throws
  // DeviceOpenError if it cannot.
  ServoReport start();
  // Stops serving: the region says so, the loop ends, zero torque is
  // written to the device. Idempotent.
  void stop() noexcept;
  bool serving() const noexcept;

  // the last tick's, from what it published (any thread)
  ServerStats stats() const noexcept;
  // the last tick as published to the client (any thread)
  ServedState last_published() const noexcept {
    return shm_->region()->state.read();
  }
  const std::string& name() const { return shm_->name(); }
  // the device spec a client opens it with: "served:NAME"
  std::string spec() const { return "served:" + name(); }

 private:
  class Loop;
  std::unique_ptr<ShmRegion> shm_;
  HapticDevice* device_;
  ServerOptions options_;
  std::unique_ptr<Loop> loop_;
  std::unique_ptr<ServoThread> thread_;
  std::atomic<int> read_errors_{0};  // the device's failed reads
};

class ServedDevice final : public HapticDevice {
 public:
  // `region` is not owned. stale_s: the oldest reading accepted.
  ServedDevice(ServedRegion* region, double stale_s);

  DeviceError read_joints(Joints* q_device_rad) noexcept override;
  DeviceError read_state(DeviceState* state) noexcept override;
  DeviceError write_motor_torques(const Vec3& tau_motor_Nm) noexcept override;

  // the server's last published tick and what it did with our command
  ServedState last() const noexcept { return last_; }
  std::uint64_t writes() const noexcept { return count_; }

 private:
  DeviceError server_gone() const noexcept;
  ServedRegion* region_;
  double stale_s_;
  ServedState last_;
  std::uint64_t count_ = 0;
};

class ServedBackend final : public DeviceBackend {
 public:
  // Maps the served region and takes its client slot. Throws
  // DeviceOpenError: no such served device, not serving, already used by
  // another client (its pid named).
  explicit ServedBackend(const std::string& name,
                         double stale_s = kDefaultStale_s);
  ~ServedBackend() override;  // stops, zero command, frees the slot

  DeviceIdentity identity() const override;
  CalibrationState calibration_state() override {
    return CalibrationState::kOk;  // the served device decodes its own
  }
  HapticDevice* device() noexcept override { return &device_; }
  ServoReport start(ServoLoop* loop, const ServoOptions& options) override;
  void stop() noexcept override;
  bool running() const noexcept override;
  TickStats timing() const override;
  std::string stall_cause() const override;

  ServedDevice* served() noexcept { return &device_; }
  const std::string& name() const { return shm_->name(); }

 private:
  std::unique_ptr<ShmRegion> shm_;
  ServedDevice device_;
  std::unique_ptr<ServoThread> thread_;
};

}  // namespace vmh::hw::served

#endif  // VMHAPTICS_HW_SERVED_SERVED_DEVICE_H_
