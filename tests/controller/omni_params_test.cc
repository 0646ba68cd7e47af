// OmniParams: the defaults are valid, and each bad field is named.
#include "controller/omni_params.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>

namespace vmh {
namespace {

TEST(OmniParams, DefaultsAreValid) { EXPECT_NO_THROW(OmniParams{}.validate()); }

// the Omni's published numbers (docs/sources.md §4-7)
TEST(OmniParams, DefaultsAreTheOmnis) {
  const OmniParams p;
  EXPECT_DOUBLE_EQ(p.l1_m, 0.13335);
  EXPECT_DOUBLE_EQ(p.l2_m, 0.13335);
  EXPECT_DOUBLE_EQ(p.l0_m, 0.0);
  EXPECT_DOUBLE_EQ(p.max_force_N, 3.3);
  EXPECT_DOUBLE_EQ(p.continuous_force_N, 0.88);
  EXPECT_DOUBLE_EQ(p.encoder_counts_per_rev, 15000.0);
  EXPECT_DOUBLE_EQ(p.motor_torque_limit_Nm[1], 0.350);
}

// the message of the exception thrown by validate(), or "" if none
std::string validation_error(const std::function<void(OmniParams*)>& edit) {
  OmniParams p;
  edit(&p);
  try {
    p.validate();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(OmniParams, EachBadFieldIsNamed) {
  const double nan = std::nan("");
  struct Case {
    const char* field;
    std::function<void(OmniParams*)> edit;
  };
  const Case cases[] = {
      {"l0_m", [&](OmniParams* p) { p->l0_m = nan; }},
      {"l1_m", [](OmniParams* p) { p->l1_m = 0; }},
      {"l2_m", [](OmniParams* p) { p->l2_m = -0.1; }},
      {"tool_offset_m", [](OmniParams* p) { p->tool_offset_m = INFINITY; }},
      {"q3", [](OmniParams* p) { p->joint_lower_rad[2] = 2.0; }},
      {"q6", [&](OmniParams* p) { p->joint_upper_rad[5] = nan; }},
      {"motor_torque_limit_Nm",
       [](OmniParams* p) { p->motor_torque_limit_Nm[0] = 0; }},
      {"max_force_N", [](OmniParams* p) { p->max_force_N = -1; }},
      {"continuous_force_N", [](OmniParams* p) { p->continuous_force_N = 5; }},
      {"encoder_counts_per_rev",
       [](OmniParams* p) { p->encoder_counts_per_rev = 0; }},
      {"gimbal_pot_bits", [](OmniParams* p) { p->gimbal_pot_bits = 40; }},
  };
  for (const Case& c : cases) {
    const std::string msg = validation_error(c.edit);
    EXPECT_NE(msg.find(c.field), std::string::npos)
        << "field " << c.field << ", message '" << msg << "'";
  }
}

TEST(OmniParams, JointNames) {
  EXPECT_STREQ(joint_name(0), "q1");
  EXPECT_STREQ(joint_name(5), "q6");
  EXPECT_STREQ(joint_name(6), "q?");
}

}  // namespace
}  // namespace vmh
