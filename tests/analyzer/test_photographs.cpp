// Segmentation of real photographs shipped by Debian 12 packages (tests/data/photos/masks.json: files,
// packages, licences, and hand-drawn polygon masks of named objects). Each named object must be one segment
// (IoU ≥ 0.8 with its mask), at 1× and in a copy enlarged 2× by interpolation. A photograph whose package is
// not installed is skipped with a message naming it.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <map>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "analyzer/analysis.h"
#include "tests/analyzer/synthetic.h"

namespace ct::test {
namespace {

using analyzer::AnalysisImage;
using analyzer::Segmentation;

struct NamedMask {
  std::string name;
  std::vector<std::pair<double, double>> polygon;
};

struct Photo {
  std::string file, package;
  std::vector<NamedMask> objects;
};

std::vector<Photo> photos() {
  std::ifstream in(std::string(CHROMATRACE_TEST_DATA) + "/photos/masks.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  std::vector<Photo> out;
  for (const auto& p : j["photos"]) {
    Photo photo{p["file"], p["package"], {}};
    for (const auto& o : p["objects"]) {
      NamedMask m{o["name"], {}};
      for (const auto& xy : o["polygon"]) m.polygon.emplace_back(xy[0].get<double>(), xy[1].get<double>());
      photo.objects.push_back(std::move(m));
    }
    out.push_back(std::move(photo));
  }
  return out;
}

// Pixels whose centre lies inside the polygon (even-odd rule), with the polygon scaled by `scale`.
std::vector<std::uint8_t> rasterise(const NamedMask& m, int width, int height, double scale) {
  std::vector<std::uint8_t> mask(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), 0);
  const auto& poly = m.polygon;
  for (int y = 0; y < height; ++y) {
    const double py = (y + 0.5) / scale;
    for (int x = 0; x < width; ++x) {
      const double px = (x + 0.5) / scale;
      bool inside = false;
      for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
        const auto [xi, yi] = poly[i];
        const auto [xj, yj] = poly[j];
        if ((yi > py) != (yj > py) && px < (xj - xi) * (py - yi) / (yj - yi) + xi) inside = !inside;
      }
      mask[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)] = inside;
    }
  }
  return mask;
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

Segmentation segment(const AnalysisImage& input) {
  analyzer::RegionOptions options;
  options.segment = true;
  Segmentation s;
  analyzer::select_regions(input, input.image, options, &s);
  return s;
}

// The stored values enlarged 2× by bilinear interpolation (the encoding stays: an 8-bit file's copy holds
// values between its codes, as a resampling program's float output would).
AnalysisImage enlarged(const AnalysisImage& input) {
  AnalysisImage out = input;
  cv::Mat in(input.image.height, input.image.width, CV_32FC3, const_cast<float*>(input.image.rgb.data()));
  cv::Mat big;
  cv::resize(in, big, cv::Size(2 * input.image.width, 2 * input.image.height), 0, 0, cv::INTER_LINEAR);
  out.image = {big.cols, big.rows, std::vector<float>(reinterpret_cast<float*>(big.data), reinterpret_cast<float*>(big.data) + big.total() * 3)};
  return out;
}

void check_photo(const Photo& photo, const AnalysisImage& input, const std::string& what) {
  SCOPED_TRACE(photo.file + " (" + what + ")");
  const Segmentation s1 = segment(input);
  const Segmentation s2 = segment(enlarged(input));
  EXPECT_GT(s1.valid_pixels, 0u);
  EXPECT_GE(s1.unassigned_fraction(), 0.0);
  EXPECT_LT(s1.unassigned_fraction(), 0.5);  // reported; most of a photograph is in segments
  std::vector<std::int32_t> used;
  for (const NamedMask& object : photo.objects) {
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
    EXPECT_GE(double(both) / double(std::max<std::size_t>(1, either)), 0.8) << object.name << ": 1× and 2× segments differ";
    std::cerr << what << ", " << object.name << ": IoU " << m1.iou << " at 1×, " << m2.iou << " at 2×\n";
  }
}

TEST(Photographs, NamedObjectsAreOneSegmentEachAtOneAndTwoTimesTheSize) {
  int checked = 0;
  for (const Photo& photo : photos()) {
    if (!std::filesystem::exists(photo.file)) {
      std::cerr << "skipped " << photo.file << ": install the Debian package " << photo.package << "\n";
      continue;
    }
    check_photo(photo, analyzer::read_analysis_image(photo.file), "as shipped");
    ++checked;
  }
  if (checked == 0) GTEST_SKIP() << "none of the photographs' packages is installed";
}

}  // namespace
}  // namespace ct::test
