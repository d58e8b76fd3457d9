// SPDX-License-Identifier: Apache-2.0
// Stage 3: camera curves, and the ideal XYZ camera against direct integration of known spectra.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/cie.h"
#include "core/colour.h"
#include "core/csv.h"
#include "core/error.h"
#include "core/spectral_exr.h"
#include "sensor_sim/optics.h"
#include "sensor_sim/spectral_response.h"
#include "tests/core/spectral_exr_fixtures.h"
#include "tests/sensor_sim/sensor_test_util.h"

namespace ct {
namespace {

namespace fs = std::filesystem;
using sensor::SensorConfig;

const fs::path kD65 = fs::path(CHROMATRACE_TEST_DATA) / "spectral_exr_samples" / "spectral-exr_D65_emissive.exr";
const fs::path kReflectances = fs::path(CHROMATRACE_SOURCE_DIR) / "scenes" / "spectra" / "synthetic_reflectances.csv";

// Electrons per unit of ∫ L(λ)·c̄(λ) dλ for the ideal camera, from docs/sensor.md: an energy-basis curve gives
// η_c(λ) = qe · (c̄(λ)/λ) / max(c̄/λ), so μ_e,c = G·A·T·qe·λ_n·10⁻⁹/(hc) · ∫ L c̄ dλ with λ_n = 1 / max(c̄/λ)
// (the maximum over all three CMFs and their table wavelengths, in nm⁻¹).
double xyz_scale(const SensorConfig& config) {
  double max_ratio = 0;
  for (const PiecewiseLinearSpectrum* cmf : {&cie::x_bar(), &cie::y_bar(), &cie::z_bar()})
    for (std::size_t i = 0; i < cmf->wavelengths().size(); ++i)
      max_ratio = std::max(max_ratio, cmf->values()[i] / cmf->wavelengths()[i]);
  const double aperture = std::numbers::pi / 4.0 / (config.optics.f_number * config.optics.f_number);
  const double area = config.pixel.pitch_um * config.pixel.pitch_um * 1e-12 * config.pixel.fill_factor;
  return aperture * area * *config.exposure.time_s * config.response.peak_qe / max_ratio * 1e-9 /
         (kPlanck * kLightSpeed);
}

// ∫ L c̄ dλ for band values L (a step function), integrating each CMF over each band on its own.
Vec3d direct_xyz(const float* values, const Bands& bands) {
  Vec3d xyz{0, 0, 0};
  const PiecewiseLinearSpectrum* cmf[3] = {&cie::x_bar(), &cie::y_bar(), &cie::z_bar()};
  for (std::size_t c = 0; c < 3; ++c)
    for (std::size_t b = 0; b < bands.size(); ++b) xyz[c] += values[b] * cmf[c]->integral(bands.lo(b), bands.hi(b));
  return xyz;
}

TEST(SpectralResponse, ShippedCamerasLoadWithPeakOneInGreen) {
  ASSERT_EQ(sensor::shipped_cameras().size(), 17u);
  for (const std::string& name : sensor::shipped_cameras()) {
    const sensor::CameraCurves camera = sensor::camera_curves(name, {"r", "g", "b"}, "test");
    EXPECT_DOUBLE_EQ(camera.min_wavelength(), 380.0) << name;
    EXPECT_DOUBLE_EQ(camera.max_wavelength(), 720.0) << name;
    const auto& g = camera.curves[1].values();
    EXPECT_DOUBLE_EQ(*std::max_element(g.begin(), g.end()), 1.0) << name;
  }
}

TEST(SpectralResponse, UnknownCameraAndBandsOutsideTheCurveAreErrors) {
  try {
    sensor::camera_curves("nikon_d9000", {"r", "g", "b"}, "cam.json: spectral_response.camera");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cam.json: spectral_response.camera: unknown camera \"nikon_d9000\""),
              std::string::npos)
        << e.what();
  }
  const sensor::CameraCurves camera = sensor::camera_curves("nikon_d850", {"r", "g", "b"}, "test");
  EXPECT_NO_THROW(sensor::check_band_coverage(Bands::uniform(380, 720, 10), camera, "in.exr"));
  try {
    sensor::check_band_coverage(Bands::uniform(380, 780, 10), camera, "in.exr");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("in.exr: bands 380-780 nm reach outside"), std::string::npos) << e.what();
  }
}

