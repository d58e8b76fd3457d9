// SPDX-License-Identifier: Apache-2.0
// Ticks and their labels: round numbers inside the range by Heckbert's rule, labels with the decimals the step
// needs, logarithmic axes in decades.
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "plot/ticks.h"

namespace ct::plot {
namespace {

void expect_ticks(double lo, double hi, const std::vector<double>& expected) {
  const std::vector<double> ticks = linear_ticks(lo, hi).values;
  ASSERT_EQ(ticks.size(), expected.size()) << lo << " to " << hi;
  for (std::size_t k = 0; k < ticks.size(); ++k) EXPECT_NEAR(ticks[k], expected[k], 1e-12 * (hi - lo)) << lo << " to " << hi;
}

// The step is span / intervals with its mantissa rounded: below 1.5 → 1, below 3 → 2, below 7 → 5, else 10.
TEST(Ticks, NiceStepRoundsTheMantissaByHeckbertsRule) {
  EXPECT_DOUBLE_EQ(nice_step(1.0, 5), 0.2);
  EXPECT_DOUBLE_EQ(nice_step(1.0, 4), 0.2);      // 0.25 → 2.5 → 2
  EXPECT_DOUBLE_EQ(nice_step(255, 5), 50);       // 51 → 5.1 → 5
  EXPECT_DOUBLE_EQ(nice_step(65535, 5), 10000);  // 13107 → 1.31 → 1
  EXPECT_DOUBLE_EQ(nice_step(1.49, 1), 1);
  EXPECT_DOUBLE_EQ(nice_step(1.5, 1), 2);
  EXPECT_DOUBLE_EQ(nice_step(2.99, 1), 2);
  EXPECT_DOUBLE_EQ(nice_step(3, 1), 5);
  EXPECT_DOUBLE_EQ(nice_step(6.99, 1), 5);
  EXPECT_DOUBLE_EQ(nice_step(7, 1), 10);
  EXPECT_DOUBLE_EQ(nice_step(0.0072, 1), 0.01);
  EXPECT_DOUBLE_EQ(nice_step(0, 5), 1);
  EXPECT_DOUBLE_EQ(nice_step(std::numeric_limits<double>::quiet_NaN(), 5), 1);
}

// The ticks are the step's multiples in range.
TEST(Ticks, AxisTicksAreRoundNumbersInsideTheRange) {
  expect_ticks(0, 255, {0, 50, 100, 150, 200, 250});                             // 51 = 5.1 × 10 → 50
  expect_ticks(0, 1, {0, 0.2, 0.4, 0.6, 0.8, 1});                                // 0.2
  expect_ticks(0, 65535, {0, 10000, 20000, 30000, 40000, 50000, 60000});         // 13107 = 1.31 × 10^4 → 10000
  expect_ticks(0.013, 0.087, {0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08});        // 0.0148 → 0.01
  expect_ticks(-1, 1, {-1, -0.5, 0, 0.5, 1});                                    // 0.4 → 0.5
  EXPECT_TRUE(linear_ticks(1, 1).values.empty());
  EXPECT_TRUE(linear_ticks(0, std::numeric_limits<double>::infinity()).values.empty());
  EXPECT_EQ(linear_ticks(0, 255).label(100), "100");
  EXPECT_EQ(linear_ticks(0, 1).label(0.4), "0.4");
  EXPECT_EQ(linear_ticks(0.013, 0.087).label(0.06), "0.06");
  EXPECT_EQ(linear_ticks(-1, 1).label(0), "0.0");
  EXPECT_EQ(linear_ticks(0, 65535).label(40000), "40000");
}

TEST(Ticks, MultiplesIncludeTheEndsAndWriteZeroAsZero) {
  const std::vector<double> m = multiples_in(-0.05, 0.25, 0.1);
  ASSERT_EQ(m.size(), 3u);
  EXPECT_EQ(m[0], 0.0);
  EXPECT_FALSE(std::signbit(m[0]));
  EXPECT_NEAR(m[2], 0.2, 1e-15);
  // An end a rounding error short of a multiple still gets its tick.
  EXPECT_EQ(multiples_in(0, 0.6 - 1e-12, 0.2).size(), 4u);
  EXPECT_TRUE(multiples_in(0.01, 0.09, 0.1).empty());
}

// The range is widened to whole steps; a value within 10⁻⁶ of a step of a multiple counts as on it.
TEST(Ticks, NiceRangeBeginsAndEndsOnATick) {
  const NiceRange a = nice_range(0.013, 0.087, 4);  // 0.0185 → 0.02
  EXPECT_DOUBLE_EQ(a.step, 0.02);
  EXPECT_DOUBLE_EQ(a.lo, 0);
  EXPECT_NEAR(a.hi, 0.1, 1e-15);
  const NiceRange b = nice_range(0, 1.0000001, 4);
  EXPECT_DOUBLE_EQ(b.step, 0.2);
  EXPECT_NEAR(b.hi, 1.0, 1e-15);
  const NiceRange c = nice_range(-0.03, 0.9, 4);  // 0.2325 → 0.2
  EXPECT_NEAR(c.lo, -0.2, 1e-15);
  EXPECT_NEAR(c.hi, 1.0, 1e-15);
  const NiceRange d = nice_range(2, 2, 4);  // no span: [2, 3]
  EXPECT_DOUBLE_EQ(d.step, 0.2);
  EXPECT_DOUBLE_EQ(d.lo, 2);
  EXPECT_NEAR(d.hi, 3, 1e-12);
}

TEST(Ticks, LabelsHaveTheDecimalsTheStepNeeds) {
  EXPECT_EQ(tick_label(0.30000000000000004, 0.1), "0.3");
  EXPECT_EQ(tick_label(250, 50), "250");
  EXPECT_DOUBLE_EQ(nice_step(1.0, 4), 0.2);
  EXPECT_EQ(tick_label(0.25, 0.05), "0.25");
  EXPECT_EQ(tick_label(3e-17, 0.1), "0.0");
  EXPECT_EQ(tick_label(-5.55e-17, 0.05), "0.00");
  EXPECT_EQ(tick_label(60000, 10000), "60000");
}

TEST(Ticks, LogTicks) {
  EXPECT_EQ(log_ticks(0.1, 10), (std::vector<double>{0.1, 0.2, 0.5, 1, 2, 5, 10}));
  EXPECT_EQ(log_ticks(0.01, 1000), (std::vector<double>{0.01, 0.1, 1, 10, 100, 1000}));
  EXPECT_EQ(log_ticks(3, 4), (std::vector<double>{1, 10}));
}

// A range that is not one of positive numbers is refused, not looped over from log10(0) = −∞.
TEST(Ticks, LogTicksRefuseARangeThatIsNotPositive) {
  for (const auto& [lo, hi] : {std::pair{0.0, 10.0}, std::pair{-1.0, 10.0}, std::pair{10.0, 1.0}, std::pair{1.0, HUGE_VAL},
                               std::pair{std::nan(""), 10.0}})
    EXPECT_THROW(log_ticks(lo, hi), std::invalid_argument) << lo << " " << hi;
}

TEST(Ticks, LogLabelsArePlainFromAHundredthToAThousandElsePowersOfTen) {
  EXPECT_EQ(log_tick_label(0.01), "0.01");
  EXPECT_EQ(log_tick_label(0.05), "0.05");
  EXPECT_EQ(log_tick_label(200), "200");
  EXPECT_EQ(log_tick_label(1000), "1000");
  EXPECT_EQ(log_tick_label(1e4), "10^4");
  EXPECT_EQ(log_tick_label(5e5), "5x10^5");
  EXPECT_EQ(log_tick_label(2e-3), "2x10^-3");
  EXPECT_EQ(superscript_exponent("10^4"), "10\u2074");
  EXPECT_EQ(superscript_exponent("2x10^-3"), "2\u00d710\u207b\u00b3");
  EXPECT_EQ(superscript_exponent("200"), "200");
}

}  // namespace
}  // namespace ct::plot
