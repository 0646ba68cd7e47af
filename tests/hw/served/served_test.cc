// hw/served: the layout's checks, the shared-memory object's life, and a
// server and a client over a scripted device: the client reads what the
// device reported, the device gets what the client wrote, and every way
// the other side can vanish ends in zero torque or a named error.
#include "hw/served/served_device.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <thread>

#include "hw/backends.h"
#include "hw/served/served_region.h"
#include "hw/served/served_runtime.h"
#include "hw/served/served_shm.h"
#include "tests/support/alloc_counter.h"

namespace vmh::hw::served {
namespace {

// a name no other test process uses at the same time
std::string unique_name(const char* what) {
  return std::string("t-") + what + "-" + std::to_string(::getpid());
}

// waits (on the wall clock, up to 20 s) until cond() holds
bool eventually(const std::function<bool()>& cond) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (std::chrono::steady_clock::now() < until) {
    if (cond()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return cond();
}

// a pid that certainly runs no process: a child that has exited and been
// reaped (pids are not reused that fast)
int dead_pid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  return static_cast<int>(child);
}

// A device whose reading is its own tick count, and which keeps the last
// torque written to it.
class ScriptedDevice final : public HapticDevice {
 public:
  DeviceError read_joints(Joints* q) noexcept override { return joints_of_state(q); }
  DeviceError read_state(DeviceState* s) noexcept override {
    const long n = ++reads_;
    if (fail_.load()) {
      s->present = 0;
      return DeviceError::kSensorFault;
    }
    s->present = kStateJoints | kStateButtons | kStateJacobian;
    for (int i = 0; i < 6; ++i) s->q_device_rad[i] = 1e-3 * static_cast<double>(n) + i;
    s->buttons = kButton2;
    s->jacobian.setIdentity();
    return DeviceError::kOk;
  }
  DeviceError write_motor_torques(const Vec3& tau) noexcept override {
    for (int i = 0; i < 3; ++i) tau_[i].store(tau[i]);
    ++writes_;
    return DeviceError::kOk;
  }
  Vec3 tau() const { return Vec3(tau_[0].load(), tau_[1].load(), tau_[2].load()); }
  long writes() const { return writes_.load(); }
  std::atomic<bool> fail_{false};

 private:
  std::atomic<long> reads_{0};
  std::atomic<long> writes_{0};
  std::atomic<double> tau_[3] = {0.0, 0.0, 0.0};
};

DeviceIdentity scripted_identity() {
  DeviceIdentity id;
  id.backend = "scripted";
  id.config = "scripted:test";
  id.model = "PHANTOM Omni (scripted)";
  id.serial = "SCRIPT-1";
  id.input_dof = 6;
  id.output_dof = 3;
  return id;
}

// a client loop that writes a fixed torque and keeps the last reading
class WriteLoop final : public ServoLoop {
 public:
  explicit WriteLoop(HapticDevice* d, Vec3 tau) : d_(d), tau_(tau) {}
  bool tick(double) noexcept override {
    DeviceState s;
    if (d_->read_state(&s) == DeviceError::kOk) {
      q0_.store(s.q_device_rad[0]);
      ++ok_;
    } else {
      ++failed_;
    }
    d_->write_motor_torques(tau_);
    return true;
  }
  std::atomic<double> q0_{0.0};
  std::atomic<long> ok_{0}, failed_{0};

