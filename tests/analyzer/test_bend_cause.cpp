// SPDX-License-Identifier: Apache-2.0
// What bends a cluster, on synthetic images whose bend has one known cause: a highlight leaving a matte line (an
// L, the glossy component), interreflected light whose share falls as the direct light grows (the indirect
// component), pixels mixing two objects along an edge, and a response curve over a line that misses black. Each is
// named, and only it; the other tests run on the same image and leave the cluster bent.
#include <cmath>

#include <gtest/gtest.h>

#include "analyzer/analysis.h"
#include "analyzer/bend_cause.h"
#include "tests/analyzer/synthetic.h"

namespace ct::test {
namespace {

using namespace ct::analyzer;

// The region of object 1, analysed as the series does (the final layer, regions from object_id).
const RegionAnalysis& object_one(const ImageAnalysis& a) {
  for (const RegionAnalysis& r : a.results)
    if (r.source == "labels" && r.label == 1) return r;
  throw std::runtime_error("no object 1");
}

ImageAnalysis analyse(const AnalysisImage& input) {
  return analyse_image(input, "", select_regions(input, input.image, {}), AnalyzeOptions{}, std::nullopt, false);
}

RgbImage sum(const RgbImage& a, const RgbImage& b) {
  RgbImage s = a;
  for (std::size_t i = 0; i < s.rgb.size(); ++i) s.rgb[i] += b.rgb[i];
  return s;
}

void expect_only(const RegionAnalysis& r, const char* cause) {
  ASSERT_TRUE(r.bend) << "class " << class_name(r.shape.shape) << ": " << r.shape.reason;
  EXPECT_GT(r.bend->bend, AnalyzeOptions{}.criteria.max_bend_for_straight);
  ASSERT_EQ(r.bend->causes.size(), 1u) << r.bend->summary;
  EXPECT_EQ(r.bend->causes.front(), cause) << r.bend->summary;
  EXPECT_TRUE(r.bend->straightened) << r.bend->summary;
  for (const BendTest& t : r.bend->tests)
    EXPECT_EQ(t.straight, t.cause == cause) << t.cause << ": " << t.bend << " (" << r.bend->summary << ")";
}

// One object (id 1) whose light is diffuse_direct plus a second component, named second_name.
SensorExr with_components(const RgbImage& direct, const std::string& second_name, const RgbImage& second) {
  const RgbImage total = sum(direct, second);
  return {total, total, {{"diffuse_direct", direct}, {second_name, second}},
          std::vector<std::int32_t>(static_cast<std::size_t>(direct.width) * direct.height, 1), {{1, "object"}}};
}

// A matte line with a narrow highlight at its bright end (the dichromatic model's L): the glossy light bends it.
TEST(BendCause, AHighlightBentLIsTheHighlightLobe) {
  const RgbImage body = make_image(96, 96, [](double u, double) { return (0.05 + 0.95 * u) * kBody; });
  const RgbImage glossy = make_image(96, 96, [](double u, double v) {
    return 0.8 * std::exp(-(std::pow(u - 0.85, 2) + std::pow(v - 0.5, 2)) / (2 * 0.06 * 0.06)) * kIlluminant;
  });
  const ImageAnalysis a = analyse(analysis_image(with_components(body, "glossy_direct", glossy)));
  expect_only(object_one(a), kCauseHighlight);
}

// Interreflected light of another colour whose share of the light falls as the direct light grows (most of it
// where the object is dark, as inside a concave object): the indirect light bends the line into a banana.
TEST(BendCause, AnInterreflectionBentLineIsInterreflection) {
  const Vec3 bounce = kBody.cwiseProduct(kSecondLight).normalized();
  const RgbImage direct = make_image(96, 96, [](double u, double) { return (0.05 + 0.95 * u) * kBody; });
  const RgbImage indirect = make_image(96, 96, [&](double u, double) {
    const double s = 0.05 + 0.95 * u;
    return 0.35 * s * (1 - s) * bounce;
  });
  const ImageAnalysis a = analyse(analysis_image(with_components(direct, "diffuse_indirect", indirect)));
  const RegionAnalysis& r = object_one(a);
  expect_only(r, kCauseInterreflection);
  EXPECT_EQ(r.shape.shape, ShapeClass::Curved) << r.shape.reason;
}

// A thin object (4 columns) shaded top to bottom whose edge column records a mix with its bright neighbour, the more
// the lower (an edge that slants across the pixels): the mixed pixels bend its line.
TEST(BendCause, AnEdgeMixIsMixingAtEdges) {
  const Vec3 other(0.3, 0.9, 0.4);
  const RgbImage image = make_image(16, 96, [&](double u, double v) -> Vec3 {
    const int x = static_cast<int>(std::lround(u * 15));
    const Vec3 own = (0.1 + 0.9 * v) * kBody;
    if (x > 3) return 0.8 * other.normalized();
    if (x == 3) {
      const double w = 0.6 * v * v;
      return (1 - w) * own + w * 0.8 * other.normalized();
    }
    return own;
  });
  std::vector<std::int32_t> ids;
  for (int y = 0; y < 96; ++y)
    for (int x = 0; x < 16; ++x) ids.push_back(x <= 3 ? 1 : 2);
  AnalysisImage input;
  input.image = image;
  input.object_ids = ids;
  input.object_names = {{1, "thin"}, {2, "neighbour"}};
  expect_only(object_one(analyse(input)), kCauseEdgeMixing);
}

// A line that misses black (an ambient offset) encoded by I' = I^(1/2.2), with the curve declared: in linear light
// it is straight, so the camera's curve bent it.
TEST(BendCause, AGammaCurveIsTheCameraCurve) {
  AnalysisImage input;
  input.image = gamma_line();
  input.encoding.curve = ToneCurve{kGamma, 1, false};
  input.encoding.curve_source = "the test";
  input.object_ids.assign(static_cast<std::size_t>(input.image.width) * input.image.height, 1);
  input.object_names = {{1, "line"}};
  expect_only(object_one(analyse(input)), kCauseCameraCurve);
}

// A straight line is not bent: no cause is looked for.
TEST(BendCause, AStraightLineHasNoBend) {
  const RgbImage line = matte_line();
  const ImageAnalysis a = analyse(analysis_image(with_components(line, "diffuse_indirect", make_image(128, 128, [](double, double) {
    return Vec3(0, 0, 0);
  }))));
  EXPECT_FALSE(object_one(a).bend);
}

}  // namespace
}  // namespace ct::test
