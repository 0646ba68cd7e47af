// FirewireBackend end to end: the project's servo thread driving a loop
// that reads and writes the FireWire Omni over a streaming fake transport.
#include "hw/firewire/firewire_omni.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <thread>

#include "tests/hw/firewire/fake_transport.h"

namespace vmh::hw::fw {
namespace {

using testing::FakeTransport;

// reads the state and commands a small torque every tick
class PushLoop final : public ServoLoop {
 public:
  explicit PushLoop(HapticDevice* dev) : dev_(dev) {}
  bool tick(double) noexcept override {
    DeviceState st;
    if (dev_->read_state(&st) == DeviceError::kOk) {
      ++ok_reads;
      last_count.store(st.encoder_counts[0]);
    }
    if (dev_->write_motor_torques(Vec3(0.05, -0.05, 0.1)) == DeviceError::kOk) {
      ++ok_writes;
    }
    ++ticks;
    return true;
  }
  std::atomic<long> ticks{0}, ok_reads{0}, ok_writes{0};
  std::atomic<std::int32_t> last_count{0};

 private:
  HapticDevice* dev_;
};

TEST(FirewireBackend, LoopTicksAndStopLeavesZeroWithMotorsOff) {
  auto owned = std::make_unique<FakeTransport>();
  FakeTransport* t = owned.get();
  t->stream = true;
  pot_words_from_code(1000, &t->stream_packet.gimbal_a[0],
                      &t->stream_packet.gimbal_b[0]);
  pot_words_from_code(1000, &t->stream_packet.gimbal_a[1],
                      &t->stream_packet.gimbal_b[1]);
  pot_words_from_code(1000, &t->stream_packet.gimbal_a[2],
                      &t->stream_packet.gimbal_b[2]);
  DeviceIdentity id;
  id.config = "firewire:test";
  FirewireBackend backend(std::move(owned), FirewireOmniOptions{}, id);

  const DeviceIdentity got = backend.identity();
  EXPECT_EQ(got.backend, "firewire");
  EXPECT_EQ(got.config, "firewire:test");
  EXPECT_EQ(got.model, "PHANTOM Omni");
  EXPECT_EQ(got.serial, "4660");  // from the transport's node
  EXPECT_EQ(got.input_dof, 6);
  EXPECT_EQ(got.output_dof, 3);
  EXPECT_EQ(backend.calibration_state(), CalibrationState::kNeedsUpdate);

  PushLoop loop(backend.device());
  ServoOptions so;
  so.period_s = 1e-3;
  so.realtime = false;
  backend.start(&loop, so);
  EXPECT_TRUE(backend.running());
  EXPECT_EQ(t->start_calls.load(), 1);
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  backend.stop();
  EXPECT_FALSE(backend.running());

  // about 100 ticks at 1 kHz; at least a third of them on a loaded machine
  const long ticks = loop.ticks.load();
  EXPECT_GT(ticks, 30) << "ticks in 100 ms";
  EXPECT_LT(ticks, 200) << "ticks in 100 ms";
  EXPECT_EQ(loop.ok_reads.load(), ticks);
  EXPECT_EQ(loop.ok_writes.load(), ticks);
  EXPECT_GE(backend.timing().ticks, ticks);
  // the device saw the stream: one count per packet on t1
  EXPECT_EQ(loop.last_count.load(),
            static_cast<std::int32_t>(t->receive_calls.load()));
  EXPECT_EQ(backend.omni()->stats().packets,
            static_cast<std::uint64_t>(loop.ok_reads.load()));
  EXPECT_EQ(backend.omni()->stats().lost_packets, 0u);

  // commands: a zero before the loop, one per tick with the motors on, and
  // a zero with the motors off as the last packet before the transport stops
  const std::size_t n = t->n_sent.load();
  ASSERT_EQ(n, static_cast<std::size_t>(ticks) + 2);
  EXPECT_FALSE(t->sent_command(0).motors_on());
  EXPECT_TRUE(t->sent_command(1).motors_on());
  EXPECT_TRUE(t->sent_command(n - 2).motors_on());
  EXPECT_EQ(t->stop_calls.load(), 1);
  EXPECT_EQ(t->sent_at_stop.load(), static_cast<long>(n) - 1);
  const std::uint8_t zero_off[16] = {0xff, 0x07, 0xff, 0x07, 0xff, 0x07,
                                     0xc0, 0x53, 0, 0, 0, 0, 0, 0, 0, 0};
  for (std::size_t b = 0; b < 16; ++b) {
    EXPECT_EQ(t->sent[(n - 1) % FakeTransport::kSent][b], zero_off[b])
        << "byte " << b;
  }

  // stop is idempotent and sends nothing more
  backend.stop();
  EXPECT_EQ(t->n_sent.load(), n);
  EXPECT_EQ(t->stop_calls.load(), 1);
}

TEST(FirewireBackend, RestartsAfterStop) {
  auto owned = std::make_unique<FakeTransport>();
  FakeTransport* t = owned.get();
  t->stream = true;
  for (std::size_t i = 0; i < 3; ++i) {
    pot_words_from_code(10, &t->stream_packet.gimbal_a[i],
                        &t->stream_packet.gimbal_b[i]);
  }
  FirewireBackend backend(std::move(owned), FirewireOmniOptions{}, {});
  PushLoop loop(backend.device());
  ServoOptions so;
  so.realtime = false;
  for (int run = 0; run < 2; ++run) {
    backend.start(&loop, so);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    backend.stop();
    EXPECT_FALSE(t->last_command().motors_on()) << "run " << run;
  }
  EXPECT_EQ(t->start_calls.load(), 2);
  EXPECT_GT(loop.ticks.load(), 2);
}

TEST(FirewireBackend, NullTransportAndBadOptionsThrow) {
  EXPECT_THROW(FirewireBackend(nullptr, FirewireOmniOptions{}, {}),
               std::invalid_argument);
  FirewireOmniOptions bad;
  bad.receive_timeout_s = -1.0;
  EXPECT_THROW(FirewireBackend(std::make_unique<FakeTransport>(), bad, {}),
               std::invalid_argument);
}

TEST(FirewireBackend, CalibratedOptionsReportOk) {
  FirewireOmniOptions o;
  o.calibrated = true;
  FirewireBackend b(std::make_unique<FakeTransport>(), o, {});
  EXPECT_EQ(b.calibration_state(), CalibrationState::kOk);
  FirewireBackend c(std::make_unique<FakeTransport>(), FirewireOmniOptions{},
                    {});
  EXPECT_EQ(c.calibration_state(), CalibrationState::kNeedsUpdate);
  c.omni()->set_calibration(nominal_calibration());
  EXPECT_EQ(c.calibration_state(), CalibrationState::kOk);
}

}  // namespace
}  // namespace vmh::hw::fw
