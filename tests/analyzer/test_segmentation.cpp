// SPDX-License-Identifier: Apache-2.0
// Automatic segmentation (analyzer/segmentation.h) on synthetic scenes of known masks: dichromatic spheres
// with shading, highlights and sensor noise, on black and on a shaded wall. Every finding is checked over
// sizes and noise seeds, not on one image.
#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "analyzer/interpretation.h"
#include "analyzer/segmentation.h"
#include "core/file_io.h"
#include "tests/analyzer/synthetic.h"
#include "tests/cli/run_command.h"
#include "tests/core/spectral_exr_fixtures.h"

namespace ct::test {
namespace {

using analyzer::Segmentation;

constexpr int kWall = 5;

// The four spheres (ids 1–4) of `size` pixels each; with a wall, the black background becomes a matte
// grey-blue wall shaded top to bottom (id 5). Noise: shot noise of full_well electrons at 1 and read noise.
Scene spheres(int size, bool wall, double full_well, std::uint32_t seed) {
  Scene scene = dichromatic_scene(Vec3(1, 0.9, 0.75), size);
  const int w = scene.image.width;
  if (wall)
    for (std::size_t p = 0; p < scene.ids.size(); ++p) {
      if (scene.ids[p] != 0) continue;
      const double v = static_cast<double>(p / static_cast<std::size_t>(w)) / w;
      const Vec3 c = (0.25 + 0.3 * v) * Vec3(0.4, 0.45, 0.6);
      for (std::size_t k = 0; k < 3; ++k) scene.image.rgb[p * 3 + k] = static_cast<float>(c[static_cast<Eigen::Index>(k)]);
      scene.ids[p] = kWall;
    }
  if (full_well > 0) scene.image = add_sensor_noise(scene.image, full_well, 3.0, seed);
  return scene;
}

Segmentation segment(const RgbImage& image, const analyzer::SegmentationOptions& options = {}) {
  return analyzer::segment_image(image, std::nullopt, 1.0, 0.0, options);
}

struct Match {
  std::int32_t label = 0;
  double iou = 0;
};

// The segment that best covers object `id`, and its intersection over union with the object's mask.
Match best_segment(const Segmentation& s, const std::vector<std::int32_t>& ids, std::int32_t id) {
  std::map<std::int32_t, std::size_t> overlap, size;
  std::size_t object = 0;
  for (std::size_t p = 0; p < ids.size(); ++p) {
    if (s.labels[p] > 0) ++size[s.labels[p]];
    if (ids[p] != id) continue;
    ++object;
    if (s.labels[p] > 0) ++overlap[s.labels[p]];
  }
  Match m;
  for (const auto& [label, common] : overlap) {
    const double iou = double(common) / double(object + size[label] - common);
    if (iou > m.iou) m = {label, iou};
  }
  return m;
}

// The object's highlight: its pixels whose colour is turned by more than 3° from its body colour (the
// direction of its darkest lit pixels, where no highlight is), in the noise-free scene.
std::vector<std::size_t> highlight_pixels(const Scene& clean, std::int32_t id) {
  std::vector<std::pair<double, std::size_t>> by_brightness;
  for (std::size_t p = 0; p < clean.ids.size(); ++p)
    if (clean.ids[p] == id)
      by_brightness.emplace_back(clean.image.rgb[p * 3] + clean.image.rgb[p * 3 + 1] + clean.image.rgb[p * 3 + 2], p);
  std::sort(by_brightness.begin(), by_brightness.end());
  Vec3 body = Vec3::Zero();
  for (std::size_t k = 0; k < by_brightness.size() / 5; ++k) {
    const std::size_t p = by_brightness[k].second;
    body += Vec3(clean.image.rgb[p * 3], clean.image.rgb[p * 3 + 1], clean.image.rgb[p * 3 + 2]).normalized();
  }
  std::vector<std::size_t> out;
  for (const auto& [b, p] : by_brightness) {
    const Vec3 c(clean.image.rgb[p * 3], clean.image.rgb[p * 3 + 1], clean.image.rgb[p * 3 + 2]);
    if (std::acos(std::clamp(c.normalized().dot(body.normalized()), -1.0, 1.0)) > 3.0 * M_PI / 180) out.push_back(p);
  }
  return out;
}

// The label map of a segmentation of a size × size image scaled to `to` × `to` (nearest pixel).
std::vector<std::int32_t> scaled_mask(const Segmentation& s, std::int32_t label, int to) {
  std::vector<std::int32_t> out(static_cast<std::size_t>(to) * static_cast<std::size_t>(to));
  for (int y = 0; y < to; ++y)
    for (int x = 0; x < to; ++x) {
      const int sx = x * s.width / to, sy = y * s.height / to;
      out[static_cast<std::size_t>(y) * static_cast<std::size_t>(to) + static_cast<std::size_t>(x)] =
          s.labels[static_cast<std::size_t>(sy) * static_cast<std::size_t>(s.width) + static_cast<std::size_t>(sx)] == label;
    }
  return out;
}

double iou(const std::vector<std::int32_t>& a, const std::vector<std::int32_t>& b) {
  std::size_t both = 0, either = 0;
  for (std::size_t p = 0; p < a.size(); ++p) both += a[p] && b[p], either += a[p] || b[p];
  return either ? double(both) / double(either) : 0.0;
}

std::size_t segment_count(const Segmentation& s) {
  return static_cast<std::size_t>(std::count_if(s.regions.begin(), s.regions.end(), [](const analyzer::Region& r) { return r.source == "segment"; }));
}

// Every sphere (and the wall) is one segment holding its highlight, over three sizes (the largest is
// area-averaged to the working size), two noise levels and three noise seeds.
TEST(Segmentation, EveryObjectIsOneSegmentThatKeepsItsHighlight) {
  for (const bool wall : {true, false})
    for (const int size : {96, 192, 384})
      for (const double full_well : {400.0, 4000.0})
        for (const std::uint32_t seed : {1u, 2u, 3u}) {
          SCOPED_TRACE(::testing::Message() << "wall " << wall << ", size " << size << ", full well " << full_well << ", seed " << seed);
          const Scene clean = spheres(size, wall, 0, 0);
          const Scene scene = spheres(size, wall, full_well, seed);
          const Segmentation s = segment(scene.image);
          std::set<std::int32_t> used;
          for (std::int32_t id = 1; id <= (wall ? kWall : 4); ++id) {
            const Match m = best_segment(s, scene.ids, id);
            EXPECT_GE(m.iou, 0.8) << "object " << id;
            EXPECT_TRUE(used.insert(m.label).second) << "object " << id << " shares segment " << m.label;
            if (id == kWall) continue;
            const std::vector<std::size_t> highlight = highlight_pixels(clean, id);
            ASSERT_GT(highlight.size(), 20u);
            const auto kept = std::count_if(highlight.begin(), highlight.end(), [&](std::size_t p) { return s.labels[p] == m.label; });
            EXPECT_GE(double(kept), 0.9 * double(highlight.size())) << "object " << id << ": highlight of " << highlight.size() << " pixels";
          }
          EXPECT_EQ(segment_count(s), wall ? 5u : 4u);
          // The unassigned pixels are counted and are a region of their own: on black, the background.
          std::size_t unassigned = 0;
          for (const std::int32_t l : s.labels) unassigned += l == 0;
          EXPECT_EQ(s.unassigned_pixels, unassigned);
          EXPECT_EQ(s.valid_pixels, s.labels.size());
          if (wall) {
            EXPECT_LT(s.unassigned_fraction(), 0.1);  // the noisiest shadow sides only
          } else {
            // The black background has no colour: all of it is unassigned (and the darkest, noisiest rims of
            // the spheres' shadow sides may be too).
            std::size_t black = 0, black_unassigned = 0;
            for (std::size_t p = 0; p < scene.ids.size(); ++p) black += scene.ids[p] == 0, black_unassigned += scene.ids[p] == 0 && s.labels[p] == 0;
            EXPECT_GE(double(black_unassigned), 0.99 * double(black));
            EXPECT_GE(s.unassigned_fraction(), 0.99 * double(black) / double(scene.ids.size()));
          }
          ASSERT_FALSE(s.regions.empty());
          if (unassigned > 0) {
            EXPECT_EQ(s.regions.back().source, "unassigned");
            EXPECT_EQ(s.regions.back().pixels.size(), unassigned);
          }
        }
}

// The same objects give the same segments at 1×, 2× and 4× size, rendered at each size with its own noise.
TEST(Segmentation, SameSegmentsAtEverySize) {
  for (const std::uint32_t seed : {1u, 2u, 3u}) {
    SCOPED_TRACE(::testing::Message() << "seed " << seed);
    const Scene one = spheres(96, true, 1000, seed);
    const Segmentation s1 = segment(one.image);
    for (const int factor : {2, 4}) {
      SCOPED_TRACE(::testing::Message() << factor << "x");
      const Scene rendered = spheres(96 * factor, true, 1000, seed + 100);
      const Segmentation sk = segment(rendered.image);
      EXPECT_EQ(segment_count(sk), segment_count(s1));
      for (std::int32_t id = 1; id <= kWall; ++id) {
        const Match m1 = best_segment(s1, one.ids, id), mk = best_segment(sk, rendered.ids, id);
        EXPECT_GE(iou(scaled_mask(s1, m1.label, 192 * factor), scaled_mask(sk, mk.label, 192 * factor)), 0.8) << "object " << id;
      }
    }
  }
}

// A copy enlarged by interpolation (what a person does to a photograph) has noise shared between
// neighbouring pixels; from the working size on, the copy and the original give the same segments.
TEST(Segmentation, AnEnlargedCopyGivesTheSameSegments) {
  for (const std::uint32_t seed : {1u, 2u}) {
    SCOPED_TRACE(::testing::Message() << "seed " << seed);
    const Scene one = spheres(384, true, 1000, seed);  // 768 × 768, above the working size
    const int n = one.image.width, to = 2 * n;
    RgbImage enlarged{to, to, std::vector<float>(static_cast<std::size_t>(to) * static_cast<std::size_t>(to) * 3)};
    for (int y = 0; y < to; ++y)
      for (int x = 0; x < to; ++x) {
        const double fx = std::clamp((x + 0.5) / 2 - 0.5, 0.0, n - 1.0), fy = std::clamp((y + 0.5) / 2 - 0.5, 0.0, n - 1.0);
        const int x0 = std::min(n - 2, static_cast<int>(fx)), y0 = std::min(n - 2, static_cast<int>(fy));
        const double ax = fx - x0, ay = fy - y0;
        for (std::size_t k = 0; k < 3; ++k) {
          auto at = [&](int xx, int yy) { return double(one.image.rgb[(static_cast<std::size_t>(yy) * static_cast<std::size_t>(n) + static_cast<std::size_t>(xx)) * 3 + k]); };
          enlarged.rgb[(static_cast<std::size_t>(y) * static_cast<std::size_t>(to) + static_cast<std::size_t>(x)) * 3 + k] = static_cast<float>(
              (1 - ay) * ((1 - ax) * at(x0, y0) + ax * at(x0 + 1, y0)) + ay * ((1 - ax) * at(x0, y0 + 1) + ax * at(x0 + 1, y0 + 1)));
        }
      }
    std::vector<std::int32_t> ids(static_cast<std::size_t>(to) * static_cast<std::size_t>(to));
    for (int y = 0; y < to; ++y)
      for (int x = 0; x < to; ++x) ids[static_cast<std::size_t>(y) * static_cast<std::size_t>(to) + static_cast<std::size_t>(x)] = one.ids[static_cast<std::size_t>(y / 2) * static_cast<std::size_t>(n) + static_cast<std::size_t>(x / 2)];
    const Segmentation s1 = segment(one.image), s2 = segment(enlarged);
    EXPECT_EQ(segment_count(s2), segment_count(s1));
    for (std::int32_t id = 1; id <= kWall; ++id) {
      const Match m1 = best_segment(s1, one.ids, id), m2 = best_segment(s2, ids, id);
      EXPECT_GE(m2.iou, 0.8) << "object " << id;
      EXPECT_GE(iou(scaled_mask(s1, m1.label, to), scaled_mask(s2, m2.label, to)), 0.8) << "object " << id;
    }
  }
}

// The noise is estimated once for the image, from its flat parts: known shot and read noise on a shaded,
// textured surface (a fine stripe pattern of ±20 % that a within-region spread would count as noise) are
// found within 25 %, over seeds.
TEST(Segmentation, NoiseIsTheImagesNotTheTexture) {
  for (const std::uint32_t seed : {1u, 2u, 3u}) {
    const int n = 256;
    RgbImage image{n, n, std::vector<float>(static_cast<std::size_t>(n) * n * 3)};
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        // Left half flat-shaded, right half striped every 2 pixels.
        const double shade = 0.2 + 0.6 * y / double(n), texture = x >= n / 2 ? (((x / 2) % 2) ? 1.2 : 0.8) : 1.0;
        for (std::size_t k = 0; k < 3; ++k)
          image.rgb[(static_cast<std::size_t>(y) * n + static_cast<std::size_t>(x)) * 3 + k] = static_cast<float>(shade * texture * (0.5 + 0.2 * double(k)));
      }
    const double full_well = 2000, read = 5;
    const Segmentation s = segment(add_sensor_noise(image, full_well, read, seed));
    for (const double level : {0.2, 0.5}) {
      const double truth = std::sqrt(read * read + level * full_well) / full_well;
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(s.noise.sigma(c, level), truth, 0.25 * truth) << "seed " << seed << ", level " << level << ", channel " << c;
    }
  }
}

// The same input gives the same labels; segments are numbered by decreasing size.
TEST(Segmentation, DeterministicAndNumberedBySize) {
  const Scene scene = spheres(96, true, 1000, 7);
  const Segmentation a = segment(scene.image), b = segment(scene.image);
  EXPECT_EQ(a.labels, b.labels);
  for (std::size_t k = 1; k < a.regions.size(); ++k)
    if (a.regions[k].source == "segment") {
      EXPECT_GE(a.regions[k - 1].pixels.size(), a.regions[k].pixels.size());
    }
}

// NaN pixels (unreadable, transparent, negative) are in no segment and not counted as valid.
TEST(Segmentation, InvalidPixelsAreNeitherSegmentedNorCounted) {
  Scene scene = spheres(96, true, 1000, 3);
  for (std::size_t p = 0; p < 192 * 20; ++p) scene.image.rgb[p * 3 + 1] = std::nanf("");
  const Segmentation s = segment(scene.image);
  EXPECT_EQ(s.valid_pixels, scene.ids.size() - 192 * 20);
  for (std::size_t p = 0; p < 192 * 20; ++p) ASSERT_EQ(s.labels[p], 0);
  std::size_t in_regions = 0;
  for (const auto& r : s.regions) in_regions += r.pixels.size();
  EXPECT_EQ(in_regions, s.valid_pixels);
}

// analyze --segment writes labels.png (16-bit, 0 = unassigned, k = segment k), which --labels reads back as
// the same regions; analysis.json reports the unassigned fraction; plots for the N largest regions only; the
// same labels with one thread or two.
TEST(SegmentCommand, WritesLabelsThatLabelsReadsBack) {
  TempDir dir;
  write_rgb(dir.file("scene.png"), spheres(96, true, 1000, 5).image, 16);
  const auto out = dir.file("out"), again = dir.file("again"), one_thread = dir.file("one");
  const CommandResult r = run_chromatrace({"analyze", dir.file("scene.png").string(), "-o", out.string(), "--segment", "--plots", "2",
                                           "--no-report", "-q", "--threads", "2", "--input-transfer", "linear"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_TRUE(std::filesystem::is_regular_file(out / "labels.png"));
  const nlohmann::json a = nlohmann::json::parse(read_file(out / "analysis.json"));
  const nlohmann::json& seg = a["segmentation"];
  ASSERT_TRUE(seg.is_object());
  EXPECT_EQ(seg["labels_file"], "labels.png");
  EXPECT_EQ(seg["valid_pixels"], 192 * 192);
  EXPECT_NEAR(seg["unassigned_fraction"].get<double>(), seg["unassigned_pixels"].get<double>() / (192.0 * 192.0), 1e-12);
  std::map<std::int64_t, std::size_t> segments;
  std::size_t unassigned = 0, plotted = 0;
  for (const auto& region : a["regions"]) {
    if (region["source"] == "segment") segments[region["label"].get<std::int64_t>()] = region["pixels"];
    if (region["source"] == "unassigned") unassigned = region["pixels"];
    plotted += !region["files"]["plot"].is_null();
  }
  EXPECT_EQ(segments.size(), 5u);  // four spheres and the wall
  EXPECT_EQ(unassigned, seg["unassigned_pixels"].get<std::size_t>());
  EXPECT_EQ(plotted, 2u);
  std::size_t plot_files = 0;
  for (const auto& f : std::filesystem::directory_iterator(out / "plots")) plot_files += f.path().extension() == ".png";
  EXPECT_EQ(plot_files, 4u);  // the two largest regions, each with its density plot
  // Read back: label k is segment k, with the same pixels.
  const CommandResult back = run_chromatrace({"analyze", dir.file("scene.png").string(), "-o", again.string(), "--labels",
                                              (out / "labels.png").string(), "--no-plots", "--no-report", "-q", "--input-transfer", "linear"});
  ASSERT_EQ(back.exit_code, 0) << back.err;
  const nlohmann::json b = nlohmann::json::parse(read_file(again / "analysis.json"));
  std::map<std::int64_t, std::size_t> labels;
  for (const auto& region : b["regions"])
    if (region["source"] == "labels") labels[region["label"].get<std::int64_t>()] = region["pixels"];
  EXPECT_EQ(labels, segments);
  // Deterministic whatever the thread count.
  const CommandResult single = run_chromatrace({"analyze", dir.file("scene.png").string(), "-o", one_thread.string(), "--segment",
                                                "--no-plots", "--no-report", "-q", "--threads", "1", "--input-transfer", "linear"});
  ASSERT_EQ(single.exit_code, 0) << single.err;
  EXPECT_EQ(read_file(one_thread / "labels.png"), read_file(out / "labels.png"));
}

// Bad parameters: one line naming the option, exit 2.
TEST(SegmentCommand, BadParametersAreOneLineErrorsNamingTheOption) {
  TempDir dir;
  write_rgb(dir.file("scene.png"), spheres(96, true, 0, 0).image, 8);
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--segment-min-area", "0"}, "--segment-min-area"}, {{"--segment-size", "-1"}, "--segment-size"},
      {{"--segment-tolerance", "0"}, "--segment-tolerance"}, {{"--segment-angle", "90"}, "--segment-angle"},
      {{"--segment-dark", "-2"}, "--segment-dark"}, {{"--plots", "some"}, "--plots"}};
  for (const auto& [extra, option] : cases) {
    std::vector<std::string> args{"analyze", dir.file("scene.png").string(), "-o", dir.file("out").string(), "--segment", "-q"};
    args.insert(args.end(), extra.begin(), extra.end());
    const CommandResult r = run_chromatrace(args);
    EXPECT_EQ(r.exit_code, 2) << option;
    EXPECT_NE(r.err.find(option), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
}

// A segment's separate areas (the interpretation's "this segment is N separate areas"): 4-connected parts of at
// least 1 % of its pixels, against a flood fill over random regions of every density, and on shapes whose answer
// is known — a U is one area, a pixel at a row's end and the next row's first are two, a diagonal step is two.
TEST(SeparateAreas, CountsFourConnectedPartsOfAtLeastOnePercent) {
  auto region = [](const std::vector<std::uint8_t>& in) {
    analyzer::Region r;
    for (std::size_t p = 0; p < in.size(); ++p)
      if (in[p]) r.pixels.push_back(static_cast<std::uint32_t>(p));
    return r;
  };
  auto flood = [](std::vector<std::uint8_t> in, int w) {
    const int h = static_cast<int>(in.size()) / w;
    const std::size_t n = static_cast<std::size_t>(std::count(in.begin(), in.end(), 1));
    std::size_t areas = 0;
    for (int start = 0; start < w * h; ++start) {
      if (in[static_cast<std::size_t>(start)] != 1) continue;
      std::vector<int> stack{start};
      in[static_cast<std::size_t>(start)] = 2;
      std::size_t size = 0;
      while (!stack.empty()) {
        const int p = stack.back();
        stack.pop_back();
        ++size;
        const int x = p % w, y = p / w;
        for (const auto& [dx, dy] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
          if (x + dx < 0 || x + dx >= w || y + dy < 0 || y + dy >= h) continue;
          const auto q = static_cast<std::size_t>((y + dy) * w + x + dx);
          if (in[q] == 1) in[q] = 2, stack.push_back(static_cast<int>(q));
        }
      }
      if (static_cast<double>(size) >= 0.01 * static_cast<double>(n)) ++areas;
    }
    return areas;
  };
  std::mt19937 random(7);
  for (const int w : {1, 2, 13, 40})
    for (const double density : {0.2, 0.45, 0.6, 0.9}) {
      std::bernoulli_distribution in(density);
      std::vector<std::uint8_t> pixels(static_cast<std::size_t>(w) * 31);
      for (auto& p : pixels) p = in(random);
      EXPECT_EQ(analyzer::separate_areas(region(pixels), w), flood(pixels, w)) << w << " wide, density " << density;
    }
  const int w = 10;
  std::vector<std::uint8_t> u(100, 0);
  for (int y = 1; y <= 8; ++y) u[static_cast<std::size_t>(y * w + 1)] = u[static_cast<std::size_t>(y * w + 8)] = 1;
  for (int x = 1; x <= 8; ++x) u[static_cast<std::size_t>(8 * w + x)] = 1;
  EXPECT_EQ(analyzer::separate_areas(region(u), w), 1u);
  std::vector<std::uint8_t> wrap(100, 0);
  wrap[9] = wrap[10] = 1;  // (9, 0) and (0, 1): one after the other in memory, not neighbours
  EXPECT_EQ(analyzer::separate_areas(region(wrap), w), 2u);
  std::vector<std::uint8_t> diagonal(100, 0);
  diagonal[11] = diagonal[22] = 1;
  EXPECT_EQ(analyzer::separate_areas(region(diagonal), w), 2u);
  std::vector<std::uint8_t> speck(100 * 100, 0);  // a 10 × 11 block and one pixel apart: under 1 % of 111
  for (int y = 0; y < 11; ++y)
    for (int x = 0; x < 10; ++x) speck[static_cast<std::size_t>(y * 100 + x)] = 1;
  speck[50 * 100 + 50] = 1;
  EXPECT_EQ(analyzer::separate_areas(region(speck), 100), 1u);
}

}  // namespace
}  // namespace ct::test
