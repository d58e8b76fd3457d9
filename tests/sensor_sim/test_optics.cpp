// SPDX-License-Identifier: Apache-2.0
// Stage 1: cos⁴ fall-off from the camera's field of view, the aperture factor, and the lens transmittance.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/camera.h"
#include "core/error.h"
#include "sensor_sim/optics.h"
#include "tests/core/spectral_exr_fixtures.h"
#include "tests/sensor_sim/sensor_test_util.h"

namespace ct {
namespace {

namespace fs = std::filesystem;

const Bands kBands = Bands::uniform(500, 600, 50);

// A uniform radiance field of an odd size, so that the centre pixel lies on the optical axis.
constexpr int kWidth = 33, kHeight = 25;
constexpr double kFovDeg = 60.0;

double degrees_to_tan_half(double deg) { return std::tan(deg * std::numbers::pi / 360.0); }

TEST(Optics, Cos4CornerToCentreRatioFollowsTheFieldOfView) {
  test::TempDir dir;
  test::write_radiance(
      dir.file("flat.exr"), kBands, kWidth, kHeight, [](int, int, std::size_t) { return 1.0f; },
      test::camera_attribute(kFovDeg, kWidth, kHeight));
  const auto report = test::run_sensor(dir.file("flat.exr"), dir.file("out.exr"), test::config_of(Json::object()));
  ASSERT_FALSE(report.notes.empty());
  const test::RgbLayer image = test::read_rgb(dir.file("out.exr"), "linear");

  // The corner pixel's centre (0.5, 0.5) on the image plane at unit distance: x = (1/W − 1)·tan(h/2),
  // y = (1 − 1/H)·tan(v/2) with tan(v/2) = tan(h/2)·H/W for square pixels; α = atan √(x² + y²).
  const double th = degrees_to_tan_half(kFovDeg), tv = th * kHeight / kWidth;
  const double x = (1.0 / kWidth - 1.0) * th, y = (1.0 - 1.0 / kHeight) * tv;
  const double alpha = std::atan(std::hypot(x, y));
  const double expected = std::pow(std::cos(alpha), 4);
  for (int c = 0; c < 3; ++c) {
    const double centre = image.at(kWidth / 2, kHeight / 2, c);
    for (const auto& [cx, cy] : {std::pair{0, 0}, {kWidth - 1, 0}, {0, kHeight - 1}, {kWidth - 1, kHeight - 1}})
      EXPECT_NEAR(image.at(cx, cy, c) / centre, expected, 1e-6) << "corner " << cx << "," << cy;
  }
  EXPECT_LT(expected, 0.6);  // a wide field: the fall-off is large, not a rounding effect
}

// The sensor's fall-off and the scene camera's off-axis angle are one image plane: for a camera of the scene
// format (here 4:3, field of view on the smaller axis), cos⁴ of the angle the camera gives each pixel centre is
// the fall-off the sensor applies there, with the fields of view the renderer writes into chromatrace.camera.
TEST(Optics, Cos4IsTheSceneCamerasOffAxisAngle) {
  Camera camera;
  camera.width = 40;
  camera.height = 30;
  camera.fov_deg = 50;
  camera.fov_axis = FovAxis::Smaller;
  const double to_deg = 360.0 / std::numbers::pi;
  const sensor::FieldOfView fov{std::atan(camera.tan_half_width()) * to_deg, std::atan(camera.tan_half_height()) * to_deg, "test"};
  EXPECT_NEAR(fov.vertical_deg, 50.0, 1e-12);
  const sensor::Cos4Falloff falloff(fov, camera.width, camera.height);
  for (const auto& [i, j] : {std::pair{0, 0}, {39, 0}, {17, 11}, {39, 29}, {20, 15}})
    EXPECT_NEAR(falloff.at(i, j), std::pow(std::cos(camera.off_axis_angle(i + 0.5, j + 0.5)), 4), 1e-12) << i << "," << j;
}

TEST(Optics, FieldOfViewOptionStandsInForAMissingCameraElseCos4IsOff) {
  test::TempDir dir;
  test::write_radiance(
      dir.file("with.exr"), kBands, kWidth, kHeight, [](int, int, std::size_t) { return 1.0f; },
      test::camera_attribute(kFovDeg, kWidth, kHeight));
  test::write_radiance(dir.file("without.exr"), kBands, kWidth, kHeight, [](int, int, std::size_t) { return 1.0f; });
  test::run_sensor(dir.file("with.exr"), dir.file("a.exr"), test::config_of(Json::object()));
  test::run_sensor(dir.file("without.exr"), dir.file("b.exr"), test::config_of({{"optics", {{"fov_deg", kFovDeg}}}}));
  const auto off = test::run_sensor(dir.file("without.exr"), dir.file("c.exr"), test::config_of(Json::object()));
  const test::RgbLayer a = test::read_rgb(dir.file("a.exr")), b = test::read_rgb(dir.file("b.exr"));
  const test::RgbLayer c = test::read_rgb(dir.file("c.exr"));
  for (std::size_t i = 0; i < a.values.size(); ++i) EXPECT_NEAR(a.values[i] / b.values[i], 1.0, 1e-6);
  for (std::size_t i = 0; i < c.values.size(); ++i) EXPECT_EQ(c.values[i], c.values[i % 3]);
  ASSERT_EQ(off.notes.size(), 1u);
  EXPECT_NE(off.notes[0].find("cos4 fall-off off"), std::string::npos) << off.notes[0];
}

// E = (π/4)(1/N)²·τ·L: doubling N quarters the signal; a flat τ scales it; without optics E = L × 1 sr.
TEST(Optics, ApertureAndTransmittanceScaleTheIrradiance) {
  test::TempDir dir;
  test::write_radiance(dir.file("flat.exr"), kBands, 4, 4, [](int, int, std::size_t) { return 2.0f; });
  const auto run = [&](const Json& optics, const std::string& name) {
    test::run_sensor(dir.file("flat.exr"), dir.file(name), test::config_of({{"optics", optics}}));
    return test::read_rgb(dir.file(name)).at(1, 1, 1);
  };
  const double f2 = run({{"f_number", 2.0}}, "f2.exr");
  EXPECT_NEAR(run({{"f_number", 4.0}}, "f4.exr") / f2, 0.25, 1e-6);
  EXPECT_NEAR(run({{"f_number", 2.0}, {"transmittance", 0.8}}, "t.exr") / f2, 0.8, 1e-6);
  EXPECT_NEAR(run({{"enabled", false}}, "off.exr") / f2, 1.0 / sensor::aperture_factor(2.0), 1e-6);
  EXPECT_DOUBLE_EQ(sensor::aperture_factor(2.0), std::numbers::pi / 16.0);
}

// Veiling glare adds flare × the image's mean signal to every pixel, per channel, whatever the pixel; the path
// components are the scene's light and stay as they were.
TEST(Optics, VeilingGlareAddsAFractionOfTheMeanSignalEverywhere) {
  test::TempDir dir;
  test::write_radiance(dir.file("ramp.exr"), kBands, 8, 6, [](int x, int y, std::size_t b) {
    return static_cast<float>(0.2 + 0.3 * x + 0.1 * y * (b + 1));
  });
  const auto linear = [&](double flare, const std::string& name) {
    test::run_sensor(dir.file("ramp.exr"), dir.file(name), test::config_of({{"optics", {{"flare", flare}}}}));
    return test::read_rgb(dir.file(name), "linear");
  };
  const test::RgbLayer clean = linear(0.0, "clean.exr"), glared = linear(0.02, "glare.exr");
  const std::size_t pixels = clean.values.size() / 3;
  for (std::size_t c = 0; c < 3; ++c) {
    double mean = 0;
    for (std::size_t p = 0; p < pixels; ++p) mean += clean.values[3 * p + c] / double(pixels);
    for (std::size_t p = 0; p < pixels; ++p)
      EXPECT_NEAR(glared.values[3 * p + c] - clean.values[3 * p + c], 0.02 * mean, 1e-5 * mean) << "channel " << c;
  }
  EXPECT_THROW(test::config_of({{"optics", {{"flare", 1.5}}}}), InputError);  // a fraction in [0, 1]
}

TEST(Optics, MalformedCameraAttributeNamesIt) {
  test::TempDir dir;
  test::write_radiance(dir.file("bad.exr"), kBands, 2, 2, [](int, int, std::size_t) { return 1.0f; },
                       {{"chromatrace.camera", "{\"fov_deg\": 40}"}});
  try {
    test::run_sensor(dir.file("bad.exr"), dir.file("out.exr"), test::config_of(Json::object()));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("attribute chromatrace.camera: horizontal_fov_deg"), std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(fs::exists(dir.file("out.exr")));
}

}  // namespace
}  // namespace ct
