// SPDX-License-Identifier: Apache-2.0
// Reference tracer against known answers: the furnace, a plane under a rectangular emitter, component sums,
// determinism across thread counts, and bands versus continuous spectral sampling.
//
// Tolerances come from the Monte Carlo standard error estimated from the rendered pixels themselves:
// pixels are independent estimates, so the standard error of a mean over n pixels is their spread / √n.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>

#include <unistd.h>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/scene.h"
#include "core/spectral_exr.h"
#include "reference_tracer/render.h"
#include "tests/reference_tracer/lobe_albedo.h"
#include "tests/common/view_factor.h"
#include "core/statistics.h"

namespace ct::rt {
namespace {

using nlohmann::json;

Scene make_scene(const json& doc) { return parse_scene(doc, "test-scene", std::filesystem::temp_directory_path()); }

struct Stats {
  double mean = 0, se = 0;
};

// Mean over pixels of one band of one layer, and its standard error.
Stats band_stats(const RenderedImage& image, int layer, int band) {
  const std::vector<float>& data = image.layers[static_cast<std::size_t>(layer)];
  const std::size_t nb = image.bands.size(), n = data.size() / nb;
  double sum = 0, sum2 = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double v = data[i * nb + static_cast<std::size_t>(band)];
    sum += v;
    sum2 += v * v;
  }
  const double mean = sum / n;
  return {mean, std::sqrt(std::max(0.0, sum2 / n - mean * mean) / (n - 1))};
}

// A closed cube of uniform albedo rho(λ) and emission Le = 1 on its inner faces, seen from inside. Flat
// faces keep it a true furnace: on a smooth-shaded tessellated sphere, directions sampled about the shading
// normal that fall below the facet are lost (as in Cycles), so energy is not conserved exactly there.
json furnace(const json& albedo, int max_bounces, const std::string& mode) {
  // Each face as corner, edge1, edge2; emission is two-sided, so the winding does not matter.
  const double faces[6][9] = {{-1, -1, -1, 0, 2, 0, 2, 0, 0},  {-1, -1, 1, 2, 0, 0, 0, 2, 0},
                              {-1, -1, -1, 0, 0, 2, 0, 2, 0},  {1, -1, -1, 0, 2, 0, 0, 0, 2},
                              {-1, -1, -1, 2, 0, 0, 0, 0, 2},  {-1, 1, -1, 0, 0, 2, 2, 0, 0}};
  json lights = json::array();
  for (int f = 0; f < 6; ++f) {
    const double* v = faces[f];
    lights.push_back({{"name", fmt::format("face{}", f)},
                      {"group", "shell"},
                      {"shape", {{"type", "quad"}, {"corner", {v[0], v[1], v[2]}}, {"edge1", {v[3], v[4], v[5]}},
                                 {"edge2", {v[6], v[7], v[8]}}}},
                      {"radiance", "one"},
                      {"two_sided", true},
                      {"material", "shell"}});
  }
  return {{"format", "chromatrace-scene/1"},
          {"spectra", {{"albedo", albedo}, {"one", {{"constant", 1.0}}}}},
          {"materials", {{"shell", {{"type", "lambert"}, {"reflectance", "albedo"}}}}},
          {"lights", lights},
          {"objects", json::array()},
          {"camera",
           {{"position", {0.1, -0.2, 0.3}}, {"look_at", {0.5, 1, 0}}, {"up", {0, 0, 1}}, {"fov_deg", 100}, {"resolution", {16, 16}}}},
          {"render", {{"samples", 64}, {"max_bounces", max_bounces}, {"bands", "400:700:100"}, {"spectral_mode", mode}}}};
}

TEST(Furnace, RadianceIsEmissionOverOneMinusAlbedo) {
  // Albedo 0.2, 0.5, 0.8 in the three bands (constant within each, so both modes have the same answer).
  const json albedo = {{"samples", {{400, 0.2}, {499.999, 0.2}, {500.001, 0.5}, {599.999, 0.5}, {600.001, 0.8}, {700, 0.8}}}};
  for (const std::string mode : {"bands", "continuous"}) {
    RenderOptions options;
    options.progress = false;
    options.components = {false, false, false};
    const Scene scene = make_scene(furnace(albedo, 200, mode));
    const RenderedImage image = render(scene, options);
    const double rho[3] = {0.2, 0.5, 0.8};
    for (int b = 0; b < 3; ++b) {
      // In bands mode the band average of the albedo is used; its ramps over 2 µm change it by < 1e-5.
      const double expected = 1.0 / (1.0 - rho[b]);
      const Stats s = band_stats(image, 0, b);
      EXPECT_NEAR(s.mean, expected, 4.0 * s.se + 2e-5 * expected) << mode << " band " << b << " se " << s.se;
      EXPECT_GT(s.se, 0.0);
    }
  }
}

TEST(Furnace, EachBounceOrderIsEmissionTimesAlbedoToTheK) {
  const int k_max = 6;
  RenderOptions options;
  options.progress = false;
  options.components = {true, true, true};
  const Scene scene = make_scene(furnace({{"constant", 0.6}}, k_max, "bands"));
  const RenderedImage image = render(scene, options);
  int first_bounce = -1;
  for (std::size_t c = 0; c < image.components.size(); ++c)
    if (image.components[c] == "bounce.0") first_bounce = static_cast<int>(c) + 1;
  ASSERT_GT(first_bounce, 0);
  double geometric_sum = 0;
  for (int k = 0; k <= k_max; ++k) {
    const Stats s = band_stats(image, first_bounce + k, 1);
    const double expected = std::pow(0.6, k);
    geometric_sum += expected;
    EXPECT_NEAR(s.mean, expected, 4.0 * s.se + 1e-6) << "bounce " << k;
  }
  // Truncated at k_max bounces, the total is the partial geometric series.
  const Stats total = band_stats(image, 0, 1);
  EXPECT_NEAR(total.mean, geometric_sum, 4.0 * total.se + 1e-6);
}

using test::rectangle_view_factor;

TEST(DirectLight, LambertianPlaneUnderRectangularEmitterMatchesClosedForm) {
  // A plane of albedo 0.5 at z = 0, a 1 m × 0.6 m emitter of radiance 2 facing down at z = 0.8, and a
  // camera looking straight down through a hole-free gap: L(p) = ρ · Le · F(p) exactly (no other paths).
  const json doc = {
      {"format", "chromatrace-scene/1"},
      {"spectra", {{"half", {{"constant", 0.5}}}, {"two", {{"constant", 2.0}}}}},
      {"materials", {{"plane", {{"type", "lambert"}, {"reflectance", "half"}}}}},
      {"lights",
       {{{"name", "panel"},
         {"shape", {{"type", "quad"}, {"corner", {-0.5, -0.3, 0.8}}, {"edge1", {0, 0.6, 0}}, {"edge2", {1.0, 0, 0}}}},
         {"radiance", "two"}}}},
      {"objects",
       {{{"name", "plane"},
         {"material", "plane"},
         {"shape", {{"type", "quad"}, {"corner", {-5, -5, 0}}, {"edge1", {10, 0, 0}}, {"edge2", {0, 10, 0}}}}}}},
      {"camera",
       {{"position", {1.2, 0, 0.5}}, {"look_at", {1.2, 0, 0}}, {"up", {0, 1, 0}}, {"fov_deg", 120}, {"resolution", {24, 24}}}},
      {"render", {{"samples", 256}, {"max_bounces", 3}, {"bands", "500:600:100"}, {"pixel_filter", "point"}}}};
  const Scene scene = make_scene(doc);
  ASSERT_NEAR(scene.lights[0].shape.index() == 0 ? std::get<QuadShape>(scene.lights[0].shape).normal().z() : 0.0, -1.0, 1e-12);
  RenderOptions options;
  options.progress = false;
  const RenderedImage image = render(scene, options);
  const Camera& cam = scene.camera;
  double sum_residual = 0, sum_residual2 = 0, sum_expected = 0;
  int n = 0;
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      const Vec3 d = cam.ray_direction(x + 0.5, y + 0.5);
      const double t = -cam.position.z() / d.z();
      const Vec3 p = cam.position + t * d;
      const double expected = 0.5 * 2.0 * rectangle_view_factor(p.x(), p.y(), -0.5, 0.5, -0.3, 0.3, 0.8);
      const double r = image.layers[0][static_cast<std::size_t>(y * cam.width + x)] - expected;
      sum_residual += r;
      sum_residual2 += r * r;
      sum_expected += expected;
      ++n;
    }
  const double mean = sum_residual / n;
  const double se = std::sqrt((sum_residual2 / n - mean * mean) / (n - 1));
  EXPECT_LT(std::abs(mean), 4.0 * se + 1e-7) << "mean residual " << mean << " (se " << se << ")";
  // And the error is small in absolute terms: the noise itself is a few percent of the signal.
  EXPECT_LT(std::sqrt(sum_residual2 / n), 0.05 * sum_expected / n);
}

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

