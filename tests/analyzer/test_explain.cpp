// Attributing a cluster to light paths: energy shares per component, direct / indirect and diffuse /
// glossy splits, dominant components, and the indirect light's share of the spread off the direct light's
// dichromatic plane.
#include <gtest/gtest.h>

#include "analyzer/analysis.h"
#include "analyzer/edge_mixing.h"
#include "analyzer/explain.h"
#include "analyzer/line_fit.h"
#include "analyzer/superposition.h"
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

// ---- Superposed luminaires ------------------------------------------------------------------------------

namespace ct::test {
namespace {

analyzer::AnalysisImage two_lights(double share_b, const Vec3& warm, const Vec3& cool) {
  return analysis_image(two_luminaires(share_b, warm, cool));
}

double energy(const RgbImage& image) { double e = 0; for (float v : image.rgb) e += v; return e; }

TEST(Superposition, TwoLuminairesOfDifferentColoursAreSuperposed) {
  const Vec3 warm(1.0, 0.8, 0.55), cool(0.8, 0.9, 1.0);
  const analyzer::AnalysisImage input = two_lights(0.4, warm, cool);
  const analyzer::Region region = analyzer::whole_image_region(64, 64);
  const auto s = analyzer::find_superposition(input, region, analyzer::ShapeCriteria{});
  ASSERT_TRUE(s);
  ASSERT_EQ(s->groups.size(), 2u);
  const double e_warm = energy(input.components[0].image), e_cool = energy(input.components[1].image);
  EXPECT_EQ(s->groups[0].name, e_warm >= e_cool ? "light.warm" : "light.cool");
  EXPECT_NEAR(s->groups[0].share, std::max(e_warm, e_cool) / (e_warm + e_cool), 1e-6);
  EXPECT_NEAR(s->angle_deg, analyzer::line_angle_degrees(kBody.cwiseProduct(warm), kBody.cwiseProduct(cool)), 1e-3);
  EXPECT_TRUE(s->superposed);

  // The cluster itself: a wedge between the two colours; the analysis calls it superposed and says why.
  analyzer::AnalyzeOptions options;
  const analyzer::ImageAnalysis a = analyzer::analyse_image(input, "final", {region}, options, std::nullopt, false);
  EXPECT_EQ(a.results[0].shape.shape, analyzer::ShapeClass::Superposed) << a.results[0].shape.reason;
  EXPECT_NE(a.results[0].shape.reason.find("light.warm"), std::string::npos);
  // Analysing one luminaire's own layer is no superposition.
  const analyzer::ImageAnalysis one = analyzer::analyse_image(input, "light.warm", {region}, options, std::nullopt, false);
  EXPECT_NE(one.results[0].shape.shape, analyzer::ShapeClass::Superposed);
}

TEST(Superposition, SameColouredLuminairesOrAWeakSecondOneAreNot) {
  const Vec3 warm(1.0, 0.8, 0.55);
  const analyzer::Region region = analyzer::whole_image_region(64, 64);
  // Two lamps of one colour: their sum is the structure of one lamp.
  const auto same = analyzer::find_superposition(two_lights(0.5, warm, warm), region, analyzer::ShapeCriteria{});
  ASSERT_TRUE(same);
  EXPECT_LT(same->angle_deg, 1e-3);
  EXPECT_FALSE(same->superposed);
  // A second lamp carrying 5 % of the light, under superposed_share.
  const analyzer::AnalysisImage input = two_lights(0.05, warm, Vec3(0.8, 0.9, 1.0));
  const auto weak = analyzer::find_superposition(input, region, analyzer::ShapeCriteria{});
  ASSERT_TRUE(weak);
  const double e_warm = energy(input.components[0].image), e_cool = energy(input.components[1].image);
  EXPECT_NEAR(weak->groups[1].share, e_cool / (e_warm + e_cool), 1e-6);
  EXPECT_LT(weak->groups[1].share, analyzer::ShapeCriteria{}.superposed_share);
  EXPECT_FALSE(weak->superposed);
}

}  // namespace
}  // namespace ct::test

// ---- Mixed edge pixels ------------------------------------------------------------------------------------

namespace ct::test {
namespace {

analyzer::AnalysisImage two_objects(bool box_filter) { return analysis_image(two_objects_edge(box_filter)); }

TEST(EdgeMixing, MixedEdgePixelsOfPixelAreaAreFoundAndNamed) {
  const analyzer::AnalysisImage input = two_objects(true);
  const analyzer::Region left = analyzer::label_regions(input.object_ids, "object", input.object_names, {0})[0];
  const analyzer::EdgeMixing m = analyzer::find_edge_mixing(input.image, input.object_ids, left, 1, 0.0);
  EXPECT_EQ(m.edge_pixels, 64u);  // column 31
  EXPECT_EQ(m.mixed.size(), 64u);
  EXPECT_EQ(m.with.at(2), 64u);

  analyzer::AnalyzeOptions options;
  const analyzer::ImageAnalysis a = analyzer::analyse_image(
      input, "final", analyzer::select_regions(input, input.image, {}), options, std::nullopt, false);
  ASSERT_EQ(a.results.size(), 3u);
  const analyzer::ClusterShape& s = a.results[1].shape;
  EXPECT_EQ(s.shape, analyzer::ShapeClass::Mixed) << s.reason;
  EXPECT_NE(s.reason.find("without them linear"), std::string::npos) << s.reason;
  // The dimmest rows, where the two colours differ by less than 3 × the measured noise, are not judged.
  EXPECT_NE(s.reason.find("with its neighbours' (right ("), std::string::npos) << s.reason;
  EXPECT_EQ(a.results[2].shape.shape, analyzer::ShapeClass::Linear) << a.results[2].shape.reason;  // pure on its side
}

TEST(EdgeMixing, PointSampledEdgesAreNotMixed) {
  const analyzer::AnalysisImage input = two_objects(false);
  const analyzer::Region left = analyzer::label_regions(input.object_ids, "object", input.object_names, {0})[0];
  const analyzer::EdgeMixing m = analyzer::find_edge_mixing(input.image, input.object_ids, left, 1, 0.0);
  EXPECT_EQ(m.edge_pixels, 64u);
  EXPECT_TRUE(m.mixed.empty());
  analyzer::AnalyzeOptions options;
  const analyzer::ImageAnalysis a = analyzer::analyse_image(
      input, "final", analyzer::select_regions(input, input.image, {}), options, std::nullopt, false);
  EXPECT_EQ(a.results[1].shape.shape, analyzer::ShapeClass::Linear) << a.results[1].shape.reason;
}

}  // namespace
}  // namespace ct::test
