// SPDX-License-Identifier: Apache-2.0
// On an image whose values a power curve encoded, the γ fitted to the bent cluster is compared with the curve the
// input declared: the true curve agrees within the fit's uncertainty, a different one does not.
#include <cmath>

#include <gtest/gtest.h>

#include "analyzer/analysis.h"
#include "tests/analyzer/synthetic.h"

namespace ct::test {
namespace {

using namespace ct::analyzer;

std::optional<GammaComparison> compared(const RgbImage& image, const ToneCurve& declared) {
  AnalysisImage input;
  input.file = "gamma_line";
  input.image = image;
  input.encoding.curve = declared;
  input.encoding.curve_source = "the test";
  const ImageAnalysis a = analyse_image(input, "", {whole_image_region(image.width, image.height)}, AnalyzeOptions{}, std::nullopt, false);
  EXPECT_EQ(a.results.front().shape.shape, ShapeClass::Gamma) << a.results.front().shape.reason;
  return a.results.front().declared_gamma;
}

// gamma_line() is encoded with I' = I^(1/2.2) (kGamma). With sensor noise the fitted γ scatters; its bootstrap
// standard error covers the truth within 3 standard errors in at least 9 frames of 10 (as in
// ClusterShape.GammaHasAStandardErrorThatCoversTheTruth), so the declared 1/2.2 agrees at least as often; a
// declared 1/1.8, 0.10 away, lies tens of standard errors off in every frame.
TEST(DeclaredGamma, TheTrueCurveAgreesAndAnotherDoesNot) {
  int agreed = 0;
  for (std::uint32_t seed = 1; seed <= 10; ++seed) {
    const RgbImage noisy = add_sensor_noise(gamma_line(), 1e8, 1, seed);
    const auto right = compared(noisy, ToneCurve{1 / 2.2, 1, false});
    ASSERT_TRUE(right) << "seed " << seed;
    EXPECT_NEAR(right->declared_gamma, 1 / 2.2, 1e-12);
    EXPECT_NEAR(right->difference_in_se, std::abs(right->fitted - right->declared_gamma) / right->se, 1e-9);
    agreed += right->agree;
    const auto wrong = compared(noisy, ToneCurve{1 / 1.8, 1, false});
    ASSERT_TRUE(wrong);
    EXPECT_FALSE(wrong->agree) << "seed " << seed << ": fitted " << wrong->fitted << " ± " << wrong->se;
  }
  EXPECT_GE(agreed, 9);
}

// The sRGB curve has no single exponent; over a range of stored values its effective one lies between its local
// exponents d ln I' / d ln I = (V + 0.055) / (2.4 V) at the range's ends.
TEST(DeclaredGamma, SrgbEffectiveExponentLiesBetweenItsLocalOnes) {
  auto local = [](double v) { return (v + 0.055) / (2.4 * v); };
  for (const auto& [lo, hi] : {std::pair{0.2, 1.0}, std::pair{0.5, 1.0}, std::pair{0.1, 0.4}}) {
    const double g = srgb_effective_gamma(lo, hi);
    EXPECT_GT(g, local(hi)) << lo << "–" << hi;
    EXPECT_LT(g, local(lo)) << lo << "–" << hi;
  }
}

}  // namespace
}  // namespace ct::test
