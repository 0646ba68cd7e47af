/* A C client of the open HD API on the native FireWire driver, over the
 * libraw1394 stand-in (tests/hw/firewire/fwsim/): the whole path a
 * program on a real Omni takes (hdInitDevice -> the firewire backend ->
 * Raw1394Transport -> "libraw1394" -> the bus), with the bus simulated.
 *
 * The stand-in is the library VMH_LIBRAW1394 names (set by ctest); this
 * client dlopens the same file, so it gets the same instance and so the
 * same bus, and drives it through fwsim.h's control functions: it
 * configures the bus, docks and undocks the stylus, and reads the command
 * packets the Omni node took.
 *
 * What the node sends is fixed (encoder counts, pot codes and buttons do
 * not move), so every value checked here is exact whatever the machine's
 * load; the wall clock only bounds how long the client waits for it (the
 * driver runs on the wall clock, as it does on a bus). Every expected value
 * is computed here from the documented conventions, not by the project's
 * decoder:
 *   angles    t_i = sign_i * 2 pi * count_i / 15000, signs (-1, -1, +1),
 *             offsets 0 until the stylus is docked (hw/omni_calibration.h,
 *             the nominal calibration), then the inkwell pose
 *   gimbal    t_j = gain_j * code_j / 2047 + offset_j (the drivers' lines)
 *   position  the Omni's closed form with l1 = l2 = 133.35 mm (docs/omni.md)
 *   torques   tau_i = F . dp/dt_i (virtual work, dp/dt by central
 *             differences of that closed form), mN m = N mm
 *   words     u = tau / (3.3 N * 0.13335 m), word = 0x7ff + round(u * 2048)
 *             above zero, 0x7ff + round(u * 2047) below (hw/firewire/
 *             omni_packet.h, firewire_omni.h); status 0x53c0, bit 3 motors on
 * Then the init errors through the stand-in: a bus with no Omni, a GUID
 * that is not on the bus, and lockstep asked of a real device. */
#include <HD/hd.h>

#include <dlfcn.h>
#include <math.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "tests/hw/firewire/fwsim/fwsim.h"

#include "hd_check.h"

/* -- the bus: fwsim.h's control functions, from the loaded stand-in -- */
static int (*fw_configure)(const char*);
static const char* (*fw_last_error)(void);
static int (*fw_get_node)(uint64_t, struct fwsim_node_info*);
static int (*fw_set_docked)(uint64_t, int);

static void* take(void* lib, const char* name) {
  void* p = dlsym(lib, name);
  if (p == NULL) {
    fprintf(stderr, "firewire_client: %s has no %s\n",
            getenv("VMH_LIBRAW1394"), name);
    exit(2);
  }
  return p;
}

#define OMNI_GUID 0x000b99000012abcdULL
#define OMNI_GUID_TEXT "000b99000012abcd"
#define WRONG_GUID_TEXT "000b9900deadbeef"
/* the drivers' packing of a serial "ABBCCDEEEEE" (bits 31 and 0 set): here
 * 1, 11, 22, 3, 444 */
#define SERIAL_QUADLET                                                     \
  (0x80000001u | (1u << 23) | (11u << 19) | (22u << 14) | (3u << 11) | \
   (444u << 1))
#define SERIAL_TEXT "11122300444"
static const int kCounts[3] = {300, -700, 250};
static const int kPots[3] = {1024, 900, 1200};

static const double kPi = 3.14159265358979323846;
static const double kL_mm = 133.35;
static const double kFullScale_Nm = 3.3 * 0.13335;
static const double kInkwell[3] = {0.0, -0.647, -0.477};

/* the Omni's wrist centre in the device frame, mm, t3 absolute */
static void omni_position(const double t[3], double p[3]) {
  const double r = kL_mm * cos(t[1]) + kL_mm * sin(t[2]);
  p[0] = -sin(t[0]) * r;
  p[1] = kL_mm - kL_mm * cos(t[2]) + kL_mm * sin(t[1]);
  p[2] = -kL_mm + cos(t[0]) * r;
}

/* motor torques (N m) for a force (N) at the wrist centre, by virtual work */
static void torques_for_force(const double t[3], const double f[3],
                              double tau[3]) {
  const double h = 1e-6;
  for (int i = 0; i < 3; ++i) {
    double a[3] = {t[0], t[1], t[2]}, b[3] = {t[0], t[1], t[2]};
    a[i] += h;
    b[i] -= h;
    double pa[3], pb[3];
    omni_position(a, pa);
    omni_position(b, pb);
    tau[i] = 0.0;
    for (int k = 0; k < 3; ++k) tau[i] += f[k] * (pa[k] - pb[k]) / (2 * h);
    tau[i] *= 1e-3; /* N mm -> N m */
  }
}

