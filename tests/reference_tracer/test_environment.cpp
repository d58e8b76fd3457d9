// SPDX-License-Identifier: Apache-2.0
// The environment light and image textures against known answers: the furnace under a constant environment,
// a constant latitude-longitude image against the constant spectrum, the irradiance from one bright patch of
// the image (which also pins the mapping of directions to the image and the rotation), textured reflectance
// and emission per texel, and determinism across thread counts.
//
// Tolerances are the Monte Carlo standard error estimated from the rendered pixels (pixels are independent
// estimates), or float rounding where the answer is deterministic.
#include <gtest/gtest.h>

#include "tests/core/image_fixtures.h"

#include <cmath>
#include <filesystem>
#include <numbers>

#include <unistd.h>

#include <OpenImageIO/imageio.h>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "core/colour.h"
#include "core/rgb_to_spectrum.h"
#include "core/scene.h"
#include "core/texture.h"
#include "reference_tracer/render.h"
#include "reference_tracer/scene_data.h"

namespace ct::rt {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

class EnvironmentTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / fmt::format("ct-env-{}-{}", ::getpid(), counter_++);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Writes an image of `channels` channels (float for .exr, 8-bit otherwise), rows from the top.
  fs::path write_image(const std::string& name, int width, int height, const std::vector<float>& pixels,
                       int channels = 3) const {
    return test::write_test_image(dir_ / name, width, height, pixels, channels);
  }
  Scene scene(const json& doc) const { return parse_scene(doc, "test-scene", dir_); }

  fs::path dir_;
  static inline int counter_ = 0;
};

RenderOptions quiet(std::vector<bool> families = {false, false, false}) {
  RenderOptions o;
  o.progress = false;
  o.components = {families[0], families[1], families[2]};
  return o;
}

int layer_of(const RenderedImage& image, const std::string& component) {
  for (std::size_t c = 0; c < image.components.size(); ++c)
    if (image.components[c] == component) return static_cast<int>(c) + 1;
  return -1;
}

double value(const RenderedImage& image, int layer, int x, int y, int band) {
  const std::size_t nb = image.bands.size();
  return image.layers[static_cast<std::size_t>(layer)][(static_cast<std::size_t>(y) * image.width + x) * nb + band];
}

// Mean and standard error of a set of residuals.
struct Residuals {
  double sum = 0, sum2 = 0;
  int n = 0;
  void add(double r) {
    sum += r;
    sum2 += r * r;
    ++n;
  }
  double mean() const { return sum / n; }
  double se() const { return std::sqrt(std::max(0.0, sum2 / n - mean() * mean()) / (n - 1)); }
};

json base_scene(const json& environment, const json& objects, const json& camera, int samples, int max_bounces) {
  return {{"format", "chromatrace-scene/1"},
          {"materials",
           {{"white", {{"type", "lambert"}, {"reflectance", {{"constant", 0.7}}}}}}},
          {"objects", objects},
          {"lights", json::array()},
          {"environment", environment},
          {"camera", camera},
          {"render", {{"samples", samples}, {"max_bounces", max_bounces}, {"bands", "400:700:100"},
                      {"pixel_filter", "point"}, {"seed", 3}}}};
}

const json kSphere = json::array({{{"name", "ball"}, {"material", "white"},
                                   {"shape", {{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 1}}}}});
const json kSphereCamera = {{"position", {0, -4, 0.5}}, {"look_at", {0, 0, 0}}, {"fov_deg", 40},
                            {"resolution", {24, 24}}};