Scene small_box() {
  Scene scene = load_scene(std::string(CHROMATRACE_SOURCE_DIR) + "/scenes/paper/box.json");
  scene.camera.width = 24;
  scene.camera.height = 18;
  return scene;
}

TEST(Render, ComponentFamiliesEachSumToTheTotal) {
  const Scene scene = small_box();
  RenderOptions options;
  options.progress = false;
  options.samples = 4;
  options.components = {true, true, true};
  const RenderedImage image = render(scene, options);
  std::vector<std::vector<int>> families(3);
  for (std::size_t c = 0; c < image.components.size(); ++c) {
    const std::string& name = image.components[c];
    const int layer = static_cast<int>(c) + 1;
    if (name.starts_with("light.")) families[1].push_back(layer);
    else if (name.starts_with("bounce.")) families[2].push_back(layer);
    else families[0].push_back(layer);
  }
  for (const auto& family : families) {
    ASSERT_FALSE(family.empty());
    for (std::size_t i = 0; i < image.layers[0].size(); ++i) {
      double sum = 0, abs_sum = 0;
      for (int l : family) {
        sum += image.layers[static_cast<std::size_t>(l)][i];
        abs_sum += std::abs(image.layers[static_cast<std::size_t>(l)][i]);
      }
      // Each layer is rounded to float once and scaled once: (n + 2) roundings of at most 2⁻²⁴ relative.
      const double tol = (family.size() + 2) * std::ldexp(1.0, -24) * (abs_sum + std::abs(image.layers[0][i])) + 1e-30;
      ASSERT_NEAR(sum, image.layers[0][i], tol) << "element " << i;
    }
  }
}

