#include "report/output_file.h"

#include <filesystem>
#include <fstream>
#include <system_error>

#include <stdexcept>

namespace vmh::report {

void write_file_atomically(const std::string& path, const std::string& text) {
  namespace fs = std::filesystem;
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw std::runtime_error(tmp + ": cannot open for writing");
    out << text;
    out.flush();
    if (!out) {
      out.close();
      std::error_code ignored;
      fs::remove(tmp, ignored);
      throw std::runtime_error(tmp + ": write failed");
    }
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw std::runtime_error(path + ": " + ec.message());
  }
}

std::string write_file_in(const std::string& dir, const std::string& name,
                          const std::string& text) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw std::runtime_error(dir + ": " + ec.message());
  const std::string path = (fs::path(dir) / name).string();
  write_file_atomically(path, text);
  return path;
}

}  // namespace vmh::report