// Furnace: a convex white sphere (ρ = 0.7) under a constant environment L = 2, direct light only. Each sphere
// pixel sees ρ·L times the share of the cosine lobe about the shading normal that lies above the facet (both
// sampling techniques lose the directions below it): (1 + cos δ) / 2, δ the angle between the two normals
// (the lost part of the lobe projects onto the half-disc minus a half-ellipse of semi-axes 1 and cos δ).
// The background is the environment itself, all of it "emission" and light group "environment".
void expect_furnace(const Scene& scene, const RenderedImage& image, double rho, const std::vector<double>& band_radiance) {
  const TracerScene tracer_scene(scene, 1);
  const Camera& cam = scene.camera;
  const int emission = layer_of(image, "emission"), group = layer_of(image, "light.environment");
  ASSERT_GT(emission, 0);
  ASSERT_GT(group, 0);
  for (int b = 0; b < 3; ++b) {
    const double radiance = band_radiance[static_cast<std::size_t>(b)];
    Residuals sphere;
    int background = 0;
    for (int y = 0; y < cam.height; ++y)
      for (int x = 0; x < cam.width; ++x) {
        const auto hit = tracer_scene.accel().intersect(cam.position, cam.ray_direction(x + 0.5, y + 0.5), 1e30);
        const double total = value(image, 0, x, y, b);
        EXPECT_NEAR(value(image, group, x, y, b), total, 1e-6 * total);
        if (!hit) {
          EXPECT_NEAR(total, radiance, 1e-6 * radiance) << x << ", " << y;
          EXPECT_NEAR(value(image, emission, x, y, b), radiance, 1e-6 * radiance);
          ++background;
          continue;
        }
        const SurfaceHit s = tracer_scene.surface(*hit);
        // A view from below the shading hemisphere (at the silhouette) ends the path.
        const bool shaded = s.ns.dot(-cam.ray_direction(x + 0.5, y + 0.5)) > 0.0;
        sphere.add(total - (shaded ? rho * radiance * (1.0 + s.ns.dot(s.ng)) / 2.0 : 0.0));
        EXPECT_EQ(value(image, emission, x, y, b), 0.0);
      }
    ASSERT_GT(sphere.n, 100);
    ASSERT_GT(background, 50);
    EXPECT_GT(sphere.se(), 0.0);
    EXPECT_LT(std::abs(sphere.mean()), 4.0 * sphere.se()) << "band " << b << ": mean residual " << sphere.mean()
                                                          << ", se " << sphere.se();
  }
}

TEST_F(EnvironmentTest, FurnaceUnderAConstantEnvironment) {
  const Scene s = scene(base_scene({{"radiance", {{"constant", 1.0}}}, {"scale", 2.0}}, kSphere, kSphereCamera, 64, 1));
  const RenderedImage image = render(s, quiet({true, true, false}));
  expect_furnace(s, image, 0.7, {2.0, 2.0, 2.0});
}

TEST_F(EnvironmentTest, ConstantImageIsTheConstantEnvironment) {
  // An emitted grey is that grey times the colour space's white (D65 of unit luminance), so an 8 × 4 image of 2.0
  // is the constant environment 2·W(λ), band by band, and its importance sampling must give the same answer.
  const fs::path sky = write_image("grey.exr", 8, 4, std::vector<float>(8 * 4 * 3, 2.0f));
  const Scene s = scene(base_scene({{"radiance", {{"texture", sky.string()}}}, {"rotation_deg", 30}}, kSphere,
                                   kSphereCamera, 64, 1));
  ASSERT_TRUE(s.environment->radiance.texture);
  EXPECT_EQ(s.environment->radiance.texture->colour_space, TextureColourSpace::Linear);
  const RenderedImage image = render(s, quiet({true, true, false}));
  std::vector<double> white = band_averages(rgb_to_emission_spectrum({1.0, 1.0, 1.0}), image.bands);
  for (double& v : white) v *= 2.0;
  expect_furnace(s, image, 0.7, white);
}

