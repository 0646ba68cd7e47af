/* vmhaptics open HD API: devices, frames, state and errors. What each
 * call does in this implementation is in docs/libhd.md. */
#ifndef VMHAPTICS_HD_DEVICE_H_
#define VMHAPTICS_HD_DEVICE_H_

#include <HD/hdDefines.h>

HD_EXTERN_C_BEGIN

/* devices: a configuration name (HD_DEFAULT_DEVICE for the default) to a
 * handle, or HD_INVALID_HANDLE with the cause on the error stack */
HDAPI HHD HDAPIENTRY hdInitDevice(HDstring pConfigName);
HDAPI void HDAPIENTRY hdDisableDevice(HHD hHD);
HDAPI HHD HDAPIENTRY hdGetCurrentDevice(void);
HDAPI void HDAPIENTRY hdMakeCurrentDevice(HHD hHD);

/* a servo frame: state sampled at its start, commands sent at its end */
HDAPI void HDAPIENTRY hdBeginFrame(HHD hHD);
HDAPI void HDAPIENTRY hdEndFrame(HHD hHD);

/* capabilities */
HDAPI void HDAPIENTRY hdEnable(HDenum cap);
HDAPI void HDAPIENTRY hdDisable(HDenum cap);
HDAPI HDboolean HDAPIENTRY hdIsEnabled(HDenum cap);

/* state and commands of the current device */
HDAPI void HDAPIENTRY hdGetBooleanv(HDenum pname, HDboolean* params);
HDAPI void HDAPIENTRY hdGetIntegerv(HDenum pname, HDint* params);
HDAPI void HDAPIENTRY hdGetFloatv(HDenum pname, HDfloat* params);
HDAPI void HDAPIENTRY hdGetDoublev(HDenum pname, HDdouble* params);
HDAPI void HDAPIENTRY hdGetLongv(HDenum pname, HDlong* params);
HDAPI HDstring HDAPIENTRY hdGetString(HDenum pname);
HDAPI void HDAPIENTRY hdSetBooleanv(HDenum pname, const HDboolean* params);
HDAPI void HDAPIENTRY hdSetIntegerv(HDenum pname, const HDint* params);
HDAPI void HDAPIENTRY hdSetFloatv(HDenum pname, const HDfloat* params);
HDAPI void HDAPIENTRY hdSetDoublev(HDenum pname, const HDdouble* params);
HDAPI void HDAPIENTRY hdSetLongv(HDenum pname, const HDlong* params);

/* errors: the most recent first, each returned once */
HDAPI HDErrorInfo HDAPIENTRY hdGetError(void);
HDAPI HDstring HDAPIENTRY hdGetErrorString(HDerror errorCode);

/* calibration */
HDAPI HDenum HDAPIENTRY hdCheckCalibration(void);
HDAPI void HDAPIENTRY hdUpdateCalibration(HDenum style);

HD_EXTERN_C_END

#endif /* VMHAPTICS_HD_DEVICE_H_ */