 private:
  HapticDevice* d_;
  Vec3 tau_;
};

// ---- the layout (pure) ----

TEST(ServedRegion, NamesFollowTheRule) {
  EXPECT_EQ(served_name_error("omni-1.a_b"), "");
  EXPECT_NE(served_name_error("").find("empty"), std::string::npos);
  EXPECT_NE(served_name_error("../etc").find("'.'"), std::string::npos);
  EXPECT_NE(served_name_error("a/b").find("letters, digits"), std::string::npos);
  EXPECT_NE(served_name_error(std::string(49, 'a')).find("at most 48"),
            std::string::npos);
  EXPECT_EQ(served_name_error(std::string(48, 'a')), "");
}

TEST(ServedRegion, HeaderCheckNamesWhatIsWrong) {
  unsigned char bytes[sizeof(ServedRegion)] = {};
  EXPECT_NE(region_header_error(bytes, 8).find("too small"), std::string::npos);
  EXPECT_NE(region_header_error(bytes, sizeof bytes).find("magic"), std::string::npos);
  const std::uint64_t magic = kServedMagic;
  std::memcpy(bytes, &magic, 8);
  std::uint32_t version = kServedVersion + 1, size = sizeof(ServedRegion);
  std::memcpy(bytes + 8, &version, 4);
  std::memcpy(bytes + 12, &size, 4);
  const std::string v = region_header_error(bytes, sizeof bytes);
  EXPECT_NE(v.find("version " + std::to_string(kServedVersion + 1)), std::string::npos) << v;
  version = kServedVersion;
  size = 12;
  std::memcpy(bytes + 8, &version, 4);
  std::memcpy(bytes + 12, &size, 4);
  EXPECT_NE(region_header_error(bytes, sizeof bytes).find("bytes"), std::string::npos);
  size = sizeof(ServedRegion);
  std::memcpy(bytes + 12, &size, 4);
  EXPECT_EQ(region_header_error(bytes, sizeof bytes), "");
  // "VMHSERV1" as the header's first eight bytes, whatever the build
  EXPECT_EQ(std::memcmp(bytes, "VMHSERV1", 8), 0);
}

TEST(ServedRegion, CommandRuleZeroesWhatIsMissingStaleOrNotFinite) {
  CommandState st = CommandState::kApplied;
  ServedCommand c;
  EXPECT_EQ(command_to_apply(c, 10.0, 0.05, &st), Vec3::Zero());
  EXPECT_EQ(st, CommandState::kNone);
  c.tau_Nm = Vec3(0.1, -0.2, 0.3);
  c.count = 7;
  c.client_s = 10.0;
  EXPECT_EQ(command_to_apply(c, 10.04, 0.05, &st), c.tau_Nm);
  EXPECT_EQ(st, CommandState::kApplied);
  EXPECT_EQ(command_to_apply(c, 10.06, 0.05, &st), Vec3::Zero());
  EXPECT_EQ(st, CommandState::kStale);
  c.tau_Nm[1] = std::nan("");
  EXPECT_EQ(command_to_apply(c, 10.0, 0.05, &st), Vec3::Zero());
  EXPECT_EQ(st, CommandState::kStale);
  EXPECT_STREQ(command_state_name(CommandState::kStale), "stale");
}

// ---- the object ----

TEST(ServedShm, OpenFindsWhatCreateMadeAndNamesWhatIsMissing) {
  const std::string name = unique_name("shm");
  try {
    ShmRegion::open(name);
    FAIL() << "opened a name nobody serves";
  } catch (const DeviceOpenError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("no such served device"), std::string::npos) << m;
    EXPECT_NE(m.find("view --serve-hd " + name), std::string::npos) << m;
  }
  auto server = ShmRegion::create(name);
  EXPECT_EQ(server->region()->server_pid.load(), ::getpid());
  // made but not yet serving: a client is told so
  try {
    ShmRegion::open(name);
    FAIL() << "opened a region whose server does not serve";
  } catch (const DeviceOpenError& e) {
    EXPECT_NE(std::string(e.what()).find("not serving"), std::string::npos) << e.what();
  }
  server->region()->serving.store(1);
  auto client = ShmRegion::open(name);
  EXPECT_FALSE(client->owner());
  // one region: what one side writes the other reads
  ServedCommand c;
  c.count = 3;
  client->region()->command.write(c);
  EXPECT_EQ(server->region()->command.read().count, 3u);
  // a second server under the same name is refused, naming the pid
  try {
    ShmRegion::create(name);
    FAIL() << "served one name twice";
  } catch (const DeviceOpenError& e) {
    EXPECT_NE(std::string(e.what()).find("already served by pid " +
                                         std::to_string(::getpid())),
              std::string::npos) << e.what();
  }
  client.reset();
  server.reset();
  // the server removed its name
  EXPECT_THROW(ShmRegion::open(name), DeviceOpenError);
}

TEST(ServedShm, ANameLeftByADeadServerIsTakenOver) {
  const std::string name = unique_name("dead");
  auto first = ShmRegion::create(name);
  first->region()->serving.store(1);
  first->region()->server_pid.store(dead_pid());
  // a client sees a server that is gone
  EXPECT_THROW(ShmRegion::open(name), DeviceOpenError);
  auto second = ShmRegion::create(name);  // takes it over
  EXPECT_EQ(second->region()->server_pid.load(), ::getpid());
  EXPECT_EQ(second->region()->serving.load(), 0u);
}

TEST(ServedShm, SomeoneElsesObjectIsRefusedWithAReason) {
  const std::string name = unique_name("alien");
  const std::string obj = served_directory() + kShmPrefix + name;
  const int fd = ::open(obj.c_str(), O_CREAT | O_RDWR, 0600);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::ftruncate(fd, 64), 0);
  ::close(fd);
  try {
    ShmRegion::open(name);
    FAIL() << "opened a 64-byte object";
  } catch (const DeviceOpenError& e) {
    EXPECT_NE(std::string(e.what()).find("too small"), std::string::npos) << e.what();
  }
  bool listed = false;
  for (const ServedListing& l : list_served()) {
    if (l.name == name) {
      listed = true;
      EXPECT_FALSE(l.serving);
      EXPECT_FALSE(l.why_not.empty());
    }
  }
  EXPECT_TRUE(listed);
  ::unlink(obj.c_str());
}

