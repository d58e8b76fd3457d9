// SPDX-License-Identifier: Apache-2.0
// The noise a cluster is judged against is the image's, measured where the image is flat: a surface whose
// shading varies from pixel to pixel (texture along its body colour) is a line, not "a single colour", and a
// flat noisy patch is still a point.
#include <cmath>
#include <filesystem>
#include <iostream>
#include <random>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "analyzer/image_input.h"
#include "analyzer/region_analysis.h"

namespace ct::test {
namespace {

using namespace ct::analyzer;

constexpr double kNoise = 0.004;  // the Gaussian noise σ of every channel
const Vec3 kColour{0.6, 0.45, 0.3};

// 256 × 128: the left half a smooth shading ramp s = 0.2 … 0.8 of kColour (planar: Immerkær's mask cancels it),
// the top right quarter the same colour with s drawn afresh for every pixel in [0.2, 0.8] (texture), the bottom
// right quarter s = 0.5 everywhere; kNoise on every channel of every pixel.
RgbImage textured_and_flat() {
  RgbImage image{256, 128, std::vector<float>(256 * 128 * 3)};
  std::mt19937 rng(17);
  std::normal_distribution<double> noise(0.0, kNoise);
  std::uniform_real_distribution<double> shading(0.2, 0.8);
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const double s = x < 128 ? 0.2 + 0.6 * x / 127.0 : y < 64 ? shading(rng) : 0.5;
      for (int c = 0; c < 3; ++c)
        image.rgb[(static_cast<std::size_t>(y) * 256 + static_cast<std::size_t>(x)) * 3 + static_cast<std::size_t>(c)] =
            static_cast<float>(s * kColour[c] + noise(rng));
    }
  return image;
}

// The noise along any direction is kNoise (independent channels of equal σ). Each band's estimate is a clipped
// median of about 2,000 residuals, relative standard error 1.17/√n ≈ 3 % (doubled for the overlap of
// neighbouring masks), and the textured pixels inside the clip shift it by about 1 %; a region averages several
// bands. 10 % is beyond four standard errors.
constexpr double kRelativeTolerance = 0.10;

TEST(ImageNoise, TexturedLineIsALineAndAFlatPatchAPoint) {
  const RgbImage image = textured_and_flat();
  const LayerContext context = layer_context(image, {}, 64);
  ASSERT_FALSE(context.noise.bands.empty());
  const AnalyzeOptions options;

  const ClusterShape textured = analyse_region(image, context, rect_region({128, 0, 128, 64}, 256, 128), options).shape;
  EXPECT_EQ(textured.shape, ShapeClass::Linear) << textured.reason;
  ASSERT_TRUE(textured.line);
  const double cosine = std::abs(textured.line->direction.normalized().dot(kColour.normalized()));
  EXPECT_GT(cosine, std::cos(1.0 * M_PI / 180.0));  // along the body colour within 1°
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(textured.noise_sigma[a] / kNoise, 1.0, kRelativeTolerance) << "axis " << a;

  const ClusterShape flat = analyse_region(image, context, rect_region({128, 64, 128, 64}, 256, 128), options).shape;
  EXPECT_EQ(flat.shape, ShapeClass::Point) << flat.reason;
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(flat.noise_sigma[a] / kNoise, 1.0, kRelativeTolerance) << "axis " << a;
}

// Shot noise grows with the signal: the bands follow it. Pure noise of σ = k·√I on a ramp of I gives each band
// the σ of its brightness.
TEST(ImageNoise, BandsFollowTheNoiseOfTheirBrightness) {
  RgbImage image{256, 256, std::vector<float>(256 * 256 * 3)};
  std::mt19937 rng(5);
  std::normal_distribution<double> unit(0.0, 1.0);
  for (std::size_t p = 0; p < image.pixel_count(); ++p) {
    const double level = 0.05 + 0.9 * static_cast<double>(p % 256) / 255.0;
    for (std::size_t c = 0; c < 3; ++c) image.rgb[p * 3 + c] = static_cast<float>(level + 0.01 * std::sqrt(level) * unit(rng));
  }
  const ImageNoise noise = estimate_image_noise(image, {-kNoLevel, -kNoLevel, -kNoLevel}, {kNoLevel, kNoLevel, kNoLevel}, 0.0);
  ASSERT_EQ(noise.bands.size(), 16u);
  for (std::size_t k = 0; k < noise.bands.size(); ++k) {
    const double level = 0.5 * (noise.bands[k].lo + noise.bands[k].hi);
    // ~4,000 residuals per band: relative standard error ≈ 2 % (4 % with overlapping masks), plus the band's
    // spread of brightness (σ varies by √(hi/lo) across it).
    EXPECT_NEAR(noise.band_sigma(k, Vec3(1, 1, 1).normalized()) / (0.01 * std::sqrt(level)), 1.0, 0.12) << "band " << k;
  }
}


// A demosaiced image: each channel interpolated from a Bayer mosaic's photosites (OpenCV's bilinear
// demosaicing, as the sensor simulator and cameras do), so that neighbouring pixels share their noise. The
// noise that judges a cluster is each pixel's own, measured here from two independent captures of the same
// flat grey: σ_c = rms(a − b)/√2 over 65,536 pixels (relative standard error 0.3 %).
struct DemosaicedCaptures {
  RgbImage a, b;
  Vec3 per_pixel_sigma;
};

DemosaicedCaptures demosaiced_flat_grey() {
  constexpr int kSize = 256;
  std::mt19937 rng(23);
  std::normal_distribution<double> noise(0.0, 40.0);  // digital numbers, on a level of 20,000
  auto capture = [&] {
    cv::Mat mosaic(kSize, kSize, CV_16UC1), rgb;
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) mosaic.at<std::uint16_t>(y, x) = cv::saturate_cast<std::uint16_t>(20000 + noise(rng));
    cv::demosaicing(mosaic, rgb, cv::COLOR_BayerRG2RGB);
    RgbImage image{kSize, kSize, std::vector<float>(static_cast<std::size_t>(kSize) * kSize * 3)};
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x)
        for (int c = 0; c < 3; ++c)
          image.rgb[(static_cast<std::size_t>(y) * kSize + static_cast<std::size_t>(x)) * 3 + static_cast<std::size_t>(c)] =
              rgb.at<cv::Vec3w>(y, x)[c];
    return image;
  };
  DemosaicedCaptures d{capture(), capture(), Vec3::Zero()};
  for (std::size_t i = 0; i < d.a.rgb.size(); ++i) d.per_pixel_sigma[static_cast<Eigen::Index>(i % 3)] += std::pow(d.a.rgb[i] - d.b.rgb[i], 2);
  for (int c = 0; c < 3; ++c) d.per_pixel_sigma[c] = std::sqrt(d.per_pixel_sigma[c] / static_cast<double>(d.a.pixel_count()) / 2.0);
  return d;
}

