/* What the C clients of the HD API in tests/hd/ share: a check that counts
 * and reports instead of stopping (a client runs to its end and prints its
 * tally), and the error stack emptied. For one translation unit each. */
#ifndef VMHAPTICS_TESTS_HD_HD_CHECK_H_
#define VMHAPTICS_TESTS_HD_HD_CHECK_H_

#include <stdio.h>

#include <HD/hd.h>

static int g_failed = 0;
static int g_checks = 0;
#define CHECK(cond, ...)                                                 \
  do {                                                                   \
    ++g_checks;                                                          \
    if (!(cond)) {                                                       \
      ++g_failed;                                                        \
      fprintf(stderr, "FAILED %s:%d: %s: ", __FILE__, __LINE__, #cond);  \
      fprintf(stderr, __VA_ARGS__);                                      \
      fputc('\n', stderr);                                               \
    }                                                                    \
  } while (0)

/* pops every pending error; returns the most recent code (0: none) */
static inline HDerror pop_errors(void) {
  HDerror last = HD_SUCCESS;
  for (int i = 0; i < 64; ++i) {
    HDErrorInfo e = hdGetError();
    if (!HD_DEVICE_ERROR(e)) break;
    if (last == HD_SUCCESS) last = e.errorCode;
  }
  return last;
}

#endif /* VMHAPTICS_TESTS_HD_HD_CHECK_H_ */