static int motor_word(double tau_Nm) {
  const double u = tau_Nm / kFullScale_Nm;
  return 0x7ff + (int)lround(u >= 0 ? u * 2048.0 : u * 2047.0);
}

static int le16(const uint8_t* p) { return p[0] | (p[1] << 8); }

static double now_s(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}


/* -- the servo callback: the command of the phase main asks for -- */
enum { kPhaseNone = 0, kPhaseForce, kPhaseJointTorque };
static _Atomic int g_phase = kPhaseNone;
static _Atomic long g_ticks = 0;
static _Atomic long g_comm_errors = 0; /* a starved servo thread on a loaded host */
static _Atomic long g_velocity_errors = 0; /* the re-homing jump when docked */
static _Atomic int g_other_error = 0;  /* anything but those and the impulse limit */
static const double kForce_N[3] = {0.5, 0.3, -0.4};
static const double kJointTorque_mNm[3] = {60.0, -80.0, 40.0};

static HDCallbackCode HDCALLBACK servo(void* user) {
  const HHD h = *(const HHD*)user;
  hdBeginFrame(h);
  switch (atomic_load(&g_phase)) {
    case kPhaseForce: hdSetDoublev(HD_CURRENT_FORCE, kForce_N); break;
    case kPhaseJointTorque: hdSetDoublev(HD_CURRENT_JOINT_TORQUE, kJointTorque_mNm); break;
    default: break;
  }
  hdEndFrame(h);
  for (HDErrorInfo e = hdGetError(); HD_DEVICE_ERROR(e); e = hdGetError()) {
    if (e.errorCode == HD_COMM_ERROR) {
      atomic_fetch_add(&g_comm_errors, 1);
    } else if (e.errorCode == HD_EXCEEDED_MAX_VELOCITY) {
      atomic_fetch_add(&g_velocity_errors, 1);
    } else if (e.errorCode != HD_EXCEEDED_MAX_FORCE_IMPULSE) {
      atomic_store(&g_other_error, (int)e.errorCode);
    }
  }
  atomic_fetch_add(&g_ticks, 1);
  return HD_CALLBACK_CONTINUE;
}

/* -- a copy of one frame's state, taken in a synchronous callback -- */
struct Snapshot {
  HHD h;
  HDlong encoders[6];
  double joints[3], gimbal[3], position[3], transform[16];
  double force[3];
  HDint buttons;
  HDboolean inkwell;
};
static HDCallbackCode HDCALLBACK snapshot(void* user) {
  struct Snapshot* s = (struct Snapshot*)user;
  hdBeginFrame(s->h);
  hdGetLongv(HD_CURRENT_ENCODER_VALUES, s->encoders);
  hdGetDoublev(HD_CURRENT_JOINT_ANGLES, s->joints);
  hdGetDoublev(HD_CURRENT_GIMBAL_ANGLES, s->gimbal);
  hdGetDoublev(HD_CURRENT_POSITION, s->position);
  hdGetDoublev(HD_CURRENT_TRANSFORM, s->transform);
  hdGetDoublev(HD_LAST_FORCE, s->force);
  hdGetIntegerv(HD_CURRENT_BUTTONS, &s->buttons);
  hdGetBooleanv(HD_CURRENT_INKWELL_SWITCH, &s->inkwell);
  hdEndFrame(s->h);
  return HD_CALLBACK_DONE;
}

/* waits (up to `limit_s` of wall time: a bound, never a figure) until the
 * frame's encoders read the counts the node sends and `inkwell` is as
 * asked; returns the last snapshot */
static int wait_for_frame(HHD h, HDboolean inkwell, double limit_s,
                          struct Snapshot* out) {
  const double t0 = now_s();
  do {
    memset(out, 0, sizeof *out);
    out->h = h;
    hdScheduleSynchronous(snapshot, out, HD_DEFAULT_SCHEDULER_PRIORITY);
    int ok = out->inkwell == inkwell;
    for (int i = 0; i < 3; ++i) {
      ok = ok && out->encoders[i] == kCounts[i] && out->encoders[3 + i] == kPots[i];
    }
    if (ok) return 1;
    usleep(2000);
  } while (now_s() - t0 < limit_s);
  return 0;
}

