// The project's own declarations of the part of the OpenHaptics HD API
// (libHD.so) the backend uses: types, enum values and the functions' types,
// written from docs/sources.md §9.1 (no vendor header is needed or shipped).
// hd_library.h resolves the functions at run time with dlsym.
//
// Units as the HD API has them: mm, mm/s, N, mN m, rad; positions and forces
// in the device frame (controller/device_frame.h).
#ifndef VMHAPTICS_HW_OPENHAPTICS_HD_API_H_
#define VMHAPTICS_HW_OPENHAPTICS_HD_API_H_

namespace vmh::hw::hd {

// -- types (§9.1) --
using HHD = unsigned int;
using HDenum = unsigned int;
using HDerror = unsigned int;
using HDCallbackCode = unsigned int;
using HDdouble = double;
using HDint = int;
using HDlong = long;
using HDboolean = unsigned char;
using HDushort = unsigned short;
using HDstring = const char*;
using HDSchedulerHandle = unsigned long;

struct HDErrorInfo {
  HDerror errorCode;      // HD_SUCCESS (0) when there is none
  int internalErrorCode;  // the vendor's own code
  HHD hHD;                // the device it concerns
};

inline constexpr HHD kInvalidHandle = 0xFFFFFFFFu;  // HD_INVALID_HANDLE

// -- scheduler --
inline constexpr HDCallbackCode kCallbackDone = 0;      // HD_CALLBACK_DONE
inline constexpr HDCallbackCode kCallbackContinue = 1;  // HD_CALLBACK_CONTINUE
inline constexpr HDushort kMaxSchedulerPriority = 65535;
inline constexpr HDushort kDefaultSchedulerPriority = 32767;  // the midpoint

// -- parameters read with hdGet...v (count, unit) --
inline constexpr HDenum kCurrentButtons = 0x2000;         // 1 int, bit mask
inline constexpr HDenum kCurrentSafetySwitch = 0x2001;
inline constexpr HDenum kCurrentInkwellSwitch = 0x2002;   // 1 boolean, 0 docked
inline constexpr HDenum kCurrentEncoderValues = 0x2010;   // longs, counts
inline constexpr HDenum kCurrentPosition = 0x2050;        // 3, mm
inline constexpr HDenum kCurrentVelocity = 0x2051;        // 3, mm/s
inline constexpr HDenum kCurrentTransform = 0x2052;       // 16, column-major
inline constexpr HDenum kCurrentAngularVelocity = 0x2053;
inline constexpr HDenum kCurrentJacobian = 0x2054;        // 36, order unknown
inline constexpr HDenum kCurrentJointAngles = 0x2100;     // 3, rad, t3 absolute
inline constexpr HDenum kCurrentGimbalAngles = 0x2150;    // 3, rad
inline constexpr HDenum kLastOffset = 0x200;              // LAST_x = CURRENT_x + this

// identification (hdGetString)
inline constexpr HDenum kVersion = 0x2500;
inline constexpr HDenum kDeviceModelType = 0x2501;
inline constexpr HDenum kDeviceDriverVersion = 0x2502;
inline constexpr HDenum kDeviceVendor = 0x2503;
inline constexpr HDenum kDeviceSerialNumber = 0x2504;
inline constexpr HDenum kDeviceFirmwareVersion = 0x2505;

// hardware (hdGetIntegerv / hdGetDoublev)
inline constexpr HDenum kMaxWorkspaceDimensions = 0x2550;
inline constexpr HDenum kUsableWorkspaceDimensions = 0x2551;
inline constexpr HDenum kTabletopOffset = 0x2552;
inline constexpr HDenum kInputDof = 0x2553;
inline constexpr HDenum kOutputDof = 0x2554;
inline constexpr HDenum kCalibrationStyle = 0x2555;  // bit mask of styles

inline constexpr HDenum kUpdateRate = 0x2600;
inline constexpr HDenum kInstantaneousUpdateRate = 0x2601;
inline constexpr HDenum kNominalMaxStiffness = 0x2602;
inline constexpr HDenum kNominalMaxForce = 0x2603;
inline constexpr HDenum kNominalMaxContinuousForce = 0x2604;
inline constexpr HDenum kMotorTemperature = 0x2605;

// -- parameters written with hdSet...v --
inline constexpr HDenum kCurrentForce = 0x2700;        // 3, N, device frame
inline constexpr HDenum kCurrentJointTorque = 0x2703;  // 3, mN m
inline constexpr HDenum kCurrentGimbalTorque = 0x2704;

// -- capabilities (hdEnable / hdDisable) --
inline constexpr HDenum kForceOutput = 0x4000;
inline constexpr HDenum kMaxForceClamping = 0x4001;
inline constexpr HDenum kForceRamping = 0x4002;
inline constexpr HDenum kSoftwareForceLimit = 0x4003;
inline constexpr HDenum kOneFrameLimit = 0x4004;

// -- error codes --
inline constexpr HDerror kSuccess = 0;
inline constexpr HDerror kInvalidEnum = 0x100;
inline constexpr HDerror kInvalidValue = 0x101;
inline constexpr HDerror kInvalidOperation = 0x102;
inline constexpr HDerror kInvalidInputType = 0x103;
inline constexpr HDerror kBadHandle = 0x104;
inline constexpr HDerror kWarmMotors = 0x200;
inline constexpr HDerror kExceededMaxForce = 0x201;
inline constexpr HDerror kExceededMaxForceImpulse = 0x202;
inline constexpr HDerror kExceededMaxVelocity = 0x203;
inline constexpr HDerror kForceError = 0x204;
inline constexpr HDerror kDeviceFault = 0x300;
inline constexpr HDerror kDeviceAlreadyInitiated = 0x301;
inline constexpr HDerror kCommError = 0x302;
inline constexpr HDerror kCommConfigError = 0x303;
inline constexpr HDerror kTimerError = 0x304;
inline constexpr HDerror kIllegalBegin = 0x400;
inline constexpr HDerror kIllegalEnd = 0x401;
inline constexpr HDerror kFrameError = 0x402;
inline constexpr HDerror kInvalidPriority = 0x500;
inline constexpr HDerror kSchedulerFull = 0x501;
inline constexpr HDerror kInvalidLicense = 0x600;

// -- calibration --
inline constexpr HDenum kCalibrationOk = 0x5000;
inline constexpr HDenum kCalibrationNeedsUpdate = 0x5001;
inline constexpr HDenum kCalibrationNeedsManualInput = 0x5002;
inline constexpr HDint kCalibrationEncoderReset = 1;  // styles (bit mask)
inline constexpr HDint kCalibrationAuto = 2;
inline constexpr HDint kCalibrationInkwell = 4;

// -- the functions' types, C ABI (libHD.so exports them unmangled) --
extern "C" {
typedef HDCallbackCode (*HDSchedulerCallback)(void* user_data);

typedef HHD (*PfnInitDevice)(HDstring config);
typedef void (*PfnDisableDevice)(HHD h);
typedef void (*PfnMakeCurrentDevice)(HHD h);
typedef void (*PfnBeginFrame)(HHD h);
typedef void (*PfnEndFrame)(HHD h);
typedef HDErrorInfo (*PfnGetError)();
typedef HDstring (*PfnGetErrorString)(HDerror code);
typedef void (*PfnEnable)(HDenum cap);
typedef void (*PfnDisable)(HDenum cap);
typedef void (*PfnGetBooleanv)(HDenum param, HDboolean* out);
typedef void (*PfnGetIntegerv)(HDenum param, HDint* out);
typedef void (*PfnGetDoublev)(HDenum param, HDdouble* out);
typedef void (*PfnGetLongv)(HDenum param, HDlong* out);
typedef HDstring (*PfnGetString)(HDenum param);
typedef void (*PfnSetDoublev)(HDenum param, const HDdouble* in);
typedef HDenum (*PfnCheckCalibration)();
typedef void (*PfnUpdateCalibration)(HDenum style);
typedef void (*PfnStartScheduler)();
typedef void (*PfnStopScheduler)();
typedef HDSchedulerHandle (*PfnScheduleAsynchronous)(HDSchedulerCallback cb,
                                                     void* user_data,
                                                     HDushort priority);
typedef void (*PfnScheduleSynchronous)(HDSchedulerCallback cb,
                                       void* user_data, HDushort priority);
typedef void (*PfnUnschedule)(HDSchedulerHandle handle);
// the project's own library's extension (include/HD/vmhd.h, docs/libhd.md):
// absent from the vendor's
typedef HDdouble (*PfnVmhdSchedulerTime)();
typedef int (*PfnVmhdReadTruth)(HHD h, void* truth, unsigned long size);
}  // extern "C"

// Every function the backend calls, resolved from one loaded library.
struct HdApi {
  PfnInitDevice hdInitDevice = nullptr;
  PfnDisableDevice hdDisableDevice = nullptr;
  PfnMakeCurrentDevice hdMakeCurrentDevice = nullptr;
  PfnBeginFrame hdBeginFrame = nullptr;
  PfnEndFrame hdEndFrame = nullptr;
  PfnGetError hdGetError = nullptr;
  PfnGetErrorString hdGetErrorString = nullptr;
  PfnEnable hdEnable = nullptr;
  PfnDisable hdDisable = nullptr;
  PfnGetBooleanv hdGetBooleanv = nullptr;
  PfnGetIntegerv hdGetIntegerv = nullptr;
  PfnGetDoublev hdGetDoublev = nullptr;
  PfnGetLongv hdGetLongv = nullptr;
  PfnGetString hdGetString = nullptr;
  PfnSetDoublev hdSetDoublev = nullptr;
  PfnCheckCalibration hdCheckCalibration = nullptr;
  PfnUpdateCalibration hdUpdateCalibration = nullptr;
  PfnStartScheduler hdStartScheduler = nullptr;
  PfnStopScheduler hdStopScheduler = nullptr;
  PfnScheduleAsynchronous hdScheduleAsynchronous = nullptr;
  PfnScheduleSynchronous hdScheduleSynchronous = nullptr;
  PfnUnschedule hdUnschedule = nullptr;
  // optional: only the project's open HD API has them (nullptr otherwise)
  PfnVmhdSchedulerTime vmhdGetSchedulerTime = nullptr;
  PfnVmhdReadTruth vmhdReadTruth = nullptr;
};

}  // namespace vmh::hw::hd

#endif  // VMHAPTICS_HW_OPENHAPTICS_HD_API_H_
