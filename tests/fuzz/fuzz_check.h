// What the libFuzzer harnesses share: a property check that stops the run.
//
// A harness checks properties, not only "it did not crash": when one fails,
// FUZZ_CHECK prints the property and the harness's context and aborts, and
// libFuzzer keeps the input as a crasher (crash-<sha1>).
#ifndef VMHAPTICS_TESTS_FUZZ_FUZZ_CHECK_H_
#define VMHAPTICS_TESTS_FUZZ_FUZZ_CHECK_H_

#include <cstdio>
#include <cstdlib>
#include <string>

namespace vmh::fuzz {

[[noreturn]] inline void fail(const char* file, int line, const char* what,
                              const std::string& context) {
  std::fprintf(stderr, "%s:%d: property failed: %s\n  %s\n", file, line, what,
               context.c_str());
  std::abort();
}

}  // namespace vmh::fuzz

#define FUZZ_CHECK(cond, context)                                   \
  do {                                                              \
    if (!(cond)) ::vmh::fuzz::fail(__FILE__, __LINE__, #cond, (context)); \
  } while (0)

#endif  // VMHAPTICS_TESTS_FUZZ_FUZZ_CHECK_H_