/* waits until the node's last command is `want` (three words, each within
 * one word) with status `status`; returns the node's state then */
static int wait_for_command(const int want[3], int status, double limit_s,
                            struct fwsim_node_info* node) {
  const double t0 = now_s();
  do {
    memset(node, 0, sizeof *node);
    if (fw_get_node(OMNI_GUID, node) == 0 && node->commands > 0) {
      int ok = le16(node->last_command + 6) == status;
      for (int i = 0; i < 3; ++i) {
        ok = ok && abs(le16(node->last_command + 2 * i) - want[i]) <= 1;
      }
      if (ok) return 1;
    }
    usleep(2000);
  } while (now_s() - t0 < limit_s);
  return 0;
}

static void check_init_error(const char* name, int internal, const char* const* words) {
  pop_errors();
  const HHD bad = hdInitDevice(name);
  CHECK(bad == HD_INVALID_HANDLE, "%s: handle %u", name ? name : "(default)", bad);
  const HDErrorInfo e = hdGetError();
  CHECK(e.errorCode == HD_COMM_CONFIG_ERROR, "%s: code 0x%x", name ? name : "(default)",
        e.errorCode);
  CHECK(e.internalErrorCode == internal, "%s: internal %d, expected %d",
        name ? name : "(default)", e.internalErrorCode, internal);
  const char* why = hdGetErrorString(e.errorCode);
  CHECK(why != NULL && strchr(why, '\n') == NULL, "one line: %s", why ? why : "(null)");
  CHECK(why != NULL && strncmp(why, "the device could not be opened: ", 32) == 0,
        "the code's meaning first: %s", why ? why : "(null)");
  for (int i = 0; words[i] != NULL; ++i) {
    CHECK(why != NULL && strstr(why, words[i]) != NULL, "the cause names '%s': %s",
          words[i], why ? why : "(null)");
  }
  CHECK(hdGetError().errorCode == HD_SUCCESS, "no stale error after %s",
        name ? name : "(default)");
  printf("  init error: %s\n", why ? why : "(null)");
}

