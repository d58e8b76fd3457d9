// SPDX-License-Identifier: Apache-2.0
// Real photographs available on Debian 12 (tests/data/photos/masks.json: files, packages, licences, hand-drawn
// masks of named objects, white references, clipped faces and findings). On each photograph:
//  - every named object is one segment (IoU ≥ 0.8 with its mask) that keeps its highlight, at 1× and in a
//    copy enlarged 2× by interpolation, the two segments the same (IoU ≥ 0.8), and the unassigned fraction
//    reported and consistent with the label map;
//  - a glossy object's highlight branch points to the light's colour measured on a white object of the same
//    photograph, within 3 times the estimate's own standard error;
//  - the chosen illuminant estimate lies within 2 of its standard errors of every white object's colour, or is
//    marked unreliable with the reason; every region's interpretation carries its own numbers; a camera raw's
//    as-shot white balance stands beside each estimate;
//  - an over-exposed object's clipped faces are named with their channels.
// A photograph whose package is not installed is skipped with a message naming the package.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <map>
#include <numeric>

#include <fmt/core.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <tbb/global_control.h>

#include "analyzer/analysis.h"
#include "analyzer/analysis_json.h"
#include "analyzer/illuminant.h"
#include "analyzer/raw_input.h"
#include "tests/analyzer/statement_audit.h"
#include "tests/analyzer/synthetic.h"

namespace ct::test {
namespace {

using analyzer::AnalysisImage;
using analyzer::Segmentation;

// A polygon (corners) or an ellipse, less its holes, in pixels of the file.
struct Shape {
  std::string name;
  std::vector<std::pair<double, double>> polygon;
  std::array<double, 4> ellipse{};  // cx, cy, rx, ry (rx > 0 when an ellipse)
  std::vector<Shape> holes;

