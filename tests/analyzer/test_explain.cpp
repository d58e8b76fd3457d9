// SPDX-License-Identifier: Apache-2.0
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

// Two objects side by side, `width` columns each; `left(x, m)` gives the left object's colour in column x at
// shading m, the right object is the second light's body colour; `mixed_column` (if ≥ 0) records the left
// colour mixed with a share of the right one that changes from row to row between 5 % and 45 %, as the pixels
// along a slightly slanted edge are covered by the right object.
template <class F>
analyzer::AnalysisImage side_by_side(int width, F left, int mixed_column) {
  const Vec3 other = kBody.cwiseProduct(kSecondLight).normalized();
  const RgbImage image = make_image(2 * width, 64, [&](double u, double v) -> Vec3 {
    const double m = 0.1 + 0.9 * v;
    const int x = static_cast<int>(std::lround(u * (2 * width - 1)));
    const double share = 0.05 + 0.4 * ((static_cast<int>(std::lround(v * 63)) * 7) % 16) / 15.0;
    if (x == mixed_column) return (1 - share) * left(x, m) + share * m * other;
    return x < width ? left(x, m) : Vec3(m * other);
  });
  std::vector<std::int32_t> ids;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 2 * width; ++x) ids.push_back(x < width ? 1 : 2);
  return analysis_image({image, image, {}, ids, {{1, "left"}, {2, "right"}}});
}

analyzer::ClusterShape left_shape(const analyzer::AnalysisImage& input) {
  const analyzer::ImageAnalysis a = analyzer::analyse_image(input, "final", analyzer::select_regions(input, input.image, {}), {},
                                                            std::nullopt, false);
  return a.results.at(1).shape;
}

// A wide matte object with one mixed column: 64 of its 8 192 pixels leave its line (99.2 % stay on it, so
// the class is linear with them or without them), and they are the tail from its line towards the neighbour.
// (Mixed in one proportion all along the edge, they would make a second line through black: a fork.)
TEST(EdgeMixing, AFewMixedPixelsOffALineAreItsTail) {
  const auto input = side_by_side(128, [](int, double m) { return Vec3(m * kBody); }, 127);
  const analyzer::ClusterShape s = left_shape(input);
  EXPECT_EQ(s.shape, analyzer::ShapeClass::Mixed) << s.reason;
  // The four rows mixed at 5 % are not beyond "at least 5 % of the way" (an angle, a little under the share).
  EXPECT_NE(s.reason.find("60 of its 64 edge pixels"), std::string::npos) << s.reason;
  EXPECT_NE(s.reason.find("of them off its linear cluster"), std::string::npos) << s.reason;
}

// A colour that turns smoothly across the object towards the neighbour's (shading, an offset under a tone
// curve) is not a mix: here 60 % of the way at the edge, as (x/127)^8, 14 % of it in the last column alone,
// so that the last column turns 3.7 % of the way beyond the one behind it, but continues the turn of the two
// behind it to within 0.3 %.
TEST(EdgeMixing, ASmoothTurnTowardsTheEdgeIsNoMix) {
  const Vec3 other = kBody.cwiseProduct(kSecondLight).normalized();
  const auto turned = [&](int x, double m) {
    const double s = 0.6 * std::pow(x / 127.0, 8);
    return Vec3(m * ((1 - s) * kBody + s * other));
  };
  const auto input = side_by_side(128, turned, -1);
  const analyzer::Region left = analyzer::label_regions(input.object_ids, "object", input.object_names, {0})[0];
  EXPECT_TRUE(analyzer::find_edge_mixing(input.image, input.object_ids, left, 1, 0.0).mixed.empty());
}

// Point-sampled pixels (chromatrace.pixel_area 0) hold one surface each: the mixed column is then not looked at
// as a mix, and the record says why.
TEST(EdgeMixing, PointSampledFilesAreNotSearchedForMixing) {
  auto input = side_by_side(32, [](int, double m) { return Vec3(m * kBody); }, 31);
  input.encoding.pixel_area = false;
  const analyzer::ClusterShape s = left_shape(input);
  EXPECT_NE(s.shape, analyzer::ShapeClass::Mixed) << s.reason;
  ASSERT_FALSE(s.decisions.empty());
  EXPECT_EQ(s.decisions.back().test, "pixels integrate an area (chromatrace.pixel_area)");
  input.encoding.pixel_area = true;
  EXPECT_EQ(left_shape(input).shape, analyzer::ShapeClass::Mixed);
}

}  // namespace
}  // namespace ct::test