int main(void) {
  const char* lib_file = getenv("VMH_LIBRAW1394");
  if (lib_file == NULL || *lib_file == '\0') {
    fprintf(stderr, "firewire_client: VMH_LIBRAW1394 must name the fwsim stand-in\n");
    return 2;
  }
  const char* clock = getenv("VMH_HD_CLOCK");
  if (clock != NULL && strcmp(clock, "lockstep") == 0) {
    fprintf(stderr, "firewire_client: a device on a bus runs on the wall clock; "
                    "unset VMH_HD_CLOCK\n");
    return 2;
  }
  /* the same file the transport loads: the same instance, the same bus */
  void* lib = dlopen(lib_file, RTLD_NOW | RTLD_LOCAL);
  if (lib == NULL) {
    fprintf(stderr, "firewire_client: %s\n", dlerror());
    return 2;
  }
  *(void**)&fw_configure = take(lib, "fwsim_configure");
  *(void**)&fw_last_error = take(lib, "fwsim_last_error");
  *(void**)&fw_get_node = take(lib, "fwsim_get_node");
  *(void**)&fw_set_docked = take(lib, "fwsim_set_docked");

  /* names beside the default device (VMH_HD_DEVICE=firewire) */
  char dir[] = "/tmp/vmhd_fw_client_XXXXXX";
  if (mkdtemp(dir) == NULL) return 2;
  char conf[256];
  snprintf(conf, sizeof conf, "%s/hd.conf", dir);
  FILE* fc = fopen(conf, "w");
  if (fc == NULL) return 2;
  fprintf(fc, "# written by firewire_client\n"
              "WrongGuid = firewire:" WRONG_GUID_TEXT "\n");
  fclose(fc);
  setenv("VMH_HD_CONFIG", conf, 1);
  setenv("VMH_HD_QUIET", "1", 1);
  const char* dev = getenv("VMH_HD_DEVICE");
  CHECK(dev != NULL && strncmp(dev, "firewire", 8) == 0,
        "VMH_HD_DEVICE=firewire expected, is %s", dev ? dev : "(unset)");

  /* -- init errors through the stand-in -- */
  printf("init errors:\n");
  /* a bus whose only node is not an Omni */
  CHECK(fw_configure("clock=wall;node=0000aa0000c0ffee") == 0, "%s", fw_last_error());
  {
    const char* words[] = {"HD_DEFAULT_DEVICE", "'firewire", "no PHANTOM Omni", NULL};
    check_init_error(HD_DEFAULT_DEVICE, 4, words);
  }
  /* the Omni, and a name whose GUID is not on the bus */
  char bus[512];
  snprintf(bus, sizeof bus,
           "clock=wall;omni=%s,rate=1000,counts=%d/%d/%d,pots=%d/%d/%d,"
           "buttons=1,docked=0,serial=%08x;node=0000aa0000c0ffee",
           OMNI_GUID_TEXT, kCounts[0], kCounts[1], kCounts[2], kPots[0], kPots[1],
           kPots[2], SERIAL_QUADLET);
  CHECK(fw_configure(bus) == 0, "%s", fw_last_error());
  {
    const char* words[] = {"WrongGuid", WRONG_GUID_TEXT, OMNI_GUID_TEXT, NULL};
    check_init_error("WrongGuid", 4, words);
  }
  /* lockstep is for simulated devices */
  setenv("VMH_HD_CLOCK", "lockstep", 1);
  {
    const char* words[] = {"lockstep", "simulated", NULL};
    check_init_error(HD_DEFAULT_DEVICE, 3, words);
  }
  unsetenv("VMH_HD_CLOCK");
  struct fwsim_node_info node;
  CHECK(fw_get_node(OMNI_GUID, &node) == 0 && !node.streaming,
        "a refused open leaves the node quiet");

  /* -- the device -- */
  pop_errors();
  HHD h = hdInitDevice(HD_DEFAULT_DEVICE);
  CHECK(h != HD_INVALID_HANDLE, "firewire: %s", hdGetErrorString(hdGetError().errorCode));
  if (h == HD_INVALID_HANDLE) return 1;
  hdMakeCurrentDevice(h);

  const char* model = hdGetString(HD_DEVICE_MODEL_TYPE);
  const char* vendor = hdGetString(HD_DEVICE_VENDOR);
  const char* serial = hdGetString(HD_DEVICE_SERIAL_NUMBER);
  const char* driver = hdGetString(HD_DEVICE_DRIVER_VERSION);
  CHECK(model && strcmp(model, "PHANTOM Omni") == 0, "model %s", model);
  CHECK(vendor && strcmp(vendor, "SensAble Technologies") == 0,
        "vendor (from the node's vendor quadlet 0x000b9900) %s", vendor);
  CHECK(serial && strcmp(serial, SERIAL_TEXT) == 0, "serial (quadlet 0x%08x) %s",
        SERIAL_QUADLET, serial);
  CHECK(driver && strstr(driver, "firewire") && strstr(driver, lib_file),
        "driver names the backend and the libraw1394 loaded: %s", driver);
  CHECK(pop_errors() == HD_SUCCESS, "identification raised nothing");
  printf("identification: model '%s', vendor '%s', serial '%s', driver '%s'\n", model,
         vendor, serial, driver);
  HDint style = 0;
  hdGetIntegerv(HD_CALIBRATION_STYLE, &style);
  CHECK(style == HD_CALIBRATION_INKWELL, "calibration style 0x%x", style);
  CHECK(hdCheckCalibration() == HD_CALIBRATION_NEEDS_UPDATE,
        "no stored calibration (XDG_CONFIG_HOME is empty): needs an update");

  /* -- the stream -- */
  HDSchedulerHandle servo_handle =
      hdScheduleAsynchronous(servo, &h, HD_DEFAULT_SCHEDULER_PRIORITY);
  hdStartScheduler();
  CHECK(pop_errors() == HD_SUCCESS, "start");
  struct Snapshot s;
  CHECK(wait_for_frame(h, HD_TRUE, 10.0, &s), "the node's counts (%ld %ld %ld, %ld %ld %ld)",
        s.encoders[0], s.encoders[1], s.encoders[2], s.encoders[3], s.encoders[4],
        s.encoders[5]);
  CHECK(fw_get_node(OMNI_GUID, &node) == 0 && node.streaming, "streaming");
  CHECK(node.reg_control & 0x08, "0x1087 bit 3 set: 0x%02x", node.reg_control);
  for (int i = 0; i < 3; ++i) {
    CHECK(node.encoder_counts[i] == kCounts[i], "the node sends count %d: %d", kCounts[i],
          node.encoder_counts[i]);
  }
  double t[3];
  const int sign[3] = {-1, -1, +1};
  const double gain[3] = {5.48, -5.28, 4.76}, offset[3] = {-2.74, 2.64, -2.38};
  for (int i = 0; i < 3; ++i) {
    t[i] = sign[i] * 2 * kPi * kCounts[i] / 15000.0;
    CHECK(fabs(s.joints[i] - t[i]) < 1e-12, "t%d %.15g, expected %.15g", i + 1,
          s.joints[i], t[i]);
    const double g = gain[i] * kPots[i] / 2047.0 + offset[i];
    CHECK(fabs(s.gimbal[i] - g) < 1e-12, "t%d %.15g, expected %.15g", i + 4, s.gimbal[i], g);
  }
  double p[3];
  omni_position(t, p);
  for (int i = 0; i < 3; ++i) {
    CHECK(fabs(s.position[i] - p[i]) < 1e-9, "position %d %.12g mm, expected %.12g", i,
          s.position[i], p[i]);
    CHECK(s.transform[12 + i] == s.position[i], "transform column 4");
  }
  CHECK(s.buttons == 1, "button 1 held: %d", s.buttons);
  printf("state: counts %ld %ld %ld pots %ld %ld %ld -> t %.6f %.6f %.6f rad, "
         "gimbal %.6f %.6f %.6f rad, position %.4f %.4f %.4f mm\n",
         s.encoders[0], s.encoders[1], s.encoders[2], s.encoders[3], s.encoders[4],
         s.encoders[5], s.joints[0], s.joints[1], s.joints[2], s.gimbal[0], s.gimbal[1],
         s.gimbal[2], s.position[0], s.position[1], s.position[2]);

  /* a force at the wrist centre: the motor words the node took */
  double tau[3];
  int want[3];
  torques_for_force(t, kForce_N, tau);
  for (int i = 0; i < 3; ++i) want[i] = motor_word(tau[i]);
  atomic_store(&g_phase, kPhaseForce);
  CHECK(wait_for_command(want, 0x53c8, 10.0, &node),
        "force (%g %g %g) N: words %03x %03x %03x (status %04x), expected %03x %03x "
        "%03x (%04x)",
        kForce_N[0], kForce_N[1], kForce_N[2], le16(node.last_command),
        le16(node.last_command + 2), le16(node.last_command + 4),
        le16(node.last_command + 6), want[0], want[1], want[2], 0x53c8);
  for (int i = 0; i < 3; ++i) {
    const int w = le16(node.last_command + 2 * i) - 0x7ff;
    CHECK((w > 0) == (tau[i] > 0) && w != 0, "motor %d: word %+d for %g N m", i + 1, w,
          tau[i]);
  }
  printf("force (%g, %g, %g) N -> tau %.5f %.5f %.5f N m -> words 0x%03x 0x%03x 0x%03x "
         "(expected 0x%03x 0x%03x 0x%03x)\n",
         kForce_N[0], kForce_N[1], kForce_N[2], tau[0], tau[1], tau[2],
         le16(node.last_command), le16(node.last_command + 2), le16(node.last_command + 4),
         want[0], want[1], want[2]);
  hdScheduleSynchronous(snapshot, &s, HD_DEFAULT_SCHEDULER_PRIORITY);
  for (int i = 0; i < 3; ++i) {
    CHECK(s.force[i] == kForce_N[i], "LAST_FORCE %d %g", i, s.force[i]);
  }

  /* joint torques: the words from the documented full scale alone */
  for (int i = 0; i < 3; ++i) want[i] = motor_word(kJointTorque_mNm[i] * 1e-3);
  atomic_store(&g_phase, kPhaseJointTorque);
  CHECK(wait_for_command(want, 0x53c8, 10.0, &node),
        "joint torque: words %03x %03x %03x, expected %03x %03x %03x",
        le16(node.last_command), le16(node.last_command + 2), le16(node.last_command + 4),
        want[0], want[1], want[2]);
  printf("joint torque (%g, %g, %g) mN m -> words 0x%03x 0x%03x 0x%03x (expected "
         "0x%03x 0x%03x 0x%03x)\n",
         kJointTorque_mNm[0], kJointTorque_mNm[1], kJointTorque_mNm[2],
         le16(node.last_command), le16(node.last_command + 2), le16(node.last_command + 4),
         want[0], want[1], want[2]);

  /* docked: the switch, re-homing to the inkwell pose, the force cut. The
   * counts do not move, so re-homing moves the angles from the pose above
   * to the inkwell's in one tick: the velocity limit speaks then, and only
   * then (a real stylus is in the inkwell pose when it docks) */
  CHECK(atomic_load(&g_velocity_errors) == 0, "velocity errors before docking: %ld",
        atomic_load(&g_velocity_errors));
  CHECK(fw_set_docked(OMNI_GUID, 1) == 0, "dock");
  CHECK(wait_for_frame(h, HD_FALSE, 10.0, &s), "docked: inkwell switch %d", s.inkwell);
  const int zero[3] = {0x7ff, 0x7ff, 0x7ff};
  CHECK(wait_for_command(zero, 0x53c8, 10.0, &node), "docked: zero words, %03x %03x %03x",
        le16(node.last_command), le16(node.last_command + 2), le16(node.last_command + 4));
  CHECK(fw_set_docked(OMNI_GUID, 0) == 0, "undock");
  CHECK(wait_for_frame(h, HD_TRUE, 10.0, &s), "undocked");
  for (int i = 0; i < 3; ++i) {
    CHECK(fabs(s.joints[i] - kInkwell[i]) < 1e-12,
          "re-homed: the same counts read t%d = %.15g, the inkwell's %.15g", i + 1,
          s.joints[i], kInkwell[i]);
  }
  CHECK(s.encoders[0] == kCounts[0], "the counts unchanged by re-homing");
  omni_position(kInkwell, p);
  printf("re-homed at the inkwell: t %.6f %.6f %.6f rad, position %.3f %.3f %.3f mm "
         "(closed form %.3f %.3f %.3f)\n",
         s.joints[0], s.joints[1], s.joints[2], s.position[0], s.position[1],
         s.position[2], p[0], p[1], p[2]);
  for (int i = 0; i < 3; ++i) {
    CHECK(fabs(s.position[i] - p[i]) < 1e-9, "inkwell position %d", i);
  }

  /* a force again, then the device disabled with the scheduler running */
  torques_for_force(kInkwell, kForce_N, tau);
  for (int i = 0; i < 3; ++i) want[i] = motor_word(tau[i]);
  atomic_store(&g_phase, kPhaseForce);
  CHECK(wait_for_command(want, 0x53c8, 10.0, &node),
        "force at the inkwell pose: words %03x %03x %03x, expected %03x %03x %03x",
        le16(node.last_command), le16(node.last_command + 2), le16(node.last_command + 4),
        want[0], want[1], want[2]);
  const long ticks = atomic_load(&g_ticks);
  hdDisableDevice(h);
  CHECK(pop_errors() == HD_SUCCESS, "disable");
  CHECK(fw_get_node(OMNI_GUID, &node) == 0, "node");
  for (int i = 0; i < 3; ++i) {
    CHECK(le16(node.last_command + 2 * i) == 0x7ff, "after disable motor %d word 0x%03x",
          i + 1, le16(node.last_command + 2 * i));
  }
  CHECK(le16(node.last_command + 6) == 0x53c0, "after disable the motors are off: 0x%04x",
        le16(node.last_command + 6));
  CHECK(!node.streaming && (node.reg_control & 0x08) == 0,
        "after disable the node stopped streaming (0x1087 0x%02x)", node.reg_control);
  const uint64_t commands = node.commands;
  usleep(50000);
  CHECK(fw_get_node(OMNI_GUID, &node) == 0 && node.commands == commands,
        "nothing sent after disable (%llu then %llu)", (unsigned long long)commands,
        (unsigned long long)node.commands);
  printf("disabled after %ld ticks: last command %03x %03x %03x status %04x, "
         "%llu commands taken, %ld communication errors on the way\n",
         ticks, le16(node.last_command), le16(node.last_command + 2),
         le16(node.last_command + 4), le16(node.last_command + 6),
         (unsigned long long)node.commands, atomic_load(&g_comm_errors));
  CHECK(atomic_load(&g_other_error) == HD_SUCCESS, "a tick raised 0x%x",
        atomic_load(&g_other_error));
  hdMakeCurrentDevice(h);
  CHECK(pop_errors() == HD_BAD_HANDLE, "the disabled handle");
  hdUnschedule(servo_handle);
  pop_errors();

  unlink(conf);
  rmdir(dir);
  printf("firewire_client: %d checks, %d failed\n", g_checks, g_failed);
  return g_failed == 0 ? 0 : 1;
}
