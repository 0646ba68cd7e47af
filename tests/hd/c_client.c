/* A C client of the open HD API, written against the project's own
 * include/HD/hd.h as a stranger's program would be: every device, state,
 * error, scheduler and calibration call, every CURRENT and LAST parameter
 * an Omni has, two devices, and the init errors. Run by ctest on the
 * emulator in lockstep (VMH_HD_CLOCK=lockstep), with a configuration file
 * it writes itself (VMH_HD_CONFIG). Prints each failed check and exits 1
 * if any failed. */
#include <HD/hd.h>
#include <HDU/hduError.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "hd_check.h"


/* -- what the servo callback sees, written on the scheduler thread -- */
struct Servo {
  HHD h;
  long frames;
  double start_mm[3];
  double position_mm[3];
  double prev_position_mm[3];
  double transform[16];
  double last_position_mm[3];
  double set_force_N[3];
  double read_force_N[3];
  double last_force_N[3];
  double prev_force_N[3];
  double last_joint_torque_mNm[3];
  double joints_rad[3], gimbal_rad[3], last_joints_rad[3], prev_joints_rad[3];
  double velocity_mm_s[3], angular_velocity[3], jacobian[36];
  double temperature[6], references_rad[6];
  HDlong encoders[6], start_encoders[6];
  double start_joints_rad[3];
  HDint buttons, rate_Hz;
  HDboolean inkwell, safety;
  double timestamp_s;
  HDerror frame_error;       /* an error raised by a state call in a frame */
  HDerror illegal_end;       /* what an unmatched hdEndFrame raised */
  HDerror mismatches;        /* LAST_ that did not equal the previous frame */
  int order[4];
  int n_order;
};
static struct Servo g_s;

static HDCallbackCode HDCALLBACK servo(void* user) {
  struct Servo* s = (struct Servo*)user;
  hdBeginFrame(s->h);
  hdBeginFrame(s->h); /* nested: shares the frame */
  hdGetDoublev(HD_CURRENT_POSITION, s->position_mm);
  hdGetDoublev(HD_CURRENT_TRANSFORM, s->transform);
  hdGetDoublev(HD_LAST_POSITION, s->last_position_mm);
  hdGetDoublev(HD_CURRENT_JOINT_ANGLES, s->joints_rad);
  hdGetDoublev(HD_LAST_JOINT_ANGLES, s->last_joints_rad);
  hdGetDoublev(HD_CURRENT_GIMBAL_ANGLES, s->gimbal_rad);
  hdGetDoublev(HD_CURRENT_VELOCITY, s->velocity_mm_s);
  hdGetDoublev(HD_CURRENT_ANGULAR_VELOCITY, s->angular_velocity);
  hdGetDoublev(HD_CURRENT_JACOBIAN, s->jacobian);
  hdGetDoublev(HD_MOTOR_TEMPERATURE, s->temperature);
  hdGetDoublev(HD_JOINT_ANGLE_REFERENCES, s->references_rad);
  hdGetLongv(HD_CURRENT_ENCODER_VALUES, s->encoders);
  hdGetIntegerv(HD_CURRENT_BUTTONS, &s->buttons);
  hdGetIntegerv(HD_INSTANTANEOUS_UPDATE_RATE, &s->rate_Hz);
  hdGetBooleanv(HD_CURRENT_INKWELL_SWITCH, &s->inkwell);
  hdGetBooleanv(HD_CURRENT_SAFETY_SWITCH, &s->safety);
  hdGetDoublev(HD_LAST_FORCE, s->last_force_N);
  hdGetDoublev(HD_LAST_JOINT_TORQUE, s->last_joint_torque_mNm);
  if (s->frames > 0) {
    for (int i = 0; i < 3; ++i) {
      if (s->last_position_mm[i] != s->prev_position_mm[i] ||
          s->last_joints_rad[i] != s->prev_joints_rad[i] ||
          s->last_force_N[i] != s->prev_force_N[i]) {
        if (s->mismatches == 0) {
          fprintf(stderr, "frame %ld axis %d: LAST_POSITION %g vs %g, LAST_JOINT %g vs %g, LAST_FORCE %g vs %g\n",
                  s->frames, i, s->last_position_mm[i], s->prev_position_mm[i],
                  s->last_joints_rad[i], s->prev_joints_rad[i], s->last_force_N[i], s->prev_force_N[i]);
        }
        ++s->mismatches;
      }
    }
  } else {
    memcpy(s->start_mm, s->position_mm, sizeof s->start_mm);
    memcpy(s->start_encoders, s->encoders, sizeof s->start_encoders);
    memcpy(s->start_joints_rad, s->joints_rad, sizeof s->start_joints_rad);
  }
  /* 0.6 N along +x of the device frame for the first 300 frames */
  const double f[3] = {s->frames < 300 ? 0.6 : 0.0, 0.0, 0.0};
  hdSetDoublev(HD_CURRENT_FORCE, f);
  hdGetDoublev(HD_CURRENT_FORCE, s->read_force_N);
  const double tau[3] = {0.0, 0.0, 0.0};
  hdSetDoublev(HD_CURRENT_JOINT_TORQUE, tau);
  hdSetDoublev(HD_CURRENT_GIMBAL_TORQUE, tau);
  hdSetDoublev(HD_CURRENT_TORQUE, tau); /* deprecated, still accepted */
  const HDlong dac[3] = {0, 0, 0};
  hdSetLongv(HD_CURRENT_MOTOR_DAC_VALUES, dac);
  s->timestamp_s = hdGetSchedulerTimeStamp();
  hdEndFrame(s->h);
  hdEndFrame(s->h);
  HDErrorInfo e = hdGetError();
  /* the impulse limit may speak at the force's onset; anything else is a
   * failure */
  while (HD_DEVICE_ERROR(e)) {
    if (!hduIsForceError(&e)) s->frame_error = e.errorCode;
    e = hdGetError();
  }
  memcpy(s->prev_position_mm, s->position_mm, sizeof s->position_mm);
  memcpy(s->prev_joints_rad, s->joints_rad, sizeof s->joints_rad);
  memcpy(s->prev_force_N, s->read_force_N, sizeof s->read_force_N);
  ++s->frames;
  return HD_CALLBACK_CONTINUE;
}