// A black 16 × 8 image with one patch of radiance 5 (columns 4–7, rows 1–2: longitudes from +X to +Y, polar
// angles 22.5°–67.5°), seen by a white plane facing `normal`: its radiance is ρ/π ∫_patch L max(0, n·ω) dω, integrated
// here by the midpoint rule over the patch in (φ, cos θ), where dω = dφ d(cos θ).
double patch_radiance(const Vec3& normal, double rotation_deg, double rho, double radiance) {
  const int n = 400;
  const double phi0 = 0, phi1 = std::numbers::pi / 2;  // columns 4..7: u in [4/16, 8/16), φ = π(1 − 2u)
  const double z0 = std::cos(std::numbers::pi * 1 / 8), z1 = std::cos(std::numbers::pi * 3 / 8);
  const double r = rotation_deg * std::numbers::pi / 180;
  double sum = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double phi = phi0 + (i + 0.5) / n * (phi1 - phi0) + r, z = z0 + (j + 0.5) / n * (z1 - z0);
      const double s = std::sqrt(1 - z * z);
      sum += std::max(0.0, normal.dot(Vec3(s * std::cos(phi), s * std::sin(phi), z)));
    }
  return rho / std::numbers::pi * radiance * sum * (phi1 - phi0) * (z0 - z1) / (n * n);
}

TEST_F(EnvironmentTest, BrightPatchLightsAPlaneAsTheIntegralSays) {
  std::vector<float> pixels(16 * 8 * 3, 0.0f);
  for (int y = 1; y <= 2; ++y)
    for (int x = 4; x <= 7; ++x)
      for (int c = 0; c < 3; ++c) pixels[(y * 16 + x) * 3 + c] = 5.0f;
  const fs::path sky = write_image("patch.exr", 16, 8, pixels);
  struct Case {
    Vec3 normal;
    double rotation_deg;
  };
  // The patch lies between +X (the image's centre) and +Y (a quarter from its left edge), above the horizon
  // (the top row is +Z): planes facing +X, +Y and +Z see it, −X, −Y and −Z not at all. Turned by 90°
  // (counter-clockwise seen from above) it lies between +Y and −X.
  const std::vector<Case> cases = {{{1, 0, 0}, 0},  {{0, 1, 0}, 0},   {{0, -1, 0}, 0}, {{0, 0, 1}, 0},
                                   {{0, 0, -1}, 0}, {{-1, 0, 0}, 0},  {{-1, 0, 0}, 90}, {{0, 1, 0}, 90},
                                   {{1, 0, 0}, 90}};
  for (const Case& c : cases) {
    // A 2 m square facing `normal` through the origin, and a camera 3 m in front of it.
    const auto frame = orthonormal_frame(c.normal);
    const Vec3 corner = -frame[0] - frame[1];
    const json objects = json::array(
        {{{"name", "plane"}, {"material", "white"},
          {"shape", {{"type", "quad"}, {"corner", {corner.x(), corner.y(), corner.z()}},
                     {"edge1", {2 * frame[0].x(), 2 * frame[0].y(), 2 * frame[0].z()}},
                     {"edge2", {2 * frame[1].x(), 2 * frame[1].y(), 2 * frame[1].z()}}}}}});
    const Vec3 eye = 3.0 * c.normal;
    const json camera = {{"position", {eye.x(), eye.y(), eye.z()}}, {"look_at", {0, 0, 0}},
                         {"up", {frame[1].x(), frame[1].y(), frame[1].z()}}, {"fov_deg", 30}, {"resolution", {16, 16}}};
    const Scene s = scene(base_scene({{"radiance", {{"texture", sky.string()}}}, {"rotation_deg", c.rotation_deg}},
                                     objects, camera, 64, 1));
    const RenderedImage image = render(s, quiet());
    // The patch's texels (5, 5, 5) emit 5·W(λ), W the colour space's white: band 1 has W's average there.
    const double white = band_averages(rgb_to_emission_spectrum({1.0, 1.0, 1.0}), image.bands)[1];
    const double expected = patch_radiance(c.normal, c.rotation_deg, 0.7, 5.0 * white);
    Residuals r;
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) r.add(value(image, 0, x, y, 1) - expected);
    if (expected == 0.0) {
      EXPECT_EQ(r.sum2, 0.0) << c.normal.transpose();
    } else {
      EXPECT_GT(expected, 0.05);
      EXPECT_LT(std::abs(r.mean()), 4.0 * r.se() + 1e-9) << c.normal.transpose() << " rotation " << c.rotation_deg
                                                         << ": expected " << expected << ", residual " << r.mean();
    }
  }
}

