// Writing the testbed's outputs (traces, summaries, tables, plots) so that a
// failed or interrupted write never leaves a half-written file behind.
#ifndef VMHAPTICS_OUTPUT_OUTPUT_FILE_H_
#define VMHAPTICS_OUTPUT_OUTPUT_FILE_H_

#include <sys/types.h>

#include <cstdint>
#include <string>

namespace vmh::output {

// What a path that is not a regular file is, for messages: "a folder",
// "a FIFO", "a socket", "a character device", "a block device", "a
// symbolic link" (as lstat sees it), else "not a regular file".
std::string file_kind(mode_t mode);

// Throws std::runtime_error "<path>: exists and is not a regular file (<its
// kind>); it is not replaced" unless nothing or a regular file is at `path`
// (a symbolic link is not followed): what write_file_atomically checks
// first, for a command that must know before it does its work.
void check_replaceable(const std::string& path);

// Reading what a user hands the program (scenes, recordings, stored
// calibrations) so that no file can hang or exhaust the reader: opens
// `path` for reading if it is a regular file of at most max_bytes and
// returns the descriptor (O_RDONLY | O_NONBLOCK | O_CLOEXEC; checked again
// with fstat once open, so a FIFO swapped in after the stat is refused
// rather than waited on), or -1 with *missing = true when nothing is
// there. Throws std::runtime_error "<path> is a FIFO, not a regular file",
// "<path> is N bytes, over the reader's bound of M", or the OS error.
int open_regular_file(const std::string& path, std::uint64_t max_bytes,
                      bool* missing);

// The whole of such a file, the bound checked again as it is read (a file
// that grows while it is read is refused at the bound). Throws as
// open_regular_file; *missing as there.
std::string read_regular_file(const std::string& path, std::uint64_t max_bytes,
                              bool* missing);

// "N bytes", or "N MiB" for whole MiB: sizes in messages
std::string bytes_text(std::uint64_t bytes);

// Writes `text` to `path` through a temporary file beside it, named
// "<path>.tmp-<pid>-<n>" (unique per process and per call, so two processes
// writing the same path never share one), and a rename (atomic on one file
// system): readers see the old file or the whole new one. Only a regular
// file is replaced: anything else at `path` (a device node, a FIFO, a
// folder, a symbolic link) is refused, since the rename would put the file
// in its place. Throws std::runtime_error naming the path and the OS error
// (or what is at the path) when it cannot open, write or rename; the
// temporary file is removed.
void write_file_atomically(const std::string& path, const std::string& text);

// Creates `dir` if needed and writes dir/name as write_file_atomically does.
// Returns the path written. Throws std::runtime_error naming the folder or
// the path.
std::string write_file_in(const std::string& dir, const std::string& name,
                          const std::string& text);

// Checks that `dir` is a folder this process can write in: creates it (and
// its parents) if needed, creates and removes a probe file in it, then
// removes the folders it created (the writers create them again), so that
// the check itself leaves nothing. Checks of one new folder may run at
// once (two runs into one new --out): a folder another check took away
// meanwhile is made again. Throws std::runtime_error "<dir>: <the OS's
// reason>" (e.g. "Not a directory", "Permission denied") otherwise.
void check_writable_dir(const std::string& dir);

// A folder's files written as one set: they go into a private temporary
// folder beside `dest` (".<name>.tmp-<pid>-XXXXXX", made as mkdtemp makes
// it), and commit() renames that folder to `dest` once every file is
// complete. An existing `dest` is swapped for the new one at once (Linux's
// renameat2 RENAME_EXCHANGE; else moved aside to a private name first) and
// then removed: a reader sees the previous whole set or the new whole set,
// never a mix. Without commit() (an error, an interrupt) the destructor
// removes the temporary folder and `dest` is left as it was.
class OutputSet {
 public:
  // Creates dest's parent if needed and the temporary folder. `dest` is
  // taken as its lexically normal form without a trailing '/' ("out/" and
  // "./out" are "out"). Throws std::runtime_error naming the folder and the
  // OS error, or for a dest that names no folder of its own (".", "..",
  // "/", "a/.."): a set would replace the current folder or a parent.
  explicit OutputSet(const std::string& dest);
  ~OutputSet();  // removes the temporary folder unless committed
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;

  // Writes dest/name (in the temporary folder for now). Throws
  // std::runtime_error "dest/name: <the OS's reason>".
  void write(const std::string& name, const std::string& text);
  // Puts the set in place of `dest`. Throws std::runtime_error naming dest
  // and the OS error (the temporary folder is removed then too).
  void commit();

  const std::string& temp_dir() const { return tmp_; }

 private:
  std::string dest_;
  std::string tmp_;
  bool committed_ = false;
};

}  // namespace vmh::output

#endif  // VMHAPTICS_OUTPUT_OUTPUT_FILE_H_
