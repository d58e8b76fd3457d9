#include "analyzer/noise_level.h"

#include <algorithm>
#include <cmath>

namespace ct::analyzer {

std::vector<float> neighbour_differences(const RgbImage& image, const RegionSamples& samples, std::size_t max_pairs) {
  std::vector<std::uint8_t> inside(image.pixel_count(), 0);
  for (const std::uint32_t p : samples.pixels) inside[p] = 1;
  const auto w = static_cast<std::size_t>(image.width);
  // Each sample has up to two pairs (right, down); a stride keeps the count bounded on huge regions.
  const std::size_t stride = std::max<std::size_t>(1, 2 * samples.pixels.size() / std::max<std::size_t>(1, max_pairs));
  std::vector<float> d;
  auto add = [&](std::size_t a, std::size_t b) {
    for (std::size_t c = 0; c < 3; ++c) d.push_back(image.rgb[b * 3 + c] - image.rgb[a * 3 + c]);
  };
  for (std::size_t i = 0; i < samples.pixels.size(); i += stride) {
    const std::size_t p = samples.pixels[i];
    if ((p + 1) % w != 0 && inside[p + 1]) add(p, p + 1);
    if (p + w < inside.size() && inside[p + w]) add(p, p + w);
  }
  return d;
}

double noise_sigma(std::span<const float> differences, const Vec3& u, double floor) {
  const std::size_t n = differences.size() / 3;
  if (n == 0) return floor;
  std::vector<double> a(n);
  for (std::size_t i = 0; i < n; ++i)
    a[i] = std::abs(differences[i * 3] * u[0] + differences[i * 3 + 1] * u[1] + differences[i * 3 + 2] * u[2]);
  std::nth_element(a.begin(), a.begin() + static_cast<std::ptrdiff_t>(n / 2), a.end());
  return std::max(floor, 1.4826 * a[n / 2] / std::sqrt(2.0));
}

}  // namespace ct::analyzer
