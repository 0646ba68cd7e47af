// Small helpers the studies share (internal to studies/): a number as
// exact text, and the calling thread's CPU time.
#ifndef VMHAPTICS_STUDIES_STUDY_NUMBERS_H_
#define VMHAPTICS_STUDIES_STUDY_NUMBERS_H_

#include <time.h>

#include <cstdio>
#include <string>

namespace vmh::studies::detail {

// "%.17g": reads back the same through strtod (the case loader's), so an
// override written with it sets exactly this double
inline std::string exact(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

// CPU time of the calling thread (s): unlike the wall clock, it does not
// count the time other processes held the core, which on a shared machine
// is most of the noise (POSIX clock_gettime)
inline double thread_cpu_s() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) +
         1e-9 * static_cast<double>(ts.tv_nsec);
}

}  // namespace vmh::studies::detail

#endif  // VMHAPTICS_STUDIES_STUDY_NUMBERS_H_