TEST(Render, SameSeedGivesIdenticalBytesWithOneAndTwoThreads) {
  const Scene scene = small_box();
  const auto dir = std::filesystem::temp_directory_path() / fmt::format("ct-det-{}", ::getpid());
  std::filesystem::create_directories(dir);
  std::string bytes[2];
  for (int threads : {1, 2}) {
    RenderOptions options;
    options.progress = false;
    options.samples = 3;
    options.threads = threads;
    options.components = {true, true, true};
    const auto path = dir / fmt::format("t{}.exr", threads);
    write_render(path, scene, render(scene, options));
    bytes[threads - 1] = slurp(path);
  }
  std::filesystem::remove_all(dir);
  ASSERT_GT(bytes[0].size(), 1000u);
  EXPECT_TRUE(bytes[0] == bytes[1]);
}

TEST(Render, BandsAndContinuousAgreeWhenSpectraAreConstantWithinBands) {
  // The Cornell box with its spectra replaced by band-constant ones: then every wavelength in a band
  // sees the same transport, and both modes estimate the same band averages.
  Scene scene = load_scene(std::string(CHROMATRACE_SOURCE_DIR) + "/scenes/cornell_box/cornell_box.json");
  json doc = scene.json;
  auto steps = [](double a, double b, double c) {
    return json{{"samples", {{400, a}, {499.999, a}, {500.001, b}, {599.999, b}, {600.001, c}, {700, c}}}};
  };
  doc["spectra"] = {{"white", steps(0.7, 0.75, 0.72)}, {"red", steps(0.05, 0.1, 0.6)},
                    {"green", steps(0.1, 0.5, 0.15)}, {"light", steps(6.0, 12.0, 17.0)}};
  doc["camera"]["resolution"] = {24, 24};
  doc["render"]["bands"] = "400:700:100";
  const Scene stepped = parse_scene(doc, "stepped", std::filesystem::path(CHROMATRACE_SOURCE_DIR) / "scenes/cornell_box");
  RenderOptions options;
  options.progress = false;
  options.samples = 64;
  options.components = {false, false, false};
  options.mode = SpectralMode::Bands;
  const RenderedImage bands = render(stepped, options);
  options.mode = SpectralMode::Continuous;
  options.seed = 99;
  const RenderedImage continuous = render(stepped, options);
  for (int b = 0; b < 3; ++b) {
    // Pixel-wise differences are independent, zero-mean under agreement; their spread gives the SE.
    double sum = 0, sum2 = 0;
    const std::size_t n = bands.layers[0].size() / 3;
    for (std::size_t i = 0; i < n; ++i) {
      const double d = bands.layers[0][i * 3 + b] - continuous.layers[0][i * 3 + b];
      sum += d;
      sum2 += d * d;
    }
    const double mean = sum / n, se = std::sqrt((sum2 / n - mean * mean) / (n - 1));
    EXPECT_LT(std::abs(mean), 4.0 * se) << "band " << b << ": mean difference " << mean << ", se " << se;
  }
}

