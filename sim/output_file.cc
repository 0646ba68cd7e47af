#include "sim/output_file.h"

#include <filesystem>
#include <fstream>
#include <system_error>

#include "sim/mujoco_util.h"

namespace vmh::sim {

void write_file_atomically(const std::string& path, const std::string& text) {
  namespace fs = std::filesystem;
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw SimError(tmp + ": cannot open for writing");
    out << text;
    out.flush();
    if (!out) {
      out.close();
      std::error_code ignored;
      fs::remove(tmp, ignored);
      throw SimError(tmp + ": write failed");
    }
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw SimError(path + ": " + ec.message());
  }
}

}  // namespace vmh::sim
