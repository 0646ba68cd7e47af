#include "output/output_file.h"

#include <fcntl.h>
#include <stdio.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <random>
#include <stdexcept>
#include <system_error>
#include <vector>

namespace vmh::output {
namespace fs = std::filesystem;
namespace {

// "-<pid>-<n>": unique among this process's calls and other processes'
std::string unique_suffix() {
  static std::atomic<unsigned long> counter{0};
  return "-" + std::to_string(static_cast<long>(getpid())) + "-" +
         std::to_string(++counter);
}

std::string os_error(int err) { return std::strerror(err); }

// writes `text` to a new file `path` (which must not exist), mode 0666 less
// the umask; returns 0 or the errno of what failed (the file is removed)
int write_new_file(const std::string& path, const std::string& text) {
  const int fd = open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) return errno;
  const char* p = text.data();
  std::size_t left = text.size();
  int err = 0;
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      err = errno;
      break;
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  if (close(fd) != 0 && err == 0) err = errno;
  if (err != 0) unlink(path.c_str());
  return err;
}

}  // namespace

std::string file_kind(mode_t mode) {
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISLNK(mode)) return "a symbolic link";
  return "not a regular file";
}

std::string bytes_text(std::uint64_t b) {
  char buf[64];
  if (b != 0 && b % (std::uint64_t{1} << 20) == 0) {
    std::snprintf(buf, sizeof buf, "%llu MiB",
                  static_cast<unsigned long long>(b >> 20));
  } else {
    std::snprintf(buf, sizeof buf, "%llu bytes",
                  static_cast<unsigned long long>(b));
  }
  return buf;
}

int open_regular_file(const std::string& path, std::uint64_t max_bytes,
                      bool* missing) {
  *missing = false;
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    if (errno == ENOENT) {
      *missing = true;
      return -1;
    }
    throw std::runtime_error(path + ": " + std::strerror(errno));
  }
  if (!S_ISREG(st.st_mode)) {
    throw std::runtime_error(path + " is " + file_kind(st.st_mode) +
                             ", not a regular file");
  }
  if (static_cast<std::uint64_t>(st.st_size) > max_bytes) {
    throw std::runtime_error(path + " is " +
                             bytes_text(static_cast<std::uint64_t>(st.st_size)) +
                             ", over the reader's bound of " + bytes_text(max_bytes));
  }
  // O_NONBLOCK: a FIFO put in its place after the stat opens without
  // waiting for a writer, and the fstat below refuses it
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw std::runtime_error(path + ": " + std::strerror(errno));
  struct stat st2 {};
  if (::fstat(fd, &st2) != 0 || !S_ISREG(st2.st_mode)) {
    ::close(fd);
    throw std::runtime_error(path + " changed into something that is not a "
                             "regular file while it was opened");
  }
  return fd;
}

std::string read_regular_file(const std::string& path, std::uint64_t max_bytes,
                              bool* missing) {
  const int fd = open_regular_file(path, max_bytes, missing);
  if (fd < 0) return {};
  std::string text;
  char buf[65536];
  for (;;) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int e = errno;
      ::close(fd);
      throw std::runtime_error(path + ": " + std::strerror(e));
    }
    if (n == 0) break;
    text.append(buf, static_cast<std::size_t>(n));
    if (text.size() > max_bytes) {
      ::close(fd);
      throw std::runtime_error(path + " grew over the reader's bound of " +
                               bytes_text(max_bytes) + " while it was read");
    }
  }
  ::close(fd);
  return text;
}

void check_replaceable(const std::string& path) {
  // the rename would put a file in place of whatever is at `path`: a
  // device node, a FIFO, a folder, a link are refused, not replaced
  struct stat st {};
  if (lstat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
    throw std::runtime_error(path + ": exists and is not a regular file (" +
                             file_kind(st.st_mode) + "); it is not replaced");
  }
}

void write_file_atomically(const std::string& path, const std::string& text) {
  check_replaceable(path);
  const std::string tmp = path + ".tmp" + unique_suffix();
  if (const int err = write_new_file(tmp, text)) {
    throw std::runtime_error(path + ": " + os_error(err));
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    unlink(tmp.c_str());
    throw std::runtime_error(path + ": " + os_error(err));
  }
}

std::string write_file_in(const std::string& dir, const std::string& name,
                          const std::string& text) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw std::runtime_error(dir + ": " + ec.message());
  const std::string path = (fs::path(dir) / name).string();
  write_file_atomically(path, text);
  return path;
}