// A black-bodied, fully glossy GGX plane inside a closed cube that emits 1 everywhere, direct light only:
// each pixel sees the lobe's directional albedo ρ(θo) = ∫ f cos θi dωi at the camera's angle, which the lobe's
// own samples estimate independently. The two maskings must agree at normal incidence (Λ(wo) = 0 there, so
// both are G1(wi)) and as roughness → 0, and differ at grazing incidence on a rough surface, where the
// separable product shadows more.
TEST(GgxMasking, RendersAgreeWhereTheyMustAndDifferWhereTheyMust) {
  const auto render_plane = [](double roughness, const std::string& masking, double view_deg) {
    json doc = furnace({{"constant", 0.5}}, 1, "bands");
    doc["spectra"]["black"] = {{"constant", 0.0}};
    doc["materials"]["plane"] = {{"type", "dichromatic"}, {"diffuse", "black"}, {"specular", 1.0},
                                 {"lobe", "ggx"}, {"roughness", roughness}, {"masking", masking}};
    doc["objects"] = json::array({{{"name", "plane"}, {"material", "plane"},
                                   {"shape", {{"type", "quad"}, {"corner", {-0.8, -0.8, -0.5}}, {"edge1", {1.6, 0, 0}},
                                              {"edge2", {0, 1.6, 0}}}}}});
    const double t = view_deg * std::numbers::pi / 180;
    doc["camera"] = {{"position", {0.9 * std::sin(t), 0, -0.5 + 0.9 * std::cos(t)}}, {"look_at", {0, 0, -0.5}},
                     {"up", {0, 1, 0}}, {"fov_deg", 1}, {"resolution", {4, 4}}};
    doc["render"] = {{"samples", 4096}, {"max_bounces", 1}, {"bands", "500:600:100"}, {"seed", 7}};
    RenderOptions options;
    options.progress = false;
    options.components = {false, false, false};
    return band_stats(render(make_scene(doc), options), 0, 0);
  };
  // ρ(θo) from the lobe's own samples: E[weight].
  const auto albedo = [](double roughness, bool correlated, double view_deg) {
    const double t = view_deg * std::numbers::pi / 180;
    return test::directional_albedo(GgxLobe{roughness * roughness, correlated}, Vec3(std::sin(t), 0, std::cos(t)), 400000, 19);
  };
  const auto near = [](const Stats& a, const Stats& b) { return std::abs(a.mean - b.mean) <= kSigmasPerItem * std::hypot(a.se, b.se); };

  const Stats normal_separable = render_plane(1.0, "separable", 0), normal_correlated = render_plane(1.0, "height-correlated", 0);
  EXPECT_TRUE(near(normal_separable, normal_correlated)) << normal_separable.mean << " vs " << normal_correlated.mean;
  const Stats smooth_separable = render_plane(0.05, "separable", 80), smooth_correlated = render_plane(0.05, "height-correlated", 80);
  EXPECT_TRUE(near(smooth_separable, smooth_correlated)) << smooth_separable.mean << " vs " << smooth_correlated.mean;

  const Stats grazing_separable = render_plane(1.0, "separable", 80), grazing_correlated = render_plane(1.0, "height-correlated", 80);
  EXPECT_GT(grazing_correlated.mean - grazing_separable.mean, kSigmasPerItem * std::hypot(grazing_correlated.se, grazing_separable.se))
      << grazing_separable.mean << " vs " << grazing_correlated.mean;
  // Each render holds its lobe's albedo (the camera's 1° field of view changes θo by ±0.5°).
  EXPECT_NEAR(normal_separable.mean, albedo(1.0, false, 0).mean, 0.01 * normal_separable.mean + 4 * normal_separable.se);
  EXPECT_NEAR(grazing_separable.mean, albedo(1.0, false, 80).mean, 0.01 * grazing_separable.mean + 4 * grazing_separable.se);
  EXPECT_NEAR(grazing_correlated.mean, albedo(1.0, true, 80).mean, 0.01 * grazing_correlated.mean + 4 * grazing_correlated.se);
}

// The --components grammar from the table the Blender add-on's parser is tested against too.
TEST(ComponentGrammar, EveryCaseOfTheSharedTable) {
  std::ifstream file(std::string(CHROMATRACE_TEST_DATA) + "/component_grammar.json");
  const nlohmann::json table = nlohmann::json::parse(file);
  ASSERT_GE(table["cases"].size(), 10u);
  for (const nlohmann::json& c : table["cases"]) {
    const std::string input = c["input"].get<std::string>();
    if (c.contains("error")) {
      try {
        ComponentSelection::parse(input, "--components");
        ADD_FAILURE() << "\"" << input << "\" parsed; expected: " << c["error"];
      } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()), "--components: " + c["error"].get<std::string>()) << input;
      }
      continue;
    }
    const ComponentSelection s = ComponentSelection::parse(input, "--components");
    std::vector<std::string> families;
    if (s.bounces) families.push_back("bounces");
    if (s.lights) families.push_back("lights");
    if (s.paths) families.push_back("paths");
    EXPECT_EQ(nlohmann::json(families), c["families"]) << "\"" << input << "\"";
  }
}

}  // namespace
}  // namespace ct::rt
