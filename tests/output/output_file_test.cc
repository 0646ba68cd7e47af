// output/output_file.h: single files through a unique temporary name, and
// a folder's files as one set renamed into place whole (OutputSet).
#include "output/output_file.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "tests/support/read_file.h"

namespace vmh::output {
namespace {

namespace fs = std::filesystem;

fs::path fresh(const std::string& name) {
  const fs::path d = fs::path(::testing::TempDir()) / ("vmh_output_file_" + name);
  fs::remove_all(d);
  return d;
}


// the names in a folder
std::set<std::string> names(const fs::path& d) {
  std::set<std::string> n;
  for (const auto& e : fs::directory_iterator(d)) n.insert(e.path().filename().string());
  return n;
}

TEST(WriteFileAtomically, WritesAndLeavesNoTemporary) {
  const fs::path d = fresh("single");
  fs::create_directories(d);
  write_file_atomically((d / "a.txt").string(), "one");
  write_file_atomically((d / "a.txt").string(), "two");
  EXPECT_EQ(vmh::testing::read_file(d / "a.txt"), "two");
  EXPECT_EQ(names(d), std::set<std::string>({"a.txt"}));
}

TEST(WriteFileAtomically, NamesThePathAndTheOsReason) {
  const fs::path d = fresh("single_missing");
  try {
    write_file_atomically((d / "no" / "a.txt").string(), "x");
    FAIL() << "written";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              (d / "no" / "a.txt").string() + ": No such file or directory");
  }
}

// Only a regular file is replaced: a rename over a FIFO, a folder, a
// symbolic link or a device node would put the file in its place.
TEST(WriteFileAtomically, ReplacesOnlyARegularFile) {
  const fs::path d = fresh("not_regular");
  fs::create_directories(d / "folder");
  ASSERT_EQ(mkfifo((d / "fifo").c_str(), 0600), 0);
  std::ofstream(d / "target") << "kept";
  fs::create_symlink(d / "target", d / "link");
  for (const char* name : {"fifo", "folder", "link"}) {
    try {
      write_file_atomically((d / name).string(), "x");
      ADD_FAILURE() << name << " replaced";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find((d / name).string() +
                                           ": exists and is not a regular file"),
                std::string::npos)
          << e.what();
    }
  }
  EXPECT_TRUE(fs::is_fifo(d / "fifo"));
  EXPECT_TRUE(fs::is_directory(d / "folder"));
  EXPECT_TRUE(fs::is_symlink(d / "link"));
  EXPECT_EQ(vmh::testing::read_file(d / "target"), "kept");
  // nothing else was left: no temporary beside them
  EXPECT_EQ(names(d), std::set<std::string>({"fifo", "folder", "link", "target"}));
  // /dev/null is a device: refused by type, never opened for the rename
  try {
    write_file_atomically("/dev/null", "x");
    ADD_FAILURE() << "/dev/null replaced";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("(a character device)"), std::string::npos)
        << e.what();
  }
}

TEST(OutputSet, FirstSetIsRenamedIntoPlace) {
  const fs::path d = fresh("first");
  {
    OutputSet set((d / "case1").string());
    EXPECT_EQ(fs::path(set.temp_dir()).parent_path(), d);
    EXPECT_EQ(fs::path(set.temp_dir()).filename().string().rfind(
                  ".case1.tmp-" + std::to_string(getpid()) + "-", 0),
              0u);
    set.write("a.txt", "A");
    set.write("b.txt", "B");
    // nothing at the destination until the set is complete
    EXPECT_FALSE(fs::exists(d / "case1"));
    set.commit();
  }
  EXPECT_EQ(names(d), std::set<std::string>({"case1"}));
  EXPECT_EQ(names(d / "case1"), std::set<std::string>({"a.txt", "b.txt"}));
  EXPECT_EQ(vmh::testing::read_file(d / "case1" / "a.txt"), "A");
}

// "out/" and "./out" name the folder "out" (a trailing '/' made the set
// rename itself into its own temporary folder: EINVAL); ".", ".." and "/"
// name no folder a set may replace whole, and are refused unwritten
TEST(OutputSet, ATrailingSlashIsTheSameFolderAndDotIsRefused) {
  const fs::path d = fresh("slash");
  {
    OutputSet set((d / "out").string() + "/");
    set.write("a.txt", "A");
    set.commit();
  }
  EXPECT_EQ(names(d), std::set<std::string>({"out"}));
  EXPECT_EQ(vmh::testing::read_file(d / "out" / "a.txt"), "A");
  {
    OutputSet set((d / "." / "out" / "x" / "..").string() + "//");
    set.write("b.txt", "B");
    set.commit();
  }
  EXPECT_EQ(names(d / "out"), std::set<std::string>({"b.txt"}));
  for (const std::string bad : {".", "..", "/", "./", "a/..", "../x/../.."}) {
    try {
      OutputSet set(bad);
      ADD_FAILURE() << "'" << bad << "' was taken as a set's folder";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("names no folder of its own"), std::string::npos)
          << e.what();
    }
  }
  EXPECT_EQ(names(d), std::set<std::string>({"out"}));
}