// Adjacent taps see almost none of an interpolated channel's noise (bilinear red and blue residuals vanish at
// three pixels of four); taps 3 pixels apart see each pixel's own. A 16-bit file without the camera's numbers
// is taken as demosaiced; one whose metadata says no CFA was demosaiced keeps adjacent taps.
TEST(ImageNoise, DemosaicedNoiseIsEachPixelsOwn) {
  const DemosaicedCaptures d = demosaiced_flat_grey();
  ImageEncoding photograph;
  photograph.integer = true;
  photograph.bits = 16;
  photograph.full_scale = 65535;
  const LayerContext context = layer_context(d.a, photograph, 64);
  ASSERT_EQ(context.noise.spacing, kInterpolatedNoiseSpacing);
  ASSERT_EQ(context.noise.bands.size(), 16u);
  const Vec3 axes[3] = {Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ()};
  const std::vector<double> everywhere(16, 1.0 / 16);
  for (int c = 0; c < 3; ++c)  // the same tolerance as for white noise above
    EXPECT_NEAR(noise_sigma(context.noise, everywhere, axes[c]) / d.per_pixel_sigma[c], 1.0, kRelativeTolerance) << "channel " << c;

  ImageEncoding measured = photograph;
  measured.demosaiced = false;  // what chromatrace.cfa 0 says: wrongly here, to show what adjacent taps see
  const LayerContext adjacent = layer_context(d.a, measured, 64);
  ASSERT_EQ(adjacent.noise.spacing, 1);
  for (int c = 0; c < 3; ++c)
    EXPECT_LT(noise_sigma(adjacent.noise, everywhere, axes[c]), 0.5 * d.per_pixel_sigma[c]) << "channel " << c;
}

// White noise is independent at adjacent pixels: the measured correlation shows it so, float or 8-bit, and the
// mask's taps are adjacent. The residuals of white noise correlate with their neighbours' by −2/3 exactly; 16
// tiles' jackknife puts the standard error of the departure near 0.003 at 256², so 0.02 is many of them away.
TEST(ImageNoise, WhiteNoiseIsMeasuredWithAdjacentTaps) {
  for (const bool eight_bit : {false, true}) {
    SCOPED_TRACE(eight_bit ? "8-bit" : "float");
    RgbImage image{256, 256, std::vector<float>(256 * 256 * 3)};
    std::mt19937 rng(3);
    std::normal_distribution<double> unit(0.0, 1.0);
    for (std::size_t p = 0; p < image.pixel_count(); ++p) {
      const double level = 40 + 160 * static_cast<double>(p % 256) / 255.0;  // a ramp, in codes
      for (std::size_t c = 0; c < 3; ++c) {
        const double v = level + 3 * unit(rng);
        image.rgb[p * 3 + c] = static_cast<float>(eight_bit ? std::round(v) : v / 255.0);
      }
    }
    ImageEncoding encoding;  // nothing said of the pixels' noise: it is measured
    if (eight_bit) encoding.integer = true, encoding.bits = 8, encoding.full_scale = 255;
    const LayerContext context = layer_context(image, encoding, 64);
    ASSERT_TRUE(context.noise.spacing_choice);
    const SpacingChoice& choice = *context.noise.spacing_choice;
    EXPECT_EQ(context.noise.spacing, 1);
    EXPECT_TRUE(choice.confirmed);
    EXPECT_FALSE(choice.correlated_beyond);
    for (const SpacingTest& t : choice.tests) {
      EXPECT_TRUE(t.measurable) << t.spacing;
      EXPECT_LT(t.departure + 2 * t.standard_error, kSpacingTolerance) << t.spacing;
    }
  }
}