TEST(ServedShm, AFifoInTheObjectsPlaceIsRefusedWithoutHanging) {
  const std::string name = unique_name("fifo");
  const std::string obj = served_directory() + kShmPrefix + name;
  ASSERT_EQ(::mkfifo(obj.c_str(), 0600), 0);
  try {
    ShmRegion::open(name);
    FAIL() << "opened a FIFO";
  } catch (const DeviceOpenError& e) {
    EXPECT_NE(std::string(e.what()).find("not a regular"), std::string::npos) << e.what();
  }
  ::unlink(obj.c_str());
}

TEST(ServedShm, VmhServedDirKeepsAPrivateSetOfDevices) {
  char tmpl[] = "/tmp/vmh-served-XXXXXX";
  ASSERT_NE(::mkdtemp(tmpl), nullptr);
  const char* before = std::getenv("VMH_SERVED_DIR");
  const std::string saved = before != nullptr ? before : "";
  ::setenv("VMH_SERVED_DIR", tmpl, 1);
  EXPECT_EQ(served_directory(), tmpl);
  const std::string name = unique_name("private");
  {
    auto server = ShmRegion::create(name);
    EXPECT_TRUE(std::filesystem::exists(std::string(tmpl) + kShmPrefix + name));
    const std::vector<ServedListing> l = list_served();
    ASSERT_EQ(l.size(), 1u);
    EXPECT_EQ(l[0].name, name);
  }
  EXPECT_TRUE(list_served().empty());
  if (before != nullptr) {
    ::setenv("VMH_SERVED_DIR", saved.c_str(), 1);
  } else {
    ::unsetenv("VMH_SERVED_DIR");
  }
  ::rmdir(tmpl);
}

TEST(ServedBackendOpen, ASecondClientIsRefusedNamingTheFirst) {
  const std::string name = unique_name("busy");
  ScriptedDevice dev;
  ServedServer server(name, &dev, scripted_identity(), ServerOptions{});
  server.start();
  {
    // the slot held by a process that runs (our parent)
    auto peek = ShmRegion::open(name);
    peek->region()->client_pid.store(static_cast<int>(::getppid()));
    try {
      ServedBackend b(name);
      FAIL() << "two clients on one device";
    } catch (const DeviceOpenError& e) {
      EXPECT_NE(std::string(e.what()).find("in use by the client pid " +
                                           std::to_string(::getppid())),
                std::string::npos) << e.what();
    }
    // held by a client that died: taken over
    peek->region()->client_pid.store(dead_pid());
    ServedBackend b(name);
    EXPECT_EQ(peek->region()->client_pid.load(), ::getpid());
    const DeviceIdentity id = b.identity();
    EXPECT_EQ(id.backend, "served");
    EXPECT_EQ(id.config, name);
    EXPECT_EQ(id.model, "PHANTOM Omni (scripted)");
    EXPECT_EQ(id.serial, "SCRIPT-1");
    EXPECT_EQ(id.output_dof, 3);
  }
  // the client's end freed the slot
  auto peek = ShmRegion::open(name);
  EXPECT_EQ(peek->region()->client_pid.load(), 0);
}

TEST(ServedRegistry, TheBackendIsRegisteredAndRefusesBadRequests) {
  runtime::BackendRegistry reg;
  register_served_backend(&reg);
  std::string arg;
  EXPECT_EQ(reg.resolve("served:abc", &arg).name, "served");
  EXPECT_EQ(arg, "abc");
  runtime::OpenRequest rq;
  EXPECT_THROW(reg.open("served", rq), runtime::RequestError);
  EXPECT_THROW(reg.open("served:a/b", rq), runtime::RequestError);
  try {
    reg.open("served:" + unique_name("nobody"), rq);
    FAIL();
  } catch (const DeviceOpenError& e) {
    EXPECT_NE(std::string(e.what()).find("no such served device"), std::string::npos);
  }
  // hw::register_backends has it among hw/'s
  runtime::BackendRegistry all;
  hw::register_backends(&all);
  EXPECT_NE(all.find("served"), nullptr);
}

// ---- server and client, on the wall clock ----

