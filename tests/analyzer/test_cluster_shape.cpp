// SPDX-License-Identifier: Apache-2.0
// Synthetic clusters of known structure are classified right, and noise-free fits find the true
// directions (the dichromatic body and illuminant colours, the plane they span) within 0.5°.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include <fmt/core.h>
#include <gtest/gtest.h>

#include "analyzer/region_analysis.h"
#include "tests/analyzer/synthetic.h"

namespace ct::test {
namespace {

using namespace ct::analyzer;

ClusterShape shape_of(const RgbImage& image, const ImageEncoding& encoding = {}) {
  const LayerContext context = layer_context(image, encoding, 64);
  return analyse_region(image, context, whole_image_region(image.width, image.height), AnalyzeOptions{}).shape;
}

std::string describe(const ClusterShape& s) {
  std::string text = std::string(class_name(s.shape)) + ": " + s.reason + "\n";
  for (const Decision& d : s.decisions)
    text += "  " + d.test + ": " + std::to_string(d.value) + " vs " + std::to_string(d.threshold) + (d.passed ? " yes\n" : " no\n");
  return text;
}

constexpr double kDegrees = 0.5;

TEST(ClusterShape, MatteLineIsLinearAlongTheBodyColour) {
  const ClusterShape s = shape_of(matte_line());
  ASSERT_EQ(s.shape, ShapeClass::Linear) << describe(s);
  ASSERT_TRUE(s.line);
  EXPECT_LT(line_angle_degrees(s.line->direction, kBody), kDegrees);
  EXPECT_GT(s.linearity, 0.99);
}

TEST(ClusterShape, NarrowHighlightAtTheBrightEndIsAnL) {
  const ClusterShape s = shape_of(l_shape());
  ASSERT_EQ(s.shape, ShapeClass::L) << describe(s);
  EXPECT_LT(line_angle_degrees(s.two_lines->body.direction, kBody), kDegrees);
  EXPECT_LT(line_angle_degrees(s.two_lines->highlight.direction, kIlluminant), kDegrees);
  EXPECT_NEAR(s.two_lines->junction_on_body, 1.0, 0.02);
  // The highlight leaves the body line at m_b = 1.
  EXPECT_LT((s.two_lines->junction - kBody).norm(), 0.01);
  const Vec3 normal = kBody.cross(kIlluminant).normalized();
  EXPECT_LT(line_angle_degrees(s.plane->normal, normal), kDegrees);
  EXPECT_LT(line_angle_degrees(s.black_plane->normal, normal), kDegrees);
}

// A small sphere's highlight holds well under 1 % of its pixels; the highlight is judged by its samples and
// its length, not its share.
TEST(ClusterShape, SmallHighlightIsStillAnL) {
  const ClusterShape s = shape_of(small_highlight_l());
  ASSERT_EQ(s.shape, ShapeClass::L) << describe(s);
  EXPECT_GE(s.two_lines->body_fraction, 0.98);  // the body line alone holds nearly every pixel
  EXPECT_LT(line_angle_degrees(s.two_lines->highlight.direction, kIlluminant), kDegrees);
}

// A handful of stray pixels off a matte line is not a highlight.
TEST(ClusterShape, StrayPixelsDoNotMakeAnL) {
  RgbImage image = matte_line();
  for (int i = 0; i < 5; ++i)
    for (int c = 0; c < 3; ++c) image.rgb[static_cast<std::size_t>(3 * (64 * 128 + 20 * i) + c)] += static_cast<float>(0.2 * kIlluminant[c]);
  const ClusterShape s = shape_of(image);
  EXPECT_EQ(s.shape, ShapeClass::Linear) << describe(s);
}

// Two light colours on one object: two lines from near black (the paper's fork).
TEST(ClusterShape, TwoLinesFromNearBlackAreAFork) {
  const ClusterShape s = shape_of(fork_shape());
  ASSERT_EQ(s.shape, ShapeClass::Fork) << describe(s);
  const Vec3 second = kBody.cwiseProduct(kSecondLight).normalized();
  const bool body_first = line_angle_degrees(s.two_lines->body.direction, kBody) < kDegrees;
  EXPECT_LT(line_angle_degrees(s.two_lines->body.direction, body_first ? kBody : second), kDegrees);
  EXPECT_LT(line_angle_degrees(s.two_lines->highlight.direction, body_first ? second : kBody), kDegrees);
  EXPECT_NEAR(s.two_lines->angle_deg, line_angle_degrees(kBody, second), kDegrees);
}

// Interreflection turning the colour a little both ways across the object: a thickened line, not a plane.
TEST(ClusterShape, LineTurnedBothWaysIsAThickenedLine) {
  const ClusterShape s = shape_of(thickened_line());
  ASSERT_EQ(s.shape, ShapeClass::ThickenedLine) << describe(s);
  ASSERT_TRUE(s.line);
  // The body line is one of the fan's rays: within its half-angle atan(0.04) of the body colour.
  EXPECT_LT(line_angle_degrees(s.line->direction, kBody), std::atan(0.04) * 180 / 3.14159265358979 + kDegrees);
  // σ2 / σ1 of a fan of half-angle atan(0.04) about a line: below thick_line_ratio, well above noise.
  EXPECT_LT(s.sigma[1] / s.sigma[0], 0.15);
}

TEST(ClusterShape, HighlightLeavingHalfWayIsASkewedT) {
  const ClusterShape s = shape_of(skewed_t());
  ASSERT_EQ(s.shape, ShapeClass::SkewedT) << describe(s);
  EXPECT_NEAR(s.two_lines->junction_on_body, 0.5, 0.02);
  EXPECT_LT(line_angle_degrees(s.two_lines->body.direction, kBody), kDegrees);
  EXPECT_LT(line_angle_degrees(s.two_lines->highlight.direction, kIlluminant), kDegrees);
  EXPECT_LT(line_angle_degrees(s.black_plane->normal, kBody.cross(kIlluminant)), kDegrees);
}

// Two lines whose junction lies far beyond the body line's bright end are no L (docs/analyze.md: the junction
// lies on the body line, within highlight_end of its ends): the second line approaches where the body line would
// be at 0.9 of its colour, and the body's pixels reach only 0.5 of it, so the junction sits at 1.9 of its length.
TEST(ClusterShape, AJunctionBeyondTheBodyLinesEndIsNoL) {
  const RgbImage image = make_image(128, 128, [](double u, double) -> Vec3 {
    if (u < 0.7) return (0.05 + 0.45 * u / 0.7) * kBody;
    return 0.9 * kBody + (0.05 + 0.6 * (u - 0.7) / 0.3) * kIlluminant;
  });
  const ClusterShape s = shape_of(image);
  EXPECT_NE(s.shape, ShapeClass::L) << describe(s);
  EXPECT_NE(s.shape, ShapeClass::SkewedT) << describe(s);
  const auto bound = std::find_if(s.decisions.begin(), s.decisions.end(),
                                  [](const Decision& d) { return d.test == "junction on body line within highlight_end of its ends"; });
  ASSERT_NE(bound, s.decisions.end()) << describe(s);
  EXPECT_FALSE(bound->passed);
  EXPECT_NEAR(bound->value, (0.9 - 0.05) / 0.45, 0.05);
}

TEST(ClusterShape, BroadHighlightIsAP) {
  const ClusterShape s = shape_of(p_shape());
  ASSERT_EQ(s.shape, ShapeClass::P) << describe(s);
  EXPECT_LT(line_angle_degrees(s.body_only->line.direction, kBody), kDegrees);
  EXPECT_LT(line_angle_degrees(s.plane->normal, kBody.cross(kIlluminant)), kDegrees);
  EXPECT_LT(line_angle_degrees(s.black_plane->normal, kBody.cross(kIlluminant)), kDegrees);
}

TEST(ClusterShape, BentClusterIsCurved) {
  const ClusterShape s = shape_of(curved_cluster());
  ASSERT_EQ(s.shape, ShapeClass::Curved) << describe(s);
  EXPECT_GT(s.curve->bend, 0.1);
}

TEST(ClusterShape, OverExposedLineIsClippedOnTheRedFace) {
  const ClusterShape s = shape_of(clipped_line());
  ASSERT_EQ(s.shape, ShapeClass::Clipped) << describe(s);
  ASSERT_EQ(s.clipping.faces.size(), 1u);
  EXPECT_EQ(s.clipping.faces[0].channel, 0);
  EXPECT_TRUE(s.clipping.faces[0].high);
  ASSERT_EQ(s.unclipped.size(), 1u);
  EXPECT_EQ(s.unclipped[0].shape, ShapeClass::Linear) << describe(s.unclipped[0]);
  EXPECT_LT(line_angle_degrees(s.unclipped[0].line->direction, kBody), kDegrees);
}

// Faces at black cut off the darkest end of the body line, not the highlight: an L whose blue is 0 along its darkest
// quarter (a colour under the file's black there) is an L, read on its samples off the face, with the face kept;
// with blue 0 along more than half of it, it is clipped, and an L off the face. (A face at the top makes a cluster
// clipped from clipped_fraction on: OverExposedLineIsClippedOnTheRedFace.)
TEST(ClusterShape, AnLWithItsDarkestPixelsAtBlackIsAnL) {
  for (const double cut : {0.25, 0.6}) {
    SCOPED_TRACE(::testing::Message() << "blue at 0 below u = " << cut);
    const RgbImage image = make_image(128, 128, [cut](double u, double) -> Vec3 {
      Vec3 c = u < 0.85 ? Vec3(u / 0.85 * kBody) : Vec3(kBody + 0.5 * (u - 0.85) / 0.15 * kIlluminant);
      if (u < cut) c[2] = 0;
      return c;
    });
    int columns = 0;  // x ≥ 1 (x = 0 is black in every channel: dark, not clipped) with u = x / 127 < cut
    for (int x = 1; x < 128; ++x) columns += x / 127.0 < cut;
    const ClusterShape s = shape_of(image);
    ASSERT_EQ(s.clipping.faces.size(), 1u) << describe(s);
    EXPECT_EQ(s.clipping.faces[0].channel, 2);
    EXPECT_FALSE(s.clipping.faces[0].high);
    EXPECT_DOUBLE_EQ(s.clipping.fraction, columns / 128.0);
    EXPECT_EQ(s.samples, 128u * 128u);
    EXPECT_EQ(s.shape, cut < 0.5 ? ShapeClass::L : ShapeClass::Clipped) << describe(s);
    const ClusterShape& l = off_the_faces(s);
    ASSERT_EQ(l.shape, ShapeClass::L) << describe(l);
    EXPECT_LT(line_angle_degrees(l.two_lines->body.direction, kBody), kDegrees);
    EXPECT_LT(line_angle_degrees(l.two_lines->highlight.direction, kIlluminant), kDegrees);
  }
}

TEST(ClusterShape, PowerCurveBendsALineAndTheFitFindsGamma) {
  const ClusterShape s = shape_of(gamma_line());
  ASSERT_EQ(s.shape, ShapeClass::Gamma) << describe(s);
  EXPECT_NEAR(s.gamma->gamma, kGamma, 0.005);
}

// With sensor noise the fitted γ scatters from frame to frame; its bootstrap standard error must describe that
// scatter: the true γ lies within 3 standard errors in nearly every frame (at least 9 of 10), and the standard
// error is within a factor of 3 of the fits' spread over the frames. (The fit itself, on the noisy points: the
// class decision also asks the curve to remove the spread, which noise keeps.)
TEST(ClusterShape, GammaHasAStandardErrorThatCoversTheTruth) {
  std::vector<double> gammas, errors;
  int covered = 0;
  for (std::uint32_t seed = 1; seed <= 10; ++seed) {
    const RgbImage noisy = add_sensor_noise(gamma_line(), 1000000, 1, seed);
    std::vector<Vec3> points;
    for (std::size_t i = 0; i + 2 < noisy.rgb.size(); i += 3) points.emplace_back(noisy.rgb[i], noisy.rgb[i + 1], noisy.rgb[i + 2]);
    const auto fit = fit_gamma(points);
    ASSERT_TRUE(fit);
    const double se = gamma_standard_error(points, seed);
    gammas.push_back(fit->gamma);
    errors.push_back(se);
    covered += std::abs(fit->gamma - kGamma) <= 3 * se;
  }
  EXPECT_GE(covered, 9);
  double mean = 0, var = 0, se = 0;
  for (const double g : gammas) mean += g / 10;
  for (const double g : gammas) var += (g - mean) * (g - mean) / 9;
  for (const double e : errors) se += e / 10;
  fmt::print("γ over 10 frames: mean {:.4f}, spread {:.4f}; mean standard error {:.4f}\n", mean, std::sqrt(var), se);
  EXPECT_LT(se, 3 * std::sqrt(var));
  EXPECT_GT(se, std::sqrt(var) / 3);
}

TEST(ClusterShape, SpreadOffThePlaneIsThickening) {
  const ClusterShape s = shape_of(thickened_plane());
  ASSERT_EQ(s.shape, ShapeClass::Thickened) << describe(s);
}

TEST(ClusterShape, SensorNoiseAloneDoesNotThickenALine) {
  const ClusterShape s = shape_of(add_sensor_noise(matte_line(), 20000, 5, 7));
  EXPECT_EQ(s.shape, ShapeClass::Linear) << describe(s);
  // The body line is one of the fan's rays: within its half-angle atan(0.04) of the body colour.
  EXPECT_LT(line_angle_degrees(s.line->direction, kBody), std::atan(0.04) * 180 / 3.14159265358979 + kDegrees);
}

TEST(ClusterShape, NoisyLStaysAnL) {
  const ClusterShape s = shape_of(add_sensor_noise(l_shape(), 20000, 5, 8));
  EXPECT_EQ(s.shape, ShapeClass::L) << describe(s);
}

TEST(ClusterShape, UniformPatchIsAPoint) {
  const ClusterShape s = shape_of(add_sensor_noise(make_image(32, 32, [](double, double) { return Vec3(0.4, 0.3, 0.2); }), 20000, 5, 9));
  EXPECT_EQ(s.shape, ShapeClass::Point) << describe(s);
}

TEST(ClusterShape, RandomColoursAreAVolume) {
  const ClusterShape s = shape_of(make_image(64, 64, [](double u, double v) -> Vec3 {
    return Vec3(0.5 + 0.4 * std::sin(40 * u + 3 * v), 0.5 + 0.4 * std::sin(31 * v + 7 * u), 0.5 + 0.4 * std::cos(23 * u * v + 5 * u));
  }));
  EXPECT_EQ(s.shape, ShapeClass::Volume) << describe(s);
}

TEST(ClusterShape, IntegerImagesAreJudgedInDigitalNumbers) {
  RgbImage image = l_shape();
  for (float& v : image.rgb) v = std::round(v * 200.0f);  // the highlight stays below 255
  const ClusterShape s = shape_of(image, ImageEncoding{true, 8, 255});
  EXPECT_EQ(s.shape, ShapeClass::L) << describe(s);
  EXPECT_LT(line_angle_degrees(s.two_lines->body.direction, kBody), 1.0);
}

// A glossy object of a deep orange (blue a tenth of red) with Gaussian noise, its values cut at the file's black: its dim
// samples lose their noise below 0, and those left lean off the plane. The samples clear of black — ordered, for
// each channel with a face at black, by the sum of the other two, whose noise is their own — give the plane spanned by the body and the light within the noise's own
// tilt (4 × noise / (σ2 √n): 4 standard errors, which a Rayleigh-distributed tilt passes with odds of e⁻⁸), over
// seeds; the samples off the faces lean further, by a bias that no number of samples takes away.
TEST(ClusterShape, ThePlaneOfTheSamplesClearOfBlackIsNotTiltedByTheCut) {
  const Vec3 body(0.8, 0.3, 0.08), light(1.0, 0.85, 0.6);
  const Vec3 normal = body.cross(light).normalized();
  constexpr double noise = 0.01;
  double clear_sum = 0, off_sum = 0;
  for (const unsigned seed : {1u, 2u, 3u, 4u, 5u}) {
    // A smooth picture, so that the image's noise is measured as such: the shading rises as the cube of x (most
    // pixels dim), a highlight's bump sits in the bright part.
    RgbImage image;
    image.width = 800, image.height = 200;
    image.rgb.resize(3 * image.pixel_count());
    std::mt19937 generator(seed);
    std::normal_distribution<double> grain(0.0, noise);
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x) {
        const double m_b = std::pow((x + 0.5) / image.width, 3.0);
        const double m_s = 0.4 * std::exp(-((x - 640.0) * (x - 640.0) + (y - 100.0) * (y - 100.0)) / (2 * 50.0 * 50.0));
        const Vec3 c = m_b * body + m_s * light;
        const std::size_t p = static_cast<std::size_t>(y * image.width + x);
        for (std::size_t k = 0; k < 3; ++k)
          image.rgb[3 * p + k] = static_cast<float>(std::max(0.0, c[static_cast<Eigen::Index>(k)] + grain(generator)));
      }
    const ClusterShape s = shape_of(image);
    ASSERT_FALSE(s.clipping.faces.empty()) << describe(s);
    ASSERT_TRUE(only_at_black(s.clipping));
    ASSERT_EQ(s.clear_of_black.size(), 1u) << describe(s);
    const ClusterShape& clear = s.clear_of_black.front();
    ASSERT_TRUE(clear.black_plane);
    EXPECT_FALSE(std::isnan(s.clear_levels[2]));  // blue, the weakest channel, has a face at black
    const double tilt = std::asin(std::min(1.0, std::abs(clear.black_plane->normal.normalized().cross(normal).norm()))) * 180 / std::numbers::pi;
    const double allowed = 4 * noise / (clear.sigma[1] * std::sqrt(static_cast<double>(clear.samples))) * 180 / std::numbers::pi;
    const ClusterShape& off = off_the_faces(s);
    const double off_tilt = std::asin(std::min(1.0, std::abs(off.black_plane->normal.normalized().cross(normal).norm()))) * 180 / std::numbers::pi;
    std::cerr << fmt::format("seed {}: {:.1f} % at black; clear of black: {} samples above R + G = {:.3f} (for B), tilted {:.3f}° "
                             "(allowed {:.3f}°); off the faces {:.3f}°\n", seed, 100 * s.clipping.fraction, clear.samples,
                             s.clear_levels[2], tilt, allowed, off_tilt);
    EXPECT_LE(tilt, allowed) << "seed " << seed;
    clear_sum += tilt, off_sum += off_tilt;
  }
  // The cut's tilt is a bias, not noise: over the seeds the plane off the faces leans twice as far or more.
  EXPECT_GT(off_sum, 2 * clear_sum) << "the cut does not tilt the plane here, so this test shows nothing";
}

}  // namespace
}  // namespace ct::test