// A 4 × 4 sRGB texture: the left half red, the right half blue, and the top-left texel green.
std::vector<float> texture_pixels() {
  std::vector<float> p;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) {
      const std::array<float, 3> red = {200 / 255.f, 30 / 255.f, 30 / 255.f}, blue = {30 / 255.f, 30 / 255.f, 200 / 255.f},
                                 green = {30 / 255.f, 200 / 255.f, 30 / 255.f};
      const auto& c = x == 0 && y == 0 ? green : x < 2 ? red : blue;
      p.insert(p.end(), c.begin(), c.end());
    }
  return p;
}

// The linear sRGB of texel (x from the left, y from the top) of texture_pixels(), as the scene reads it.
std::array<double, 3> texel_rgb(int x, int y) {
  const std::vector<float> p = texture_pixels();
  std::array<double, 3> rgb;
  for (int c = 0; c < 3; ++c) rgb[c] = srgb_decode(std::round(p[(y * 4 + x) * 3 + c] * 255) / 255);
  return rgb;
}

// A quad facing +Z over [-1, 1]², seen from above with image-up +Y: (u, v) = ((x + 1) / 2, (y + 1) / 2).
const json kTexturedQuadCamera = {{"position", {0, 0, 3}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov_deg", 36},
                                  {"resolution", {32, 32}}};
json textured_quad(const json& material_or_light) {
  json q = material_or_light;
  q["shape"] = {{"type", "quad"}, {"corner", {-1, -1, 0}}, {"edge1", {2, 0, 0}}, {"edge2", {0, 2, 0}}};
  return q;
}

// The texel under pixel (x, y)'s centre: x from the left, y from the top of the texture.
std::pair<int, int> texel_under(const Camera& cam, int x, int y) {
  const Vec3 d = cam.ray_direction(x + 0.5, y + 0.5);
  const Vec3 p = cam.position + (-cam.position.z() / d.z()) * d;
  const double u = (p.x() + 1) / 2, v = (p.y() + 1) / 2;
  return {std::min(3, static_cast<int>(u * 4)), 3 - std::min(3, static_cast<int>(v * 4))};
}

TEST_F(EnvironmentTest, TexturedReflectanceFollowsTheTexelUnderEachPixel) {
  const fs::path texture = write_image("paint.png", 4, 4, texture_pixels());
  json doc = base_scene({{"radiance", {{"constant", 1.0}}}},
                        json::array({textured_quad({{"name", "canvas"}, {"material", "paint"}})}), kTexturedQuadCamera,
                        64, 1);
  doc["materials"]["paint"] = {{"type", "lambert"}, {"reflectance", {{"texture", "paint.png"}, {"colour_space", "sRGB"}}}};
  const Scene s = scene(doc);
  const RenderedImage image = render(s, quiet());
  // A flat plane under a constant environment L = 1 reflects ρ(λ) · L: each band the texel's upsampled spectrum.
  for (int b = 0; b < 3; ++b) {
    Residuals per_texel[3];  // red, blue, the green corner
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x) {
        const auto [tx, ty] = texel_under(s.camera, x, y);
        const double expected = band_averages(rgb_to_spectrum(texel_rgb(tx, ty)), image.bands)[static_cast<std::size_t>(b)];
        per_texel[tx == 0 && ty == 0 ? 2 : tx < 2 ? 0 : 1].add(value(image, 0, x, y, b) - expected);
      }
    for (int k = 0; k < 3; ++k) {
      ASSERT_GT(per_texel[k].n, 10);
      EXPECT_LT(std::abs(per_texel[k].mean()), 4.0 * per_texel[k].se()) << "band " << b << " region " << k;
    }
  }
  // And the regions differ as their colours do: red reflects more at 600–700 nm than blue, blue at 400–500.
  const auto band = [&](int x, int y, int b) { return value(image, 0, x, y, b); };
  EXPECT_GT(band(6, 16, 2), 2 * band(26, 16, 2));
  EXPECT_GT(band(26, 16, 0), 2 * band(6, 16, 0));
}