// Demosaiced noise is shared by neighbours: the correlation says so at 1 and 2 pixels, and 3 is chosen (bilinear
// interpolation reaches one photosite: at 3 pixels the taps' noise is independent again).
TEST(ImageNoise, DemosaicedNoiseIsMeasuredThreePixelsApart) {
  const DemosaicedCaptures d = demosaiced_flat_grey();
  ImageEncoding photograph;
  photograph.integer = true, photograph.bits = 16, photograph.full_scale = 65535;
  const LayerContext context = layer_context(d.a, photograph, 64);
  ASSERT_TRUE(context.noise.spacing_choice);
  const SpacingChoice& choice = *context.noise.spacing_choice;
  EXPECT_EQ(context.noise.spacing, 3);
  ASSERT_EQ(choice.tests.size(), 3u);
  // Adjacent: red and blue residuals vanish at three pixels of four, so nothing can be told; 2 apart: still shared;
  // 3 apart: independent again, shown so.
  EXPECT_FALSE(choice.tests[0].measurable);
  ASSERT_TRUE(choice.tests[1].measurable);
  EXPECT_GT(choice.tests[1].departure - 2 * choice.tests[1].standard_error, kSpacingTolerance);
  EXPECT_TRUE(choice.confirmed);
  EXPECT_FALSE(choice.correlated_beyond);
}

// A JPEG photograph (Debian's matplotlib sample grace_hopper.jpg: demosaiced, enlarged, compressed) and an HDR
// EXR (Blender's interior.exr, DWA-compressed): neither's noise is independent at adjacent pixels — adjacent taps
// read a fraction of it — and the taps go 3 pixels apart, saying why.
TEST(ImageNoise, APhotographsNoiseIsMeasuredWhereItIsIndependent) {
  int checked = 0;
  for (const std::string file : {"/usr/share/matplotlib/mpl-data/sample_data/grace_hopper.jpg",
                                 "/usr/share/blender/datafiles/studiolights/world/interior.exr"}) {
    if (!std::filesystem::exists(file)) {
      std::cerr << "skipped " << file << ": not installed\n";
      continue;
    }
    SCOPED_TRACE(file);
    const AnalysisImage input = read_analysis_image(file);
    const LayerContext context = layer_context(input.image, input.encoding, 64);
    ASSERT_TRUE(context.noise.spacing_choice);
    const SpacingChoice& choice = *context.noise.spacing_choice;
    EXPECT_EQ(context.noise.spacing, 3);
    EXPECT_FALSE(choice.confirmed);
    ASSERT_EQ(choice.tests.size(), 3u);
    // Adjacent taps: not shown independent — on the JPEG shown shared, beyond 2 standard errors; on the EXR, whose
    // residuals its compression set to 0 in many bands, too uncertain to show either.
    const SpacingTest& adjacent = choice.tests.front();
    EXPECT_TRUE(!adjacent.measurable || adjacent.departure + 2 * adjacent.standard_error > kSpacingTolerance)
        << adjacent.departure << " ± " << adjacent.standard_error;
    if (file.ends_with(".jpg")) {
      ASSERT_TRUE(adjacent.measurable);
      EXPECT_GT(adjacent.departure - 2 * adjacent.standard_error, kSpacingTolerance);
    }
    // … so adjacent taps read less of the noise than taps 3 apart, by more than the estimator's 10 %.
    const ImageNoise one = estimate_image_noise(input.image, context.clipping.low, context.high_levels, context.quantisation_sigma, 1);
    const std::vector<double> everywhere(context.noise.bands.size(), 1.0 / static_cast<double>(context.noise.bands.size()));
    const Vec3 grey = Vec3::Ones().normalized();
    EXPECT_LT(noise_sigma(one, everywhere, grey), 0.9 * noise_sigma(context.noise, everywhere, grey));
    std::cerr << file << ": spacing " << context.noise.spacing << "; departures";
    for (const SpacingTest& t : choice.tests)
      std::cerr << " " << t.spacing << ": " << (t.measurable ? fmt::format("{:.4f} ± {:.4f}", t.departure, t.standard_error) : "not measurable");
    std::cerr << "\n";
    ++checked;
  }
  if (checked == 0) GTEST_SKIP() << "install python-matplotlib-data or blender";
}

}  // namespace
}  // namespace ct::test
