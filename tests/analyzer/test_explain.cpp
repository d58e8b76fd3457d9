// Attributing a cluster to light paths: energy shares per component, direct / indirect and diffuse /
// glossy splits, dominant components, and the indirect light's share of the spread off the direct light's
// dichromatic plane.
#include <gtest/gtest.h>

#include "analyzer/explain.h"
#include "tests/analyzer/synthetic.h"
#include "tests/core/spectral_exr_fixtures.h"

namespace ct::test {
namespace {

using namespace ct::analyzer;

double sum_of(const RgbImage& image, const Region& region) {
  double s = 0;
  for (const std::uint32_t p : region.pixels) s += double(image.rgb[p * 3]) + image.rgb[p * 3 + 1] + image.rgb[p * 3 + 2];
  return s;
}

class Explain : public ::testing::Test {
 protected:
  void SetUp() override {
    write_sensor_exr(dir.file("s.exr"), scene);
    input = read_analysis_image(dir.file("s.exr"));
    regions = label_regions(input.object_ids, "object", input.object_names, {0});
  }
  TempDir dir;
  SensorExr scene = scene_with_components();
  AnalysisImage input;
  std::vector<Region> regions;
};

TEST_F(Explain, SharesAreEnergyFractionsOfTheLinearTotal) {
  ASSERT_EQ(regions.size(), 4u);
  for (const Region& r : regions) {
    const auto e = explain_region(input, r);
    ASSERT_TRUE(e);
    const double total = sum_of(scene.linear, r);
    const double glossy = sum_of(scene.components[1].second, r) / total;
    const double indirect = sum_of(scene.components[2].second, r) / total;
    EXPECT_NEAR(*e->glossy_share, glossy, 1e-6);
    EXPECT_NEAR(*e->indirect_share, indirect, 1e-6);
    EXPECT_NEAR(*e->direct_share + *e->indirect_share, 1.0, 1e-6);
    EXPECT_NEAR(*e->diffuse_share + *e->glossy_share, 1.0, 1e-6);
    ASSERT_EQ(e->families.size(), 3u);  // paths, lights, bounces
    EXPECT_EQ(e->families[1].family, ComponentFamily::LightGroup);
    EXPECT_NEAR(e->families[1].components[0].energy_share, 1.0, 1e-6);
    EXPECT_NEAR(e->families[2].components[1].energy_share, indirect, 1e-6);  // bounce.2
  }
}

TEST_F(Explain, IndirectLightAccountsForTheSpreadOffTheDichromaticPlane) {
  for (const Region& r : regions) {
    const auto e = explain_region(input, r);
    ASSERT_TRUE(e->off_structure);
    EXPECT_EQ(e->off_structure->structure, "dichromatic plane");
    EXPECT_LT(e->off_structure->rms_direct, 1e-3 * e->off_structure->rms_total);
    EXPECT_GT(e->off_structure->indirect_share, 0.999);
  }
}

TEST_F(Explain, HighlightsAreDominatedByGlossyLight) {
  const std::vector<int> map = dominant_component_map(input);
  int glossy = 0, diffuse = 0;
  for (int c : map) glossy += c == 1, diffuse += c == 0;
  EXPECT_GT(glossy, 10);
  EXPECT_GT(diffuse, 20 * glossy);
}

TEST(ComponentNames, Directness) {
  EXPECT_EQ(is_direct("emission"), true);
  EXPECT_EQ(is_direct("bounce.1"), true);
  EXPECT_EQ(is_direct("bounce.2"), false);
  EXPECT_EQ(is_direct("transmission_indirect"), false);
  EXPECT_FALSE(is_direct("light.key"));
}

}  // namespace
}  // namespace ct::test
