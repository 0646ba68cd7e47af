// Small MJCF scenes written from strings into a fresh temporary directory,
// so that a test can build exactly the scene it needs (a missing joint, a
// bad <custom> field) and load it the way the simulator does, by path. The
// directory is removed with the object.
#ifndef VMHAPTICS_TESTS_SUPPORT_TEMP_MJCF_H_
#define VMHAPTICS_TESTS_SUPPORT_TEMP_MJCF_H_

#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>

namespace vmh::testing {

class TempMjcfDir {
 public:
  TempMjcfDir() {
    static std::atomic<int> counter{0};
    std::random_device rd;
    dir_ = std::filesystem::temp_directory_path() /
           ("vmh_simtest_" + std::to_string(::getpid()) + "_" +
            std::to_string(counter++) + "_" + std::to_string(rd()));
    std::filesystem::create_directories(dir_);
  }
  ~TempMjcfDir() {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  TempMjcfDir(const TempMjcfDir&) = delete;
  TempMjcfDir& operator=(const TempMjcfDir&) = delete;

  // writes `xml` to <dir>/<name> and returns the file's path
  std::string write(const std::string& name, const std::string& xml) const {
    const std::filesystem::path p = dir_ / name;
    std::ofstream out(p);
    out << xml;
    if (!out) throw std::runtime_error("cannot write " + p.string());
    return p.string();
  }

  // the directory itself
  const std::filesystem::path& path() const { return dir_; }

 private:
  std::filesystem::path dir_;
};

// <numeric> and <text> entries of a <custom> block
inline std::string numeric_field(const std::string& name,
                                 const std::string& data) {
  return "<numeric name=\"" + name + "\" data=\"" + data + "\"/>";
}
inline std::string text_field(const std::string& name,
                              const std::string& data) {
  return "<text name=\"" + name + "\" data=\"" + data + "\"/>";
}

// a scene with no bodies, only the given <custom> entries
inline std::string custom_only_scene(const std::string& custom_entries) {
  return "<mujoco model=\"custom_only\">\n  <custom>\n    " + custom_entries +
         "\n  </custom>\n</mujoco>\n";
}

}  // namespace vmh::testing

#endif  // VMHAPTICS_TESTS_SUPPORT_TEMP_MJCF_H_