static HDCallbackCode HDCALLBACK unmatched_end(void* user) {
  struct Servo* s = (struct Servo*)user;
  hdEndFrame(s->h);
  s->illegal_end = hdGetError().errorCode;
  pop_errors();
  return HD_CALLBACK_DONE;
}

static HDCallbackCode HDCALLBACK low(void* user) {
  struct Servo* s = (struct Servo*)user;
  if (s->n_order < 4) s->order[s->n_order++] = 1;
  return HD_CALLBACK_DONE;
}
static HDCallbackCode HDCALLBACK high(void* user) {
  struct Servo* s = (struct Servo*)user;
  if (s->n_order < 4) s->order[s->n_order++] = 2;
  return HD_CALLBACK_DONE;
}

struct Copy {
  double position_mm[3];
  int ran;
};
static HDCallbackCode HDCALLBACK copy_state(void* user) {
  struct Copy* c = (struct Copy*)user;
  hdBeginFrame(hdGetCurrentDevice());
  hdGetDoublev(HD_CURRENT_POSITION, c->position_mm);
  hdEndFrame(hdGetCurrentDevice());
  c->ran = 1;
  return HD_CALLBACK_DONE;
}

static int near(double a, double b, double tol) { return fabs(a - b) <= tol; }

int main(void) {
  /* the configuration: a second device under the name clients use */
  char dir[] = "/tmp/vmhd_c_client_XXXXXX";
  CHECK(mkdtemp(dir) != NULL, "mkdtemp");
  char conf[256];
  snprintf(conf, sizeof conf, "%s/hd.conf", dir);
  FILE* fc = fopen(conf, "w");
  CHECK(fc != NULL, "cannot write %s", conf);
  fprintf(fc, "# written by c_client\nPhantom2 = emulator:case2?hand=none\n");
  fclose(fc);
  setenv("VMH_HD_CONFIG", conf, 1);
  setenv("VMH_HD_CLOCK", "lockstep", 1);
  setenv("VMH_HD_QUIET", "1", 1);

  /* -- before any device -- */
  CHECK(hdGetCurrentDevice() == HD_INVALID_HANDLE, "no device yet");
  CHECK(pop_errors() == HD_BAD_HANDLE, "BAD_HANDLE before init");
  CHECK(hdGetError().errorCode == HD_SUCCESS, "the error was popped");

  /* -- init errors -- */
  HHD bad = hdInitDevice("No Such Omni");
  CHECK(bad == HD_INVALID_HANDLE, "unknown name");
  HDErrorInfo e = hdGetError();
  CHECK(e.errorCode == HD_COMM_CONFIG_ERROR, "code 0x%x", e.errorCode);
  CHECK(e.internalErrorCode == 1, "internal %d", e.internalErrorCode);
  const char* why = hdGetErrorString(e.errorCode);
  CHECK(why != NULL && strstr(why, "No Such Omni") && strstr(why, "Phantom2"),
        "the cause names the name and what is configured: %s", why ? why : "(null)");
  CHECK(hdGetError().errorCode == HD_SUCCESS, "no stale error");
  FILE* sink = tmpfile();
  hduPrintError(sink, &e, "init: ");
  CHECK(ftell(sink) > 10, "hduPrintError wrote");
  fclose(sink);
  /* a communication error stops the scheduler's work */
  CHECK(hduIsSchedulerError(&e) && hduIsCommError(&e) && !hduIsForceError(&e),
        "hdu classifies");

  /* -- two devices -- */
  HHD h = hdInitDevice(HD_DEFAULT_DEVICE);
  CHECK(h != HD_INVALID_HANDLE, "default device: %s",
        hdGetErrorString(hdGetError().errorCode));
  CHECK(hdGetCurrentDevice() == h, "current after init");
  HHD again = hdInitDevice("Default PHANToM");
  CHECK(again == HD_INVALID_HANDLE, "the same device twice");
  CHECK(pop_errors() == HD_DEVICE_ALREADY_INITIATED, "already initiated");
  HHD h2 = hdInitDevice("Phantom2");
  CHECK(h2 != HD_INVALID_HANDLE && h2 != h, "second device %u", h2);
  CHECK(pop_errors() == HD_SUCCESS, "no errors opening two devices");
  hdMakeCurrentDevice(h);
  CHECK(hdGetCurrentDevice() == h, "make current");
  hdMakeCurrentDevice(77);
  CHECK(pop_errors() == HD_BAD_HANDLE, "bad handle");

  /* -- identification and figures -- */
  const HDenum strings[] = {HD_VERSION, HD_DEVICE_MODEL_TYPE,
                            HD_DEVICE_DRIVER_VERSION, HD_DEVICE_VENDOR,
                            HD_DEVICE_SERIAL_NUMBER, HD_DEVICE_FIRMWARE_VERSION};
  for (int i = 0; i < 6; ++i) {
    CHECK(hdGetString(strings[i]) != NULL, "string 0x%x", strings[i]);
  }
  CHECK(strstr(hdGetString(HD_DEVICE_MODEL_TYPE), "Omni") != NULL, "model");
  CHECK(pop_errors() == HD_SUCCESS, "strings raise nothing");
  CHECK(hdGetString(HD_CURRENT_POSITION) == NULL, "not a string");
  CHECK(pop_errors() == HD_INVALID_INPUT_TYPE, "INVALID_INPUT_TYPE");
  HDint dof_in = 0, dof_out = 0, rate = 0, style = 0;
  hdGetIntegerv(HD_INPUT_DOF, &dof_in);
  hdGetIntegerv(HD_OUTPUT_DOF, &dof_out);
  hdGetIntegerv(HD_UPDATE_RATE, &rate);
  hdGetIntegerv(HD_CALIBRATION_STYLE, &style);
  CHECK(dof_in == 6 && dof_out == 3, "dof %d %d", dof_in, dof_out);
  CHECK(rate == 1000, "rate %d", rate);
  CHECK(style != 0, "calibration style");
  double v = 0, ws[6] = {0}, us[6] = {0};
  hdGetDoublev(HD_NOMINAL_MAX_FORCE, &v);
  CHECK(near(v, 3.3, 1e-12), "max force %g", v);
  hdGetDoublev(HD_NOMINAL_MAX_CONTINUOUS_FORCE, &v);
  CHECK(near(v, 0.88, 1e-12), "continuous force %g", v);
  hdGetDoublev(HD_NOMINAL_MAX_STIFFNESS, &v);
  CHECK(v > 0, "stiffness %g", v);
  hdGetDoublev(HD_NOMINAL_MAX_DAMPING, &v);
  CHECK(v > 0, "damping %g", v);
  hdGetDoublev(HD_MAX_WORKSPACE_DIMENSIONS, ws);
  hdGetDoublev(HD_USABLE_WORKSPACE_DIMENSIONS, us);
  for (int i = 0; i < 3; ++i) {
    CHECK(ws[i] < us[i] && us[i] < us[i + 3] && us[i + 3] < ws[i + 3],
          "workspace axis %d", i);
  }
  hdGetDoublev(HD_TABLETOP_OFFSET, &v);
  hdGetDoublev(HD_NOMINAL_MAX_TORQUE_STIFFNESS, &v);
  hdGetDoublev(HD_NOMINAL_MAX_TORQUE_DAMPING, &v);
  hdGetDoublev(HD_NOMINAL_MAX_TORQUE_FORCE, &v);
  hdGetDoublev(HD_NOMINAL_MAX_TORQUE_CONTINUOUS_FORCE, &v);
  float fv = 0;
  hdGetFloatv(HD_NOMINAL_MAX_FORCE, &fv);
  CHECK(near(fv, 3.3, 1e-6), "float getter %g", fv);
  CHECK(pop_errors() == HD_SUCCESS, "figures raise nothing");
  hdGetDoublev(0x2fff, &v);
  CHECK(pop_errors() == HD_INVALID_ENUM, "unknown parameter");

  /* -- capabilities and limits -- */
  const HDenum caps[] = {HD_FORCE_OUTPUT, HD_MAX_FORCE_CLAMPING,
                         HD_FORCE_RAMPING, HD_SOFTWARE_FORCE_LIMIT,
                         HD_ONE_FRAME_LIMIT, HD_SOFTWARE_VELOCITY_LIMIT,
                         HD_SOFTWARE_FORCE_IMPULSE_LIMIT};
  for (int i = 0; i < 7; ++i) {
    hdEnable(caps[i]);
    CHECK(hdIsEnabled(caps[i]) == HD_TRUE, "enable 0x%x", caps[i]);
    hdDisable(caps[i]);
    CHECK(hdIsEnabled(caps[i]) == HD_FALSE, "disable 0x%x", caps[i]);
  }
  hdEnable(HD_FORCE_OUTPUT);
  hdEnable(HD_MAX_FORCE_CLAMPING);
  hdEnable(HD_SOFTWARE_VELOCITY_LIMIT);
  hdEnable(HD_SOFTWARE_FORCE_IMPULSE_LIMIT);
  hdEnable(0x4999);
  CHECK(pop_errors() == HD_INVALID_ENUM, "unknown capability");
  const double vel = 1200.0, ramp = 4.0, impulse = 0.2;
  hdSetDoublev(HD_SOFTWARE_VELOCITY_LIMIT, &vel);
  hdSetDoublev(HD_FORCE_RAMPING_RATE, &ramp);
  hdSetDoublev(HD_SOFTWARE_FORCE_IMPULSE_LIMIT, &impulse);
  hdGetDoublev(HD_SOFTWARE_VELOCITY_LIMIT, &v);
  CHECK(v == vel, "velocity limit %g", v);
  hdGetDoublev(HD_FORCE_RAMPING_RATE, &v);
  CHECK(v == ramp, "ramp rate %g", v);
  hdGetDoublev(HD_SOFTWARE_FORCE_IMPULSE_LIMIT, &v);
  CHECK(v == impulse, "impulse %g", v);
  const double negative = -1.0;
  hdSetDoublev(HD_SOFTWARE_VELOCITY_LIMIT, &negative);
  CHECK(pop_errors() == HD_INVALID_VALUE, "a negative limit");
  const double pos[3] = {1, 2, 3};
  hdSetDoublev(HD_CURRENT_POSITION, pos);
  CHECK(pop_errors() == HD_INVALID_OPERATION, "state is read-only");
  const double force[3] = {1, 0, 0};
  hdSetDoublev(HD_CURRENT_FORCE, force);
  CHECK(pop_errors() == HD_INVALID_OPERATION, "a force outside the scheduler");
  const HDint light = LED_STATUS_SOLID_GRN;
  hdSetIntegerv(HD_USER_STATUS_LIGHT, &light);
  HDint light_back = -1;
  hdGetIntegerv(HD_USER_STATUS_LIGHT, &light_back);
  CHECK(light_back == light, "status light %d", light_back);

  /* -- calibration -- */
  CHECK(hdCheckCalibration() == HD_CALIBRATION_OK, "calibration");
  hdUpdateCalibration(HD_CALIBRATION_INKWELL);
  CHECK(pop_errors() == HD_SUCCESS, "update calibration");
  hdUpdateCalibration(0x77);
  CHECK(pop_errors() == HD_INVALID_VALUE, "bad style");

  /* -- the scheduler -- */
  struct Copy before = {{0, 0, 0}, 0};
  hdScheduleSynchronous(copy_state, &before, HD_DEFAULT_SCHEDULER_PRIORITY);
  CHECK(before.ran == 1, "a synchronous call with no scheduler runs here");
  hdSetSchedulerRate(1000);
  CHECK(pop_errors() == HD_SUCCESS, "rate");
  hdSetSchedulerRate(5);
  CHECK(pop_errors() == HD_INVALID_VALUE, "a rate out of range");
  g_s.h = h;
  HDSchedulerHandle hs = hdScheduleAsynchronous(servo, &g_s, HD_MAX_SCHEDULER_PRIORITY);
  CHECK(hs != 0, "schedule");
  hdScheduleAsynchronous(low, &g_s, 10);
  hdScheduleAsynchronous(high, &g_s, 20);
  hdScheduleAsynchronous(unmatched_end, &g_s, HD_MIN_SCHEDULER_PRIORITY);
  CHECK(hdScheduleAsynchronous(NULL, NULL, 0) == 0, "a null callback");
  CHECK(pop_errors() == HD_INVALID_VALUE, "null callback refused");
  hdStartScheduler();
  CHECK(pop_errors() == HD_SUCCESS, "start");
  CHECK(hdWaitForCompletion(hs, HD_WAIT_CHECK_STATUS) == HD_TRUE, "scheduled");
  for (int i = 0; i < 400 && g_s.frames < 600; ++i) usleep(5000);
  struct Copy during = {{0, 0, 0}, 0};
  hdScheduleSynchronous(copy_state, &during, HD_DEFAULT_SCHEDULER_PRIORITY);
  CHECK(during.ran == 1, "a synchronous call with the scheduler");
  hdUnschedule(hs);
  CHECK(hdWaitForCompletion(hs, HD_WAIT_INFINITE) == HD_TRUE, "completed");
  CHECK(hdWaitForCompletion(hs, HD_WAIT_CHECK_STATUS) == HD_FALSE, "no longer scheduled");
  hdUnschedule(hs);
  CHECK(pop_errors() == HD_INVALID_OPERATION, "unscheduled twice");
  hdStopScheduler();

  /* what the callback saw */
  const struct Servo* s = &g_s;
  CHECK(s->frames >= 600, "frames %ld", s->frames);
  CHECK(s->frame_error == HD_SUCCESS, "a frame raised 0x%x", s->frame_error);
  CHECK(s->mismatches == 0, "LAST_ differed from the previous frame %u times",
        s->mismatches);
  CHECK(s->illegal_end == HD_ILLEGAL_END, "unmatched end 0x%x", s->illegal_end);
  CHECK(s->n_order == 2 && s->order[0] == 2 && s->order[1] == 1,
        "higher priority first");
  for (int i = 0; i < 3; ++i) {
    CHECK(s->transform[12 + i] == s->position_mm[i],
          "transform column 4 is the position (%d)", i);
    CHECK(isfinite(s->velocity_mm_s[i]) && isfinite(s->angular_velocity[i]),
          "velocities");
  }
  CHECK(s->read_force_N[0] == 0.0, "the force read back in the frame");
  /* the +x force moved the stylus along +x (device frame, mm) */
  CHECK(s->position_mm[0] - s->start_mm[0] > 5.0, "moved %g mm along +x",
        s->position_mm[0] - s->start_mm[0]);
  CHECK(fabs(s->jacobian[0]) + fabs(s->jacobian[1]) + fabs(s->jacobian[2]) > 10,
        "Jacobian column t1 (mm/rad)");
  CHECK(s->rate_Hz == 1000, "instantaneous rate %d", s->rate_Hz);
  CHECK(s->inkwell == 1, "out of the inkwell");
  CHECK(s->timestamp_s >= 0.0 && s->timestamp_s < 1.0, "time stamp %g",
        s->timestamp_s);
  CHECK(fabs(s->references_rad[1]) > 0.1, "references");
  /* the encoders (the device's raw counts, its own offsets and signs)
   * moved with the joints, 15000 counts per turn */
  for (int i = 0; i < 3; ++i) {
    const double counts = fabs((double)(s->encoders[i] - s->start_encoders[i]));
    const double turned = fabs(s->joints_rad[i] - s->start_joints_rad[i]) * 15000 / (2 * M_PI);
    CHECK(fabs(counts - turned) <= 2.0, "encoder t%d moved %g counts for %g", i + 1,
          counts, turned);
  }
  CHECK(fabs(s->joints_rad[0] - s->start_joints_rad[0]) > 0.02, "t1 turned");
  CHECK(during.position_mm[0] != before.position_mm[0], "state moved");

  hdDisableDevice(h2);
  hdDisableDevice(h);
  CHECK(pop_errors() == HD_SUCCESS, "disable");
  CHECK(hdGetCurrentDevice() == HD_INVALID_HANDLE, "no device left");
  pop_errors();
  hdDisableDevice(h);
  CHECK(pop_errors() == HD_BAD_HANDLE, "disabled twice");

  unlink(conf);
  rmdir(dir);
  printf("c_client: %d checks, %d failed, %ld frames\n", g_checks, g_failed,
         s->frames);
  return g_failed == 0 ? 0 : 1;
}