// μ_p = E·A·T·λ/(hc)·Δλ per band (eq. 1) and μ_e = η·μ_p (eq. 3): a photon-basis flat curve with peak QE η
// gives Q = η·λ_c·Δλ·10⁻⁹/(hc) for a band of centre λ_c (∫ λ dλ over the band is Δλ·λ_c exactly).
TEST(SpectralResponse, PhotonBasisCountsPhotonsPerBand) {
  test::TempDir dir;
  const sensor::CameraCurves camera =
      sensor::camera_curves(test::write_flat_camera(dir.path()).string(), {"r", "g", "b"}, "test");
  const Bands bands = Bands::from_edges({400, 410, 500, 700});
  const auto q = sensor::photon_response(bands, camera, sensor::ResponseBasis::Photon, 0.6,
                                         PiecewiseLinearSpectrum::constant(1.0));
  for (std::size_t b = 0; b < bands.size(); ++b) {
    const double expected = 0.6 * bands.centre(b) * 1e-9 / (kPlanck * kLightSpeed) * bands.width(b);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(q[static_cast<std::size_t>(c)][b] / expected, 1.0, 1e-12);
  }
}

TEST(SpectralResponse, CieCameraGivesTheXyzOfTheD65Sample) {
  test::TempDir dir;
  const SensorConfig config = test::config_of({{"preset", "ideal"}});
  test::run_sensor(kD65, dir.file("d65.exr"), config);
  const test::RgbLayer xyz = test::read_rgb(dir.file("d65.exr"));

  SpectralExrReader reader(kD65);
  const std::vector<float> radiance = reader.read_layer(reader.info().total());
  const Vec3d expected = direct_xyz(radiance.data(), reader.info().bands);
  const double scale = xyz_scale(config);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(xyz.at(0, 0, c) / (scale * expected[static_cast<std::size_t>(c)]), 1.0, 1e-5);
  // And the D65 white point: x, y = (0.3127, 0.3290) to the table's rounding.
  const double sum = expected[0] + expected[1] + expected[2];
  EXPECT_NEAR(expected[0] / sum, 0.3127, 2e-4);
  EXPECT_NEAR(expected[1] / sum, 0.3290, 2e-4);
}

TEST(SpectralResponse, CieCameraGivesTheXyzOfReflectancesUnderAnIlluminant) {
  test::TempDir dir;
  const CsvTable table = read_csv(kReflectances);
  const PiecewiseLinearSpectrum& light = cie::illuminant("A");
  const Bands bands = Bands::uniform(380, 780, 10);
  // A Lambertian reflector under irradiance E(λ) = S(λ) (W·m⁻²·nm⁻¹) has radiance R·S/π: band averages,
  // integrated exactly.
  const int patches = static_cast<int>(table.columns.size());
  test::write_radiance(dir.file("chart.exr"), bands, patches, 2, [&](int x, int, std::size_t b) {
    const PiecewiseLinearSpectrum r = table.spectrum(table.columns[static_cast<std::size_t>(x)]);
    return static_cast<float>(integral_of_product(r, light, bands.lo(b), bands.hi(b)) / bands.width(b) /
                              std::numbers::pi);
  });
  const SensorConfig config = test::config_of({{"exposure", {{"time_s", 0.5}}}, {"optics", {{"f_number", 2.0}}}});
  test::run_sensor(dir.file("chart.exr"), dir.file("xyz.exr"), config);
  const test::RgbLayer xyz = test::read_rgb(dir.file("xyz.exr"));

  SpectralExrReader reader(dir.file("chart.exr"));
  const std::vector<float> radiance = reader.read_layer(reader.info().total());
  const double scale = xyz_scale(config);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < patches; ++x) {
      const Vec3d expected =
          direct_xyz(radiance.data() + (static_cast<std::size_t>(y * patches + x)) * bands.size(), bands);
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(xyz.at(x, y, c) / (scale * expected[static_cast<std::size_t>(c)]), 1.0, 1e-5)
            << table.columns[static_cast<std::size_t>(x)] << " channel " << c;
    }
}

}  // namespace
}  // namespace ct
