// SPDX-License-Identifier: Apache-2.0
#include "core/guided.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <stdexcept>
#include <utility>

#include <fmt/core.h>

#include "core/assembly.h"
#include "core/parallel.h"

namespace ct {
namespace {

// The pixels of one object and the rectangle that holds them.
struct ObjectExtent {
  std::int32_t id = 0;
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // [x0, x1) × [y0, y1)
  std::size_t pixels = 0;
};

// 1 for each pixel whose eight neighbours (those in the image) have its object id.
std::vector<std::uint8_t> interior_pixels(const GuidedImage& image) {
  const std::size_t w = static_cast<std::size_t>(image.width);
  std::vector<std::uint8_t> interior(w * static_cast<std::size_t>(image.height), 1);
  if (image.object_ids.empty()) return interior;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if (nx < 0 || ny < 0 || nx >= image.width || ny >= image.height) continue;
          if (image.object_ids[ny * w + nx] != image.object_ids[y * w + x]) interior[y * w + x] = 0;
        }
  return interior;
}

std::vector<ObjectExtent> object_extents(const GuidedImage& image) {
  std::map<std::int32_t, ObjectExtent> found;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const std::int32_t id =
          image.object_ids.empty() ? 0 : image.object_ids[static_cast<std::size_t>(y) * image.width + x];
      auto [it, inserted] = found.try_emplace(id, ObjectExtent{id, x, y, x + 1, y + 1, 0});
      ObjectExtent& e = it->second;
      e.x0 = std::min(e.x0, x), e.y0 = std::min(e.y0, y), e.x1 = std::max(e.x1, x + 1), e.y1 = std::max(e.y1, y + 1);
      ++e.pixels;
    }
  std::vector<ObjectExtent> out;
  for (const auto& [id, e] : found) out.push_back(e);
  return out;
}

// Summed-area tables over an object's rectangle of the guided band t, the guide g, |g| and g², each over the
// object's pixels that are reconstructed; entry (x, y) holds the sums over [x0, x0 + x) × [y0, y0 + y).
struct WindowSums {
  int w = 0, h = 0;
  std::vector<double> t, g, abs_g, g2;

  double at(const std::vector<double>& s, int x, int y) const { return s[static_cast<std::size_t>(y) * (w + 1) + x]; }
  // The sum of `s` over the local rectangle [xa, xb) × [ya, yb).
  double sum(const std::vector<double>& s, int xa, int ya, int xb, int yb) const {
    return at(s, xb, yb) - at(s, xa, yb) - at(s, xb, ya) + at(s, xa, ya);
  }
};

struct Plane {
  const GuidedImage& image;
  const std::vector<float>& layer;
  std::size_t band;
  const std::vector<std::size_t>& guide_bands;

  const std::vector<std::uint8_t>& interior;

  std::size_t index(int x, int y) const { return static_cast<std::size_t>(y) * image.width + x; }
  // Whether a pixel is reconstructed as part of object o: it is o's, and so are its eight neighbours. A pixel
  // on an edge mixes two objects, and keeps its own values: their ratios differ; and even where the colour is a
  // factor apart, Cycles' passes are averages over the pixel's samples, whose product at an edge (where the
  // colour changes from sample to sample) depends on how many samples there were.
  bool on(const ObjectExtent& o, int x, int y) const {
    return interior[index(x, y)] && (image.object_ids.empty() || image.object_ids[index(x, y)] == o.id);
  }
  double t(int x, int y) const { return layer[index(x, y) * image.bands + band]; }
  double g(int x, int y) const {
    double s = 0;
    for (const std::size_t k : guide_bands) s += layer[index(x, y) * image.bands + k];
    return s;
  }
};

