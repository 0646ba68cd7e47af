/* vmhaptics open HD API: calling-convention and export macros.
 *
 * Written for this project from the published facts of the OpenHaptics HD
 * API (docs/libhd.md); no vendor text. On Linux the vendor's macros are
 * empty; they are defined here whichever of `linux` and `__linux__` the
 * compiler predefines (strict C modes define only the latter). */
#ifndef VMHAPTICS_HD_EXPORT_H_
#define VMHAPTICS_HD_EXPORT_H_

#if defined(_WIN32)
#define HDAPIENTRY __stdcall
#define HDCALLBACK __stdcall
#define HDAPI __declspec(dllimport)
#else
#define HDAPIENTRY
#define HDCALLBACK
#if defined(VMHAPTICS_HD_BUILDING)
#define HDAPI __attribute__((visibility("default")))
#else
#define HDAPI
#endif
#endif

#ifdef __cplusplus
#define HD_EXTERN_C_BEGIN extern "C" {
#define HD_EXTERN_C_END }
#else
#define HD_EXTERN_C_BEGIN
#define HD_EXTERN_C_END
#endif

#endif /* VMHAPTICS_HD_EXPORT_H_ */
