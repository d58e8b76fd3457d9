// SPDX-License-Identifier: Apache-2.0
#include "analyzer/moments.h"

#include <algorithm>
#include <vector>

#include "core/parallel.h"

namespace ct::analyzer {
namespace {

constexpr std::size_t kBlock = 1 << 16;

struct Partial {
  double n = 0;
  Vec3 mean = Vec3::Zero();
  Mat3 scatter = Mat3::Zero();  // Σ (x − mean)(x − mean)ᵀ
};

Partial block_partial(std::span<const float> rgb, std::size_t i0, std::size_t i1) {
  // Sums about the block's first sample keep the squares small (no cancellation for 16-bit data).
  const double s0 = rgb[i0 * 3], s1 = rgb[i0 * 3 + 1], s2 = rgb[i0 * 3 + 2];
  double a0 = 0, a1 = 0, a2 = 0, q00 = 0, q01 = 0, q02 = 0, q11 = 0, q12 = 0, q22 = 0;
  for (std::size_t i = i0; i < i1; ++i) {
    const double x = rgb[i * 3] - s0, y = rgb[i * 3 + 1] - s1, z = rgb[i * 3 + 2] - s2;
    a0 += x, a1 += y, a2 += z;
    q00 += x * x, q01 += x * y, q02 += x * z, q11 += y * y, q12 += y * z, q22 += z * z;
  }
  Partial p;
  p.n = static_cast<double>(i1 - i0);
  const Vec3 d(a0 / p.n, a1 / p.n, a2 / p.n);
  p.mean = Vec3(s0, s1, s2) + d;
  Mat3 q;
  q << q00, q01, q02, q01, q11, q12, q02, q12, q22;
  p.scatter = q - p.n * d * d.transpose();
  return p;
}

Partial merge(const Partial& a, const Partial& b) {
  if (a.n == 0) return b;
  Partial m;
  m.n = a.n + b.n;
  const Vec3 delta = b.mean - a.mean;
  m.mean = a.mean + delta * (b.n / m.n);
  m.scatter = a.scatter + b.scatter + delta * delta.transpose() * (a.n * b.n / m.n);
  return m;
}

}  // namespace

Moments moments(std::span<const float> rgb, int threads) {
  Moments m;
  const std::size_t n = rgb.size() / 3;
  m.count = n;
  if (n == 0) return m;
  const std::size_t blocks = (n + kBlock - 1) / kBlock;
  std::vector<Partial> partial(blocks);
  parallel_for(blocks, threads, [&](std::size_t b) {
    partial[b] = block_partial(rgb, b * kBlock, std::min(n, (b + 1) * kBlock));
  });
  Partial total;
  for (const Partial& p : partial) total = merge(total, p);
  m.mean = total.mean;
  m.covariance = total.scatter / total.n;
  principal_axes(m.covariance, m.eigenvalues, m.axes);
  return m;
}

}  // namespace ct::analyzer
