// Reading a file the tests' programs wrote: whole, or its first line.
#ifndef VMHAPTICS_TESTS_SUPPORT_READ_FILE_H_
#define VMHAPTICS_TESTS_SUPPORT_READ_FILE_H_

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace vmh::testing {

// a whole file, as its bytes ("" if it cannot be read)
inline std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// the first line of a text file ("" if it cannot be read)
inline std::string first_line(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::string line;
  std::getline(in, line);
  return line;
}

}  // namespace vmh::testing

#endif  // VMHAPTICS_TESTS_SUPPORT_READ_FILE_H_
