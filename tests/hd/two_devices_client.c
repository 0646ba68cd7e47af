/* A C client of the open HD API with two devices under two configured
 * names (each an emulator), a callback on each, and one device disabled
 * while the scheduler serves both: the other must go on being served (its
 * callback runs, its stylus moves on from where it was, its tick time goes
 * on), the disabled handle must answer with the vendor's error
 * (HD_BAD_HANDLE, docs/libhd.md), the scheduler must stop and start again,
 * and the last device's leaving must leave nothing running. Run by ctest in
 * lockstep (VMH_HD_CLOCK=lockstep): the physics is the same whatever the
 * machine's load; the wall clock only bounds the waits. */
#include <HD/hd.h>
#include <HD/vmhd.h>

#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "hd_check.h"


static double wall_s(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* one device's callback state: the counters main polls are atomic; the
 * rest is written on the servo thread and read by main only through a
 * synchronous call (or with the scheduler stopped) */
struct Dev {
  HHD h;
  const char* name;
  _Atomic long frames;      /* frames served */
  _Atomic long bad_frames;  /* hdBeginFrame refused the handle */
  double position_mm[3];
  double prev_position_mm[3];
  double max_step_mm;       /* the largest move between two frames */
  double t_s;               /* the tick's time (vmhdGetSchedulerTime) */
  long time_backwards;      /* ticks whose time was not after the last's */
  HDerror other_error;      /* anything but the impulse limit's warning */
};

static HDCallbackCode HDCALLBACK serve(void* user) {
  struct Dev* d = (struct Dev*)user;
  hdBeginFrame(d->h);
  HDErrorInfo e = hdGetError();
  if (e.errorCode == HD_BAD_HANDLE) {
    atomic_fetch_add(&d->bad_frames, 1);
    pop_errors();
    return HD_CALLBACK_CONTINUE;
  }
  hdGetDoublev(HD_CURRENT_POSITION, d->position_mm);
  /* 0.3 N along +x: the stylus moves while the device is served */
  const double f[3] = {0.3, 0.0, 0.0};
  hdSetDoublev(HD_CURRENT_FORCE, f);
  hdEndFrame(d->h);
  for (e = hdGetError(); HD_DEVICE_ERROR(e); e = hdGetError()) {
    if (e.errorCode != HD_EXCEEDED_MAX_FORCE_IMPULSE) d->other_error = e.errorCode;
  }
  const double t = vmhdGetSchedulerTime();
  if (atomic_load(&d->frames) > 0) {
    double step = 0.0;
    for (int i = 0; i < 3; ++i) {
      const double s = d->position_mm[i] - d->prev_position_mm[i];
      step += s * s;
    }
    step = sqrt(step);
    if (step > d->max_step_mm) d->max_step_mm = step;
    if (!(t > d->t_s)) ++d->time_backwards;
  }
  d->t_s = t;
  memcpy(d->prev_position_mm, d->position_mm, sizeof d->position_mm);
  atomic_fetch_add(&d->frames, 1);
  return HD_CALLBACK_CONTINUE;
}

/* a consistent copy of a device's callback state, taken on the servo thread */
struct Copy {
  const struct Dev* d;
  double position_mm[3];
  double t_s;
  long frames;
};
static HDCallbackCode HDCALLBACK copy_dev(void* user) {
  struct Copy* c = (struct Copy*)user;
  memcpy(c->position_mm, c->d->position_mm, sizeof c->position_mm);
  c->t_s = c->d->t_s;
  c->frames = atomic_load(&c->d->frames);
  return HD_CALLBACK_DONE;
}

/* waits until d has served `n` more frames than `from` (a bound of wall
 * time, never a figure); returns whether it did */
static int wait_frames(struct Dev* d, long from, long n, double limit_s) {
  const double t0 = wall_s();
  while (atomic_load(&d->frames) < from + n) {
    if (wall_s() - t0 > limit_s) return 0;
    usleep(2000);
  }
  return 1;
}

int main(void) {
  char dir[] = "/tmp/vmhd_two_devices_XXXXXX";
  if (mkdtemp(dir) == NULL) return 2;
  char conf[256];
  snprintf(conf, sizeof conf, "%s/hd.conf", dir);
  FILE* fc = fopen(conf, "w");
  if (fc == NULL) return 2;
  fprintf(fc, "# written by two_devices_client\n"
              "Left  = emulator:case1?hand=none\n"
              "Right = emulator:case2?hand=none\n");
  fclose(fc);
  setenv("VMH_HD_CONFIG", conf, 1);
  setenv("VMH_HD_CLOCK", "lockstep", 1);
  setenv("VMH_HD_QUIET", "1", 1);

  static struct Dev a = {.name = "Left"}, b = {.name = "Right"};
  a.h = hdInitDevice("Left");
  CHECK(a.h != HD_INVALID_HANDLE, "Left: %s", hdGetErrorString(hdGetError().errorCode));
  b.h = hdInitDevice("Right");
  CHECK(b.h != HD_INVALID_HANDLE && b.h != a.h, "Right: %s",
        hdGetErrorString(hdGetError().errorCode));
  if (a.h == HD_INVALID_HANDLE || b.h == HD_INVALID_HANDLE) return 1;
  CHECK(pop_errors() == HD_SUCCESS, "two devices open");
  CHECK(hdGetCurrentDevice() == b.h, "the last opened is current");

  const HDSchedulerHandle ha = hdScheduleAsynchronous(serve, &a, HD_DEFAULT_SCHEDULER_PRIORITY);
  const HDSchedulerHandle hb = hdScheduleAsynchronous(serve, &b, HD_DEFAULT_SCHEDULER_PRIORITY);
  CHECK(ha != 0 && hb != 0, "scheduled");
  hdStartScheduler();
  CHECK(pop_errors() == HD_SUCCESS, "start");
  CHECK(wait_frames(&a, 0, 200, 60.0) && wait_frames(&b, 0, 200, 60.0),
        "both served: %ld and %ld frames", atomic_load(&a.frames), atomic_load(&b.frames));

  struct Copy before = {.d = &b};
  hdScheduleSynchronous(copy_dev, &before, HD_DEFAULT_SCHEDULER_PRIORITY);

  /* -- Left leaves while the scheduler runs -- */
  hdDisableDevice(a.h);
  CHECK(pop_errors() == HD_SUCCESS, "disable Left (the scheduler restarted for Right)");
  const long a_frames = atomic_load(&a.frames);
  const long b_at_disable = atomic_load(&b.frames);
  CHECK(hdGetCurrentDevice() == b.h, "Right is still current");
  CHECK(pop_errors() == HD_SUCCESS, "current device");

  /* Right goes on being served */
  CHECK(wait_frames(&b, b_at_disable, 100, 60.0), "Right served after: %ld frames",
        atomic_load(&b.frames) - b_at_disable);
  /* its state advances: its tick time by a period a frame (lockstep), its
   * stylus along the force */
  struct Copy mid = {.d = &b}, after = {.d = &b};
  hdScheduleSynchronous(copy_dev, &mid, HD_DEFAULT_SCHEDULER_PRIORITY);
  const long b_mid = mid.frames;
  CHECK(wait_frames(&b, b_mid, 200, 60.0), "Right served on: %ld frames",
        atomic_load(&b.frames) - b_mid);
  hdScheduleSynchronous(copy_dev, &after, HD_DEFAULT_SCHEDULER_PRIORITY);
  const double per_frame_s = (after.t_s - mid.t_s) / (double)(after.frames - mid.frames);
  CHECK(after.frames - mid.frames >= 200 && fabs(per_frame_s - 1e-3) < 1e-9,
        "Right's tick time %.4f then %.4f s over %ld frames", mid.t_s, after.t_s,
        after.frames - mid.frames);
  CHECK(after.position_mm[0] - mid.position_mm[0] > 0.5,
        "Right's stylus moves along +x: %.3f then %.3f mm", mid.position_mm[0],
        after.position_mm[0]);
  /* Left's callback is still scheduled: it gets HD_BAD_HANDLE, no frame */
  CHECK(atomic_load(&a.bad_frames) > 0, "Left's callback saw HD_BAD_HANDLE (%ld times)",
        atomic_load(&a.bad_frames));
  CHECK(atomic_load(&a.frames) == a_frames, "no frame of Left after it left: %ld then %ld",
        a_frames, atomic_load(&a.frames));

  /* the disabled handle, off the servo thread */
  hdMakeCurrentDevice(a.h);
  CHECK(pop_errors() == HD_BAD_HANDLE, "hdMakeCurrentDevice(disabled)");
  hdBeginFrame(a.h);
  CHECK(pop_errors() == HD_BAD_HANDLE, "hdBeginFrame(disabled)");
  hdDisableDevice(a.h);
  CHECK(pop_errors() == HD_BAD_HANDLE, "hdDisableDevice(disabled)");
  CHECK(hdGetCurrentDevice() == b.h, "a refused hdMakeCurrentDevice changes nothing");
  hdUnschedule(ha);
  CHECK(pop_errors() == HD_SUCCESS, "Left's callback unscheduled");

  /* -- the scheduler stopped and started again -- */
  const long a_bad = atomic_load(&a.bad_frames);
  hdStopScheduler();
  const long b_stopped = atomic_load(&b.frames);
  usleep(20000);
  CHECK(atomic_load(&b.frames) == b_stopped, "no frame while stopped");
  hdStartScheduler();
  CHECK(pop_errors() == HD_SUCCESS, "hdStartScheduler again");
  hdStartScheduler();
  CHECK(pop_errors() == HD_SUCCESS, "hdStartScheduler while running changes nothing");
  CHECK(wait_frames(&b, b_stopped, 200, 60.0), "Right served after the restart: %ld",
        atomic_load(&b.frames) - b_stopped);
  CHECK(atomic_load(&a.bad_frames) == a_bad, "Left's callback unscheduled: %ld then %ld",
        a_bad, atomic_load(&a.bad_frames));

  /* the name Left can be opened again once the scheduler is stopped */
  HHD again = hdInitDevice("Left");
  CHECK(again == HD_INVALID_HANDLE, "no device opened while the scheduler runs");
  CHECK(pop_errors() == HD_INVALID_OPERATION, "opening while running");
  const char* why = hdGetErrorString(HD_INVALID_OPERATION);
  CHECK(why != NULL && strstr(why, "hdInitDevice(\"Left\")") &&
            strstr(why, "stop the scheduler"),
        "the cause under the code raised: %s", why ? why : "(null)");
  hdStopScheduler();
  again = hdInitDevice("Left");
  CHECK(again != HD_INVALID_HANDLE, "Left again: %s",
        hdGetErrorString(hdGetError().errorCode));
  if (again != HD_INVALID_HANDLE) hdDisableDevice(again);
  CHECK(pop_errors() == HD_SUCCESS, "Left opened and closed again");
  hdMakeCurrentDevice(b.h);

  /* -- the last device leaves while running: nothing runs after -- */
  hdStartScheduler();
  CHECK(pop_errors() == HD_SUCCESS, "start for Right alone");
  CHECK(wait_frames(&b, atomic_load(&b.frames), 50, 60.0), "Right served");
  hdDisableDevice(b.h);
  CHECK(pop_errors() == HD_SUCCESS, "disable the last device");
  const long b_end = atomic_load(&b.frames);
  usleep(20000);
  CHECK(atomic_load(&b.frames) == b_end, "no frame after the last device left");
  CHECK(hdGetCurrentDevice() == HD_INVALID_HANDLE, "no device left");
  pop_errors();
  hdStartScheduler();
  CHECK(pop_errors() == HD_TIMER_ERROR, "no device to start the scheduler for");

  /* With the scheduler stopped, Right's callback state is ours to read.
   * A restarted scheduler finds the stylus where it was (the emulator
   * resumes, as a real device's stylus stays put): no jump between two
   * frames across the restarts (before the emulator resumed, 43.8 mm back
   * to the scene's start pose). The tick's time is the scheduler's own
   * and begins again at each start: reported, not asserted. */
  CHECK(b.max_step_mm < 2.0,
        "Right's stylus jumped %.3f mm between two frames across a restart",
        b.max_step_mm);
  printf("two_devices_client: the scheduler's time began again at %ld starts; "
         "largest move between two frames %.3f mm\n",
         b.time_backwards, b.max_step_mm);
  CHECK(a.other_error == HD_SUCCESS && b.other_error == HD_SUCCESS,
        "a frame raised 0x%x / 0x%x", a.other_error, b.other_error);
  printf("two_devices_client: Left %ld frames (then %ld refused), Right %ld frames; "
         "Right before the disable t=%.3f s x=%.3f mm, after it t=%.3f s x=%.3f mm "
         "and %ld frames later t=%.3f s x=%.3f mm\n",
         a_frames, a_bad, b_end, before.t_s, before.position_mm[0], mid.t_s,
         mid.position_mm[0], after.frames - mid.frames, after.t_s, after.position_mm[0]);
  hdUnschedule(hb);

  unlink(conf);
  rmdir(dir);
  printf("two_devices_client: %d checks, %d failed\n", g_checks, g_failed);
  return g_failed == 0 ? 0 : 1;
}