WindowSums window_sums(const Plane& plane, const ObjectExtent& o) {
  WindowSums s;
  s.w = o.x1 - o.x0, s.h = o.y1 - o.y0;
  const std::size_t size = static_cast<std::size_t>(s.w + 1) * (s.h + 1);
  s.t.assign(size, 0.0), s.g.assign(size, 0.0), s.abs_g.assign(size, 0.0), s.g2.assign(size, 0.0);
  for (int y = 0; y < s.h; ++y) {
    double row_t = 0, row_g = 0, row_abs_g = 0, row_g2 = 0;
    for (int x = 0; x < s.w; ++x) {
      if (plane.on(o, o.x0 + x, o.y0 + y)) {
        const double g = plane.g(o.x0 + x, o.y0 + y);
        row_t += plane.t(o.x0 + x, o.y0 + y), row_g += g, row_abs_g += std::abs(g), row_g2 += g * g;
      }
      const std::size_t above = static_cast<std::size_t>(y) * (s.w + 1) + x + 1, here = above + (s.w + 1);
      s.t[here] = s.t[above] + row_t, s.g[here] = s.g[above] + row_g;
      s.abs_g[here] = s.abs_g[above] + row_abs_g, s.g2[here] = s.g2[above] + row_g2;
    }
  }
  return s;
}

// The fewest pixels the guide's light in a window must be spread over, as (Σg)² / Σg², for a ratio: a
// highlight of a few pixels gives a ratio as noisy as those pixels and a test with no pixels to stand on.
constexpr double kMinLitPixels = 16;

// The local ratio Σt / Σg, or nothing where the guide gives no stable ratio: no light in the guide, light in
// fewer than kMinLitPixels, or a guide whose values of both signs cancel (Cycles' bounce differences).
std::optional<double> ratio(double sum_t, double sum_g, double sum_abs_g, double sum_g2) {
  if (!(sum_g > 0.0) || sum_g < 0.5 * sum_abs_g || sum_g * sum_g < kMinLitPixels * sum_g2) return std::nullopt;
  return sum_t / sum_g;
}

// Running sums of residuals over one set of pixels. The noise's variance comes from the differences of
// neighbouring residuals (Rice's estimator): a bias that changes slowly from pixel to pixel cancels in them, so
// it shows in the mean without inflating the variance it is measured against; and the noise may differ from
// one part of the object to another (brighter parts are noisier), so each set has its own.
struct Residuals {
  double n = 0, sum = 0;
  double pairs = 0, sum_squared_differences = 0;
  void add(double e) { n += 1, sum += e; }
  void add_pair(double e, double neighbour) { pairs += 1, sum_squared_differences += (e - neighbour) * (e - neighbour); }
  // The mean over its standard error, when there are enough pixels for the normal approximation.
  std::optional<double> z(double min_pixels) const {
    if (n < min_pixels || pairs < min_pixels / 2) return std::nullopt;
    const double variance = sum_squared_differences / (2 * pairs);
    if (!(variance > 0.0)) return std::nullopt;
    return sum / n / std::sqrt(variance / n);
  }
};

// The side of the squares the residuals are tested over, and the fewest pixels a test needs (the normal
// approximation of a mean of path-traced values, which are skewed, needs a few tens).
constexpr int kTestSquare = 8;
constexpr double kMinTestPixels = 32;

struct ObjectResult {
  std::vector<float> reconstructed;  // over the object's rectangle, row-major; NaN where a pixel keeps its value
  double worst_z = 0;
  std::size_t tests = 0;
};

