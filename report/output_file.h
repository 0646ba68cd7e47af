// Writing the testbed's outputs (traces, summaries, tables, plots) so that a
// failed or interrupted write never leaves a half-written file behind.
#ifndef VMHAPTICS_REPORT_OUTPUT_FILE_H_
#define VMHAPTICS_REPORT_OUTPUT_FILE_H_

#include <string>

namespace vmh::report {

// Writes `text` to `path` through "<path>.tmp" and a rename (atomic on one
// file system): readers see the old file or the whole new one. Throws
// std::runtime_error naming the path when it cannot open, write or rename.
void write_file_atomically(const std::string& path, const std::string& text);

// Creates `dir` if needed and writes dir/name as write_file_atomically does.
// Returns the path written. Throws std::runtime_error naming the folder or
// the path.
std::string write_file_in(const std::string& dir, const std::string& name,
                          const std::string& text);

}  // namespace vmh::report

#endif  // VMHAPTICS_REPORT_OUTPUT_FILE_H_
