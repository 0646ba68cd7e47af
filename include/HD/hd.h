/* vmhaptics open HD API: the one header a client includes.
 *
 * An implementation of the OpenHaptics HD API (libHD.so) over the project's
 * devices: the MuJoCo emulator, the native FireWire Omni driver, a
 * recording. docs/libhd.md says how to run a program on it, what is
 * implemented and what is not. Written from the API's published facts; no
 * vendor header was used as text. */
#ifndef VMHAPTICS_HD_H_
#define VMHAPTICS_HD_H_

#include <HD/hdCompilerConfig.h>
#include <HD/hdDefines.h>
#include <HD/hdDevice.h>
#include <HD/hdScheduler.h>

#endif /* VMHAPTICS_HD_H_ */
