// A scene's case parameters without MuJoCo: the <custom> fields of an MJCF
// file read straight from its XML, so that a machine that only drives a
// device (VMH_BUILD_SIM=OFF) can run a case's controller (`hw run
// case1 --device firewire`), and every build reads a real device's
// parameters the same way. The simulated loop reads the same fields through
// MuJoCo (sim/cases/case_config.h); tests/sim/cases/scene_fields_test.cc checks that
// the two agree on every scene of models/ and the tests.
//
// What it reads, as MuJoCo 2.2.2 does:
//   - <numeric name="..." data="x y z" [size="n"]/> and <text name="..."
//     data="..."/> inside <custom>, anywhere in the model tree;
//   - <include file="..."/> anywhere, the file's path relative to the
//     directory of the MAIN model file (not the including one), its root
//     <mujoco> element's children taking the include's place;
//   - a numeric's size pads its data with zeros; more data than its size is
//     an error, as is a numeric with neither.
// XML comments, processing instructions and the five predefined entities
// (&amp; &lt; &gt; &quot; &apos;) and numeric character references are
// understood; anything else of XML that an MJCF file does not use (DTDs,
// CDATA in attributes) is refused with the file and line named.
//
// Bounds (so that a hostile file cannot hang or exhaust the reader): a
// regular file only (a FIFO or a device is refused by type before it is
// opened, and opened without blocking), at most kMaxSceneBytes for the
// scene and its includes together, includes nested at most 16 deep and
// never in a cycle.
#ifndef VMHAPTICS_SIM_CASES_SCENE_FIELDS_H_
#define VMHAPTICS_SIM_CASES_SCENE_FIELDS_H_

#include <cstdint>
#include <string>
#include <vector>

#include "sim/cases/case_params.h"

namespace vmh::sim {

// What the scene's files hold together, read as above: what the loader
// bounds before MuJoCo compiles it (sim/mujoco_util.h).
inline constexpr std::uint64_t kMaxSceneBytes = std::uint64_t{8} << 20;
struct SceneCensus {
  std::vector<std::string> files;  // the scene, then each include as read
  std::uint64_t bytes = 0;         // their sizes, summed
  int bodies = 0;                  // <body> elements (the world body is not one)
  std::vector<std::string> assets;      // file= of <mesh>, <texture>, <hfield>, <skin>
  std::vector<std::string> asset_dirs;  // <compiler> meshdir, texturedir, assetdir
};

// The census of a scene and its includes. Throws ParamError as
// read_scene_fields does (a file not regular, over the bound, malformed,
// an include cycle).
SceneCensus scan_scene(const std::string& scene_path);

// Every <custom> <numeric> and <text> of the scene and its includes, in
// document order (a numeric's value as its numbers, space-separated).
// Throws ParamError naming the file (and line) and what was wrong.
std::vector<CustomField> read_scene_fields(const std::string& scene_path);

// The scene's case parameters with `overrides` (case_params_from_fields).
// Throws ParamError.
CaseParams load_scene_params(const std::string& scene_path,
                             const std::vector<std::string>& overrides);

}  // namespace vmh::sim

#endif  // VMHAPTICS_SIM_CASES_SCENE_FIELDS_H_