  bool contains(double x, double y) const {
    bool inside = false;
    if (ellipse[2] > 0) {
      const double u = (x - ellipse[0]) / ellipse[2], v = (y - ellipse[1]) / ellipse[3];
      inside = u * u + v * v <= 1;
    } else {
      for (std::size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
        const auto [xi, yi] = polygon[i];
        const auto [xj, yj] = polygon[j];
        if ((yi > y) != (yj > y) && x < (xj - xi) * (y - yi) / (yj - yi) + xi) inside = !inside;
      }
    }
    return inside && std::none_of(holes.begin(), holes.end(), [&](const Shape& h) { return h.contains(x, y); });
  }
};

Shape parse_shape(const nlohmann::json& j) {
  Shape s;
  s.name = j.value("name", "");
  if (j.contains("ellipse"))
    for (int k = 0; k < 4; ++k) s.ellipse[static_cast<std::size_t>(k)] = j["ellipse"][static_cast<std::size_t>(k)].get<double>();
  if (j.contains("polygon"))
    for (const auto& xy : j["polygon"]) s.polygon.emplace_back(xy[0].get<double>(), xy[1].get<double>());
  if (j.contains("holes"))
    for (const auto& h : j["holes"]) s.holes.push_back(parse_shape(h));
  return s;
}

struct Photo {
  std::string file, package, kind;
  std::vector<Shape> objects, left_out, references;
  std::vector<std::pair<std::string, std::string>> separate;  // objects that must not share a segment
  std::vector<std::pair<std::string, std::string>> light;  // glossy object, white reference
  std::vector<std::pair<std::string, std::vector<std::string>>> clipped;  // object, faces ("R high")
};

void PrintTo(const Photo& photo, std::ostream* out) { *out << photo.file; }

std::string photo_dir() { return std::string(CHROMATRACE_TEST_DATA) + "/photos"; }

std::vector<Photo> photos() {
  std::ifstream in(photo_dir() + "/masks.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  std::vector<Photo> out;
  for (const auto& p : j["photos"]) {
    Photo photo;
    photo.file = p["file"];
    if (!photo.file.starts_with("/")) photo.file = photo_dir() + "/" + photo.file;
    photo.package = p["package"];
    photo.kind = p.value("kind", "");
    for (const auto& o : p["objects"]) photo.objects.push_back(parse_shape(o));
    for (const auto& o : p.value("left_out", nlohmann::json::array())) photo.left_out.push_back(parse_shape(o));
    for (const auto& pair : p.value("separate", nlohmann::json::array())) photo.separate.emplace_back(pair[0], pair[1]);
    for (const auto& o : p.value("references", nlohmann::json::array())) photo.references.push_back(parse_shape(o));
    // A reference may be a named object's own outline ("same_as").
    for (std::size_t k = 0; k < photo.references.size(); ++k) {
      const auto& o = p["references"][k];
      if (!o.contains("same_as")) continue;
      for (const Shape& object : photo.objects)
        if (object.name == o["same_as"].get<std::string>()) photo.references[k] = object, photo.references[k].name = o["name"];
    }
    for (const auto& l : p.value("light", nlohmann::json::array())) photo.light.emplace_back(l["glossy"], l["white"]);
    for (const auto& c : p.value("clipped", nlohmann::json::array()))
      photo.clipped.emplace_back(c["object"], c["faces"].get<std::vector<std::string>>());
    out.push_back(std::move(photo));
  }
  return out;
}

bool available(const Photo& photo) {
  if (std::filesystem::exists(photo.file)) return true;
  std::cerr << "skipped " << photo.file << ": install the Debian package " << photo.package << "\n";
  return false;
}

// Pixels whose centre lies inside the shape, scaled by `scale`.
std::vector<std::uint8_t> rasterise(const Shape& s, int width, int height, double scale) {
  std::vector<std::uint8_t> mask(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), 0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      mask[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)] = s.contains((x + 0.5) / scale, (y + 0.5) / scale);
  return mask;
}

// An object, left-out object or reference by name.
const Shape& named(const Photo& photo, const std::string& name) {
  for (const auto* list : {&photo.objects, &photo.left_out, &photo.references})
    for (const Shape& s : *list)
      if (s.name == name) return s;
  throw std::runtime_error("masks.json: no shape named " + name);
}

struct Match {
  std::int32_t label = 0;
  double iou = 0;
};

Match best_segment(const Segmentation& s, const std::vector<std::uint8_t>& mask) {
  std::map<std::int32_t, std::size_t> overlap, size;
  std::size_t inside = 0;
  for (std::size_t p = 0; p < mask.size(); ++p) {
    if (s.labels[p] > 0) ++size[s.labels[p]];
    if (!mask[p]) continue;
    ++inside;
    if (s.labels[p] > 0) ++overlap[s.labels[p]];
  }
  Match m;
  for (const auto& [label, common] : overlap) {
    const double iou = double(common) / double(inside + size[label] - common);
    if (iou > m.iou) m = {label, iou};
  }
  return m;
}

struct Segmented {
  Segmentation s;
  std::vector<analyzer::Region> regions;  // the segments, then the unassigned pixels
};

Segmented segment(const AnalysisImage& input) {
  analyzer::RegionOptions options;
  options.segment = true;
  Segmented out;
  out.regions = analyzer::select_regions(input, input.image, options, &out.s);
  out.regions.erase(out.regions.begin());  // the whole image
  return out;
}

// The stored values enlarged 2× by bilinear interpolation (the encoding stays: an 8-bit file's copy holds
// values between its codes, as a resampling program's float output would).
AnalysisImage enlarged(const AnalysisImage& input) {
  AnalysisImage out;
  out.file = input.file;
  out.encoding = input.encoding;
  const int w = 2 * input.image.width, h = 2 * input.image.height;
  out.image = {w, h, std::vector<float>(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 3)};
  const cv::Mat in(input.image.height, input.image.width, CV_32FC3, const_cast<float*>(input.image.rgb.data()));
  cv::Mat big(h, w, CV_32FC3, out.image.rgb.data());
  cv::resize(in, big, big.size(), 0, 0, cv::INTER_LINEAR);
  return out;
}

// The photographs as read and segmented at 1×, read once for all tests.
struct Read {
  AnalysisImage input;
  Segmented segmented;
};
const Read& read(const Photo& photo) {
  static std::map<std::string, Read> cache;
  auto it = cache.find(photo.file);
  if (it == cache.end()) {
    Read r{analyzer::read_analysis_image(photo.file), {}};
    r.segmented = segment(r.input);
    it = cache.emplace(photo.file, std::move(r)).first;
  }
  return it->second;
}

void check_unassigned(const Segmented& segmented) {
  const Segmentation& s = segmented.s;
  std::size_t zero = 0;
  for (const std::int32_t l : s.labels) zero += l == 0;
  // Label 0 holds the unassigned pixels and the invalid ones (non-finite or negative: a few in interior.exr).
  EXPECT_EQ(s.unassigned_pixels + (s.labels.size() - s.valid_pixels), zero);
  EXPECT_EQ(s.unassigned_pixels, s.dark_pixels + s.small_pixels);
  EXPECT_LT(s.unassigned_fraction(), 0.5);  // most of a photograph is in segments
  const auto region = std::find_if(segmented.regions.begin(), segmented.regions.end(), [](const analyzer::Region& r) { return r.source == "unassigned"; });
  ASSERT_EQ(region != segmented.regions.end(), s.unassigned_pixels > 0) << "the unassigned pixels are a region of their own";
  if (region != segmented.regions.end()) {
    EXPECT_EQ(region->pixels.size(), s.unassigned_pixels);
  }
}

std::size_t segment_count(const Segmented& s) {
  return static_cast<std::size_t>(std::count_if(s.regions.begin(), s.regions.end(), [](const analyzer::Region& r) { return r.source == "segment"; }));
}

void check_photo(const Photo& photo) {
  SCOPED_TRACE(photo.file);
  const Read& r = read(photo);
  const Segmented big = segment(enlarged(r.input));
  const Segmentation &s1 = r.segmented.s, &s2 = big.s;
  check_unassigned(r.segmented);
  check_unassigned(big);
  std::cerr << fmt::format("{}: {} segments, {:.1f} % unassigned at 1×; {} segments, {:.1f} % at 2×\n", photo.file,
                           segment_count(r.segmented), 100 * s1.unassigned_fraction(), segment_count(big), 100 * s2.unassigned_fraction());
  std::vector<std::int32_t> used;
  for (const Shape& object : photo.objects) {
    const auto mask1 = rasterise(object, s1.width, s1.height, 1.0), mask2 = rasterise(object, s2.width, s2.height, 2.0);
    const Match m1 = best_segment(s1, mask1), m2 = best_segment(s2, mask2);
    EXPECT_GE(m1.iou, 0.8) << object.name << " at 1×";
    EXPECT_GE(m2.iou, 0.8) << object.name << " at 2×";
    EXPECT_EQ(std::count(used.begin(), used.end(), m1.label), 0) << object.name << " shares a segment";
    used.push_back(m1.label);
    // The same segment at both sizes.
    std::size_t both = 0, either = 0;
    for (int y = 0; y < s2.height; ++y)
      for (int x = 0; x < s2.width; ++x) {
        const bool a = s1.labels[static_cast<std::size_t>(y / 2) * static_cast<std::size_t>(s1.width) + static_cast<std::size_t>(x / 2)] == m1.label;
        const bool b = s2.labels[static_cast<std::size_t>(y) * static_cast<std::size_t>(s2.width) + static_cast<std::size_t>(x)] == m2.label;
        both += a && b, either += a || b;
      }
    const double same = double(both) / double(std::max<std::size_t>(1, either));
    EXPECT_GE(same, 0.8) << object.name << ": 1× and 2× segments differ";
    std::cerr << fmt::format("  {}: IoU {:.3f} at 1×, {:.3f} at 2×, 1× vs 2× {:.3f}\n", object.name, m1.iou, m2.iou, same);
  }
  // Objects left out: their IoU printed, for the reasons masks.json gives.
  for (const Shape& object : photo.left_out) {
    const Match m1 = best_segment(s1, rasterise(object, s1.width, s1.height, 1.0)), m2 = best_segment(s2, rasterise(object, s2.width, s2.height, 2.0));
    std::cerr << fmt::format("  left out: {}: IoU {:.3f} at 1×, {:.3f} at 2×\n", object.name, m1.iou, m2.iou);
  }
  // Objects that must never share a segment (dark, nearly neutral objects apart: a navy jacket and a black hat):
  // the segment that holds most of one holds almost none (under 5 %) of the other, at both sizes.
  for (const auto& [first, second] : photo.separate)
    for (const Segmentation* s : {&s1, &s2}) {
      const double scale = s == &s1 ? 1.0 : 2.0;
      const auto a = rasterise(named(photo, first), s->width, s->height, scale), b = rasterise(named(photo, second), s->width, s->height, scale);
      auto main_label = [&](const std::vector<std::uint8_t>& mask) {
        std::map<std::int32_t, std::size_t> count;
        for (std::size_t p = 0; p < mask.size(); ++p)
          if (mask[p] && s->labels[p] > 0) ++count[s->labels[p]];
        std::int32_t best = 0;
        std::size_t most = 0;
        for (const auto& [label, n] : count)
          if (n > most) most = n, best = label;
        return best;
      };
      auto share = [&](const std::vector<std::uint8_t>& mask, std::int32_t label) {
        std::size_t in = 0, all = 0;
        for (std::size_t p = 0; p < mask.size(); ++p)
          if (mask[p]) ++all, in += s->labels[p] == label;
        return double(in) / double(std::max<std::size_t>(all, 1));
      };
      const std::int32_t la = main_label(a), lb = main_label(b);
      EXPECT_NE(la, lb) << first << " and " << second << " share segment " << la << " at " << scale << "×";
      EXPECT_LT(share(b, la), 0.05) << first << "'s segment holds part of " << second << " at " << scale << "×";
      EXPECT_LT(share(a, lb), 0.05) << second << "'s segment holds part of " << first << " at " << scale << "×";
    }
}

TEST(Photographs, NamedObjectsAreOneSegmentEachAtOneAndTwoTimesTheSize) {
  int checked = 0;
  for (const Photo& photo : photos()) {
    if (!available(photo)) continue;
    check_photo(photo);
    ++checked;
  }
  if (checked == 0) GTEST_SKIP() << "none of the photographs' packages is installed";
}

// The test set covers what the issue asks for: at least six photographs, among them 8-bit sRGB, JPEG, 16-bit,
// linear HDR, glossy objects with highlights, clipping and coloured light.
TEST(Photographs, TheSetCoversTheKindsOfPicturesPeopleBring) {
  const std::vector<Photo> all = photos();
  EXPECT_GE(all.size(), 6u);
  auto count = [&](const std::string& word) {
    return std::count_if(all.begin(), all.end(), [&](const Photo& p) { return p.kind.find(word) != std::string::npos; });
  };
  for (const char* kind : {"8-bit sRGB", "JPEG", "16-bit", "linear HDR", "glossy", "clipped", "warm"}) EXPECT_GE(count(kind), 1) << kind;
  EXPECT_GE(std::count_if(all.begin(), all.end(), [](const Photo& p) { return !p.light.empty(); }), 1);
  EXPECT_GE(std::count_if(all.begin(), all.end(), [](const Photo& p) { return !p.clipped.empty(); }), 1);
}

// The segment that holds a named object, analysed as `analyze --segment` would (in linear light for an
// encoded file).
struct Analysed {
  analyzer::Region region;
  analyzer::ImageAnalysis analysis;
  const analyzer::ClusterShape& light_shape() const {
    const analyzer::RegionAnalysis& r = analysis.results.front();
    return r.linear_light ? *r.linear_light : r.shape;
  }
};
Analysed analyse_object(const Photo& photo, const std::string& name) {
  const Read& r = read(photo);
  const Segmentation& s = r.segmented.s;
  // An object the segmentation cannot make one segment (left_out) is analysed on its mask.
  if (std::any_of(photo.left_out.begin(), photo.left_out.end(), [&](const Shape& o) { return o.name == name; })) {
    const auto mask = rasterise(named(photo, name), s.width, s.height, 1.0);
    analyzer::Region region{"mask " + name, "mask", -1, {}};
    for (std::size_t p = 0; p < mask.size(); ++p)
      if (mask[p]) region.pixels.push_back(static_cast<std::uint32_t>(p));
    Analysed a{region, {}};
    a.analysis = analyzer::analyse_image(r.input, "", {region}, analyzer::AnalyzeOptions{}, std::nullopt, false);
    return a;
  }
  const Match m = best_segment(s, rasterise(named(photo, name), s.width, s.height, 1.0));
  const auto it = std::find_if(r.segmented.regions.begin(), r.segmented.regions.end(), [&](const analyzer::Region& g) { return g.source == "segment" && g.label == m.label; });
  if (it == r.segmented.regions.end()) throw std::runtime_error("no segment for " + name);
  Analysed a{*it, {}};
  a.analysis = analyzer::analyse_image(r.input, "", {*it}, analyzer::AnalyzeOptions{}, std::nullopt, false);
  return a;
}

// The light's colour measured on a white or grey object: the mean linear colour of its pixels below every
// clipping level.
Vec3 measured_light(const Photo& photo, const std::string& reference) {
  const Read& r = read(photo);
  const analyzer::RgbImage linear = analyzer::linear_light(r.input);
  const auto mask = rasterise(named(photo, reference), linear.width, linear.height, 1.0);
  const auto clip = r.input.encoding.integer ? r.input.encoding.clipping_level().value_or(r.input.encoding.full_scale) : std::numeric_limits<double>::infinity();
  Vec3 sum = Vec3::Zero();
  std::size_t n = 0;
  for (std::size_t p = 0; p < mask.size(); ++p) {
    if (!mask[p]) continue;
    const float* stored = &r.input.image.rgb[p * 3];
    if (!std::isfinite(stored[0] + stored[1] + stored[2]) || std::max({stored[0], stored[1], stored[2]}) >= clip) continue;
    sum += Vec3(linear.rgb[p * 3], linear.rgb[p * 3 + 1], linear.rgb[p * 3 + 2]);
    ++n;
  }
  EXPECT_GT(n, 100u) << reference << ": too few unclipped pixels";
  return sum / double(std::max<std::size_t>(n, 1));
}

// The segmentation runs on every core; its labels are the same on one (bands of rows add in a fixed order).
TEST(Photographs, LabelsDoNotDependOnTheThreadCount) {
  int checked = 0;
  for (const Photo& photo : photos()) {
    if (!available(photo) || photo.file.ends_with(".CR2")) continue;  // the 16-bit raw file is slow to read twice
    const Read& r = read(photo);
    Segmented one;
    {
      tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
      one = segment(r.input);
    }
    EXPECT_EQ(one.s.labels, r.segmented.s.labels) << photo.file;
    ++checked;
  }
  if (checked == 0) GTEST_SKIP() << "none of the photographs' packages is installed";
}

// A glossy object's highlight adds the light's colour: the highlight branch of its segment's cluster (in linear
// light; its mask's when the segmentation leaves it out) points to the colour of a white object lit by the same
// light, within 3 standard errors of the highlight-line estimate (its uncertainty_deg: the branch's regression, its
// spread and its two halves' agreement, analyzer/highlight_branch.h) and within 3°.
// Where the analysis finds no highlight branch (the cluster is not classed L, skewed-T or P, or its highlight
// line runs into a clipping level), nothing can be compared: the test says so and skips that object.
TEST(Photographs, AGlossyObjectsHighlightBranchPointsToTheLightsColour) {
  int checked = 0;
  std::string missing;
  for (const Photo& photo : photos()) {
    if (photo.light.empty() || !available(photo)) continue;
    for (const auto& [glossy, white] : photo.light) {
      SCOPED_TRACE(photo.file + ": " + glossy);
      const Analysed a = analyse_object(photo, glossy);
      const analyzer::ClusterShape& shape = a.light_shape();
      const Vec3 light = measured_light(photo, white).normalized();
      const auto& estimate = a.analysis.illuminant.highlight_lines;
      if (!estimate || !estimate->uncertainty_deg) {
        missing += fmt::format("{}: {} is classed {} in linear light ({}); {} — the light, measured on {}, is ({:.3f}, {:.3f}, {:.3f}). ",
                               photo.file, glossy, analyzer::class_name(shape.shape), shape.reason,
                               a.analysis.illuminant.notes.empty() ? "" : a.analysis.illuminant.notes.front(), white, light[0], light[1], light[2]);
        continue;
      }
      const double angle = analyzer::angular_error_deg(estimate->rgb, light);
      std::cerr << fmt::format("{}: {} ({}), highlight branch ({:.3f}, {:.3f}, {:.3f}), {} ({:.3f}, {:.3f}, {:.3f}): {:.2f}° apart, "
                               "uncertainty {:.2f}°\n", photo.file, glossy, analyzer::class_name(shape.shape), estimate->rgb[0],
                               estimate->rgb[1], estimate->rgb[2], white, light[0], light[1], light[2], angle, *estimate->uncertainty_deg);
      EXPECT_LE(angle, 3 * *estimate->uncertainty_deg);
      EXPECT_LE(angle, 3.0) << "the highlight branch is more than 3° from the white object's colour";
      ++checked;
    }
  }
  if (checked == 0) GTEST_SKIP() << "no highlight branch to compare: " << missing;
}

// With a glossy object's highlight branch among the regions (its segment, or its mask when the segmentation leaves
// it out) beside the photograph's segments, the chosen estimate lies within 2 of its own standard errors of the white
// object's colour (a 2-D direction error lies within 2σ with probability 1 − e⁻² ≈ 86 %; within 1σ only 39 %).
TEST(Photographs, TheChosenEstimateBesideAHighlightBranchIsWithinItsUncertaintyOfTheWhiteObject) {
  int checked = 0;
  for (const Photo& photo : photos()) {
    if (photo.light.empty() || !available(photo)) continue;
    for (const auto& [glossy, white] : photo.light) {
      SCOPED_TRACE(photo.file + ": " + glossy);
      const Read& r = read(photo);
      std::vector<analyzer::Region> regions = r.segmented.regions;
      regions.push_back(analyse_object(photo, glossy).region);
      if (regions.back().source == "segment") regions.pop_back();
      const analyzer::ImageAnalysis a = analyzer::analyse_image(r.input, "", regions, analyzer::AnalyzeOptions{}, std::nullopt, false);
      const analyzer::IlluminantEstimate& chosen = a.illuminant.best();
      if (!chosen.reliable || !chosen.uncertainty_deg) continue;
      const double angle = analyzer::angular_error_deg(chosen.rgb, measured_light(photo, white));
      std::cerr << fmt::format("{}: chosen {} ({:.3f}, {:.3f}, {:.3f}) ± {:.2f}°, {:.2f}° from {}\n", photo.file, chosen.method,
                               chosen.rgb[0], chosen.rgb[1], chosen.rgb[2], *chosen.uncertainty_deg, angle, white);
      EXPECT_LE(angle, 2 * *chosen.uncertainty_deg) << a.illuminant.choice;
      ++checked;
    }
  }
  if (checked == 0) GTEST_SKIP() << "no reliable estimate beside a highlight branch";
}

// An over-exposed object's segment names its clipped faces: the channels and the end (high, low) they are
// clipped at, exactly those a person sees on the picture.
TEST(Photographs, ClippedFacesAreNamedWithTheirChannels) {
  int checked = 0;
  for (const Photo& photo : photos()) {
    if (photo.clipped.empty() || !available(photo)) continue;
    for (const auto& [object, faces] : photo.clipped) {
      SCOPED_TRACE(photo.file + ": " + object);
      const Analysed a = analyse_object(photo, object);
      std::vector<std::string> found;
      for (const analyzer::ClippedFace& f : a.analysis.results.front().shape.clipping.faces)
        if (f.high) found.push_back(fmt::format("{} high", "RGB"[f.channel]));
      std::vector<std::string> expected = faces;
      std::sort(found.begin(), found.end());
      std::sort(expected.begin(), expected.end());
      EXPECT_EQ(found, expected);
      ++checked;
    }
  }
  if (checked == 0) GTEST_SKIP() << "none of the photographs' packages is installed";
}

// White cloth, plates, glass and the flames return the light's colour unchanged, so the segmentation, which groups
// by colour direction, joins them: the segment holding most of a white reference says its colour is the light's and
// that it may hold several objects — measured against the light of a glossy object's highlight branch (its segment,
// or its mask when it is left out), where that is known to within 3°.
TEST(Photographs, ASegmentOfTheLightsColourSaysItMayHoldSeveralObjects) {
  int checked = 0;
  std::string missing;
  for (const Photo& photo : photos()) {
    if (photo.light.empty() || !available(photo)) continue;
    for (const auto& [glossy, white] : photo.light) {
      SCOPED_TRACE(photo.file + ": " + white);
      const Read& r = read(photo);
      const Segmentation& s = r.segmented.s;
      std::vector<analyzer::Region> regions = r.segmented.regions;
      regions.push_back(analyse_object(photo, glossy).region);
      if (regions.back().source == "segment") regions.pop_back();
      const analyzer::ImageAnalysis a = analyzer::analyse_image(r.input, "", regions, analyzer::AnalyzeOptions{}, std::nullopt, false);
      const auto& lines = a.illuminant.highlight_lines;
      if (!lines || !lines->reliable || !lines->uncertainty_deg || *lines->uncertainty_deg > 3) {
        missing += fmt::format("{}: no highlight branch known to 3°. ", photo.file);
        continue;
      }
      const Match m = best_segment(s, rasterise(named(photo, white), s.width, s.height, 1.0));
      for (std::size_t i = 0; i < a.regions.size(); ++i) {
        if (a.regions[i].source != "segment" || a.regions[i].label != m.label) continue;
        const analyzer::Interpretation& in = a.interpretations[i];
        const bool says = std::any_of(in.findings.begin(), in.findings.end(), [](const analyzer::Statement& f) {
          return f.kind == "light_coloured" && f.text.find("the light itself") != std::string::npos && f.text.find("several of them") != std::string::npos;
        });
        EXPECT_TRUE(says) << a.regions[i].name << ": " << analyzer::interpretation_text(in);
        std::cerr << fmt::format("{}: {} (IoU {:.2f} with {}): {}\n", photo.file, a.regions[i].name, m.iou, white,
                                 analyzer::interpretation_text(in));
        ++checked;
      }
    }
  }
  if (checked == 0) GTEST_SKIP() << missing;
}

// Each photograph analysed whole, as `analyze --segment` does: the image, its segments and the unassigned pixels.
const analyzer::ImageAnalysis& analysed(const Photo& photo) {
  static std::map<std::string, analyzer::ImageAnalysis> cache;
  auto it = cache.find(photo.file);
  if (it == cache.end()) {
    const Read& r = read(photo);
    std::vector<analyzer::Region> regions{analyzer::Region{"image", "image", -1, {}}};
    regions.front().pixels.resize(r.input.image.pixel_count());
    std::iota(regions.front().pixels.begin(), regions.front().pixels.end(), 0u);
    for (const analyzer::Region& g : r.segmented.regions) regions.push_back(g);
    it = cache.emplace(photo.file, analyzer::analyse_image(r.input, "", std::move(regions), analyzer::AnalyzeOptions{}, std::nullopt, false)).first;
  }
  return it->second;
}

std::string test_name(const Photo& photo) {
  std::string name = std::filesystem::path(photo.file).stem().string();
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return name;
}

class EachPhotograph : public ::testing::TestWithParam<Photo> {};

// The chosen illuminant estimate lies within 2 of its own standard errors of the colour of every white or grey
// object in view, measured on that object's unclipped pixels; or the analysis marks it unreliable and says why
// (grey world, a guess, is never reliable). Each estimate's numbers are printed beside the object's.
TEST_P(EachPhotograph, TheChosenIlluminantIsWithinTwoSigmaOfEachWhiteObjectOrMarkedUnreliable) {
  const Photo& photo = GetParam();
  if (photo.references.empty()) GTEST_SKIP() << photo.file << ": no white or grey object in view";
  if (!available(photo)) GTEST_SKIP() << "install the Debian package " << photo.package;
  const analyzer::IlluminantAnalysis& il = analysed(photo).illuminant;
  const analyzer::IlluminantEstimate& chosen = il.best();
  for (const Shape& white : photo.references) {
    const Vec3 light = measured_light(photo, white.name).normalized();
    for (const auto* e : {il.planes ? &*il.planes : nullptr, il.highlight_lines ? &*il.highlight_lines : nullptr, &il.grey_world}) {
      if (!e) continue;
      std::cerr << fmt::format("{}: {} ({:.3f}, {:.3f}, {:.3f}) {:.2f}° from {} ({:.3f}, {:.3f}, {:.3f}); σ {}; {}{}\n", photo.file,
                                 e->method, e->rgb[0], e->rgb[1], e->rgb[2], analyzer::angular_error_deg(e->rgb, light), white.name,
                                 light[0], light[1], light[2], e->uncertainty_deg ? fmt::format("{:.2f}°", *e->uncertainty_deg) : "none",
                                 e->reliable ? "reliable" : "unreliable: " + e->unreliable_reason, e == &chosen ? " (chosen)" : "");
    }
    if (chosen.reliable) {
      ASSERT_TRUE(chosen.uncertainty_deg) << chosen.method << " is reliable but states no uncertainty";
      EXPECT_LE(analyzer::angular_error_deg(chosen.rgb, light), 2 * *chosen.uncertainty_deg) << chosen.method << " against " << white.name;
    } else {
      EXPECT_FALSE(chosen.unreliable_reason.empty()) << chosen.method << " is unreliable without a reason";
    }
  }
}

// Every region's written interpretation carries the region's own numbers: read back from analysis.json, each
// equals what the region's shape (in linear light, when a curve encoded the file) and the chosen illuminant give,
// and the text quotes them.
TEST_P(EachPhotograph, EachRegionsInterpretationCarriesItsOwnNumbers) {
  const Photo& photo = GetParam();
  if (!available(photo)) GTEST_SKIP() << "install the Debian package " << photo.package;
  const analyzer::ImageAnalysis& a = analysed(photo);
  const nlohmann::json j = nlohmann::json::parse(analyzer::analysis_to_json(a).dump());
  const Vec3 chosen = a.illuminant.best().rgb.normalized();
  auto vec = [](const nlohmann::json& v) { return Vec3(v[0].get<double>(), v[1].get<double>(), v[2].get<double>()); };
  ASSERT_EQ(j["regions"].size(), a.results.size());
  for (std::size_t i = 0; i < a.results.size(); ++i) {
    const nlohmann::json& region = j["regions"][i];
    SCOPED_TRACE(region["name"].get<std::string>());
    const nlohmann::json& in = region["interpretation"];
    ASSERT_TRUE(in.is_object());
    const nlohmann::json& shape = region["linear_light"].is_object() ? region["linear_light"] : region["shape"];
    const std::string text = in["text"];
    EXPECT_EQ(in["class_in_linear_light"], shape["class"]);
    EXPECT_EQ(in["class_as_stored"], region["shape"]["class"]);
    EXPECT_TRUE(text.starts_with(shape["class"].get<std::string>() + " in linear light")) << text;
    EXPECT_DOUBLE_EQ(in["clipped_fraction"].get<double>(), region["shape"]["clipping"]["fraction"].get<double>());
    if (shape["samples"].get<std::size_t>() == 0) continue;
    ASSERT_FALSE(in["light_colour"].is_null());
    EXPECT_LT(analyzer::angular_error_deg(vec(in["light_colour"]), chosen), 1e-5);
    if (!in["body_colour"].is_null()) {
      const double angle = analyzer::angular_error_deg(vec(in["body_colour"]), chosen);
      EXPECT_NEAR(in["body_light_angle_deg"].get<double>(), angle, 1e-5);
      EXPECT_NE(text.find(fmt::format("{:.1f}° from the light's colour", angle)), std::string::npos) << text;
    }
    // A clipped cluster is read on its samples off the faces.
    const nlohmann::json& read = shape["class"] == "clipped" && shape.contains("unclipped") ? shape["unclipped"] : shape;
    if (read.contains("thickness_over_noise") && !in["thickness_over_noise"].is_null()) {
      EXPECT_NEAR(in["thickness_over_noise"].get<double>(), read["thickness_over_noise"].get<double>(), 1e-9);
      EXPECT_NE(text.find(fmt::format("{:.1f} × as thick as its noise", read["thickness_over_noise"].get<double>())), std::string::npos) << text;
    }
    if (!in["highlight_direction"].is_null()) {
      const nlohmann::json& branch = read["highlight_branch"];
      const Vec3 expected = branch.is_object() ? vec(branch["direction"]) : vec(read["two_lines"]["highlight"]["direction"]);
      EXPECT_LT(analyzer::angular_error_deg(vec(in["highlight_direction"]), expected), 1e-5);  // acos near 1: ~1e-7°
      EXPECT_NEAR(in["highlight_light_angle_deg"].get<double>(), analyzer::angular_error_deg(expected, chosen), 1e-5);
    }
    // A highlight branch read below a clipping level says its brightest part is cut.
    const auto& all_faces = region["shape"]["clipping"]["faces"];
    const bool cut = std::any_of(all_faces.begin(), all_faces.end(), [](const nlohmann::json& f) { return f["side"] == "high"; });
    if (!in["highlight_direction"].is_null()) {
      EXPECT_EQ(text.find("its brightest part is clipped") != std::string::npos, cut) << text;
    }
    // Faces only at black, under half of the cluster: its class is that of the pixels off them, and it says so; a
    // segment with at least half of it there may hold several dark objects, and says why.
    const bool at_black_only = !all_faces.empty() && !cut;
    const bool read_off_faces = text.find("its class is that of the pixels off the faces") != std::string::npos;
    EXPECT_EQ(read_off_faces, at_black_only && region["shape"]["clipping"]["fraction"].get<double>() >= j["criteria"]["clipped_fraction"].get<double>() &&
                                  region["shape"]["class"] != "clipped" && shape["class"] != "clipped") << text;
    if (read_off_faces) {  // and the class says so itself
      EXPECT_NE(shape["reason"].get<std::string>().find("samples off the faces"), std::string::npos) << shape["reason"];
    }
    EXPECT_EQ(text.find("a segment of such pixels may hold several") != std::string::npos,
              at_black_only && region["source"] == "segment" &&
                  region["shape"]["clipping"]["fraction"].get<double>() >= j["criteria"]["black_faces_fraction"].get<double>()) << text;
    for (const auto& face : region["shape"]["clipping"]["faces"]) {
      EXPECT_NE(text.find(fmt::format("{} {} at {:.4g}", face["channel"].get<std::string>(), face["side"].get<std::string>(),
                                      face["level"].get<double>())), std::string::npos) << text;
    }
    if (const nlohmann::json& g = region["gamma_against_declared"]; !g.is_null()) {
      if (g["measured"].get<bool>()) {
        EXPECT_NEAR(in["fitted_gamma"].get<double>(), g["fitted_gamma"].get<double>(), 1e-12);
      } else {  // a fit at the end of its range, or one whose uncertainty reaches past it, is no γ
        EXPECT_TRUE(in["fitted_gamma"].is_null());
        EXPECT_NE(text.find("do not measure γ: " + g["not_measured"].get<std::string>()), std::string::npos) << text;
      }
    }
  }
}

// Every sentence of every region's interpretation is true: its premises, recomputed from analysis.json and the
// region's pixels by the statement audit (statement_audit.h), hold; the sentences the numbers call for are there;
// no colour or direction is quoted with a negative component.
TEST_P(EachPhotograph, EverySentenceOfTheInterpretationsIsTrue) {
  const Photo& photo = GetParam();
  if (!available(photo)) GTEST_SKIP() << "install the Debian package " << photo.package;
  const analyzer::ImageAnalysis& a = analysed(photo);
  const analyzer::RgbImage& layer = analyzer::select_layer(read(photo).input, a.layer);
  const nlohmann::json j = nlohmann::json::parse(analyzer::analysis_to_json(a).dump());
  const std::vector<std::string> wrong = audit_statements(j, [&](std::size_t r) {
    std::vector<float> rgb;
    for (const std::uint32_t p : a.regions[r].pixels) {
      const float* v = &layer.rgb[static_cast<std::size_t>(p) * 3];
      if (std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2])) rgb.insert(rgb.end(), v, v + 3);
    }
    return rgb;
  });
  for (const std::string& w : wrong) ADD_FAILURE() << photo.file << ": " << w;
  std::size_t statements = 0;
  for (const auto& region : j["regions"]) statements += region["interpretation"]["statements"].size();
  std::cerr << fmt::format("{}: {} regions, {} statements audited, {} false\n", photo.file, j["regions"].size(), statements, wrong.size());
}

