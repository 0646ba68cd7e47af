/* vmhaptics open HD API: types, parameter names, error codes and constants.
 *
 * The values are the HD API's published ones (OpenHaptics 3.0; the project's
 * docs/sources.md §9.1 and docs/libhd.md list them with their sources). The
 * layout of this file and its comments are the project's own. Units are the
 * API's: mm, mm/s, N, mN m, rad, positions and forces in the device frame. */
#ifndef VMHAPTICS_HD_DEFINES_H_
#define VMHAPTICS_HD_DEFINES_H_

#include <limits.h>
#include <stddef.h>

#include <HD/hdExport.h>

HD_EXTERN_C_BEGIN

/* -- scalar types -- */
typedef unsigned int HDuint;
typedef unsigned char HDboolean; /* one byte: clients pass HDboolean[1] */
typedef unsigned long HDulong;
typedef unsigned short HDushort;
typedef int HDint;
typedef float HDfloat;
typedef double HDdouble;
typedef long HDlong; /* 64 bits on LP64 Linux */
typedef char HDchar;
typedef unsigned int HDerror;
typedef unsigned int HDenum;
typedef const char* HDstring;
typedef unsigned int HHD; /* device handle */

/* An error as hdGetError() returns it, by value. */
typedef struct {
  HDerror errorCode;     /* an HD_ error code below; HD_SUCCESS: none */
  int internalErrorCode; /* the implementation's own code (docs/libhd.md) */
  HHD hHD;               /* the device current when it was raised */
} HDErrorInfo;

/* true when an HDErrorInfo carries an error */
#define HD_DEVICE_ERROR(info) ((info).errorCode != HD_SUCCESS)

#define HD_TRUE 1
#define HD_FALSE 0

#define HD_VERSION_MAJOR_NUMBER 3
#define HD_VERSION_MINOR_NUMBER 0
#define HD_VERSION_BUILD_NUMBER 0

/* -- error codes -- */
#define HD_SUCCESS 0x0000
/* a call used wrongly */
#define HD_INVALID_ENUM 0x0100
#define HD_INVALID_VALUE 0x0101
#define HD_INVALID_OPERATION 0x0102
#define HD_INVALID_INPUT_TYPE 0x0103
#define HD_BAD_HANDLE 0x0104
/* the force output and its limits */
#define HD_WARM_MOTORS 0x0200
#define HD_EXCEEDED_MAX_FORCE 0x0201
#define HD_EXCEEDED_MAX_FORCE_IMPULSE 0x0202
#define HD_EXCEEDED_MAX_VELOCITY 0x0203
#define HD_FORCE_ERROR 0x0204
/* the device and its link */
#define HD_DEVICE_FAULT 0x0300
#define HD_DEVICE_ALREADY_INITIATED 0x0301
#define HD_COMM_ERROR 0x0302
#define HD_COMM_CONFIG_ERROR 0x0303
#define HD_TIMER_ERROR 0x0304
/* frames */
#define HD_ILLEGAL_BEGIN 0x0400
#define HD_ILLEGAL_END 0x0401
#define HD_FRAME_ERROR 0x0402
/* the scheduler */
#define HD_INVALID_PRIORITY 0x0500
#define HD_SCHEDULER_FULL 0x0501
/* licensing (never raised by this implementation) */
#define HD_INVALID_LICENSE 0x0600

/* -- state read with hdGet...v: this frame's (CURRENT) and the previous
 *    frame's (LAST, CURRENT + 0x200) -- */
#define HD_CURRENT_BUTTONS 0x2000        /* 1 int, HD_DEVICE_BUTTON_n bits */
#define HD_CURRENT_SAFETY_SWITCH 0x2001  /* 1 boolean */
#define HD_CURRENT_INKWELL_SWITCH 0x2002 /* 1 boolean, 0 while docked */
#define HD_CURRENT_ENCODER_VALUES 0x2010 /* 6 long, counts */
#define HD_CURRENT_PINCH_VALUE 0x2011
#define HD_LAST_PINCH_VALUE 0x2012
#define HD_CURRENT_POSITION 0x2050         /* 3, mm */
#define HD_CURRENT_VELOCITY 0x2051         /* 3, mm/s */
#define HD_CURRENT_TRANSFORM 0x2052        /* 16, column-major, mm */
#define HD_CURRENT_ANGULAR_VELOCITY 0x2053 /* 3, rad/s */
#define HD_CURRENT_JACOBIAN 0x2054         /* 36 (docs/libhd.md: layout) */
#define HD_CURRENT_JOINT_ANGLES 0x2100     /* 3, rad, joint 3 absolute */
#define HD_CURRENT_GIMBAL_ANGLES 0x2150    /* 3, rad */

#define HD_LAST_BUTTONS 0x2200
#define HD_LAST_SAFETY_SWITCH 0x2201
#define HD_LAST_INKWELL_SWITCH 0x2202
#define HD_LAST_ENCODER_VALUES 0x2210
#define HD_LAST_POSITION 0x2250
#define HD_LAST_VELOCITY 0x2251
#define HD_LAST_TRANSFORM 0x2252
#define HD_LAST_ANGULAR_VELOCITY 0x2253
#define HD_LAST_JACOBIAN 0x2254
#define HD_LAST_JOINT_ANGLES 0x2300
#define HD_LAST_GIMBAL_ANGLES 0x2350

/* identification, read with hdGetString */
#define HD_VERSION 0x2500
#define HD_DEVICE_MODEL_TYPE 0x2501
#define HD_DEVICE_DRIVER_VERSION 0x2502
#define HD_DEVICE_VENDOR 0x2503
#define HD_DEVICE_SERIAL_NUMBER 0x2504
#define HD_DEVICE_FIRMWARE_VERSION 0x2505

