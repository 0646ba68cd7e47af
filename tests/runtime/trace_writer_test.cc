// trace.csv's writer (runtime/trace_writer.h): the column groups follow the
// layout, every row has the header's cell count whatever the record holds,
// the values are the record's, and a write that fails names the file.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>

#include "runtime/trace_writer.h"

namespace vmh::runtime {
namespace {

std::vector<std::string> cells(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string c;
  while (std::getline(ss, c, ',')) out.push_back(c);
  if (!line.empty() && line.back() == ',') out.push_back("");
  return out;
}

int index_of(const std::vector<std::string>& cols, const std::string& name) {
  for (std::size_t i = 0; i < cols.size(); ++i) {
    if (cols[i] == name) return static_cast<int>(i);
  }
  return -1;
}

TraceLayout full() {
  TraceLayout l;
  l.controller = true;
  l.vm_dof = 2;
  l.truth = true;
  l.phases = {"settle", "on_path"};
  l.present = kStateJoints | kStateButtons | kStateInkwell | kStateTransform |
              kStateVelocity | kStateJacobian | kStateEncoders | kStatePots;
  return l;
}

TEST(TraceWriter, GroupsFollowTheLayout) {
  TraceLayout bare;
  const auto b = trace_columns(bare);
  EXPECT_EQ(index_of(b, "theta_v_1"), -1);
  EXPECT_EQ(index_of(b, "tau_applied_1_Nm"), -1);
  EXPECT_EQ(index_of(b, "phase"), -1);
  EXPECT_EQ(index_of(b, "buttons"), -1);
  for (const char* c : {"t_s", "period_s", "q1_rad", "q6_rad", "p_x_mm", "a_z",
                        "tau_1_Nm", "tau_sent_3_Nm", "read_error",
                        "safety_flags", "ramp_scale"}) {
    EXPECT_GE(index_of(b, c), 0) << c;
  }
  const auto f = trace_columns(full());
  for (const char* c : {"theta_v_2", "theta_r_2", "xv_z_mm", "e_6_rad",
                        "f_6_Nmm", "F_z_N", "tau_applied_3_Nm", "hand_z_mm",
                        "hand_F_z_N", "d_path_mm", "status", "phase", "buttons",
                        "docked", "dev_p_z_mm", "dev_R_33", "dev_v_z_mm_s",
                        "dev_J_66", "enc_3", "pot_6"}) {
    EXPECT_GE(index_of(f, c), 0) << c;
  }
  EXPECT_EQ(index_of(f, "theta_v_3"), -1);
  // run's order: the reading, the controller, the torques, the plant
  EXPECT_LT(index_of(f, "a_z"), index_of(f, "theta_v_1"));
  EXPECT_LT(index_of(f, "F_z_N"), index_of(f, "tau_1_Nm"));
  EXPECT_LT(index_of(f, "tau_sent_3_Nm"), index_of(f, "tau_applied_1_Nm"));
  EXPECT_LT(index_of(f, "hand_F_z_N"), index_of(f, "d_path_mm"));
}

TEST(TraceWriter, EveryRowHasTheHeadersCellsAndTheRecordsValues) {
  const TraceLayout l = full();
  const auto cols = trace_columns(l);
  TickRecord r;
  r.t_s = 1.25;
  r.period_s = 1e-3;
  r.q_dh << 0.1, 0.2, 0.3, 0.4, 0.5, 0.6;
  r.p_mm << 1, 2, 3;
  r.tau_cmd_Nm << 0.01, -0.02, 0.03;
  r.has_truth = true;
  r.segment = 1;
  r.hand_target.p_mm << 7, 8, 9;
  r.safety = kSafetyForceRamping | kSafetyDocked;
  r.state.present = kStateJoints | kStateEncoders;  // no transform this tick
  r.state.encoder_counts = {5, -6, 7};
  std::string row;
  append_trace_row(r, l, &row);
  ASSERT_EQ(row.back(), '\n');
  row.pop_back();
  const auto c = cells(row);
  ASSERT_EQ(c.size(), cols.size());
  EXPECT_EQ(c[static_cast<std::size_t>(index_of(cols, "t_s"))], "1.25");
  EXPECT_EQ(c[static_cast<std::size_t>(index_of(cols, "q6_rad"))], "0.6");
  EXPECT_EQ(c[static_cast<std::size_t>(index_of(cols, "tau_2_Nm"))], "-0.02");
  EXPECT_EQ(c[static_cast<std::size_t>(index_of(cols, "hand_y_mm"))], "8");
  EXPECT_EQ(c[static_cast<std::size_t>(index_of(cols, "phase"))], "on_path");
  EXPECT_EQ(c[static_cast<std::size_t>(index_of(cols, "safety_flags"))],
            "force_ramping|docked");
  EXPECT_EQ(c[static_cast<std::size_t>(index_of(cols, "dev_p_x_mm"))], "nan");
  EXPECT_EQ(c[static_cast<std::size_t>(index_of(cols, "enc_2"))], "-6");
  // without truth, the plant's cells are nan and the phase empty
  r.has_truth = false;
  row.clear();
  append_trace_row(r, l, &row);
  row.pop_back();
  const auto d = cells(row);
  ASSERT_EQ(d.size(), cols.size());
  EXPECT_EQ(d[static_cast<std::size_t>(index_of(cols, "hand_y_mm"))], "nan");
  EXPECT_EQ(d[static_cast<std::size_t>(index_of(cols, "phase"))], "");
}

// The numbers are written by a scaled-integer path or by std::to_chars;
// their text must be printf's "%.9g" (what the trace wrote before, and what
// readers of it were checked on), over magnitudes from denormals to 1e300,
// both signs, the values with nine and fewer digits, and the non-finite
// ones.
TEST(TraceWriter, NumbersAreWrittenAsPrintfWritesThem) {
  TraceLayout bare;
  const auto cols = trace_columns(bare);
  const auto t_col = static_cast<std::size_t>(index_of(cols, "t_s"));
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> mantissa(1.0, 10.0);
  std::uniform_int_distribution<int> exponent(-320, 300);
  std::vector<double> values = {0.0, -0.0, 1.0, -1.0, 0.1, 1e-3, 123456789.0,
                                1234567891.0, 0.5e-323, 1e300,
                                std::numeric_limits<double>::infinity(),
                                -std::numeric_limits<double>::infinity(),
                                std::nan(""), -std::nan(""),
                                std::numeric_limits<double>::max(),
                                std::numeric_limits<double>::denorm_min()};
  for (int i = 0; i < 200000; ++i) {
    double v = mantissa(rng) * std::pow(10.0, exponent(rng));
    if (i % 2) v = -v;
    if (i % 5 == 0) v = std::round(v * 1e4) / 1e4;  // few digits
    values.push_back(v);
  }
  // where the trace's numbers are (1e-14..1e30 is written without
  // std::to_chars): at the switches between fixed and scientific text,
  // where rounding carries into a new digit, at and near ties of the ninth
  // digit, and with nine or ten significant digits
  for (double v : {1e-5, 9.99999999e-5, 9.999999995e-5, 1e-4, 0.0001000000005,
                   99999999.95, 99999999.94999, 999999999.4, 999999999.5,
                   999999999.6, 1e9, 1e-14, 9.99999e-15, 1e30, 9.9999999e29,
                   1.234567885, 1.2345678850000001, 0.5, 2.5, 123456789.5,
                   0.1234567895, 44.030070349999, 1.00000000049999}) {
    values.push_back(v);
    values.push_back(-v);
  }
  std::uniform_int_distribution<int> near(-14, 29);
  std::uniform_int_distribution<long> digits(100000000L, 9999999999L);
  for (int i = 0; i < 200000; ++i) {
    const double d = static_cast<double>(digits(rng));
    const int e = near(rng);
    double v = d * std::pow(10.0, e - 9);
    if (i % 3 == 0) v = (std::floor(d / 10) + 0.5) * std::pow(10.0, e - 8);
    values.push_back(i % 2 ? -v : v);
  }
  int mismatches = 0;
  std::string row;
  for (double v : values) {
    TickRecord r;
    r.t_s = v;
    row.clear();
    append_trace_row(r, bare, &row);
    const std::string got = cells(row.substr(0, row.size() - 1))[t_col];
    char want[48];
    std::snprintf(want, sizeof want, "%.9g", v);
    if (got != want && ++mismatches <= 5) {
      ADD_FAILURE() << "wrote " << got << ", printf writes " << want;
    }
  }
  EXPECT_EQ(mismatches, 0);
}

TEST(TraceWriter, WritesHeaderAndRowsAndNamesAFailedWrite) {
  const std::string path = ::testing::TempDir() + "vmh_trace_writer.csv";
  {
    TraceWriter w(path, "shown/trace.csv", TraceLayout{});
    TickRecord r;
    for (int k = 0; k < 3; ++k) {
      r.t_s = k;
      w.add(r);
    }
    w.close();
  }
  std::ifstream in(path);
  std::string line;
  int lines = 0;
  while (std::getline(in, line)) ++lines;
  EXPECT_EQ(lines, 4);
  std::remove(path.c_str());
  try {
    TraceWriter w("/nonexistent_dir/x.csv", "DIR/trace.csv", TraceLayout{});
    FAIL() << "opened a file in a missing folder";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("DIR/trace.csv"), std::string::npos);
  }
  // a full disk: /dev/full takes the open and refuses the write
  TraceWriter w("/dev/full", "DIR/trace.csv", TraceLayout{});
  TickRecord r;
  w.add(r);
  try {
    w.close();
    FAIL() << "a write to /dev/full succeeded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("DIR/trace.csv"), std::string::npos)
        << e.what();
  }
}

TEST(TraceWriter, SafetyFlagsAreNamed) {
  EXPECT_EQ(safety_flags_text(kSafetyOk), "ok");
  EXPECT_EQ(safety_flags_text(kSafetyCommLost | kSafetyTorqueClamped),
            "torque_clamped|comm_lost");
}

}  // namespace
}  // namespace vmh::runtime
