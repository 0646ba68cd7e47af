#include "sim/cases/case_catalogue.h"

#include <cstdlib>
#include <filesystem>

#include "sim/mujoco_util.h"

#ifndef VMH_DEFAULT_MODELS_DIR
#define VMH_DEFAULT_MODELS_DIR "models"
#endif

namespace vmh::sim {

namespace fs = std::filesystem;

const std::vector<CaseEntry>& case_catalogue() {
  static const std::vector<CaseEntry> cases = {
      {"case1", "cases/case1.xml"}, {"case2", "cases/case2.xml"},
      {"case3", "cases/case3.xml"}, {"case4", "cases/case4.xml"},
      {"case5", "cases/case5.xml"}, {"case6", "cases/case6.xml"},
      {"case7", "cases/case7.xml"},
  };
  return cases;
}

std::string models_dir() {
  const char* env = std::getenv("VMH_MODELS_DIR");
  if (env != nullptr && env[0] != '\0') return env;
  return VMH_DEFAULT_MODELS_DIR;
}

std::string resolve_scene(const std::string& case_or_path, std::string* name) {
  for (const CaseEntry& c : case_catalogue()) {
    if (case_or_path == c.name) {
      *name = c.name;
      return (fs::path(models_dir()) / c.scene).string();
    }
  }
  // without throwing: a symlink loop or a name too long for the file
  // system is a bad argument (SimError), not a failure; and only a regular
  // file is a scene (a FIFO would block the loader forever)
  std::error_code ec;
  const fs::file_status st = fs::status(case_or_path, ec);
  if (!ec && fs::is_regular_file(st)) {
    *name = fs::path(case_or_path).stem().string();
    return case_or_path;
  }
  if (!ec && fs::exists(st)) {
    throw SimError("'" + case_or_path +
                   "' is not a regular file (a scene is an MJCF file)");
  }
  if (ec && ec != std::errc::no_such_file_or_directory) {
    throw SimError("'" + case_or_path + "': " + ec.message());
  }
  std::string known;
  for (const CaseEntry& c : case_catalogue()) known += std::string(" ") + c.name;
  throw SimError("'" + case_or_path +
                 "' is neither a case (" + known.substr(1) +
                 ") nor an existing scene file");
}

}  // namespace vmh::sim
