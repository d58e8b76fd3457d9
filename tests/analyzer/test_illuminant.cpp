// SPDX-License-Identifier: Apache-2.0
// The illuminant colour from several dichromatic objects: within 1° noise-free, within 3° with shot and
// read noise; grey world reported beside it (and, on coloured objects, far off).
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <numbers>
#include <random>

#include <Eigen/Geometry>

#include "analyzer/highlight_branch.h"
#include "analyzer/illuminant.h"
#include "analyzer/moments.h"
#include "tests/analyzer/synthetic.h"

namespace ct::test {
namespace {

using namespace ct::analyzer;

const Vec3 kWarm(1.0, 0.85, 0.6);

// The light known to be kWarm, with these clipping levels.
IlluminantContext known_warm(const std::array<double, 3>& high_levels = {kNoLevel, kNoLevel, kNoLevel}) {
  IlluminantContext c;
  c.known = kWarm;
  c.high_levels = high_levels;
  return c;
}

IlluminantAnalysis estimate(const Scene& scene) {
  const LayerContext context = layer_context(scene.image, {}, 64);
  std::vector<RegionAnalysis> regions;
  for (const Region& r : label_regions(scene.ids, "object", scene.names, {0}))
    regions.push_back(analyse_region(scene.image, context, r, AnalyzeOptions{}));
  return estimate_illuminant(regions, scene.image, known_warm());
}

TEST(Illuminant, NoiseFreeObjectsGiveTheIlluminantWithinOneDegree) {
  const IlluminantAnalysis a = estimate(dichromatic_scene(kWarm));
  ASSERT_TRUE(a.planes);
  EXPECT_EQ(a.planes->regions.size(), 4u);
  EXPECT_LT(*a.planes->error_deg, 1.0);
  EXPECT_EQ(a.best().method, "dichromatic planes") << a.planes->unreliable_reason;
  // Across a sphere's highlight the diffuse shading changes too, which tilts each highlight line a little
  // towards its body colour: that estimate is biased, the planes' is not.
  ASSERT_TRUE(a.highlight_lines);
  EXPECT_LT(*a.highlight_lines->error_deg, 2.0);
  EXPECT_GT(*a.grey_world().error_deg, 3.0);  // grey world is fooled by the objects' colours
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

// The stated uncertainty is a standard error: over noise seeds the planes' estimate lies within 3 of them of the
// light in nearly every frame (a 2-D direction error within 3σ has probability 1 − e^(−4.5) ≈ 99 %; at least 17
// of 20 allows for σ itself being estimated), and less noise gives a smaller uncertainty.
TEST(Illuminant, UncertaintyCoversTheErrorOverNoiseSeeds) {
  int covered = 0, frames = 0;
  double mean_uncertainty = 0;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    Scene scene = dichromatic_scene(kWarm);
    scene.image = add_sensor_noise(scene.image, 20000, 10, seed);
    const IlluminantAnalysis a = estimate(scene);
    ASSERT_TRUE(a.planes);
    ASSERT_TRUE(a.planes->uncertainty_deg);
    ++frames;
    covered += *a.planes->error_deg <= 3 * *a.planes->uncertainty_deg;
    mean_uncertainty += *a.planes->uncertainty_deg / 20;
    fmt::print("seed {}: planes {:.3f}° ± {:.3f}°, highlight lines {:.3f}° ± {:.3f}°\n", seed, *a.planes->error_deg,
               *a.planes->uncertainty_deg, a.highlight_lines ? *a.highlight_lines->error_deg : -1.0,
               a.highlight_lines && a.highlight_lines->uncertainty_deg ? *a.highlight_lines->uncertainty_deg : -1.0);
  }
  EXPECT_GE(covered, 17) << "of " << frames;
  Scene quiet = dichromatic_scene(kWarm);
  quiet.image = add_sensor_noise(quiet.image, 2000000, 1, 7);
  const IlluminantAnalysis q = estimate(quiet);
  ASSERT_TRUE(q.planes && q.planes->uncertainty_deg);
  EXPECT_LT(*q.planes->uncertainty_deg, mean_uncertainty / 3) << "100 times the full well: about a tenth of the noise";
  // Grey world's uncertainty holds how far its assumption fails on real scenes, whatever the noise.
  EXPECT_GE(q.grey_world().uncertainty_deg.value_or(0), method_prior_deg("grey world"));
  EXPECT_NE(q.choice.find("dichromatic planes"), std::string::npos) << q.choice;
}

// A highlight line that runs into a clipping level is cut off there: it is left out of the highlight-line
// estimate, with a note naming the region and the channel; levels above every highlight leave all of them in.
TEST(Illuminant, HighlightLinesEndingAtAClippingLevelAreLeftOut) {
  const Scene scene = dichromatic_scene(kWarm);
  const LayerContext context = layer_context(scene.image, {}, 64);
  std::vector<RegionAnalysis> regions;
  for (const Region& r : label_regions(scene.ids, "object", scene.names, {0}))
    regions.push_back(analyse_region(scene.image, context, r, AnalyzeOptions{}));
  std::array<double, 3> peak{0, 0, 0};
  for (std::size_t i = 0; i + 2 < scene.image.rgb.size(); i += 3)
    for (int c = 0; c < 3; ++c) peak[c] = std::max(peak[c], static_cast<double>(scene.image.rgb[i + c]));
  const IlluminantAnalysis open = estimate_illuminant(regions, scene.image, known_warm({2 * peak[0], 2 * peak[1], 2 * peak[2]}));
  ASSERT_TRUE(open.highlight_lines);
  const std::size_t all = open.highlight_lines->regions.size();
  ASSERT_GE(all, 2u);
  // Red clips at the brightest red any highlight reaches: that highlight's line ends there.
  const IlluminantAnalysis cut = estimate_illuminant(regions, scene.image, known_warm({peak[0], kNoLevel, kNoLevel}));
  const std::size_t kept = cut.highlight_lines ? cut.highlight_lines->regions.size() : 0;
  EXPECT_LT(kept, all);
  int said = 0;
  for (const std::string& n : cut.notes) said += n.find("ends at the clipping level of R") != std::string::npos;
  EXPECT_EQ(static_cast<std::size_t>(said), all - kept);
  ASSERT_TRUE(cut.planes);  // the planes do not depend on where a highlight ends
  EXPECT_EQ(cut.planes->rgb, open.planes->rgb);
}

// A cluster pressed onto a face of the cube lost what lay beyond it, and its plane through black is partly the face:
// clipping red below one object's brightest red takes that object out of the planes' estimate, with a note.
TEST(Illuminant, APlaneOnAClippingFaceIsLeftOut) {
  Scene scene = dichromatic_scene(kWarm);
  const std::vector<Region> objects = label_regions(scene.ids, "object", scene.names, {0});
  // The red level: half the brightest red of the first object's pixels.
  double red = 0;
  for (const std::uint32_t p : objects.front().pixels) red = std::max(red, static_cast<double>(scene.image.rgb[p * 3]));
  for (std::size_t i = 0; i < scene.image.rgb.size(); i += 3)
    scene.image.rgb[i] = std::min(scene.image.rgb[i], static_cast<float>(red / 2));
  const LayerContext context = layer_context(scene.image, {}, 64);
  std::vector<RegionAnalysis> regions;
  for (const Region& r : objects) regions.push_back(analyse_region(scene.image, context, r, AnalyzeOptions{}));
  const IlluminantAnalysis a = estimate_illuminant(regions, scene.image, known_warm(context.high_levels));
  std::size_t faced = 0, said = 0;
  auto holds_a_plane = [](ShapeClass c) {
    return c == ShapeClass::L || c == ShapeClass::SkewedT || c == ShapeClass::P || c == ShapeClass::Planar || c == ShapeClass::Thickened;
  };
  for (const RegionAnalysis& r : regions)
    if (!r.shape.clipping.faces.empty() && r.shape.black_plane) {
      faced += holds_a_plane(r.shape.shape);
      if (a.planes) {
        EXPECT_EQ(std::count(a.planes->regions.begin(), a.planes->regions.end(), r.name), 0) << r.name;
      }
    }
  for (const std::string& n : a.notes) said += n.find("partly the cube's face") != std::string::npos;
  EXPECT_GE(faced, 1u);
  EXPECT_EQ(said, faced);
}

// The first `count` objects of the scene as planes without their highlight lines.
std::vector<RegionAnalysis> planes_only(const Scene& scene, std::size_t count) {
  const LayerContext context = layer_context(scene.image, {}, 64);
  std::vector<RegionAnalysis> regions;
  for (const Region& r : label_regions(scene.ids, "object", scene.names, {0})) {
    regions.push_back(analyse_region(scene.image, context, r, AnalyzeOptions{}));
    ClusterShape& s = regions.back().shape;
    s.shape = ShapeClass::Planar;
    s.two_lines.reset();
    s.highlight_branch.reset();
    if (regions.size() == count) break;
  }
  return regions;
}

// Two planes meet in a line whatever made them: without a highlight line to check them, the planes' estimate is
// marked unreliable, and the statistical method of the choice rule stands in; the choice says why.
TEST(Illuminant, TwoPlanesAloneAreUnreliable) {
  const Scene scene = dichromatic_scene(kWarm);
  const std::vector<RegionAnalysis> regions = planes_only(scene, 2);
  const IlluminantAnalysis a = estimate_illuminant(regions, scene.image, known_warm());
  ASSERT_TRUE(a.planes);
  EXPECT_FALSE(a.planes->reliable);
  EXPECT_NE(a.planes->unreliable_reason.find("two planes"), std::string::npos);
  EXPECT_EQ(a.best().method, choice_rule().fallback);
  EXPECT_NE(a.choice.find("the dichromatic planes estimate is not used"), std::string::npos) << a.choice;
}

// Every light's colour lies within 54.7° of grey (grey to a primary). Three planes that miss a common direction,
// with one degree of freedom to say by how much, have a 2σ beyond that: they could be any light's colour, and the
// statistical method of the choice rule stands in. The same three planes, meeting, are an estimate.
TEST(Illuminant, AnEstimateThatCouldBeAnyLightIsUnreliable) {
  const Scene scene = dichromatic_scene(kWarm);
  std::vector<RegionAnalysis> regions = planes_only(scene, 3);
  ASSERT_EQ(regions.size(), 3u);
  for (const RegionAnalysis& r : regions) ASSERT_TRUE(r.shape.black_plane);
  const IlluminantAnalysis meeting = estimate_illuminant(regions, scene.image, known_warm());
  ASSERT_TRUE(meeting.planes);
  EXPECT_TRUE(meeting.planes->reliable) << meeting.planes->unreliable_reason;
  // Tilt the third plane by 10° about the axis in it that is perpendicular to the light: it no longer holds the light.
  Vec3& n = regions[2].shape.black_plane->normal;
  const Vec3 axis = n.cross(kWarm.normalized()).normalized();
  n = Eigen::AngleAxisd(10 * std::numbers::pi / 180, axis) * n;
  const IlluminantAnalysis missing = estimate_illuminant(regions, scene.image, known_warm());
  ASSERT_TRUE(missing.planes);
  ASSERT_TRUE(missing.planes->uncertainty_deg);
  EXPECT_GT(2 * *missing.planes->uncertainty_deg, std::acos(1 / std::sqrt(3.0)) * 180 / std::numbers::pi);
  EXPECT_FALSE(missing.planes->reliable);
  EXPECT_NE(missing.planes->unreliable_reason.find("could be any light's colour"), std::string::npos)
      << missing.planes->unreliable_reason;
  EXPECT_EQ(missing.best().method, choice_rule().fallback);
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

namespace ct::test {
namespace {

// The highlight branch by regression (analyzer/highlight_branch.h): colours c = m_b·body + m_s·light with the
// shading m_b spread across the highlight independently of its strength m_s, plus noise. The branch points to the
// light within 3 of its standard errors; a total-least-squares line through the same colours is tilted towards
// the body colour by the shading's spread.
TEST(HighlightBranch, PointsToTheLightWhereTheShadingSpreadsAcrossTheHighlight) {
  const Vec3 body = Vec3(0.9, 0.4, 0.1).normalized(), light = Vec3(0.6, 0.6, 0.5).normalized();
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> uniform(0, 1);
  std::normal_distribution<double> noise(0, 0.003);
  std::vector<Vec3> points;
  std::vector<std::size_t> off;
  for (int i = 0; i < 3000; ++i) points.push_back(uniform(random) * body + Vec3(noise(random), noise(random), noise(random)));
  for (int i = 0; i < 600; ++i) {
    const double m_b = 0.4 + 0.5 * uniform(random), m_s = 0.05 + 0.5 * uniform(random);
    off.push_back(points.size());
    points.push_back(m_b * body + m_s * light + Vec3(noise(random), noise(random), noise(random)));
  }
  const Line body_line{Vec3::Zero(), body, 0, 1, 3000, 0.003};
  const std::optional<HighlightBranch> b = highlight_branch(points, body_line, off);
  ASSERT_TRUE(b);
  EXPECT_EQ(b->samples, 600u);
  EXPECT_LE(angular_error_deg(b->direction, light), 3 * b->uncertainty_deg);
  // The principal axis of the same colours leans towards the body colour.
  const PrincipalAxes tls = principal_axes_of(points, About::Mean, off);
  EXPECT_GT(angular_error_deg(tls.axes.col(0), light), 3 * b->uncertainty_deg);
  EXPECT_LT(angular_error_deg(tls.axes.col(0), body), angular_error_deg(light, body));
  // Too few samples: no branch.
  EXPECT_FALSE(highlight_branch(points, body_line, {off.begin(), off.begin() + 9}));
}

}  // namespace
}  // namespace ct::test
