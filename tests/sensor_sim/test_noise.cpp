// SPDX-License-Identifier: Apache-2.0
// Stage 5: noise and limits. The EMVA 1288 parameters are recovered from simulated flat fields and dark
// frames by the photon transfer method, as a camera would be characterised, and compared with the settings.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/random.h"
#include "sensor_sim/adc.h"
#include "sensor_sim/noise.h"
#include "tests/core/spectral_exr_fixtures.h"
#include "tests/sensor_sim/sensor_test_util.h"
#include "core/statistics.h"

namespace ct {
namespace {

namespace fs = std::filesystem;

// One narrow band and a flat photon-basis camera: every photon of the band is detected with probability η.
const Bands kBand = Bands::from_edges({545, 555});
constexpr int kSize = 256;  // 256² pixels × 3 channels: variances to ±0.3 % (1σ), slopes better
constexpr double kQe = 0.6, kGain = 0.25, kBlack = 100, kFullWell = 20000, kRead = 5, kDarkCurrent = 100;
constexpr double kTime = 0.01, kFNumber = 4, kPitchUm = 5;

// Photons per pixel per unit band radiance (eq. 1 and 2): μ_p = (π/4)(1/N)²·L·A·T·λ/(hc)·Δλ.
double photons_per_radiance() {
  return std::numbers::pi / 4.0 / (kFNumber * kFNumber) * kPitchUm * kPitchUm * 1e-12 * kTime * kBand.centre(0) * 1e-9 /
         (kPlanck * kLightSpeed) * kBand.width(0);
}

class PhotonTransfer : public ::testing::Test {
 protected:
  void SetUp() override { camera_ = test::write_flat_camera(dir_.path()); }

  Json settings(bool noise) const {
    return {{"optics", {{"f_number", kFNumber}}},
            {"exposure", {{"time_s", kTime}}},
            {"pixel", {{"pitch_um", kPitchUm}}},
            {"spectral_response", {{"camera", camera_.string()}, {"basis", "photon"}, {"peak_qe", kQe}}},
            {"noise",
             {{"enabled", noise},
              {"dark_current_e_per_s", kDarkCurrent},
              {"read_e", kRead},
              {"dsnu_e", 2.0},
              {"prnu", 0.01},
              {"pattern_seed", 7}}},
            {"full_well", {{"enabled", true}, {"electrons", kFullWell}}},
            {"adc", {{"enabled", true}, {"gain_dn_per_e", kGain}, {"black_level_dn", kBlack}, {"bits", 16}}}};
  }

  // Every value (pixels × channels) of one frame of a flat field of band radiance L.
  std::vector<double> frame(double radiance, std::uint64_t seed) {
    const fs::path in = dir_.file("flat.exr"), out = dir_.file("frame.exr");
    fs::remove(in);
    fs::remove(out);
    test::write_radiance(in, kBand, kSize, kSize, [&](int, int, std::size_t) { return static_cast<float>(radiance); });
    Json patch = settings(true);
    patch["noise"]["seed"] = seed;
    test::run_sensor(in, out, test::config_of(patch));
    const test::RgbLayer image = test::read_rgb(out);
    return {image.values.begin(), image.values.end()};
  }

  // EMVA 1288's mean and temporal variance from two frames: σ_y² = var(y_A − y_B)/2 removes the fixed pattern.
  struct Statistics {
    double mean, variance;
  };
  Statistics pair(double radiance) {
    const std::vector<double> a = frame(radiance, 1), b = frame(radiance, 2);
    double mean = 0, diff_mean = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      mean += (a[i] + b[i]) / 2;
      diff_mean += a[i] - b[i];
    }
    mean /= static_cast<double>(a.size());
    diff_mean /= static_cast<double>(a.size());
    double var = 0;
    for (std::size_t i = 0; i < a.size(); ++i) var += std::pow(a[i] - b[i] - diff_mean, 2);
    return {mean, var / static_cast<double>(a.size() - 1) / 2};
  }

  test::TempDir dir_;
  fs::path camera_;
};

TEST_F(PhotonTransfer, RecoversGainDarkNoiseQuantumEfficiencyAndSaturation) {
  const Statistics dark = pair(0.0);
  // Radiances putting the mean photo-electrons at 10 % … 80 % of the full well.
  std::vector<double> photons, signal, variance;
  for (int i = 1; i <= 8; ++i) {
    const double radiance = 0.1 * i * kFullWell / kQe / photons_per_radiance();
    const Statistics s = pair(radiance);
    photons.push_back(radiance * photons_per_radiance());
    signal.push_back(s.mean - dark.mean);
    variance.push_back(s.variance - dark.variance);
  }
  // Least-squares slopes through the origin: σ_y² − σ_y,dark² = K (μ_y − μ_y,dark), μ_y − μ_y,dark = K η μ_p.
  const auto slope = [](const std::vector<double>& x, const std::vector<double>& y) {
    double xy = 0, xx = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      xy += x[i] * y[i];
      xx += x[i] * x[i];
    }
    return xy / xx;
  };
  const double gain = slope(signal, variance);
  EXPECT_NEAR(gain / kGain, 1.0, 0.02) << "system gain K";
  EXPECT_NEAR(slope(photons, signal) / gain / kQe, 1.0, 0.02) << "quantum efficiency η";

  // σ_y,dark² = K² σ_d² + 1/12, with σ_d² the read noise and the dark current's shot noise I_d·T.
  const double dark_noise = std::sqrt(dark.variance - 1.0 / 12.0) / gain;
  EXPECT_NEAR(dark_noise / std::sqrt(kRead * kRead + kDarkCurrent * kTime), 1.0, 0.02) << "dark noise σ_d";
  // The dark signal: black level plus the dark current's mean.
  EXPECT_NEAR(dark.mean, kBlack + kGain * kDarkCurrent * kTime, 0.05);

