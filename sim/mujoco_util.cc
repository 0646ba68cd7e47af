#include "sim/mujoco_util.h"

#include <fstream>
#include <mutex>

#include "sim/mujoco_messages.h"

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

ModelPtr load_locked(const std::string& path) {
  // mj_loadXML's own message for a missing file is terse; say it plainly
  if (!std::ifstream(path).good()) {
    throw SimError(path + ": cannot open the scene file");
  }
  char err[1024] = "";
  ModelPtr m(mj_loadXML(path.c_str(), nullptr, err, sizeof err));
  if (!m) throw SimError(path + ": " + one_line(err, "MuJoCo could not load it"));
  return m;
}

}  // namespace

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
