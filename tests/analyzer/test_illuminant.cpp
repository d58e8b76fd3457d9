// The illuminant colour from several dichromatic objects: within 1° noise-free, within 3° with shot and
// read noise; grey world reported beside it (and, on coloured objects, far off).
#include <gtest/gtest.h>

#include "analyzer/illuminant.h"
#include "tests/analyzer/synthetic.h"

namespace ct::test {
namespace {

using namespace ct::analyzer;

const Vec3 kWarm(1.0, 0.85, 0.6);

IlluminantAnalysis estimate(const Scene& scene) {
  const LayerContext context = layer_context(scene.image, {}, 64);
  std::vector<RegionAnalysis> regions;
  for (const Region& r : label_regions(scene.ids, "object", scene.names, {0}))
    regions.push_back(analyse_region(scene.image, context, r, AnalyzeOptions{}));
  return estimate_illuminant(regions, scene.image.rgb, kWarm);
}

TEST(Illuminant, NoiseFreeObjectsGiveTheIlluminantWithinOneDegree) {
  const IlluminantAnalysis a = estimate(dichromatic_scene(kWarm));
  ASSERT_TRUE(a.planes);
  EXPECT_EQ(a.planes->regions.size(), 4u);
  EXPECT_LT(*a.planes->error_deg, 1.0);
  EXPECT_EQ(a.best().method, "dichromatic planes");
  // Across a sphere's highlight the diffuse shading changes too, which tilts each highlight line a little
  // towards its body colour: that estimate is biased, the planes' is not.
  ASSERT_TRUE(a.highlight_lines);
  EXPECT_LT(*a.highlight_lines->error_deg, 2.0);
  EXPECT_GT(*a.grey_world.error_deg, 3.0);  // grey world is fooled by the objects' colours
}

TEST(Illuminant, SensorNoiseKeepsItWithinThreeDegrees) {
  Scene scene = dichromatic_scene(kWarm);
  scene.image = add_sensor_noise(scene.image, 20000, 10, 42);
  const IlluminantAnalysis a = estimate(scene);
  ASSERT_TRUE(a.planes);
  EXPECT_LT(*a.planes->error_deg, 3.0);
  ASSERT_TRUE(a.highlight_lines);
  EXPECT_LT(*a.highlight_lines->error_deg, 3.0);
}

TEST(Illuminant, OnePlaneIsNotEnough) {
  EXPECT_FALSE(intersect_planes({Vec3::UnitZ()}));
  EXPECT_FALSE(intersect_planes({Vec3::UnitZ(), Vec3::UnitZ()}));
  const auto v = intersect_planes({Vec3::UnitZ(), Vec3::UnitX()});
  ASSERT_TRUE(v);
  EXPECT_NEAR(angular_error_deg(*v, Vec3::UnitY()), 0.0, 1e-9);
}

}  // namespace
}  // namespace ct::test
