// SPDX-License-Identifier: Apache-2.0
// core/statistics.h: the one quantile rule, the mean's standard error and the k-sigma factors, on known answers.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "core/statistics.h"

namespace ct {
namespace {

// 0, 1, …, 100 in a scrambled order: the q-quantile by the nearest rank below is ⌊100·q⌋.
std::vector<double> scrambled_hundred() {
  std::vector<double> v;
  for (int i = 0; i <= 100; ++i) v.push_back((i * 37) % 101);
  return v;
}

TEST(Statistics, QuantileIsTheNearestRankBelow) {
  const std::vector<double> v = scrambled_hundred();
  EXPECT_EQ(quantile(v, 0.0), 0.0);
  EXPECT_EQ(quantile(v, 0.5), 50.0);
  EXPECT_EQ(quantile(v, 0.99), 99.0);
  EXPECT_EQ(quantile(v, 0.995), 99.0);  // rank 99.5 rounds down
  EXPECT_EQ(quantile(v, 1.0), 100.0);
  // Four values: ranks 0..3; q = 0.5 is rank 1.5, so the second smallest; q = 0.9 is rank 2.7, the third.
  EXPECT_EQ(quantile(std::vector<double>{40, 10, 30, 20}, 0.5), 20.0);
  EXPECT_EQ(quantile(std::vector<double>{40, 10, 30, 20}, 0.9), 30.0);
}

TEST(Statistics, QuantileOfFloatsFollowsTheSameRule) {
  std::vector<float> v;
  for (double x : scrambled_hundred()) v.push_back(static_cast<float>(x));
  EXPECT_EQ(quantile(v, 0.995), 99.0);
  EXPECT_EQ(quantile_in_place(std::span<float>(v), 0.25), 25.0);
}

TEST(Statistics, QuantileOfNothingIsZeroAndQIsClamped) {
  EXPECT_EQ(quantile(std::vector<double>{}, 0.5), 0.0);
  EXPECT_EQ(quantile(std::vector<double>{3, 1, 2}, -1.0), 1.0);
  EXPECT_EQ(quantile(std::vector<double>{3, 1, 2}, 2.0), 3.0);
}

TEST(Statistics, MeanAndStandardErrorOfKnownValues) {
  // 2, 4, 4, 4, 5, 5, 7, 9: mean 5, unbiased variance 32/7, standard error √(32/7/8) = √(4/7).
  const std::vector<double> v{2, 4, 4, 4, 5, 5, 7, 9};
  const MeanAndError m = mean_and_standard_error(v);
  EXPECT_DOUBLE_EQ(m.mean, 5.0);
  EXPECT_NEAR(m.standard_error, std::sqrt(4.0 / 7.0), 1e-15);
  EXPECT_EQ(mean_and_standard_error(std::vector<double>{3.5}).standard_error, 0.0);
  EXPECT_EQ(mean_and_standard_error(std::vector<double>{3.5}).mean, 3.5);
  EXPECT_EQ(mean_and_standard_error(std::vector<double>{}).mean, 0.0);
}

TEST(Statistics, SigmaFactorsHaveTheirFalseFailureRates) {
  // Two-sided normal tail 2·(1 − Φ(k)) = erfc(k/√2).
  EXPECT_NEAR(std::erfc(kSigmasOneCheck / std::sqrt(2.0)), 2.70e-3, 0.01e-3);
  EXPECT_NEAR(std::erfc(kSigmasPerItem / std::sqrt(2.0)), 6.33e-5, 0.01e-5);
  EXPECT_NEAR(std::erfc(kSigmasManyChecks / std::sqrt(2.0)), 5.73e-7, 0.01e-7);
}

}  // namespace
}  // namespace ct