ObjectResult reconstruct_object(const Plane& plane, const ObjectExtent& o, int radius) {
  const WindowSums s = window_sums(plane, o);
  ObjectResult result;
  const std::size_t size = static_cast<std::size_t>(s.w) * s.h;
  result.reconstructed.assign(size, std::nanf(""));
  std::vector<double> residual(size, std::nan(""));
  for (int y = 0; y < s.h; ++y)
    for (int x = 0; x < s.w; ++x) {
      if (!plane.on(o, o.x0 + x, o.y0 + y)) continue;
      const int xa = std::max(0, x - radius), xb = std::min(s.w, x + radius + 1);
      const int ya = std::max(0, y - radius), yb = std::min(s.h, y + radius + 1);
      const double sum_t = s.sum(s.t, xa, ya, xb, yb), sum_g = s.sum(s.g, xa, ya, xb, yb);
      const double sum_abs_g = s.sum(s.abs_g, xa, ya, xb, yb), sum_g2 = s.sum(s.g2, xa, ya, xb, yb);
      const double t = plane.t(o.x0 + x, o.y0 + y), g = plane.g(o.x0 + x, o.y0 + y);
      if (const std::optional<double> r = ratio(sum_t, sum_g, sum_abs_g, sum_g2)) {
        result.reconstructed[static_cast<std::size_t>(y) * s.w + x] = static_cast<float>(g * *r);
        residual[static_cast<std::size_t>(y) * s.w + x] = t - g * *r;
      } else {
        result.reconstructed[static_cast<std::size_t>(y) * s.w + x] = static_cast<float>(t);
      }
    }

  const int squares_x = (s.w + kTestSquare - 1) / kTestSquare, squares_y = (s.h + kTestSquare - 1) / kTestSquare;
  std::vector<Residuals> squares(static_cast<std::size_t>(squares_x) * squares_y);
  Residuals whole;
  for (int y = 0; y < s.h; ++y)
    for (int x = 0; x < s.w; ++x) {
      const double e = residual[static_cast<std::size_t>(y) * s.w + x];
      if (std::isnan(e)) continue;
      Residuals& square = squares[static_cast<std::size_t>(y / kTestSquare) * squares_x + x / kTestSquare];
      whole.add(e), square.add(e);
      for (const auto& [nx, ny] : {std::pair{x + 1, y}, std::pair{x, y + 1}}) {
        if (nx >= s.w || ny >= s.h) continue;
        const double neighbour = residual[static_cast<std::size_t>(ny) * s.w + nx];
        if (std::isnan(neighbour)) continue;
        whole.add_pair(e, neighbour), square.add_pair(e, neighbour);
      }
    }
  const auto test = [&result](const Residuals& set) {
    if (const std::optional<double> z = set.z(kMinTestPixels)) {
      result.worst_z = std::max(result.worst_z, std::abs(*z));
      ++result.tests;
    }
  };
  test(whole);
  for (const Residuals& set : squares) test(set);
  return result;
}

void check_options(const GuidedImage& image, const GuidedOptions& options) {
  if (options.guide_bands.empty()) throw std::invalid_argument("guided reconstruction: no guide band");
  std::vector<bool> used(image.bands, false);
  for (const auto* list : {&options.guide_bands, &options.guided_bands})
    for (const std::size_t b : *list) {
      if (b >= image.bands)
        throw std::invalid_argument(fmt::format("guided reconstruction: band {} of {}", b, image.bands));
      if (used[b]) throw std::invalid_argument(fmt::format("guided reconstruction: band {} given twice", b));
      used[b] = true;
    }
  if (options.radius < 1) throw std::invalid_argument("guided reconstruction: radius below 1");
  if (!image.colours.empty() && image.colours.size() != image.layers.size())
    throw std::invalid_argument("guided reconstruction: colours given for some layers but not one per layer");
  for (std::size_t l = 0; l < image.colours.size(); ++l)
    if (!image.colours[l].empty() && image.colours[l].size() != image.layers[l].size())
      throw std::invalid_argument(fmt::format("guided reconstruction: layer {}'s colour is not its size", l));
  if (!(options.false_refusal > 0.0 && options.false_refusal < 1.0))
    throw std::invalid_argument("guided reconstruction: false_refusal outside (0, 1)");
}

