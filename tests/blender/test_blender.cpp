// The Blender add-on in the real Blender, headless (blender --background --python blender_addon/batch.py):
// the paper box to a checked spectral EXR, bad input, band multiplexing against one band per render, the
// emission convention against a closed form, resuming a killed run, and a .blend that is never written.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/scene.h"
#include "core/spectral_exr.h"
#include "tests/cli/run_command.h"
#include "tests/common/view_factor.h"
#include "tests/core/spectral_exr_fixtures.h"

namespace ct {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::CommandResult;

const std::string kSource = CHROMATRACE_SOURCE_DIR;
const std::string kBox = kSource + "/scenes/paper/box.json";

class Blender : public ::testing::Test {
 protected:
  void SetUp() override {
    setenv("CHROMATRACE_EXE", CHROMATRACE_EXE, 1);
    setenv("TMPDIR", dir_.path().c_str(), 1);  // what a killed Blender leaves behind goes with dir_
    unsetenv("CHROMATRACE_TEST_FAIL_AT_RENDER");
    unsetenv("CHROMATRACE_TEST_KILL_AT_RENDER");
  }
  void TearDown() override { unsetenv("TMPDIR"); }

  // blender --background --factory-startup --python blender_addon/batch.py -- ARGS --cache-dir <temp>/cache
  CommandResult batch(std::vector<std::string> args, const std::string& cache = "cache") {
    std::vector<std::string> full = {"--background", "--factory-startup", "--python",
                                     kSource + "/blender_addon/batch.py", "--"};
    full.insert(full.end(), args.begin(), args.end());
    full.insert(full.end(), {"--cache-dir", dir_.file(cache).string()});
    return test::run_program(BLENDER_EXE, full);
  }

  fs::path write_scene(const std::string& name, const json& scene) {
    const fs::path path = dir_.file(name);
    std::ofstream(path) << scene.dump(1);
    return path;
  }

  test::TempDir dir_;
};

// The lines of `text` that start with `prefix`.
std::vector<std::string> lines_starting(const std::string& text, const std::string& prefix) {
  std::vector<std::string> found;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    const std::string line = text.substr(start, end - start);
    if (line.rfind(prefix, 0) == 0) found.push_back(line);
    start = end + 1;
  }
  return found;
}

std::vector<float> layer(SpectralExrReader& reader, const std::string& component) {
  return reader.read_layer(reader.info().layer(component, SpectralQuantity::S0));
}

// Mean and standard error of the mean of per-pixel differences a - b in one band.
struct Difference {
  double mean = 0, se = 0, scale = 0;
};
Difference band_difference(const std::vector<float>& a, const std::vector<float>& b, std::size_t bands,
                           std::size_t band) {
  double sum = 0, sum2 = 0, level = 0;
  const std::size_t n = a.size() / bands;
  for (std::size_t p = 0; p < n; ++p) {
    const double d = a[p * bands + band] - b[p * bands + band];
    sum += d;
    sum2 += d * d;
    level += 0.5 * (a[p * bands + band] + b[p * bands + band]);
  }
  Difference r;
  r.mean = sum / n;
  r.se = std::sqrt(std::max(0.0, sum2 / n - r.mean * r.mean) / (n - 1));
  r.scale = level / n;
  return r;
}

