// SPDX-License-Identifier: Apache-2.0
#include "analyzer/regions.h"

#include <algorithm>
#include <cmath>
#include <charconv>
#include <numeric>

#include <fmt/core.h>

#include "core/error.h"

namespace ct::analyzer {

Region whole_image_region(int width, int height) {
  Region r{"image", "image", -1, std::vector<std::uint32_t>(static_cast<std::size_t>(width) * static_cast<std::size_t>(height))};
  std::iota(r.pixels.begin(), r.pixels.end(), 0u);
  return r;
}

std::vector<Region> label_regions(const std::vector<std::int32_t>& labels, const std::string& what,
                                  const std::map<std::int32_t, std::string>& names, const std::vector<std::int32_t>& skip) {
  std::map<std::int32_t, std::vector<std::uint32_t>> by_label;
  for (std::size_t i = 0; i < labels.size(); ++i) {
    if (std::find(skip.begin(), skip.end(), labels[i]) != skip.end()) continue;
    by_label[labels[i]].push_back(static_cast<std::uint32_t>(i));
  }
  std::vector<Region> regions;
  for (auto& [label, pixels] : by_label) {
    const auto name = names.find(label);
    regions.push_back({name == names.end() ? fmt::format("{} {}", what, label) : fmt::format("{} {} ({})", what, label, name->second),
                       "labels", label, std::move(pixels)});
  }
  return regions;
}

Region mask_region(const LabelImage& mask, const std::string& name) {
  Region r{name, "mask", -1, {}};
  for (std::size_t i = 0; i < mask.labels.size(); ++i)
    if (mask.labels[i] != 0) r.pixels.push_back(static_cast<std::uint32_t>(i));
  return r;
}

Region rect_region(const Rect& rect, int width, int height) {
  Region r{fmt::format("rect {},{} {}x{}", rect.x, rect.y, rect.width, rect.height), "rect", -1, {}};
  // In 64 bits: x + width may pass INT_MAX (--rect 2147483647,0,10,10).
  const int x0 = std::max(rect.x, 0), y0 = std::max(rect.y, 0);
  const int x1 = static_cast<int>(std::min<long long>(static_cast<long long>(rect.x) + rect.width, width));
  const int y1 = static_cast<int>(std::min<long long>(static_cast<long long>(rect.y) + rect.height, height));
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) r.pixels.push_back(static_cast<std::uint32_t>(y) * static_cast<std::uint32_t>(width) + static_cast<std::uint32_t>(x));
  return r;
}

Rect parse_rect(const std::string& text, const std::string& option) {
  const auto bad = [&] {
    return InputError(fmt::format("{}: expected x,y,width,height (whole numbers within ±2147483647) with width, "
                                  "height >= 0, got \"{}\"",
                                  option, text));
  };
  int fields[4] = {};
  const char* p = text.data();
  const char* const end = text.data() + text.size();
  for (int i = 0; i < 4; ++i) {
    if (i > 0 && (p == end || *p++ != ',')) throw bad();
    const auto [next, error] = std::from_chars(p, end, fields[i]);
    if (error != std::errc()) throw bad();  // not a number, or beyond an int
    p = next;
  }
  const Rect r{fields[0], fields[1], fields[2], fields[3]};
  if (p != end || r.width < 0 || r.height < 0) throw bad();
  return r;
}

RegionSamples gather_samples(const RgbImage& image, const Region& region) {
  RegionSamples s;
  const std::vector<std::uint32_t>& pixels = region.pixels;
  bool consecutive = true;
  for (std::size_t i = 1; i < pixels.size() && consecutive; ++i) consecutive = pixels[i] == pixels[0] + i;
  if (consecutive && !pixels.empty()) {
    const std::span<const float> run(image.rgb.data() + static_cast<std::size_t>(pixels[0]) * 3, pixels.size() * 3);
    if (std::all_of(run.begin(), run.end(), [](float v) { return std::isfinite(v); })) {
      s.rgb = run;
      s.pixels = pixels;
      return s;
    }
  }
  s.own_rgb_.resize(pixels.size() * 3);
  s.own_pixels_.resize(pixels.size());
  std::size_t kept = 0;
  for (const std::uint32_t p : pixels) {
    const float* v = &image.rgb[static_cast<std::size_t>(p) * 3];
    if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) {
      ++s.non_finite;
      continue;
    }
    float* to = &s.own_rgb_[kept * 3];
    to[0] = v[0], to[1] = v[1], to[2] = v[2];
    s.own_pixels_[kept++] = p;
  }
  s.own_rgb_.resize(kept * 3);
  s.own_pixels_.resize(kept);
  s.rgb = s.own_rgb_;
  s.pixels = s.own_pixels_;
  return s;
}

}  // namespace ct::analyzer