// A camera raw carries the camera's as-shot white balance: the analysis gives it as a reference, with each
// estimate's angle from it. A Bayer sensor's green is its most sensitive channel, so the light a white balance
// assumes is greenest in camera RGB.
TEST_P(EachPhotograph, ACameraRawsAsShotWhiteBalanceStandsBesideEachEstimate) {
  const Photo& photo = GetParam();
  if (!analyzer::is_camera_raw(photo.file)) GTEST_SKIP() << photo.file << " is no camera raw";
  if (!available(photo)) GTEST_SKIP() << "install the Debian package " << photo.package;
  const analyzer::IlluminantAnalysis& il = analysed(photo).illuminant;
  ASSERT_TRUE(il.camera_white);
  const Vec3 w = *il.camera_white;
  EXPECT_GT(w[1], w[0]);
  EXPECT_GT(w[1], w[2]);
  for (const auto* e : {il.planes ? &*il.planes : nullptr, il.highlight_lines ? &*il.highlight_lines : nullptr, &il.grey_world}) {
    if (!e) continue;
    {
      ASSERT_TRUE(e->camera_angle_deg) << e->method;
      EXPECT_NEAR(*e->camera_angle_deg, analyzer::angular_error_deg(e->rgb, w), 1e-9);
      std::cerr << fmt::format("{}: {} {:.2f}° from the camera's white balance ({:.3f}, {:.3f}, {:.3f})\n", photo.file, e->method,
                               *e->camera_angle_deg, w[0], w[1], w[2]);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Photographs, EachPhotograph, ::testing::ValuesIn(photos()),
                         [](const ::testing::TestParamInfo<Photo>& info) { return test_name(info.param); });

}  // namespace
}  // namespace ct::test
