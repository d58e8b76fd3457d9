// SPDX-License-Identifier: Apache-2.0
// A render split by seed (reference_tracer/seed_split.h): the shares of the samples, and the combination —
// each part weighted by its samples, exactly (Σ nᵢ·vᵢ / Σ nᵢ in double, rounded once) — and what it refuses.
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <gtest/gtest.h>

#include "core/error.h"
#include "core/spectral_exr.h"
#include "reference_tracer/render.h"
#include "reference_tracer/seed_split.h"

namespace ct::rt {
namespace {
namespace fs = std::filesystem;

class SeedParts : public ::testing::Test {
 protected:
  void SetUp() override { fs::create_directories(dir_); }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path part(const std::string& name, int samples, std::uint64_t seed, int width = 12) {
    Scene scene = load_scene(std::string(CHROMATRACE_SOURCE_DIR) + "/scenes/paper/box.json");
    scene.camera.width = width;
    scene.camera.height = 8;
    RenderOptions options;
    options.progress = false;
    options.samples = samples;
    options.seed = seed;
    const fs::path path = dir_ / name;
    write_render(path, scene, render(scene, options));
    return path;
  }

  fs::path dir_ = fs::temp_directory_path() / fmt::format("ct-seeds-{}", ::getpid());
};

TEST(SeedSplit, SharesAddUpToTheSamplesAndDifferByAtMostOne) {
  const SeedSplit split(4, 10, 7);
  EXPECT_EQ(split.part_samples(0), 3);
  EXPECT_EQ(split.part_samples(1), 3);
  EXPECT_EQ(split.part_samples(2), 2);
  EXPECT_EQ(split.part_samples(3), 2);
  EXPECT_EQ(split.part_seed(0), 7u);
  EXPECT_EQ(split.part_seed(3), 10u);
  EXPECT_THROW(SeedSplit(5, 4, 1), InputError);
  EXPECT_THROW(SeedSplit(0, 4, 1), InputError);
}

TEST_F(SeedParts, CombinationIsTheSampleWeightedMeanOfEveryValue) {
  const std::vector<fs::path> parts = {part("a.exr", 1, 5), part("b.exr", 3, 6)};
  const fs::path out = dir_ / "combined.exr";
  combine_parts(parts, out, false);

  SpectralExrReader a(parts[0]), b(parts[1]), c(out);
  EXPECT_EQ(c.info().metadata.at("chromatrace.samples"), "4");
  EXPECT_EQ(c.info().metadata.at("chromatrace.seed"), "5");
  ASSERT_EQ(c.info().layers.size(), a.info().layers.size());
  ASSERT_GT(c.info().layers.size(), 1u);  // the total and component layers alike
  for (std::size_t l = 0; l < c.info().layers.size(); ++l) {
    const std::vector<float> va = a.read_layer(a.info().layers[l]), vb = b.read_layer(b.info().layers[l]),
                             vc = c.read_layer(c.info().layers[l]);
    ASSERT_EQ(vc.size(), va.size());
    std::size_t differing = 0;
    for (std::size_t i = 0; i < vc.size(); ++i) {
      ASSERT_EQ(vc[i], static_cast<float>((1.0 * va[i] + 3.0 * vb[i]) / 4.0)) << "layer " << l << " value " << i;
      differing += va[i] != vb[i];
    }
    if (l == 0) {
      EXPECT_GT(differing, vc.size() / 2) << "the seeds should give different samples";
    }
  }
  std::vector<std::int32_t> ids_a(12 * 8), ids_c(12 * 8);
  a.read_object_ids(0, 8, ids_a);
  c.read_object_ids(0, 8, ids_c);
  EXPECT_EQ(ids_a, ids_c);
}

TEST_F(SeedParts, RefusesTheSameSeedTwiceAnotherImageAndMissingParts) {
  const fs::path a = part("a.exr", 2, 5), again = part("again.exr", 2, 5), wide = part("wide.exr", 2, 6, 16);
  const fs::path out = dir_ / "combined.exr";
  const auto message = [&](const std::vector<fs::path>& parts) {
    try {
      combine_parts(parts, out, false);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message({a, again}).find("again.exr: chromatrace.seed: 5 is also the seed of"), std::string::npos)
      << message({a, again});
  EXPECT_NE(message({a, wide}).find("wide.exr: size: differs from"), std::string::npos) << message({a, wide});
  EXPECT_NE(message({a, dir_ / "part_1.exr", dir_ / "part_2.exr"}).find("2 of 3 parts missing"), std::string::npos);
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace ct::rt
