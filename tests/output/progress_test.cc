// The progress bar: what it draws against a fake clock, that concurrent
// advances all count, and that it keeps quiet on a stderr that is no
// terminal.
#include "output/progress.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <regex>
#include <sstream>
#include <thread>
#include <vector>

namespace vmh::output {
namespace {

// the percentages drawn, in order
std::vector<int> percents(const std::string& s) {
  std::vector<int> out;
  const std::regex re("(\\d+)% ");
  for (auto it = std::sregex_iterator(s.begin(), s.end(), re);
       it != std::sregex_iterator(); ++it) {
    out.push_back(std::stoi((*it)[1]));
  }
  return out;
}

TEST(ProgressTest, DrawsGrowingPercentagesCountAndEta) {
  std::ostringstream out;
  double now_s = 100.0;
  {
    Progress bar("cases", 4, &out, [&] { return now_s; });
    for (int i = 0; i < 4; ++i) {
      now_s += 2.0;  // 2 s an item: past the redraw interval every time
      bar.advance();
    }
    EXPECT_EQ(bar.done(), 4u);
  }
  const std::string s = out.str();
  // drawn at the start, each item as it came (2 s apart), then the final
  // state once more
  EXPECT_EQ(percents(s), (std::vector<int>{0, 25, 50, 75, 100, 100}));
  EXPECT_NE(s.find("1/4"), std::string::npos);
  EXPECT_NE(s.find("4/4"), std::string::npos);
  // after one item in 2 s, three are left at the same rate: 6 s
  EXPECT_NE(s.find("1/4  elapsed 0:02  eta 0:06"), std::string::npos) << s;
  EXPECT_NE(s.find("eta 0:00"), std::string::npos);
  EXPECT_EQ(s.find('\r'), 0u);  // redrawn in place
  EXPECT_EQ(s.back(), '\n');   // and the line ended once finished
}

TEST(ProgressTest, RedrawsAtMostTenTimesASecond) {
  std::ostringstream out;
  double now_s = 0.0;
  Progress bar("items", 1000, &out, [&] { return now_s; });
  for (int i = 0; i < 999; ++i) {
    now_s += 1e-4;  // 999 items in 0.1 s
    bar.advance();
  }
  const std::string drawn = out.str();
  const auto draws = std::count(drawn.begin(), drawn.end(), '\r');
  EXPECT_LE(draws, 3) << drawn;
  bar.advance();
  EXPECT_NE(out.str().find("1000/1000"), std::string::npos);  // the end is drawn
}

TEST(ProgressTest, ConcurrentAdvancesEndAtExactlyTheTotal) {
  std::ostringstream out;
  constexpr int kThreads = 8, kEach = 5000;
  Progress bar("threads", kThreads * kEach, &out);
  std::vector<std::thread> pool;
  for (int t = 0; t < kThreads; ++t) {
    pool.emplace_back([&] {
      for (int i = 0; i < kEach; ++i) bar.advance();
    });
  }
  for (std::thread& t : pool) t.join();
  EXPECT_EQ(bar.done(), static_cast<std::size_t>(kThreads * kEach));
  bar.finish();
  EXPECT_NE(out.str().find("40000/40000"), std::string::npos);
}

TEST(ProgressTest, PartsAddUpAndNeverGoBack) {
  std::ostringstream out;
  double now_s = 0.0;
  Progress bar("report", 0, &out, [&] { return now_s; });
  const std::size_t a = bar.add_part(6);
  const std::size_t b = bar.add_part(10);  // an estimate, corrected below
  EXPECT_EQ(bar.total(), 16u);
  bar.part(b)(2, 4);
  EXPECT_EQ(bar.total(), 10u);
  EXPECT_EQ(bar.done(), 2u);
  bar.part(a)(3, 6);
  bar.part(a)(1, 6);  // late report of an earlier count: ignored
  EXPECT_EQ(bar.done(), 5u);
  bar.part(b)(9, 4);  // past its total: held at it
  EXPECT_EQ(bar.done(), 7u);
}

TEST(ProgressTest, SilentWhenStderrIsNotATerminal) {
  // CaptureStderr puts a file on descriptor 2, which is no terminal
  ::testing::internal::CaptureStderr();
  const bool terminal = is_terminal(2);
  {
    Progress bar("quiet", 3);
    EXPECT_FALSE(bar.drawing());
    bar.advance(3);
  }
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_FALSE(terminal);
  EXPECT_EQ(err, "");
}

TEST(ProgressTest, FormatLineNamesWhatIsLeft) {
  const std::string s = Progress::format_line("map", 0, 33, 0.0);
  EXPECT_NE(s.find("0/33"), std::string::npos);
  EXPECT_NE(s.find("eta --:--"), std::string::npos);  // no rate yet
  EXPECT_NE(Progress::format_line("map", 33, 33, 3725.0).find("1:02:05"),
            std::string::npos);
}

}  // namespace
}  // namespace vmh::output