TEST(OutputSet, ASecondSetReplacesTheFirstWhole) {
  const fs::path d = fresh("second");
  {
    OutputSet set((d / "case1").string());
    set.write("a.txt", "old A");
    set.write("old_only.txt", "old");
    set.commit();
  }
  {
    OutputSet set((d / "case1").string());
    set.write("a.txt", "new A");
    // the previous set stays whole until the commit
    EXPECT_EQ(vmh::testing::read_file(d / "case1" / "a.txt"), "old A");
    set.commit();
  }
  EXPECT_EQ(names(d), std::set<std::string>({"case1"}));
  EXPECT_EQ(names(d / "case1"), std::set<std::string>({"a.txt"}));
  EXPECT_EQ(vmh::testing::read_file(d / "case1" / "a.txt"), "new A");
}

// an error part way (here a file that cannot be made; ENOSPC takes the same
// path): the exception names the file and the OS error, the temporary
// folder goes, the previous set stays as it was
TEST(OutputSet, AFailedSetLeavesThePreviousOneAndNoTemporary) {
  const fs::path d = fresh("failed");
  {
    OutputSet set((d / "case1").string());
    set.write("a.txt", "old A");
    set.commit();
  }
  try {
    OutputSet set((d / "case1").string());
    set.write("a.txt", "new A");
    set.write("no/b.txt", "B");
    set.commit();
    FAIL() << "committed";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              (d / "case1" / "no" / "b.txt").string() + ": No such file or directory");
  }
  EXPECT_EQ(names(d), std::set<std::string>({"case1"}));
  EXPECT_EQ(vmh::testing::read_file(d / "case1" / "a.txt"), "old A");
}

TEST(OutputSet, WithoutCommitNothingIsLeft) {
  const fs::path d = fresh("uncommitted");
  {
    OutputSet set((d / "case1").string());
    set.write("a.txt", "A");
  }
  EXPECT_TRUE(names(d).empty());
}

// many writers of one destination at once: each commit succeeds, the last
// set is whole (its two files agree), nothing else is left
TEST(OutputSet, ConcurrentWritersLeaveOneWholeSet) {
  const fs::path d = fresh("concurrent");
  std::vector<std::thread> threads;
  std::vector<std::string> errors(8);
  for (int t = 0; t < 8; ++t) {
    threads.emplace_back([&, t] {
      try {
        for (int i = 0; i < 20; ++i) {
          OutputSet set((d / "case1").string());
          const std::string tag = std::to_string(t) + "." + std::to_string(i);
          set.write("a.txt", tag);
          set.write("b.txt", tag);
          set.commit();
        }
      } catch (const std::exception& e) {
        errors[static_cast<std::size_t>(t)] = e.what();
      }
    });
  }
  for (std::thread& th : threads) th.join();
  for (const std::string& e : errors) EXPECT_EQ(e, "");
  EXPECT_EQ(names(d), std::set<std::string>({"case1"}));
  EXPECT_EQ(names(d / "case1"), std::set<std::string>({"a.txt", "b.txt"}));
  EXPECT_EQ(vmh::testing::read_file(d / "case1" / "a.txt"),
            vmh::testing::read_file(d / "case1" / "b.txt"));
}

// the check leaves things as they were: no probe, and no folder it made
TEST(CheckWritableDir, LeavesNoProbeAndNoFolderItMade) {
  const fs::path d = fresh("writable");
  fs::create_directories(d);
  check_writable_dir(d.string());
  EXPECT_TRUE(names(d).empty());
  check_writable_dir((d / "a" / "b").string());
  EXPECT_TRUE(names(d).empty());
}

// checks of one new folder at once, as two runs into one new --out make
// them: every one passes. Each check takes away the folders it made, so a
// check that found the folder there can see it vanish before its probe;
// it then makes it again instead of failing ("No such file or directory",
// seen with two runs under load)
TEST(CheckWritableDir, ConcurrentChecksOfOneNewFolderAllPass) {
  const fs::path d = fresh("check_concurrent");
  const std::string target = (d / "out" / "sub").string();
  std::vector<std::thread> threads;
  std::vector<std::string> errors(8);
  for (int t = 0; t < 8; ++t) {
    threads.emplace_back([&, t] {
      for (int i = 0; i < 300; ++i) {
        try {
          check_writable_dir(target);
        } catch (const std::exception& e) {
          errors[static_cast<std::size_t>(t)] = e.what();
          return;
        }
      }
    });
  }
  for (std::thread& th : threads) th.join();
  for (const std::string& e : errors) EXPECT_EQ(e, "");
}

TEST(CheckWritableDir, NamesAFileOrAPathUnderAFile) {
  const fs::path d = fresh("not_dir");
  fs::create_directories(d);
  std::ofstream(d / "file") << "x";
  for (const fs::path& p : {d / "file", d / "file" / "sub"}) {
    try {
      check_writable_dir(p.string());
      FAIL() << p;
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()), p.string() + ": Not a directory");
    }
  }
}

TEST(CheckWritableDir, NamesAReadOnlyFolder) {
  if (getuid() == 0) GTEST_SKIP() << "root writes in a read-only folder";
  const fs::path d = fresh("read_only");
  fs::create_directories(d);
  fs::permissions(d, fs::perms::owner_read | fs::perms::owner_exec);
  try {
    check_writable_dir(d.string());
    ADD_FAILURE() << "writable";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), d.string() + ": Permission denied");
  }
  fs::permissions(d, fs::perms::owner_all);
}

}  // namespace
}  // namespace vmh::output