// Makes the families add up to the total again at every pixel and band. The total becomes the sum
// of the first family's members: a total reconstructed by its own ratio would mix components whose ratios
// differ (a white highlight on a yellow body) and be biased where their mixture changes. Each further
// family's residual is spread over its members in proportion to their magnitudes (to the first member where
// all are zero).
void reconcile(GuidedImage& image, const std::vector<SummingFamily>& families) {
  const std::size_t pixels = static_cast<std::size_t>(image.width) * image.height;
  for (std::size_t f = 0; f < families.size(); ++f)
    for (std::size_t p = 0; p < pixels; ++p)
      for (std::size_t b = 0; b < image.bands; ++b) {
        const std::size_t i = p * image.bands + b;
        double sum = 0, magnitude = 0;
        for (const std::size_t m : families[f].members) {
          sum += image.layers[m + 1][i];
          magnitude += std::abs(image.layers[m + 1][i]);
        }
        if (f == 0) {
          image.layers[0][i] = static_cast<float>(sum);
          continue;
        }
        const double residual = image.layers[0][i] - sum;
        for (const std::size_t m : families[f].members) {
          float& v = image.layers[m + 1][i];
          const double share =
              magnitude > 0 ? std::abs(v) / magnitude : (m == families[f].members.front() ? 1.0 : 0.0);
          v = static_cast<float>(v + residual * share);
        }
      }
}

}  // namespace

std::size_t GuidedReport::refused() const {
  return static_cast<std::size_t>(
      std::count_if(verdicts.begin(), verdicts.end(), [](const GuidedVerdict& v) { return v.refused; }));
}

double two_sided_normal_threshold(double p) {
  // erfc(z/√2) = p, by bisection: erfc is monotone, and 200 halvings of [0, 40] reach double precision.
  double lo = 0, hi = 40;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (std::erfc(mid / std::sqrt(2.0)) > p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

GuidedReport reconstruct_guided(GuidedImage& image, const GuidedOptions& options) {
  check_options(image, options);
  const std::vector<ObjectExtent> objects = object_extents(image);
  const std::vector<std::uint8_t> interior = interior_pixels(image);
  const std::vector<SummingFamily> families = summing_families(image.components);
  GuidedReport report;
  // With a family of components that adds up to it, the total is their sum, not reconstructed on its own; and
  // the only member of a further family (one light group) is the total, set by the reconciliation.
  std::vector<bool> reconstructed(image.layers.size(), options.unfactored_layers);
  for (std::size_t l = 0; l < image.colours.size(); ++l)
    if (!image.colours[l].empty()) reconstructed[l] = true;
  reconstructed[0] = reconstructed[0] && families.empty();
  for (std::size_t f = 1; f < families.size(); ++f)
    if (families[f].members.size() == 1) reconstructed[families[f].members.front() + 1] = false;
  for (std::size_t layer = 0; layer < image.layers.size(); ++layer) {
    if (!reconstructed[layer]) continue;
    for (const std::size_t band : options.guided_bands) {
      const Plane plane{image, image.layers[layer], band, options.guide_bands, interior};
      std::vector<ObjectResult> results(objects.size());
      parallel_for(objects.size(), options.threads,
                   [&](std::size_t k) { results[k] = reconstruct_object(plane, objects[k], options.radius); });
      std::size_t tests = 0;
      for (const ObjectResult& r : results) tests += r.tests;
      const double threshold = two_sided_normal_threshold(options.false_refusal / std::max<std::size_t>(1, tests));
      for (std::size_t k = 0; k < objects.size(); ++k) {
        const ObjectExtent& o = objects[k];
        const bool refused = results[k].worst_z > threshold;
        report.verdicts.push_back({layer, band, o.id, refused, results[k].worst_z, threshold, o.pixels});
        if (refused) continue;
        const int w = o.x1 - o.x0;
        for (int y = o.y0; y < o.y1; ++y)
          for (int x = o.x0; x < o.x1; ++x) {
            const float v = results[k].reconstructed[static_cast<std::size_t>(y - o.y0) * w + (x - o.x0)];
            if (!std::isnan(v)) image.layers[layer][plane.index(x, y) * image.bands + band] = v;
          }
      }
    }
  }
  for (std::size_t layer = 0; layer < image.colours.size(); ++layer)
    for (std::size_t i = 0; i < image.colours[layer].size(); ++i) image.layers[layer][i] *= image.colours[layer][i];
  image.colours.clear();
  // Every band, the guides too: a product of light and colour recomputed in float no longer carries the
  // assembly's rounding fix.
  reconcile(image, families);
  return report;
}

}  // namespace ct
