/* vmhaptics open HD API: the project's extension, not part of the
 * vendor's API. A program that wants to run on the vendor's library as
 * well looks these up with dlsym and does without them when absent (as
 * the project's own --device openhaptics backend does). */
#ifndef VMHAPTICS_VMHD_H_
#define VMHAPTICS_VMHD_H_

#include <HD/hdDefines.h>

HD_EXTERN_C_BEGIN

/* The time of the servo tick in progress, s: CLOCK_MONOTONIC on the wall
 * clock, the simulated time under VMH_HD_CLOCK=lockstep. 0 off the
 * scheduler's thread. */
HDAPI HDdouble HDAPIENTRY vmhdGetSchedulerTime(void);

/* The simulated plant's ground truth for device hHD into `truth`, a
 * vmh::PlantTruth (device/tick_record.h) of the same build; `size` must be
 * its sizeof. 1 when filled; 0 for a device that is not simulated or a size
 * that does not match. */
HDAPI int HDAPIENTRY vmhdReadTruth(HHD hHD, void* truth, unsigned long size);

HD_EXTERN_C_END

#endif /* VMHAPTICS_VMHD_H_ */
