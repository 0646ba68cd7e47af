#include "sim/mujoco_util.h"

#include <sys/stat.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <regex>

#include "output/output_file.h"
#include "sim/mujoco_messages.h"
#include "sim/cases/scene_fields.h"

namespace vmh::sim {
namespace {

// the XML parser keeps global state (and mj_saveLastXML reads it): one
// load, or load and save, at a time
std::mutex& xml_mutex() {
  static std::mutex m;
  return m;
}

// MuJoCo's messages span lines; the error contract is one line
std::string one_line(const char* err, const char* fallback) {
  std::string msg = err[0] ? err : fallback;
  for (char& ch : msg) {
    if (ch == '\n') ch = ' ';
  }
  return msg;
}

// Refuses what is not a readable regular file, before anything opens it.
// mj_loadXML's own message for a missing file is terse; this says it
// plainly. A FIFO would block the reader, a device never end, a folder
// fail with an XML error that does not say why.
void require_scene_file(const std::string& path) {
  struct stat st {};
  if (stat(path.c_str(), &st) != 0) {
    throw SimError(path + ": cannot open the scene file");
  }
  if (!S_ISREG(st.st_mode)) {
    throw SimError(path + ": not a scene file (" +
                   output::file_kind(st.st_mode) + ")");
  }
  if (!std::ifstream(path).good()) {
    throw SimError(path + ": cannot open the scene file");
  }
}

// Bounds a scene before MuJoCo reads it (MuJoCo's own reader would block
// on an included FIFO, and compiles and steps whatever size it is given):
// the scene and its includes read as sim/cases/scene_fields.h reads them (regular
// files, opened without blocking, at most kMaxSceneBytes together, no
// include cycle), at most kMaxSceneBodies bodies, and every asset file it
// names that exists a regular file of at most kMaxAssetBytes.
void check_scene_bounds(const std::string& path) {
  SceneCensus c;
  try {
    c = scan_scene(path);
  } catch (const ParamError& e) {
    throw SimError(e.what());
  }
  if (c.bodies > kMaxSceneBodies) {
    throw SimError(path + ": " + std::to_string(c.bodies) +
                   " bodies with its includes, more than a scene of this "
                   "testbed may have (" + std::to_string(kMaxSceneBodies) + ")");
  }
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  for (const std::string& asset : c.assets) {
    std::vector<std::filesystem::path> where = {dir / asset};
    for (const std::string& d : c.asset_dirs) where.push_back(dir / d / asset);
    if (std::filesystem::path(asset).is_absolute()) where = {asset};
    for (const std::filesystem::path& p : where) {
      struct stat st {};
      if (::stat(p.c_str(), &st) != 0) continue;  // MuJoCo names a missing one
      if (!S_ISREG(st.st_mode)) {
        throw SimError(path + ": asset '" + asset + "' (" + p.string() + ") is " +
                       output::file_kind(st.st_mode) + ", not a regular file");
      }
      if (static_cast<std::uint64_t>(st.st_size) > kMaxAssetBytes) {
        throw SimError(path + ": asset '" + asset + "' is " +
                       output::bytes_text(static_cast<std::uint64_t>(st.st_size)) +
                       ", over the bound of " + output::bytes_text(kMaxAssetBytes));
      }
    }
  }
}

ModelPtr load_locked(const std::string& path, const mjVFS* vfs = nullptr) {
  require_scene_file(path);
  check_scene_bounds(path);
  char err[1024] = "";
  ModelPtr m(mj_loadXML(path.c_str(), vfs, err, sizeof err));
  if (!m) throw SimError(path + ": " + one_line(err, "MuJoCo could not load it"));
  return m;
}

// a scene file's text, read as check_scene_bounds read it: a regular file
// only, opened without blocking, within the scene's bound
std::string slurp(const std::string& path) {
  bool missing = false;
  try {
    std::string text = output::read_regular_file(path, kMaxSceneBytes, &missing);
    if (!missing) return text;
  } catch (const std::runtime_error& e) {
    throw SimError(e.what());
  }
  throw SimError(path + ": cannot open the scene file");
}

// An included file less what is only drawn: geoms of a class whose name
// begins with "visual" or in geom group 2 (the models' drawn-only group:
// models/README.md), lights, cameras and the skybox texture. Every body of
// the models carries its own <inertial> and those geoms neither collide nor
// weigh, so the physics is the same without them.
std::string without_drawn(std::string xml) {
  static const std::regex kDrawn(
      "<geom[^>]*(class=\"visual[^\"]*\"|group=\"2\")[^>]*/>"
      "|<light[^>]*/>|<camera[^>]*/>|<texture[^>]*type=\"skybox\"[^>]*/>");
  return std::regex_replace(xml, kDrawn, "");
}

// the VFS of load_model_headless: each file the scene includes, as
// without_drawn() leaves it, under its own name (MuJoCo looks an included
// file up in the VFS by its name before it reads the disk)
struct HeadlessVfs {
  mjVFS vfs;
  explicit HeadlessVfs(const std::string& scene_path) {
    mj_defaultVFS(&vfs);
    const std::string scene = slurp(scene_path);
    const std::string dir =
        std::filesystem::path(scene_path).parent_path().string();
    static const std::regex kInclude("<include\\s+file=\"([^\"]+)\"");
    for (std::sregex_iterator it(scene.begin(), scene.end(), kInclude), end;
         it != end; ++it) {
      const std::string file = (*it)[1].str();
      const std::string text =
          without_drawn(slurp((std::filesystem::path(dir) / file).string()));
      const std::string name = std::filesystem::path(file).filename().string();
      if (mj_makeEmptyFileVFS(&vfs, name.c_str(), static_cast<int>(text.size())) != 0) {
        continue;  // a name twice, or the VFS full: that file from the disk
      }
      std::memcpy(vfs.filedata[vfs.nfile - 1], text.data(), text.size());
    }
  }
  ~HeadlessVfs() { mj_deleteVFS(&vfs); }
  HeadlessVfs(const HeadlessVfs&) = delete;
  HeadlessVfs& operator=(const HeadlessVfs&) = delete;
};

}  // namespace

ModelPtr load_model_headless(const std::string& path) {
  install_mujoco_handlers();
  std::lock_guard<std::mutex> lock(xml_mutex());
  // refused before HeadlessVfs reads it (a FIFO would block that read)
  require_scene_file(path);
  check_scene_bounds(path);
  const HeadlessVfs files(path);
  return load_locked(path, &files.vfs);
}

ModelPtr load_model(const std::string& path) {
  install_mujoco_handlers();
  std::lock_guard<std::mutex> lock(xml_mutex());
  return load_locked(path);
}

void save_edited_model_xml(const std::string& in_path,
                           const std::function<void(mjModel*)>& edit,
                           const std::string& out_path) {
  install_mujoco_handlers();
  std::lock_guard<std::mutex> lock(xml_mutex());
  ModelPtr m = load_locked(in_path);
  if (edit) edit(m.get());
  char err[1024] = "";
  if (!mj_saveLastXML(out_path.c_str(), m.get(), err, sizeof err)) {
    throw SimError(out_path + ": " + one_line(err, "MuJoCo could not save it"));
  }
}

int require_id(const mjModel* m, mjtObj type, const char* name,
               const std::string& source) {
  const int id = mj_name2id(m, type, name);
  if (id < 0) {
    const char* what = type == mjOBJ_JOINT      ? "joint"
                       : type == mjOBJ_SITE     ? "site"
                       : type == mjOBJ_BODY     ? "body"
                       : type == mjOBJ_ACTUATOR ? "actuator"
                                                : "object";
    throw SimError(source + ": " + what + " '" + name + "' not found");
  }
  return id;
}

std::vector<double> custom_numeric(const mjModel* m, const std::string& name) {
  const int id = mj_name2id(m, mjOBJ_NUMERIC, name.c_str());
  if (id < 0) return {};
  const int adr = m->numeric_adr[id];
  return std::vector<double>(m->numeric_data + adr,
                             m->numeric_data + adr + m->numeric_size[id]);
}

const char* custom_text(const mjModel* m, const std::string& name) {
  const int id = mj_name2id(m, mjOBJ_TEXT, name.c_str());
  return id < 0 ? nullptr : m->text_data + m->text_adr[id];
}

}  // namespace vmh::sim