  // Over-exposed three times, every pixel holds a full well: the mean signal above dark is K·μ_e,sat (less the
  // dark electrons, which the full well includes).
  const Statistics saturated = pair(3 * kFullWell / kQe / photons_per_radiance());
  EXPECT_NEAR((saturated.mean - dark.mean) / gain / kFullWell, 1.0, 0.02) << "saturation capacity";
}

// With every other noise off, rounding to whole DN leaves a uniform error of variance 1/12 DN² when the
// signal's fractional parts are spread evenly (a fine ramp of radiance).
TEST_F(PhotonTransfer, QuantisationAloneGivesOneTwelfthDnSquared) {
  const fs::path in = dir_.file("ramp.exr"), out = dir_.file("ramp_out.exr");
  const double top = 0.5 * kFullWell / kQe / photons_per_radiance();
  test::write_radiance(in, kBand, kSize, kSize, [&](int x, int y, std::size_t) {
    return static_cast<float>(top * (0.1 + 0.9 * (y * kSize + x) / double(kSize * kSize)));
  });
  test::run_sensor(in, out, test::config_of(settings(false)));
  const test::RgbLayer y = test::read_rgb(out), linear = test::read_rgb(out, "linear");
  double sum = 0, sum2 = 0;
  const double dark_dn = kGain * kDarkCurrent * kTime;
  for (std::size_t i = 0; i < y.values.size(); ++i) {
    const double error = y.values[i] - (kGain * linear.values[i] + kBlack + dark_dn);
    sum += error;
    sum2 += error * error;
  }
  const double n = static_cast<double>(y.values.size());
  const double variance = sum2 / n - (sum / n) * (sum / n);
  EXPECT_NEAR(variance * 12.0, 1.0, 0.02);
  EXPECT_NEAR(sum / n, 0.0, 0.01);  // rounding to nearest: no bias
}

TEST(Noise, PoissonHasItsMeanAsMeanAndVariance) {
  for (const double mean : {0.3, 4.0, 9.99, 10.0, 57.5, 3000.0, 2.5e6}) {
    constexpr int n = 200000;
    double sum = 0, sum2 = 0;
    for (int i = 0; i < n; ++i) {
      Random random(11, static_cast<std::uint64_t>(i));
      const double k = static_cast<double>(sensor::poisson(mean, random));
      sum += k;
      sum2 += k * k;
    }
    const double m = sum / n, v = sum2 / n - m * m;
    // Standard errors: of the mean √(μ/n), of the variance ≈ μ√(2/n) (plus the fourth cumulant μ/n, small).
    EXPECT_NEAR(m, mean, kSigmasManyChecks * std::sqrt(mean / n)) << mean;
    EXPECT_NEAR(v, mean, kSigmasManyChecks * mean * std::sqrt(2.0 / n + 1.0 / (mean * n))) << mean;
  }
}

TEST(Noise, NormalIsStandard) {
  constexpr int n = 200000;
  double sum = 0, sum2 = 0;
  for (int i = 0; i < n; ++i) {
    Random random(5, static_cast<std::uint64_t>(i));
    const double z = sensor::standard_normal(random);
    sum += z;
    sum2 += z * z;
  }
  EXPECT_NEAR(sum / n, 0.0, kSigmasManyChecks / std::sqrt(double(n)));
  EXPECT_NEAR(sum2 / n, 1.0, kSigmasManyChecks * std::sqrt(2.0 / n));
}

TEST(Noise, SameSeedSameFrameOtherSeedOtherFrameSamePattern) {
  sensor::NoiseConfig noise;
  noise.enabled = true;
  noise.read_e = 3;
  noise.prnu = 0.05;
  const sensor::FullWellConfig well;
  const double a = sensor::read_out_electrons(noise, well, 1, 1000, {42, 0, 42}, 1);
  EXPECT_EQ(a, sensor::read_out_electrons(noise, well, 1, 1000, {42, 0, 42}, 1));
  EXPECT_NE(a, sensor::read_out_electrons(noise, well, 1, 1000, {43, 0, 43}, 1));
  EXPECT_NE(a, sensor::read_out_electrons(noise, well, 1, 1000, {42, 0, 42}, 2));
  noise.seed = 1;
  EXPECT_NE(a, sensor::read_out_electrons(noise, well, 1, 1000, {42, 0, 42}, 1));
  // Without noise a pixel reads its mean, dark current included, clipped to the full well.
  noise.enabled = false;
  noise.dark_current_e_per_s = 10;
  EXPECT_EQ(sensor::read_out_electrons(noise, well, 2, 1000, {42, 0, 42}, 1), 1020);
  EXPECT_EQ(sensor::read_out_electrons(noise, {true, 500}, 2, 1000, {42, 0, 42}, 1), 500);
}

TEST(Adc, RoundsAndClipsToTheCodeRange) {
  sensor::AdcConfig adc;
  adc.gain_dn_per_e = 0.5;
  adc.black_level_dn = 10;
  adc.bits = 8;
  EXPECT_EQ(sensor::digitise(adc, 0), 10);
  EXPECT_EQ(sensor::digitise(adc, 3), 12);  // 11.5 rounds up
  EXPECT_EQ(sensor::digitise(adc, -100), 0);
  EXPECT_EQ(sensor::digitise(adc, 1e6), 255);
  adc.bits = 32;
  EXPECT_EQ(sensor::digitise(adc, 1e12), 4294967295.0);
}

}  // namespace
}  // namespace ct