void check_writable_dir(const std::string& dir) {
  std::error_code ec;
  const fs::file_status st = fs::status(dir, ec);
  if (fs::exists(st) && !fs::is_directory(st)) {
    throw std::runtime_error(dir + ": " + os_error(ENOTDIR));
  }
  // Another process's check of the same new folder (two runs into one new
  // --out) takes away the folders it made, possibly between this check's
  // making them (or finding them) and its probe, or inside
  // create_directories (which then reports EEXIST for a folder that was
  // there when it looked and gone when it checked): the attempt is made
  // again on ENOENT or EEXIST, a bounded number of times.
  constexpr int kAttempts = 50;
  for (int attempt = 1;; ++attempt) {
    // the folders this attempt makes, deepest first, to be taken away
    // again: a run refused later for bad input leaves nothing behind
    std::vector<fs::path> made;
    for (fs::path p = fs::path(dir); !p.empty() && !fs::exists(fs::symlink_status(p, ec));
         p = p.parent_path()) {
      made.push_back(p);
      if (p == p.parent_path()) break;
    }
    const auto unmake = [&made] {
      // rmdir only: a folder another run has written in meanwhile stays
      for (const fs::path& p : made) rmdir(p.c_str());
    };
    int err = 0;
    fs::create_directories(dir, ec);
    if (ec) {
      err = ec.value();
    } else {
      std::string probe = (fs::path(dir) / ".vmh-probe-XXXXXX").string();
      const int fd = mkstemp(probe.data());
      if (fd >= 0) {
        close(fd);
        unlink(probe.c_str());
        unmake();
        return;
      }
      err = errno;
    }
    unmake();
    if ((err != ENOENT && err != EEXIST) || attempt == kAttempts) {
      throw std::runtime_error(dir + ": " + os_error(err));
    }
  }
}

OutputSet::OutputSet(const std::string& dest) {
  // "out/", "./out" and "out" name one folder; ".", ".." and "/" name no
  // folder a set could replace whole (the current one, a parent, the root)
  fs::path d = fs::path(dest).lexically_normal();
  if (!d.has_filename() && d.has_parent_path() && d.parent_path() != d) {
    d = d.parent_path();
  }
  const std::string name = d.filename().string();
  if (name.empty() || name == "." || name == "..") {
    throw std::runtime_error("'" + dest + "' names no folder of its own (the current "
                             "folder, a parent or the root): a set replaces its "
                             "folder whole, so give it a folder's name");
  }
  dest_ = d.string();
  const fs::path parent = d.has_parent_path() ? d.parent_path() : fs::path(".");
  std::error_code ec;
  fs::create_directories(parent, ec);
  if (ec) throw std::runtime_error(parent.string() + ": " + ec.message());
  std::string templ = (parent / ("." + d.filename().string() + ".tmp-" +
                                 std::to_string(static_cast<long>(getpid())) +
                                 "-XXXXXX"))
                          .string();
  if (mkdtemp(templ.data()) == nullptr) {
    throw std::runtime_error(parent.string() + ": cannot make a folder in it (" +
                             os_error(errno) + ")");
  }
  // mkdtemp makes it 0700; the set's folder gets a folder's usual mode
  const mode_t mask = 022;
  chmod(templ.c_str(), 0777 & ~mask);
  tmp_ = templ;
}

OutputSet::~OutputSet() {
  if (!committed_ && !tmp_.empty()) {
    std::error_code ignored;
    fs::remove_all(tmp_, ignored);
  }
}

void OutputSet::write(const std::string& name, const std::string& text) {
  const std::string path = (fs::path(tmp_) / name).string();
  if (const int err = write_new_file(path, text)) {
    throw std::runtime_error((fs::path(dest_) / name).string() + ": " + os_error(err));
  }
}

void OutputSet::commit() {
  // another run may put its set in place between any two steps: retry
  for (int attempt = 0; attempt < 100; ++attempt) {
    // no set there yet: a plain rename (it fails if another run's set
    // arrived meanwhile)
    std::error_code ec;
    if (!fs::exists(fs::symlink_status(dest_, ec))) {
      if (std::rename(tmp_.c_str(), dest_.c_str()) == 0) {
        committed_ = true;
        return;
      }
      if (errno != ENOTEMPTY && errno != EEXIST) break;
      continue;
    }
#ifdef RENAME_EXCHANGE
    if (renameat2(AT_FDCWD, tmp_.c_str(), AT_FDCWD, dest_.c_str(),
                  RENAME_EXCHANGE) == 0) {
      // tmp_ holds the previous set now
      committed_ = true;
      std::error_code ignored;
      fs::remove_all(tmp_, ignored);
      return;
    }
    if (errno == ENOENT) continue;  // removed meanwhile
    if (errno != EINVAL && errno != ENOSYS && errno != EOPNOTSUPP) break;
#endif
    // no atomic exchange on this file system: the previous set aside to a
    // private name, the new one in, the previous one removed
    const fs::path d(dest_);
    std::string aside =
        (d.parent_path() / ("." + d.filename().string() + ".old-" +
                            std::to_string(static_cast<long>(getpid())) + "-XXXXXX"))
            .string();
    if (mkdtemp(aside.data()) == nullptr) break;
    if (std::rename(dest_.c_str(), aside.c_str()) != 0) {
      const int err = errno;
      rmdir(aside.c_str());
      if (err == ENOENT) continue;
      errno = err;
      break;
    }
    const bool in = std::rename(tmp_.c_str(), dest_.c_str()) == 0;
    const int err = errno;
    std::error_code ignored;
    fs::remove_all(aside, ignored);
    if (in) {
      committed_ = true;
      return;
    }
    if (err != ENOTEMPTY && err != EEXIST) {
      errno = err;
      break;
    }
  }
  const int err = errno;
  std::error_code ignored;
  fs::remove_all(tmp_, ignored);
  tmp_.clear();
  throw std::runtime_error(dest_ + ": " + os_error(err != 0 ? err : EBUSY));
}

}  // namespace vmh::output