TEST_F(EnvironmentTest, TexturedEmitterShowsEachTexelsSpectrumExactly) {
  const fs::path path = write_image("glow.png", 4, 4, texture_pixels());
  json doc = base_scene({{"radiance", {{"constant", 0.0}}}}, json::array(), kTexturedQuadCamera, 4, 0);
  doc["lights"] = json::array({textured_quad({{"name", "panel"}, {"scale", 3.0},
                                              {"radiance", {{"texture", "glow.png"}, {"scale", 2.0}}}})});
  const Scene s = scene(doc);
  const RenderedImage image = render(s, quiet());
  // The texels exactly as the scene reads them; the camera sees the emitter directly, so every sample of a
  // pixel is the same and only the float output rounds.
  const ImageTexture texture = read_image_texture(path, "glow.png", std::nullopt, TextureUse::Radiance, 1.0);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      const auto [tx, ty] = texel_under(s.camera, x, y);
      const std::vector<double> expected =
          band_averages(texel_spectrum(texture.texel(static_cast<std::size_t>(ty * 4 + tx)), TextureUse::Radiance).tabulated(),
                        image.bands);
      for (int b = 0; b < 3; ++b) {
        const double e = 6.0 * expected[static_cast<std::size_t>(b)];
        EXPECT_NEAR(value(image, 0, x, y, b), e, 1e-6 * e) << x << ", " << y;
      }
    }
}

TEST_F(EnvironmentTest, TextureLookupIsNearestWithTheOriginAtTheBottomLeft) {
  const fs::path path = write_image("paint.png", 4, 4, texture_pixels());
  const ImageTexture t = read_image_texture(path, "paint.png", std::nullopt, TextureUse::Reflectance, 1.0);
  EXPECT_EQ(t.colour_space, TextureColourSpace::Srgb);
  EXPECT_EQ(t.texel_at(0.1, 0.9), 0u);    // top-left
  EXPECT_EQ(t.texel_at(0.9, 0.9), 3u);    // top-right
  EXPECT_EQ(t.texel_at(0.1, 0.1), 12u);   // bottom-left
  EXPECT_EQ(t.texel_at(1.1, -0.9), 12u);  // repeats: (0.1, 0.1)
  EXPECT_NEAR(t.texel(0)[1], srgb_decode(200.0 / 255), 1e-6);
}

TEST_F(EnvironmentTest, SameSeedGivesIdenticalImagesWithOneAndTwoThreads) {
  std::vector<float> pixels(16 * 8 * 3);
  for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = 0.1f + static_cast<float>(i % 7);
  write_image("sky.exr", 16, 8, pixels);
  write_image("paint.png", 4, 4, texture_pixels());
  json doc = base_scene({{"radiance", {{"texture", "sky.exr"}}}, {"group", "sky"}},
                        json::array({textured_quad({{"name", "canvas"}, {"material", "paint"}}), kSphere[0]}),
                        kSphereCamera, 3, 4);
  doc["materials"]["paint"] = {{"type", "dichromatic"}, {"diffuse", {{"texture", "paint.png"}, {"scale", 0.9}}},
                               {"specular", 0.1}, {"roughness", 0.3}};
  const Scene s = scene(doc);
  RenderedImage images[2];
  for (int threads : {1, 2}) {
    RenderOptions o = quiet({true, true, true});
    o.threads = threads;
    images[threads - 1] = render(s, o);
  }
  EXPECT_TRUE(images[0].layers == images[1].layers);
  EXPECT_GT(layer_of(images[0], "light.sky"), 0);
}

}  // namespace
}  // namespace ct::rt
