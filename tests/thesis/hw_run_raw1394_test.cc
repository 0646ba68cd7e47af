// A thesis case through the native FireWire driver's bus code, end to end:
// `hw run`'s case (thesis/hw_run.h) on a FirewireBackend whose transport
// is Raw1394Transport over the libraw1394 stand-in (tests/hw/firewire/
// fwsim/), whose Omni is the MuJoCo emulator (fwsim_emulator.h). Every
// tick the driver drains the receive context, decodes the newest state
// packet, and refills the transmit context with the command; the stand-in
// Omni takes the commands every bus cycle and sends its state once a
// period. In lockstep: deterministic. The claims must pass, and agree with
// the same case through the in-process wire (`emulator:firewire`), which
// skips only libraw1394, within 1e-4 relative (measured: 2e-7 on case 1's
// RMS path error, the claims' values equal to six digits).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "hw/firewire/firewire_omni.h"
#include "hw/firewire/raw1394_transport.h"
#include "runtime/backend_registry.h"
#include "runtime/session.h"
#include "sim/emulator_backend.h"
#include "thesis/hw_run.h"
#include "tests/hw/firewire/fwsim/fwsim_emulator.h"
#include "tests/support/thesis_cases.h"

namespace vmh::thesis {
namespace {

using vmh::testing::EmulatorOnTheBus;
using vmh::testing::Fwsim;
using vmh::testing::thesis_case_scene;

constexpr std::uint64_t kGuid = 0x000b9900000e0e0eull;

runtime::SessionOptions raw1394_lockstep_session() {
  runtime::SessionOptions so;
  so.servo.lockstep = true;
  so.progress = false;
  return so;
}

// the emulator's ground truth for the claims
struct Truth final : runtime::TruthSource {
  explicit Truth(sim::Emulator* e) : emu(e) {}
  void read_truth(PlantTruth* t) const noexcept override { *t = emu->truth(); }
  sim::Emulator* emu;
};

Json run_in_process(const std::string& scene, const std::vector<std::string>& sets) {
  runtime::BackendRegistry reg;
  sim::register_backends(&reg);
  runtime::OpenRequest rq;
  rq.defaults["hand"] = "case";
  rq.scene_sets = sets;
  rq.load_calibration = false;
  rq.lockstep = true;
  runtime::OpenedDevice dev = reg.open("emulator:firewire:" + scene, rq);
  HwRunCase hw(scene, sets, "", 1.0);
  runtime::SessionResult r;
  return hw.run(&dev, raw1394_lockstep_session(), &r);
}

class HwRunRaw1394 : public vmh::testing::ThesisCaseTest {};

TEST_P(HwRunRaw1394, ACasePassesItsClaimsThroughTheBusCode) {
  const std::string scene = thesis_case_scene(GetParam());
  const std::vector<std::string> sets = {};
  const Fwsim bus(VMH_FWSIM_LIBRARY);
  bus.setup("omni=000b9900000e0e0e,rate=1000");

  sim::EmulatorFirewireOptions fo;
  fo.emulator.lockstep = true;
  fo.emulator.scene = scene;
  fo.emulator.hand = sim::HandProgram::kCase;
  fo.emulator.overrides = sets;
  auto omni = std::make_unique<EmulatorOnTheBus>(bus, kGuid, fo);
  sim::Emulator* emu = omni->emulator();

  hw::fw::Raw1394Options ro;
  ro.library = VMH_FWSIM_LIBRARY;
  ro.guid = kGuid;
  auto transport = std::make_unique<hw::fw::Raw1394Transport>(ro);
  hw::fw::Raw1394Transport* bus_code = transport.get();
  hw::fw::FirewireOmniOptions wo;
  wo.calibration = emu->factory_calibration();  // what its raw values imply
  wo.calibrated = true;
  DeviceIdentity id = emu->identity();
  id.backend = "firewire (libraw1394 stand-in)";
  auto backend = std::make_unique<hw::fw::FirewireBackend>(std::move(transport), wo,
                                                           id, omni.get());
  hw::fw::FirewireBackend* fw = backend.get();
  Truth truth(emu);
  runtime::OpenedDevice dev;
  dev.backend = std::move(backend);
  dev.truth = &truth;

  HwRunCase hw(scene, sets, "", 1.0);
  runtime::SessionResult session;
  const Json summary = hw.run(&dev, raw1394_lockstep_session(), &session);
  ASSERT_EQ(session.clock, "lockstep");
  ASSERT_EQ(session.stop_reason, "duration");
  ASSERT_TRUE(summary.value("claims_judged", false)) << summary.dump();
  ASSERT_FALSE(summary.at("claims").empty());
  for (const Json& c : summary.at("claims")) {
    EXPECT_TRUE(c.at("pass").get<bool>()) << c.dump();
  }
  EXPECT_EQ(summary.at("all_claims_pass"), true);

  // it went over the bus: one packet a tick (the first tick's comes at the
  // end of the first period), every command taken, nothing lost or late
  const hw::fw::FirewireOmniStats s = fw->omni()->stats();
  EXPECT_EQ(static_cast<long>(s.packets), session.ticks - 1);
  EXPECT_EQ(s.lost_packets, 0u);
  EXPECT_EQ(s.late_packets, 0u);
  EXPECT_EQ(s.superseded_packets, 0u);
  EXPECT_EQ(bus_code->start_record().wrote_20010, true);
  EXPECT_EQ(bus_code->stats().timeouts, 1u);  // the first tick's
  EXPECT_GE(omni->commands(), 8 * (session.ticks - 1));  // 8 bus cycles a period
  EXPECT_EQ(omni->periods(), session.ticks);  // a period after every tick

  // and the claims agree with the same case through the in-process wire
  const Json wire = run_in_process(scene, sets);
  const Json& a = summary.at("claims");
  const Json& b = wire.at("claims");
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double va = a[i].at("value"), vb = b[i].at("value");
    // the first tick reads nothing over the bus (the stream's first packet
    // comes at the end of the first period); nothing else differs
    EXPECT_NEAR(va, vb, 1e-4 * std::max({1e-3, std::abs(va), std::abs(vb)}))
        << a[i].at("name");
    ::testing::Test::RecordProperty(a[i].at("name").get<std::string>(),
                                    std::to_string(va) + " vs " + std::to_string(vb));
  }
  const double ea = summary.at("metrics").at("rms_path_error_mm");
  const double eb = wire.at("metrics").at("rms_path_error_mm");
  EXPECT_NEAR(ea, eb, 1e-4 * eb);
  ::testing::Test::RecordProperty("rms_path_error_mm",
                                  std::to_string(ea) + " vs " + std::to_string(eb));
}

// one case is the "done when"; the others are cheap in lockstep
INSTANTIATE_TEST_SUITE_P(Cases, HwRunRaw1394, ::testing::Values(1, 3));

}  // namespace
}  // namespace vmh::thesis