/* the hardware */
#define HD_MAX_WORKSPACE_DIMENSIONS 0x2550    /* 6, mm: min xyz, max xyz */
#define HD_USABLE_WORKSPACE_DIMENSIONS 0x2551 /* 6, mm */
#define HD_TABLETOP_OFFSET 0x2552             /* 1, mm */
#define HD_INPUT_DOF 0x2553                   /* 1 int */
#define HD_OUTPUT_DOF 0x2554                  /* 1 int */
#define HD_CALIBRATION_STYLE 0x2555           /* 1 int, style bits */

/* rates, nominal figures and the software limits */
#define HD_UPDATE_RATE 0x2600               /* 1 int, Hz */
#define HD_INSTANTANEOUS_UPDATE_RATE 0x2601 /* 1 int, Hz */
#define HD_NOMINAL_MAX_STIFFNESS 0x2602     /* 1, N/mm */
#define HD_NOMINAL_MAX_FORCE 0x2603         /* 1, N */
#define HD_NOMINAL_MAX_CONTINUOUS_FORCE 0x2604 /* 1, N */
#define HD_MOTOR_TEMPERATURE 0x2605         /* 6, 0..1 of the cut-off */
#define HD_SOFTWARE_VELOCITY_LIMIT 0x2606   /* 1, mm/s */
#define HD_SOFTWARE_FORCE_IMPULSE_LIMIT 0x2607 /* 1, N per frame */
#define HD_FORCE_RAMPING_RATE 0x2608        /* 1, N/s */
#define HD_NOMINAL_MAX_DAMPING 0x2609       /* 1, N s/mm */
#define HD_NOMINAL_MAX_TORQUE_STIFFNESS 0x2620
#define HD_NOMINAL_MAX_TORQUE_DAMPING 0x2621
#define HD_NOMINAL_MAX_TORQUE_FORCE 0x2622
#define HD_NOMINAL_MAX_TORQUE_CONTINUOUS_FORCE 0x2623

/* -- commands, written with hdSet...v (and read back) -- */
#define HD_CURRENT_FORCE 0x2700           /* 3, N, device frame */
#define HD_CURRENT_TORQUE 0x2701          /* deprecated: 3, mN m, gimbal */
#define HD_JOINT_ANGLE_REFERENCES 0x2702  /* 6, rad */
#define HD_CURRENT_JOINT_TORQUE 0x2703    /* 3, mN m, joints 1..3 */
#define HD_CURRENT_GIMBAL_TORQUE 0x2704   /* 3, mN m (no motor on an Omni) */
#define HD_CURRENT_MOTOR_DAC_VALUES 0x2750 /* deprecated: 3 long, DAC units */
#define HD_LAST_FORCE 0x2800
#define HD_LAST_TORQUE 0x2801
#define HD_LAST_JOINT_TORQUE 0x2802
#define HD_LAST_GIMBAL_TORQUE 0x2803
#define HD_LAST_MOTOR_DAC_VALUES 0x2850
#define HD_USER_STATUS_LIGHT 0x2900

/* -- capabilities: hdEnable, hdDisable, hdIsEnabled -- */
#define HD_FORCE_OUTPUT 0x4000
#define HD_MAX_FORCE_CLAMPING 0x4001
#define HD_FORCE_RAMPING 0x4002
#define HD_SOFTWARE_FORCE_LIMIT 0x4003
#define HD_ONE_FRAME_LIMIT 0x4004
/* HD_SOFTWARE_VELOCITY_LIMIT and HD_SOFTWARE_FORCE_IMPULSE_LIMIT are also
 * capabilities */

/* -- scheduler priorities (higher runs first) -- */
#define HD_MAX_SCHEDULER_PRIORITY USHRT_MAX
#define HD_MIN_SCHEDULER_PRIORITY 0
#define HD_DEFAULT_SCHEDULER_PRIORITY \
  ((HD_MAX_SCHEDULER_PRIORITY + HD_MIN_SCHEDULER_PRIORITY) / 2)
#define HD_RENDER_EFFECT_FORCE_PRIORITY (HD_MAX_SCHEDULER_PRIORITY - 1)

/* -- calibration: hdCheckCalibration's results and the styles -- */
#define HD_CALIBRATION_OK 0x5000
#define HD_CALIBRATION_NEEDS_UPDATE 0x5001
#define HD_CALIBRATION_NEEDS_MANUAL_INPUT 0x5002
#define HD_CALIBRATION_ENCODER_RESET (1 << 0)
#define HD_CALIBRATION_AUTO (1 << 1)
#define HD_CALIBRATION_INKWELL (1 << 2)

/* -- buttons -- */
#define HD_DEVICE_BUTTON_1 (1 << 0)
#define HD_DEVICE_BUTTON_2 (1 << 1)
#define HD_DEVICE_BUTTON_3 (1 << 2)
#define HD_DEVICE_BUTTON_4 (1 << 3)

#define HD_INVALID_HANDLE 0xFFFFFFFF
#define HD_DEFAULT_DEVICE NULL

/* -- the status light -- */
#define LED_MASK 0x07
#define LED_STATUS_FAST_GRNYEL 0x00
#define LED_STATUS_SLOW_YEL 0x01
#define LED_STATUS_SLOW_GRN 0x02
#define LED_STATUS_FAST_GRN 0x03
#define LED_STATUS_SOLID_GRNYEL 0x04
#define LED_STATUS_SOLID_YEL 0x05
#define LED_STATUS_SOLID_GRN 0x06
#define LED_STATUS_FAST_YEL 0x07

HD_EXTERN_C_END

#endif /* VMHAPTICS_HD_DEFINES_H_ */
