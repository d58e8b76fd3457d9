// SPDX-License-Identifier: Apache-2.0
#include "core/render_delta_e.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/statistics.h"

namespace ct {

std::vector<bool> near_emitters(const std::vector<std::int32_t>& ids, int width, int height,
                                const std::function<bool(std::int32_t)>& is_emitter) {
  const auto w = static_cast<std::size_t>(std::max(width, 0)), h = static_cast<std::size_t>(std::max(height, 0));
  std::vector<bool> out(w * h, false);
  if (ids.size() < w * h) return out;
  for (std::size_t y = 0; y < h; ++y)
    for (std::size_t x = 0; x < w; ++x) {
      if (!is_emitter(ids[y * w + x])) continue;
      for (std::size_t yy = y > 0 ? y - 1 : 0; yy <= std::min(h - 1, y + 1); ++yy)
        for (std::size_t xx = x > 0 ? x - 1 : 0; xx <= std::min(w - 1, x + 1); ++xx) out[yy * w + xx] = true;
    }
  return out;
}

Vec3d white_point(const std::vector<Vec3d>& level, const std::vector<bool>& excluded, const WhitePolicy& policy) {
  std::vector<double> ys;
  double brightest = 0;
  for (std::size_t p = 0; p < level.size(); ++p)
    if (excluded.empty() || !excluded[p]) {
      ys.push_back(level[p][1]);
      brightest = std::max(brightest, level[p][1]);
    }
  double y = quantile(std::move(ys), policy.quantile);
  if (!(y > 0)) y = brightest;
  if (!(y > 0)) y = 1;
  Vec3d white = policy.light;
  const double scale = white[1] > 0 ? y / white[1] : 1.0;
  for (double& v : white) v = std::max(v * scale, 1e-300);
  return white;
}

RenderDeltaE delta_e_between(const std::vector<Vec3d>& test, const std::vector<Vec3d>& reference, const Vec3d& white) {
  RenderDeltaE out;
  out.white = white;
  const std::size_t n = std::min(test.size(), reference.size());
  out.per_pixel.resize(n);
  for (std::size_t p = 0; p < n; ++p)
    out.per_pixel[p] = delta_e_2000(xyz_to_lab(test[p], white), xyz_to_lab(reference[p], white));
  const auto& de = out.per_pixel;
  const double count = static_cast<double>(std::max<std::size_t>(n, 1));
  out.mean = std::accumulate(de.begin(), de.end(), 0.0) / count;
  out.max = de.empty() ? 0 : *std::max_element(de.begin(), de.end());
  out.rms = std::sqrt(std::inner_product(de.begin(), de.end(), de.begin(), 0.0) / count);
  out.p95 = quantile(de, 0.95);
  return out;
}

}  // namespace ct