TEST_F(Blender, PaperBoxRendersToACheckedSpectralExrWithEveryComponentAndObjectIds) {
  const fs::path out = dir_.file("box.exr");
  const CommandResult r = batch({"--scene", kBox, "--out", out.string(), "--resolution", "64x64", "--samples", "4",
                                 "--max-bounces", "3", "--components", "all"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const CommandResult check = test::run_chromatrace({"info", "--check", out.string()});
  EXPECT_EQ(check.exit_code, 0) << check.out << check.err;

  SpectralExrReader reader(out);
  const SpectralExrInfo& info = reader.info();
  EXPECT_EQ(info.width, 64);
  ASSERT_EQ(info.bands.size(), 40u);  // the scene's own plan, 380:780:10
  for (const char* c : {"emission", "diffuse_direct", "diffuse_indirect", "glossy_direct", "glossy_indirect",
                        "light.ceiling", "bounce.0", "bounce.1", "bounce.2", "bounce.3"})
    EXPECT_NE(info.find_layer(c, SpectralQuantity::S0), nullptr) << c;
  ASSERT_TRUE(info.has_object_ids);
  EXPECT_EQ(info.object_names.size(), 8u);
  EXPECT_EQ(info.object_names.at(6), "sphere");
  EXPECT_EQ(info.object_names.at(8), "ceiling_lamp");
  EXPECT_NE(info.metadata.at("chromatrace.renderer").find("Cycles"), std::string::npos);
  EXPECT_EQ(info.metadata.at("chromatrace.samples"), "4");

  // Pixels that see only the lamp show its band-averaged radiance exactly (no noise in directly seen
  // emission): Cycles' emission colour × strength is radiance in the file's units.
  std::vector<std::int32_t> ids(64 * 64);
  reader.read_object_ids(0, 64, ids);
  const std::vector<float> emission = layer(reader, "emission");
  const Scene scene = load_scene(kBox);
  const std::vector<double> lamp = band_averages(scene.lights[0].emitted_radiance(), info.bands);
  int inside = 0;
  for (int y = 1; y < 63; ++y)
    for (int x = 1; x < 63; ++x) {
      auto id = [&](int i, int j) { return ids[static_cast<std::size_t>(j * 64 + i)]; };
      if (id(x, y) != 8 || id(x - 1, y) != 8 || id(x + 1, y) != 8 || id(x, y - 1) != 8 || id(x, y + 1) != 8) continue;
      ++inside;
      for (std::size_t b = 0; b < 40; ++b)
        EXPECT_NEAR(emission[static_cast<std::size_t>(y * 64 + x) * 40 + b], lamp[b], 1e-5 * lamp[b]) << x << "," << y;
    }
  EXPECT_GT(inside, 0);
  // The floor is at the bottom of the image, the back wall in the middle.
  EXPECT_EQ(ids[63 * 64 + 32], 1);
  EXPECT_EQ(ids[20 * 64 + 32], 3);
}

TEST_F(Blender, BadInputExitsTwoWithOneErrorLineNamingTheField) {
  const std::string out = dir_.file("out.exr").string();
  struct Case {
    std::vector<std::string> args;
    std::string must_mention;
  };
  const std::vector<Case> cases = {
      {{"--scene", kBox}, "--out"},
      {{"--scene", kBox, "--out", out, "--samples", "0"}, "--samples"},
      {{"--scene", dir_.file("missing.json").string(), "--out", out}, "missing.json"},
      {{"--scene", kSource + "/tests/data/scenes/bad/negative_radius.json", "--out", out}, "objects[1].shape.radius"},
      {{"--scene", kBox, "--out", out, "--bands", "400:705:10"}, "--bands"},
      {{"--scene", kBox, "--out", out, "--components", "paths,glow"}, "--components"},
      // Valid for the tracer; Cycles in Blender 3.x has separable masking and would render another material.
      {{"--scene", kSource + "/tests/data/scenes/ggx_height_correlated.json", "--out", out}, "materials.red_plastic.masking"},
      {{"--scene", kBox, "--out", dir_.file("no/dir/out.exr").string()}, "--out"},
  };
  for (const Case& c : cases) {
    const CommandResult r = batch(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.must_mention << ": " << r.err;
    const auto errors = lines_starting(r.err, "batch.py: ");
    ASSERT_EQ(errors.size(), 1u) << r.err;
    EXPECT_EQ(errors[0].rfind("batch.py: error: ", 0), 0u) << errors[0];
    EXPECT_NE(errors[0].find(c.must_mention), std::string::npos) << errors[0];
    EXPECT_FALSE(fs::exists(out));
  }
}

// Three bands in R, G and B of one render estimate the same as three renders of one band each: Cycles
// treats the channels alike and separately. Independent seeds, so the per-pixel differences are pure noise
// with mean zero; their mean must be within 4 standard errors of 0 in every band and component.
TEST_F(Blender, MultiplexingIsExactInExpectation) {
  const fs::path three = dir_.file("three.exr"), one = dir_.file("one.exr");
  const std::vector<std::string> common = {"--scene", kBox, "--resolution", "32x32", "--samples", "16",
                                           "--bands", "450:600:50", "--max-bounces", "4", "--components", "paths"};
  std::vector<std::string> a = common, b = common;
  a.insert(a.end(), {"--out", three.string(), "--seed", "1"});
  b.insert(b.end(), {"--out", one.string(), "--seed", "2", "--bands-per-render", "1"});
  const CommandResult ra = batch(a), rb = batch(b);
  ASSERT_EQ(ra.exit_code, 0) << ra.err;
  ASSERT_EQ(rb.exit_code, 0) << rb.err;
  EXPECT_NE(ra.err.find("3 bands in 1 renders of 3 band(s)"), std::string::npos) << ra.err;
  EXPECT_NE(rb.err.find("3 bands in 3 renders of 1 band(s)"), std::string::npos) << rb.err;

  SpectralExrReader ma(three), mb(one);
  for (const std::string component : {"", "emission", "diffuse_direct", "diffuse_indirect", "glossy_direct",
                                      "glossy_indirect"}) {
    const std::vector<float> x = component.empty() ? ma.read_layer(ma.info().total()) : layer(ma, component);
    const std::vector<float> y = component.empty() ? mb.read_layer(mb.info().total()) : layer(mb, component);
    for (std::size_t band = 0; band < 3; ++band) {
      const Difference d = band_difference(x, y, 3, band);
      fmt::print("{} band {}: level {:.5g}, mean difference {:.3g} (se {:.3g})\n",
                 component.empty() ? "total" : component, band, d.scale, d.mean, d.se);
      EXPECT_LT(std::abs(d.mean), 4 * d.se + 1e-7)
          << (component.empty() ? "total" : component) << " band " << band << ": mean difference " << d.mean
          << " (se " << d.se << ", level " << d.scale << ")";
      if (component.empty()) {
        EXPECT_LT(d.se, 0.05 * d.scale);  // the test has power: the noise is small
      }
    }
  }
}

// A Lambertian plane (ρ = 0.5) under a one-sided rectangular emitter of known spectral radiance: the
// plane's radiance is ρ · Le · F, F the view factor to the rectangle (Howell B-3 by superposition). This
// pins down Cycles' emission convention: an Emission shader of colour C and strength S on a mesh emits
// radiance C · S, in the units the passes hold (docs/blender.md).
TEST_F(Blender, EmissionUnitsMatchTheClosedFormUnderARectangularEmitter) {
  const json doc = {
      {"format", "chromatrace-scene/1"},
      {"spectra", {{"half", {{"constant", 0.5}}}, {"panel", {{"samples", {{500, 1.0}, {600, 3.0}}}}}}},
      {"materials", {{"plane", {{"type", "lambert"}, {"reflectance", "half"}}}}},
      {"lights",
       {{{"name", "panel"},
         {"shape", {{"type", "quad"}, {"corner", {-0.5, -0.3, 0.8}}, {"edge1", {0, 0.6, 0}}, {"edge2", {1.0, 0, 0}}}},
         {"radiance", "panel"},
         {"scale", 2.0}}}},
      {"objects",
       {{{"name", "plane"},
         {"material", "plane"},
         {"shape", {{"type", "quad"}, {"corner", {-5, -5, 0}}, {"edge1", {10, 0, 0}}, {"edge2", {0, 10, 0}}}}}}},
      {"camera",
       {{"position", {1.2, 0, 0.5}}, {"look_at", {1.2, 0, 0}}, {"up", {0, 1, 0}}, {"fov_deg", 120}, {"resolution", {24, 24}}}},
      {"render", {{"samples", 64}, {"max_bounces", 3}, {"bands", "500:600:50"}}}};
  const fs::path scene_file = write_scene("plane.json", doc);
  const fs::path out = dir_.file("plane.exr");
  const CommandResult r = batch({"--scene", scene_file.string(), "--out", out.string(), "--components", "none"});
  ASSERT_EQ(r.exit_code, 0) << r.err;

  const Scene scene = load_scene(scene_file);
  SpectralExrReader reader(out);
  ASSERT_EQ(reader.info().bands.size(), 2u);
  const std::vector<double> le = band_averages(scene.lights[0].emitted_radiance(), reader.info().bands);
  EXPECT_DOUBLE_EQ(le[0], 3.0);  // (1 + 2) / 2 · 2
  EXPECT_DOUBLE_EQ(le[1], 5.0);
  const std::vector<float> total = reader.read_layer(reader.info().total());
  const Camera& cam = scene.camera;
  for (std::size_t band = 0; band < 2; ++band) {
    double sum = 0, sum2 = 0, level = 0;
    int n = 0;
    for (int y = 0; y < cam.height; ++y)
      for (int x = 0; x < cam.width; ++x) {
        // The box filter averages over the pixel: so does the expectation, on a 4 × 4 grid.
        double expected = 0;
        for (int sy = 0; sy < 4; ++sy)
          for (int sx = 0; sx < 4; ++sx) {
            const Vec3 d = cam.ray_direction(x + (sx + 0.5) / 4, y + (sy + 0.5) / 4);
            const Vec3 p = cam.position - cam.position.z() / d.z() * d;
            expected += 0.5 * le[band] * test::rectangle_view_factor(p.x(), p.y(), -0.5, 0.5, -0.3, 0.3, 0.8) / 16;
          }
        const double residual = total[static_cast<std::size_t>(y * cam.width + x) * 2 + band] - expected;
        sum += residual;
        sum2 += residual * residual;
        level += expected;
        ++n;
      }
    const double mean = sum / n, se = std::sqrt((sum2 / n - mean * mean) / (n - 1));
    fmt::print("band {}: mean radiance {:.6g} W/(m2 sr nm), mean residual {:.3g} (se {:.3g})\n", band, level / n, mean,
               se);
    EXPECT_LT(std::abs(mean), 4 * se + 1e-7) << "band " << band << ": mean residual " << mean << " (se " << se << ")";
    EXPECT_LT(std::sqrt(sum2 / n), 0.1 * level / n) << "band " << band;  // and the noise itself is small
  }
}

// Max bounces 0 shows the emitters only: every reflectance (spectral or grey, as the dichromatic lobe's
// weight) is 0 during the render, so the total is the directly seen emission and nothing else.
TEST_F(Blender, MaxBouncesZeroShowsEmittersOnly) {
  const fs::path out = dir_.file("emitters.exr");
  const CommandResult r = batch({"--scene", kBox, "--out", out.string(), "--resolution", "24x24", "--samples", "2",
                                 "--bands", "400:700:100", "--max-bounces", "0", "--components", "all"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(test::run_chromatrace({"info", "--check", out.string()}).exit_code, 0);
  SpectralExrReader reader(out);
  EXPECT_EQ(reader.info().find_layer("bounce.1", SpectralQuantity::S0), nullptr);
  const std::vector<float> total = reader.read_layer(reader.info().total());
  EXPECT_EQ(total, layer(reader, "emission"));
  EXPECT_EQ(total, layer(reader, "bounce.0"));
  for (const char* c : {"diffuse_direct", "diffuse_indirect", "glossy_direct", "glossy_indirect"}) {
    const std::vector<float> v = layer(reader, c);
    EXPECT_EQ(*std::max_element(v.begin(), v.end()), 0.0f) << c;
  }
  EXPECT_GT(*std::max_element(total.begin(), total.end()), 1.0f);  // the lamp is in view
}

// A run killed after two of five renders (four band groups and the object ids) leaves them in the cache;
// running again renders only the other three and writes the same file as a run that was never interrupted.
TEST_F(Blender, KilledRunResumesWithOnlyTheRemainingRenders) {
  const fs::path out = dir_.file("resumed.exr"), reference = dir_.file("reference.exr");
  const std::vector<std::string> common = {"--scene", kBox, "--resolution", "24x24", "--samples", "4",
                                           "--bands", "400:700:25", "--max-bounces", "2", "--components", "paths"};
  std::vector<std::string> args = common;
  args.insert(args.end(), {"--out", out.string()});

  setenv("CHROMATRACE_TEST_KILL_AT_RENDER", "2", 1);
  const CommandResult killed = batch(args);
  unsetenv("CHROMATRACE_TEST_KILL_AT_RENDER");
  EXPECT_EQ(killed.exit_code, 128 + 9) << killed.err;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(lines_starting(killed.err, "chromatrace: render ").size(), 2u) << killed.err;

  const CommandResult resumed = batch(args);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  const auto renders = lines_starting(resumed.err, "chromatrace: render ");
  ASSERT_EQ(renders.size(), 5u) << resumed.err;
  EXPECT_NE(renders[0].find("already in the cache"), std::string::npos) << renders[0];
  EXPECT_NE(renders[1].find("already in the cache"), std::string::npos) << renders[1];
  EXPECT_EQ(renders[2].find("already in the cache"), std::string::npos) << renders[2];
  EXPECT_EQ(renders[3].find("already in the cache"), std::string::npos) << renders[3];
  EXPECT_NE(renders[4].find("(object ids)"), std::string::npos) << renders[4];
  EXPECT_NE(resumed.err.find("(3 renders made, 2 from the cache)"), std::string::npos) << resumed.err;

  std::vector<std::string> fresh = common;
  fresh.insert(fresh.end(), {"--out", reference.string()});
  const CommandResult uninterrupted = batch(fresh, "other-cache");
  ASSERT_EQ(uninterrupted.exit_code, 0) << uninterrupted.err;
  SpectralExrReader a(out), b(reference);
  std::vector<std::string> channels_a, channels_b;
  for (const ExrChannel& c : a.info().channels) channels_a.push_back(c.name);
  for (const ExrChannel& c : b.info().channels) channels_b.push_back(c.name);
  EXPECT_EQ(channels_a, channels_b);
  EXPECT_EQ(a.info().metadata, b.info().metadata);
  EXPECT_EQ(a.info().object_names, b.info().object_names);
  EXPECT_EQ(a.read_layer(a.info().total()), b.read_layer(b.info().total()));  // Cycles is deterministic per seed
}

// A .blend with chromatrace settings renders headless, and the file on disk stays byte for byte the same.
TEST_F(Blender, BlendFileRendersAndIsNeverWritten) {
  const fs::path blend = dir_.file("box.blend"), out = dir_.file("blend.exr");
  const CommandResult made = test::run_program(
      BLENDER_EXE, {"--background", "--factory-startup", "--python", kSource + "/tests/blender/make_blend.py", "--",
                    kBox, blend.string()});
  ASSERT_EQ(made.exit_code, 0) << made.err;
  const std::vector<char> before = test::read_bytes(blend);
  const auto mtime = fs::last_write_time(blend);
  const CommandResult r = batch({"--blend", blend.string(), "--out", out.string(), "--resolution", "16x16",
                                 "--samples", "2", "--bands", "400:700:100", "--max-bounces", "2"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(test::run_chromatrace({"info", "--check", out.string()}).exit_code, 0);
  EXPECT_EQ(test::read_bytes(blend), before);
  EXPECT_EQ(fs::last_write_time(blend), mtime);
  EXPECT_FALSE(fs::exists(dir_.file("box.blend1")));
}

}  // namespace
}  // namespace ct
