// What the recording reader's two files share (recording_reader.cc,
// recording_meta.cc). Internal to the runtime library.
#ifndef VMHAPTICS_RUNTIME_RECORDING_DETAIL_H_
#define VMHAPTICS_RUNTIME_RECORDING_DETAIL_H_

#include <string>
#include <string_view>

namespace vmh::runtime::recording_detail {

// a cell, shown in a message: at most 40 characters, control characters
// escaped, so that a binary file's bytes do not end up on the terminal
std::string shown(std::string_view s);

}  // namespace vmh::runtime::recording_detail

#endif  // VMHAPTICS_RUNTIME_RECORDING_DETAIL_H_
