/* vmhaptics open HD API utilities: printing and sorting HD errors.
 * Header-only (static inline): nothing to link beyond libHD. */
#ifndef VMHAPTICS_HDU_ERROR_H_
#define VMHAPTICS_HDU_ERROR_H_

#include <stdio.h>

#include <HD/hd.h>

#ifdef __cplusplus
extern "C" {
#endif

/* prints "message" then the error's code, its description (hdGetErrorString)
 * and the implementation's internal code, to `stream` */
static inline void hduPrintError(FILE* stream, const HDErrorInfo* error,
                                 const char* message) {
  if (stream == NULL || error == NULL) return;
  if (message != NULL) fputs(message, stream);
  fprintf(stream, "HD error 0x%04x: %s (internal %d, device %u)\n",
          error->errorCode, hdGetErrorString(error->errorCode),
          error->internalErrorCode, error->hHD);
}

/* a force-output error: a limit exceeded or the motors warm (0x02xx) */
static inline HDboolean hduIsForceError(const HDErrorInfo* error) {
  return (HDboolean)(error != NULL && (error->errorCode & 0xff00u) == 0x0200u);
}

/* an error that stops the scheduler's work: the device or its link failed
 * (0x03xx) or the scheduler itself refused (0x05xx) */
static inline HDboolean hduIsSchedulerError(const HDErrorInfo* error) {
  if (error == NULL) return HD_FALSE;
  const unsigned group = error->errorCode & 0xff00u;
  return (HDboolean)(group == 0x0300u || group == 0x0500u);
}

/* a communication error with the device (HD_COMM_ERROR,
 * HD_COMM_CONFIG_ERROR) */
static inline HDboolean hduIsCommError(const HDErrorInfo* error) {
  return (HDboolean)(error != NULL && (error->errorCode == HD_COMM_ERROR ||
                                       error->errorCode == HD_COMM_CONFIG_ERROR));
}

#ifdef __cplusplus
}
#endif

#endif /* VMHAPTICS_HDU_ERROR_H_ */
