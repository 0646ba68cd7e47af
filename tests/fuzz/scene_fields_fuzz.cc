// libFuzzer harness: a scene file as the MuJoCo-free reader reads it
// (sim/cases/scene_fields.h: read_scene_fields, what `hw run` on a device and a
// device-only build take a case's parameters from).
//
// The input is the whole file. The reader must either refuse with a
// ParamError whose message names the file, or give fields that each have a
// name, and, for a <numeric>, one or more values that are each a word
// without spaces; and it must end (no include loop or runaway nesting: an
// include of the file itself is a cycle, refused).
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <sstream>
#include <string>

#include "sim/cases/scene_fields.h"
#include "tests/fuzz/fuzz_check.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data,
                                      std::size_t size) {
  using namespace vmh;
  // one file per process, rewritten for each input (an include of
  // "fuzz.xml" is the file itself)
  static const std::string dir = [] {
    char tmpl[] = "/tmp/vmh_scene_fuzz_XXXXXX";
    const char* d = mkdtemp(tmpl);
    if (d == nullptr) fuzz::fail(__FILE__, __LINE__, "mkdtemp", "no temp folder");
    return std::string(d);
  }();
  const std::string path = dir + "/fuzz.xml";
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) fuzz::fail(__FILE__, __LINE__, "fopen", path);
  if (size > 0 && std::fwrite(data, 1, size, f) != size) {
    fuzz::fail(__FILE__, __LINE__, "fwrite", path);
  }
  std::fclose(f);

  try {
    const std::vector<sim::CustomField> fields = sim::read_scene_fields(path);
    for (const sim::CustomField& c : fields) {
      FUZZ_CHECK(!c.name.empty(), "a field without a name");
      if (c.is_text) continue;
      std::istringstream in(c.value);
      std::string word;
      int n = 0;
      while (in >> word) ++n;
      FUZZ_CHECK(n > 0, "numeric '" + c.name + "' without values: '" + c.value + "'");
    }
  } catch (const sim::ParamError& e) {
    const std::string m = e.what();
    FUZZ_CHECK(!m.empty(), "an empty refusal");
    FUZZ_CHECK(m.find(dir) != std::string::npos, "a refusal not naming the file: " + m);
  }
  return 0;
}
