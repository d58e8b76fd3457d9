// SPDX-License-Identifier: Apache-2.0
// plan/radiosity.h on known answers: the transfer factors of a closed cube (they sum to 1, and each is the
// analytic form factor between two of its faces), a small patch under a rectangle (the analytic view factor the
// tracer's tests use), the bounce recursion on a hand-made transfer, and image textures as their texels' mean
// spectrum (each texel's exact share of a surface or of the sphere of directions).
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "tests/common/view_factor.h"
#include "core/scene.h"
#include "core/statistics.h"
#include "core/texture.h"
#include "plan/radiosity.h"

namespace ct::plan {
namespace {

using Json = nlohmann::json;

Json quad(const std::string& name, std::array<double, 3> corner, std::array<double, 3> e1, std::array<double, 3> e2) {
  return {{"name", name}, {"material", "grey"}, {"shape", {{"type", "quad"}, {"corner", corner}, {"edge1", e1}, {"edge2", e2}}}};
}

Scene scene_of(Json objects, Json lights) {
  const Json doc = {{"format", "chromatrace-scene/1"},
                    {"spectra", {{"half", {{"constant", 0.5}}}, {"one", {{"constant", 1.0}}}}},
                    {"materials", {{"grey", {{"type", "lambert"}, {"reflectance", "half"}}}}},
                    {"lights", std::move(lights)},
                    {"objects", std::move(objects)},
                    {"camera", {{"position", {0.5, 0.5, 0.5}}, {"look_at", {0.5, 0.5, 0}}, {"up", {0, 1, 0}},
                                {"fov_deg", 60}, {"resolution", {8, 8}}}},
                    {"render", {{"samples", 1}, {"max_bounces", 1}, {"bands", "400:700:100"}}}};
  Json scene = doc;
  if (scene["lights"].empty()) scene["environment"] = {{"radiance", "one"}};  // a scene needs some light
  return parse_scene(scene, "radiosity-test", std::filesystem::temp_directory_path());
}

// Form factor between two parallel, directly opposed unit squares one unit apart (Howell's catalogue, C-11).
double opposite_unit_squares() {
  const double x = 1, y = 1, pi = std::numbers::pi;
  return 2 / (pi * x * y) *
         (std::log(std::sqrt((1 + x * x) * (1 + y * y) / (1 + x * x + y * y))) +
          x * std::sqrt(1 + y * y) * std::atan(x / std::sqrt(1 + y * y)) +
          y * std::sqrt(1 + x * x) * std::atan(y / std::sqrt(1 + x * x)) - x * std::atan(x) - y * std::atan(y));
}

// The binomial standard error of a fraction p estimated from n rays.
double ray_fraction_se(double p, int n) { return std::sqrt(p * (1 - p) / n); }

TEST(Radiosity, FormFactorsOfAClosedCubeSumToOneAndMatchTheAnalyticOnes) {
  // The unit cube's six faces: 0/1 the faces z = 0/1, 2/3 y = 0/1, 4/5 x = 0/1 (opposite faces paired).
  const Scene cube = scene_of(Json::array({quad("z0", {0, 0, 0}, {1, 0, 0}, {0, 1, 0}), quad("z1", {0, 0, 1}, {1, 0, 0}, {0, 1, 0}),
                                           quad("y0", {0, 0, 0}, {1, 0, 0}, {0, 0, 1}), quad("y1", {0, 1, 0}, {1, 0, 0}, {0, 0, 1}),
                                           quad("x0", {0, 0, 0}, {0, 1, 0}, {0, 0, 1}), quad("x1", {1, 0, 0}, {0, 1, 0}, {0, 0, 1})}),
                              Json::array());
  constexpr int kRays = 20000;
  const Transfer t = transfer_factors(cube, scene_meshes(cube), kRays);
  const double opposite = opposite_unit_squares(), adjacent = (1 - opposite) / 4;  // closure: 4 adjacent + 1 opposite
  ASSERT_NEAR(opposite, 0.199825, 1e-6);
  for (std::size_t o = 1; o <= 6; ++o) {
    double sum = 0;
    for (std::size_t j = 1; j <= 6; ++j) sum += t.hits[o][j];
    EXPECT_EQ(t.hits[o][0], 0.0) << "face " << o << ": rays escaped the closed cube";
    EXPECT_NEAR(sum, 1.0, 1e-12) << "face " << o;
    EXPECT_EQ(t.hits[o][o], 0.0) << "a flat face does not see itself";
    for (std::size_t j = 1; j <= 6; ++j) {
      if (j == o) continue;
      const bool across = (o - 1) / 2 == (j - 1) / 2;
      const double expected = across ? opposite : adjacent;
      EXPECT_NEAR(t.hits[o][j], expected, kSigmasPerItem * ray_fraction_se(expected, kRays)) << o << " -> " << j;
    }
  }
}

TEST(Radiosity, PatchUnderARectangularLightSeesTheAnalyticViewFactor) {
  // A 1 cm patch at the origin facing up, under a 1 m × 0.6 m emitter facing down at 0.8 m (the tracer's
  // DirectLight test's geometry): across the patch the view factor changes by ~(0.005/0.8)², far below the noise.
  const Scene scene = scene_of(
      Json::array({quad("patch", {-0.005, -0.005, 0}, {0.01, 0, 0}, {0, 0.01, 0})}),
      Json::array({{{"name", "panel"},
                    {"shape", {{"type", "quad"}, {"corner", {-0.5, -0.3, 0.8}}, {"edge1", {0, 0.6, 0}}, {"edge2", {1.0, 0, 0}}}},
                    {"radiance", "one"}}}));
  constexpr int kRays = 40000;
  const Transfer t = transfer_factors(scene, scene_meshes(scene), kRays);
  const double expected = test::rectangle_view_factor(0, 0, -0.5, 0.5, -0.3, 0.3, 0.8);
  const double tolerance = kSigmasOneCheck * ray_fraction_se(expected, kRays);
  EXPECT_NEAR(t.hits[1][2], expected, tolerance);  // the light's surface, id 2
  EXPECT_NEAR(t.lit[1][0], expected, tolerance);   // its emitting side
  EXPECT_NEAR(t.hits[1][0], 1 - expected, tolerance);  // the rest escapes
}

TEST(Radiosity, BounceTemplatesFollowTheRecursion) {
  // Surface ids: 0 background, 1 and 2 objects (albedo 0.5 and 0.25), 3 a light of radiance 2; one basis element
  // seen equally by all three channels. By hand: k = 1, I₁ = 0.2·2 = 0.4 and I₂ = 0.1·2 = 0.2, shown as ρ·I: 0.2
  // and 0.05; k = 2, I₁ = 0.3·(0.25·0.2) = 0.015 and I₂ = 0.6·(0.5·0.4) = 0.12: 0.0075 and 0.03. The background and
  // the missing glossy lobes take the mean-albedo model E·R·ρ̄^(k−1): 2·0.4^k for the background, 0 for the lobes.
  Basis b;
  for (auto& w : b.weight) w = {1.0};
  b.emission = {{0.0}, {0.0}, {0.0}, {2.0}};
  b.diffuse = {{0.4}, {0.5}, {0.25}, {0.0}};
  b.glossy = {{0.0}, {0.0}, {0.0}, {0.0}};
  b.albedo = {{0.0}, {0.5}, {0.25}, {0.0}};
  b.light = {2.0};
  b.mean_albedo = {0.4};
  Transfer t;
  t.hits = {{0, 0, 0, 0}, {0, 0, 0.3, 0.2}, {0, 0.6, 0, 0.1}, {0, 0, 0, 0}};
  t.lit = {{0.0}, {0.2}, {0.1}, {0.0}};
  TemplateSpectra spectra;
  const Templates x = bounce_templates(b, t, 2, &spectra);
  const auto diffuse_y = [&](std::size_t id, int k) { return x[id][static_cast<std::size_t>(k)][0][1]; };
  EXPECT_DOUBLE_EQ(x[3][0][0][1], 2.0);  // the light's own emission
  EXPECT_DOUBLE_EQ(diffuse_y(1, 1), 0.2);
  EXPECT_DOUBLE_EQ(diffuse_y(2, 1), 0.05);
  EXPECT_DOUBLE_EQ(diffuse_y(1, 2), 0.0075);
  EXPECT_DOUBLE_EQ(diffuse_y(2, 2), 0.03);
  EXPECT_DOUBLE_EQ(diffuse_y(0, 1), 0.8);
  EXPECT_DOUBLE_EQ(diffuse_y(0, 2), 0.32);
  EXPECT_EQ(x[1][1][1][1], 0.0);
  EXPECT_DOUBLE_EQ(spectra[2][2][0][0], 0.03);
}

ImageTexture texture_of(int width, int height, std::vector<float> rgb, TextureUse use, double scale = 1.0) {
  ImageTexture t;
  t.width = width;
  t.height = height;
  t.rgb = std::move(rgb);
  t.use = use;
  t.scale = scale;
  return t;
}

// The mean of a texture whose colours fall in different pools is the weighted mean of the texels' own spectra (the
// renderers' upsampling), the texture's scale included; a radiance's texels are relative to D65 and may exceed 1.
TEST(TextureMean, IsTheWeightedMeanOfTheTexelsSpectra) {
  for (const TextureUse use : {TextureUse::Reflectance, TextureUse::Radiance}) {
    const float k = use == TextureUse::Radiance ? 3.0f : 1.0f;
    const ImageTexture t = texture_of(3, 1, {0.8f * k, 0.05f * k, 0.05f * k, 0.05f, 0.1f, 0.8f, 0.3f, 0.3f, 0.3f},
                                      use, 0.5);
    const std::vector<double> weight = {1.0, 3.0, 0.0};  // the grey texel covers nothing
    const PiecewiseLinearSpectrum mean = mean_texture_spectrum(t, weight);
    for (double nm = 380; nm <= 780; nm += 10) {
      const double expected = 0.5 * (1.0 * texel_spectrum(t.texel(0), use)(nm) + 3.0 * texel_spectrum(t.texel(1), use)(nm)) / 4.0;
      EXPECT_NEAR(mean(nm), expected, 1e-9 * std::max(1.0, expected)) << nm;
    }
  }
}

// A quad's texels each cover their share of its area (2 × 2 texels: a quarter each) and a sphere's rows of texels
// the zone between their polar angles, (cos θa − cos θb)/2 of its area (tessellated finely, so that the flat
// triangles' area differs from the sphere's by well under the sampling error). Tolerance: three binomial standard
// errors of the 16384 points, plus 0.2 % for the tessellation.
TEST(TextureMean, SurfaceTexelsWeighByTheAreaTheyCover) {
  const Scene scene = scene_of(Json::array({quad("q", {0, 0, 0}, {2, 0, 0}, {0, 1, 0}),
                                            {{"name", "s"}, {"material", "grey"},
                                             {"shape", {{"type", "sphere"}, {"center", {0, 0, 3}}, {"radius", 1},
                                                        {"segments", 128}, {"rings", 64}}}}}),
                               Json::array());
  const std::vector<TriangleMesh> meshes = scene_meshes(scene);
  const double n = 16384;
  const ImageTexture square = texture_of(2, 2, std::vector<float>(12, 0.5f), TextureUse::Reflectance);
  std::vector<double> w = surface_texel_weights(meshes[0], corner_uvs(scene.objects[0].shape), square);
  for (double x : w) EXPECT_NEAR(x / n, 0.25, 3 * std::sqrt(0.25 * 0.75 / n)) << "quad";
  const ImageTexture rows = texture_of(1, 4, std::vector<float>(12, 0.5f), TextureUse::Reflectance);
  w = surface_texel_weights(meshes[1], corner_uvs(scene.objects[1].shape), rows);
  for (int y = 0; y < 4; ++y) {
    const double a = std::numbers::pi * y / 4, b = std::numbers::pi * (y + 1) / 4;  // row 0 at the north pole
    const double share = (std::cos(a) - std::cos(b)) / 2;
    EXPECT_NEAR(w[y] / n, share, 3 * std::sqrt(share * (1 - share) / n) + 0.002) << "sphere row " << y;
  }
}

// An equirectangular environment's rows of equal height: each row's share of the sphere of directions is exactly
// (cos θa − cos θb)/2, which the sine at the row's middle gives once normalised (2 sin(m) sin(h/2) ∝ sin m).
TEST(TextureMean, EnvironmentTexelsWeighByTheirSolidAngle) {
  const ImageTexture sky = texture_of(3, 6, std::vector<float>(54, 1.0f), TextureUse::Radiance);
  const std::vector<double> w = environment_texel_weights(sky);
  double total = 0;
  for (double x : w) total += x;
  for (int y = 0; y < 6; ++y) {
    const double a = std::numbers::pi * y / 6, b = std::numbers::pi * (y + 1) / 6;
    for (int x = 0; x < 3; ++x) EXPECT_NEAR(w[y * 3 + x] / total, (std::cos(a) - std::cos(b)) / 2 / 3, 1e-12);
  }
}

// A texture of one colour is that colour's spectrum: a surface with it, a light with it and an environment with it
// are modelled exactly as with the {"rgb"} source of that colour (a reflectance as the sigmoid, an emitter as the
// sigmoid times D65's white), so the plan sees a one-colour texture as it sees the colour.
TEST(TextureMean, OneColourTextureIsThatColoursSpectrum) {
  const std::vector<float> texels = {0.7f, 0.4f, 0.1f, 0.7f, 0.4f, 0.1f};
  const std::array<double, 3> as_float = {double(0.7f), double(0.4f), double(0.1f)};
  Scene scene = scene_of(Json::array({quad("q", {0, 0, 0}, {1, 0, 0}, {0, 1, 0})}), Json::array());
  auto& lambert = std::get<LambertMaterial>(scene.materials[scene.objects[0].material].model);
  lambert.reflectance.texture = std::make_shared<ImageTexture>(texture_of(2, 1, texels, TextureUse::Reflectance));
  scene.environment->radiance.texture = std::make_shared<ImageTexture>(texture_of(1, 2, texels, TextureUse::Radiance, 2.0));
  scene.environment->scale = 1.5;
  const Grid grid{400, 700};
  std::vector<std::string> notes;
  const SceneSurfaces s = scene_surfaces(scene, scene_meshes(scene), grid, grid.constant(1.0), false, notes);
  const ScaledSigmoid reflectance = texel_spectrum(as_float, TextureUse::Reflectance);
  const ScaledSigmoid emitted = texel_spectrum(as_float, TextureUse::Radiance);
  for (std::size_t i = 0; i < grid.n(); ++i) {
    const double nm = grid.lo + static_cast<double>(i);
    EXPECT_NEAR(s.surfaces[1].diffuse.v[i], reflectance(nm), 1e-9) << nm;
    EXPECT_NEAR(s.environment.v[i], 3.0 * emitted(nm), 1e-9 * std::max(1.0, emitted(nm))) << nm;
  }
  EXPECT_TRUE(s.textured);
  EXPECT_FALSE(notes.empty());
}

}  // namespace
}  // namespace ct::plan
