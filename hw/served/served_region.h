// The served device's shared-memory layout and its pure checks: the
// "codec" layer of hw/served (hw/served/README.md).
//
// A served device is a HapticDevice that one process (the server: `vmhaptics
// view --serve-hd NAME`, the emulator with the mouse as the hand) makes
// available to another (the client: any program on libHD.so with
// VMH_HD_DEVICE=served:NAME, or `vmhaptics hw ... --device served:NAME`)
// through one POSIX shared-memory object, /dev/shm/vmhaptics-hd-NAME.
//
// The object holds one ServedRegion: a header, the served device's
// identity, and two sequence locks (device/seqlock.h, lock-free atomics,
// which are address-free and so work between processes): the state the
// server publishes each servo tick and the command the client writes each
// of its ticks. Neither side ever waits for the other. Both sides' times
// are CLOCK_MONOTONIC, which is one clock for every process of a machine,
// so each side judges the other's freshness by its own clock.
//
// Units and frames are the device interface's (device/haptic_device.h):
// joint angles in the device convention (rad, t3 absolute), positions mm
// and velocities mm/s in the device frame, motor torques N m on t1..t3.
//
// The layout is this build's: the header's magic, version and size let a
// client built from another version refuse the region with a reason
// rather than misread it.
#ifndef VMHAPTICS_HW_SERVED_SERVED_REGION_H_
#define VMHAPTICS_HW_SERVED_SERVED_REGION_H_

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>

#include "controller/types.h"
#include "device/device_state.h"
#include "device/seqlock.h"

namespace vmh::hw::served {

// "VMHSERV1" in ASCII, little-endian
inline constexpr std::uint64_t kServedMagic = 0x3156524553484d56ULL;
inline constexpr std::uint32_t kServedVersion = 1;
// a served name: 1..kMaxNameLength of [A-Za-z0-9_.-], not starting with '.'
inline constexpr std::size_t kMaxNameLength = 48;
// the shared-memory object's name is kShmPrefix + NAME ("/vmhaptics-hd-")
inline constexpr const char* kShmPrefix = "/vmhaptics-hd-";

// What the server last did with the client's command.
enum class CommandState : std::int32_t {
  kNone = 0,     // no command written yet: zero torque
  kApplied = 1,  // the latest command is on the motors
  kStale = 2,    // the client stopped writing (watchdog): zero torque
};
const char* command_state_name(CommandState s);  // "none", "applied", "stale"

// Published by the server once per servo tick.
struct ServedState {
  DeviceState state;          // the served device's reading (present = 0 on error)
  std::int32_t error = 0;     // that read's DeviceError
  double server_s = 0.0;      // CLOCK_MONOTONIC when published, s
  std::uint64_t tick = 0;     // the server's ticks so far
  Vec3 tau_applied_Nm = Vec3::Zero();  // what the server wrote to the device
  std::int32_t command_state = 0;      // CommandState
  std::uint64_t commands_seen = 0;     // the client's write count it last read
};

// Written by the client once per its servo tick.
struct ServedCommand {
  Vec3 tau_Nm = Vec3::Zero();  // motors t1..t3, N m, finite
  double client_s = 0.0;       // CLOCK_MONOTONIC when written, s
  std::uint64_t count = 0;     // writes so far
};

// Fixed-size text, always NUL-terminated within its array.
struct ServedIdentity {
  char backend[32] = {};   // the served device's backend ("emulator")
  char config[64] = {};    // what it was opened as ("emulator:case1")
  char model[64] = {};
  char vendor[64] = {};
  char serial[64] = {};
  std::int32_t input_dof = 0;
  std::int32_t output_dof = 0;
  double period_s = 1e-3;  // the server's servo period
};

struct ServedRegion {
  std::uint64_t magic = 0;  // kServedMagic, written last by the server
  std::uint32_t version = 0;
  std::uint32_t size = 0;   // sizeof(ServedRegion) in the server's build
  std::atomic<std::int32_t> server_pid{0};
  std::atomic<std::int32_t> client_pid{0};  // 0: no client holds it
  std::atomic<std::uint32_t> serving{0};    // 1 while the server serves
  ServedIdentity identity;
  Seqlock<ServedState> state;
  Seqlock<ServedCommand> command;
};

static_assert(std::atomic<std::int32_t>::is_always_lock_free &&
                  std::atomic<std::uint32_t>::is_always_lock_free &&
                  std::atomic<std::uint64_t>::is_always_lock_free &&
                  std::atomic<unsigned>::is_always_lock_free,
              "a region shared between processes needs address-free atomics");

// "" when `name` can be served, else why not (names the rule it breaks).
std::string served_name_error(const std::string& name);

// "" when the bytes are a region of this build, else why not: not one
// (magic), another version (both named), another size. Reads only the
// header's first 16 bytes and never past `bytes`.
std::string region_header_error(const void* bytes, std::size_t size);

// Copies text into a fixed array, cut to fit and NUL-terminated.
template <std::size_t N>
void copy_text(char (&dst)[N], const std::string& text) {
  const std::size_t n = text.size() < N - 1 ? text.size() : N - 1;
  for (std::size_t i = 0; i < n; ++i) dst[i] = text[i];
  for (std::size_t i = n; i < N; ++i) dst[i] = '\0';
}
// The text of a fixed array, up to its first NUL or its end.
template <std::size_t N>
std::string text_of(const char (&src)[N]) {
  std::size_t n = 0;
  while (n < N && src[n] != '\0') ++n;
  return std::string(src, n);
}

// The server's rule for a command, pure: the torque to put on the motors
// at now_s and what became of the command. Zero, kNone, before the first
// write; zero, kStale, when the command is older than watchdog_s (the
// client stopped); zero, kStale, for a non-finite torque (a client that
// bypasses ServedDevice's check); else the command, kApplied.
Vec3 command_to_apply(const ServedCommand& c, double now_s, double watchdog_s,
                      CommandState* state) noexcept;

}  // namespace vmh::hw::served

#endif  // VMHAPTICS_HW_SERVED_SERVED_REGION_H_
