// studies/report_job: what the job refuses before it runs anything. The
// job itself (every case, study and the page) is checked end to end by
// tests/cli/report_cli_test.cc, through the command line.
#include "studies/report_job.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>

namespace vmh::studies {
namespace {

namespace fs = std::filesystem;

thesis::RenderFn rjt_no_picture() {
  return [](const std::string&, const std::string&, std::string* why_not) {
    *why_not = "test";
    return std::optional<std::string>();
  };
}

std::string rjt_refusal(const ReportJob& job) {
  try {
    make_report(job);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(ReportJob, RefusesAJobItCannotRunBeforeRunningAnything) {
  const fs::path dir = fs::path(::testing::TempDir()) / "vmh_report_job_refusals";
  fs::remove_all(dir);
  ReportJob job;
  job.out_dir = dir.string();
  job.render = rjt_no_picture();
  job.jobs = 0;
  EXPECT_NE(rjt_refusal(job).find("jobs must be >= 1, got 0"), std::string::npos);
  job.jobs = 1;
  job.out_dir.clear();
  EXPECT_NE(rjt_refusal(job).find("no output folder"), std::string::npos);
  job.out_dir = dir.string();
  job.render = nullptr;
  EXPECT_NE(rjt_refusal(job).find("no renderer"), std::string::npos);
  // nothing was made for any of them
  EXPECT_FALSE(fs::exists(dir));
}

TEST(ReportJob, NamesAFolderItCannotMake) {
  const fs::path file = fs::path(::testing::TempDir()) / "vmh_report_job_file";
  { std::FILE* f = std::fopen(file.c_str(), "w"); ASSERT_NE(f, nullptr); std::fclose(f); }
  ReportJob job;
  job.out_dir = file.string();  // a file where the folder would be
  job.render = rjt_no_picture();
  const std::string why = rjt_refusal(job);
  EXPECT_NE(why.find("cannot create directory"), std::string::npos) << why;
  EXPECT_NE(why.find(file.string()), std::string::npos) << why;
  fs::remove(file);
}

}  // namespace
}  // namespace vmh::studies