TEST(ServedRealtime, ClientReadsTheDeviceAndTheDeviceGetsTheClientsTorque) {
  const std::string name = unique_name("rt");
  ScriptedDevice dev;
  ServedServer server(name, &dev, scripted_identity(), ServerOptions{});
  server.start();
  ServedBackend client(name);
  const Vec3 tau(0.05, -0.1, 0.2);
  WriteLoop loop(client.device(), tau);
  ServoOptions so;
  so.realtime = false;
  client.start(&loop, so);
  ASSERT_TRUE(eventually([&] { return loop.ok_.load() > 50; }));
  // the reading is the device's: t1 = 1e-3 x its read count, which grows
  const double q_a = loop.q0_.load();
  ASSERT_TRUE(eventually([&] { return loop.q0_.load() > q_a; }));
  // the device gets exactly what the client wrote, and the server says so
  ASSERT_TRUE(eventually([&] { return dev.tau() == tau; }));
  ASSERT_TRUE(eventually([&] {
    return server.stats().command_state == CommandState::kApplied;
  }));
  EXPECT_EQ(server.stats().client_pid, ::getpid());
  EXPECT_EQ(client.served()->last().state.buttons, kButton2);

  // the client stops writing: after the watchdog the device gets zero
  client.stop();
  ASSERT_TRUE(eventually([&] {
    return dev.tau() == Vec3::Zero() &&
           server.stats().command_state == CommandState::kStale;
  }));

  // a reading the device could not make reaches the client as its error
  dev.fail_.store(true);
  const long before = server.stats().ticks;
  ASSERT_TRUE(eventually([&] { return server.stats().ticks > before + 2; }));
  DeviceState s;
  EXPECT_EQ(client.device()->read_state(&s), DeviceError::kSensorFault);
  EXPECT_EQ(s.present, 0u);
  dev.fail_.store(false);

  // the server ends: the client is told, and the device was left at zero
  server.stop();
  EXPECT_EQ(client.device()->read_state(&s), DeviceError::kNotConnected);
  EXPECT_EQ(client.device()->write_motor_torques(tau), DeviceError::kNotConnected);
  EXPECT_EQ(dev.tau(), Vec3::Zero());
  EXPECT_FALSE(client.stall_cause().empty());
}

TEST(ServedRealtime, ANonFiniteTorqueIsRefusedAndZeroReachesTheDevice) {
  const std::string name = unique_name("nan");
  ScriptedDevice dev;
  ServedServer server(name, &dev, scripted_identity(), ServerOptions{});
  server.start();
  ServedBackend client(name);
  EXPECT_EQ(client.device()->write_motor_torques(Vec3(0.1, 0.1, 0.1)),
            DeviceError::kOk);
  ASSERT_TRUE(eventually([&] { return dev.tau() == Vec3(0.1, 0.1, 0.1); }));
  EXPECT_EQ(client.device()->write_motor_torques(Vec3(0.1, std::nan(""), 0.1)),
            DeviceError::kInvalidCommand);
  ASSERT_TRUE(eventually([&] { return dev.tau() == Vec3::Zero(); }));
}

TEST(ServedRealtime, ReadAndWriteAllocateNothing) {
  const std::string name = unique_name("alloc");
  ScriptedDevice dev;
  ServedServer server(name, &dev, scripted_identity(), ServerOptions{});
  server.start();
  ServedBackend client(name);
  ASSERT_TRUE(eventually([&] { return server.stats().ticks > 2; }));
  HapticDevice* d = client.device();
  long ok = 0;
  std::size_t allocations = 0;
  {
    vmh::testing::AllocationScope scope;
    for (int i = 0; i < 1000; ++i) {
      DeviceState s;
      if (d->read_state(&s) == DeviceError::kOk) ++ok;
      d->write_motor_torques(Vec3(1e-3, 0.0, 0.0));
    }
    allocations = scope.count();
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_GT(ok, 0);
}

TEST(ServedRealtime, AClientOfAServerThatIsGoneIsToldNotConnected) {
  const std::string name = unique_name("gone");
  ScriptedDevice dev;
  auto server = std::make_unique<ServedServer>(name, &dev, scripted_identity(),
                                               ServerOptions{});
  server->start();
  ServedBackend client(name);
  ASSERT_TRUE(eventually([&] { return server->stats().ticks > 2; }));
  // the server's process vanished without a word: its pid no longer runs
  // and it stopped publishing (simulated: the thread ends, the flag stays)
  auto peek = ShmRegion::open(name);
  ServedRegion* r = peek->region();
  server->stop();
  r->serving.store(1);
  r->server_pid.store(dead_pid());
  ASSERT_TRUE(eventually([&] {
    DeviceState s;
    return client.device()->read_state(&s) == DeviceError::kNotConnected;
  }));
  r->server_pid.store(::getpid());  // so the server's end removes the name
}

}  // namespace
}  // namespace vmh::hw::served
