// SPDX-License-Identifier: Apache-2.0
#include "analyzer/segmentation.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <tuple>
#include <unordered_map>

#include <Eigen/Dense>
#include <fmt/core.h>

#include "analyzer/noise_level.h"
#include "core/error.h"
#include "core/statistics.h"
#include "core/parallel.h"
#include "core/progress.h"

namespace ct::analyzer {
namespace {

constexpr double kMinAngle = 0.002;  // radians: the angular noise never counts as less (noise-free renders)
constexpr double kWeakBoundary = 1.5;  // the median step (noise σ) across a boundary that is no edge
constexpr double kTextureSteps = 2.5;  // or, where both parts are textured, at most this many times the median step within the smoother one
constexpr double kEnclosed = 0.9;      // the share of a small part's boundary with segments that one segment must hold
constexpr std::uint8_t kInvalid = 0, kOk = 1, kDark = 2;

// One step's share of the segmentation's progress bar, given out in `parts` instalments as the step goes (from any
// thread), the rest when it ends.
class StepShare {
 public:
  StepShare(Progress& bar, double units, std::size_t parts)
      : bar_(bar), units_(static_cast<std::size_t>(std::max(1.0, std::round(units)))), parts_(std::max<std::size_t>(1, parts)) {}
  StepShare(const StepShare&) = delete;
  StepShare& operator=(const StepShare&) = delete;
  ~StepShare() { bar_.advance(units_ - std::min(units_, given(done_.load()))); }
  void advance() {
    const std::size_t k = done_.fetch_add(1) + 1;
    if (k <= parts_) bar_.advance(given(k) - given(k - 1));
  }

 private:
  std::size_t given(std::size_t k) const { return units_ * std::min(k, parts_) / parts_; }
  Progress& bar_;
  std::size_t units_, parts_;
  std::atomic<std::size_t> done_{0};
};

// The working size for an image of width × height: about `megapixels`, never enlarged.
std::pair<int, int> working_size(int width, int height, double megapixels) {
  const double f = std::sqrt(static_cast<double>(width) * static_cast<double>(height) / (megapixels * 1e6));
  if (!(f > 1)) return {width, height};
  return {std::max(1, static_cast<int>(std::lround(width / f))), std::max(1, static_cast<int>(std::lround(height / f)))};
}

// The image area-averaged to the working size, in linear light.
struct Work {
  int w = 0, h = 0;
  std::vector<float> rgb;           // [p][channel]
  std::vector<std::uint8_t> state;  // kInvalid, kOk, kDark
  std::vector<std::uint8_t> clipped;
  std::vector<float> angle_sigma;   // the noise σ of the colour's direction, radians
  std::size_t valid = 0;
  std::size_t size() const { return static_cast<std::size_t>(w) * static_cast<std::size_t>(h); }
};

// Each source coordinate's share of the (at most two) working coordinates it overlaps.
struct Spans {
  std::vector<int> first;
  std::vector<float> share_first;  // the rest goes to first + 1
};

Spans spans(int from, int to) {
  Spans s{std::vector<int>(static_cast<std::size_t>(from)), std::vector<float>(static_cast<std::size_t>(from))};
  const double scale = static_cast<double>(to) / from;  // working pixels per source pixel, <= 1
  for (int i = 0; i < from; ++i) {
    const double a = i * scale, b = (i + 1) * scale;
    const int k = std::min(to - 1, static_cast<int>(std::floor(a)));
    const double edge = k + 1.0;
    s.first[static_cast<std::size_t>(i)] = k;
    s.share_first[static_cast<std::size_t>(i)] = b <= edge || k + 1 >= to ? 1.0f : static_cast<float>((edge - a) / (b - a));
  }
  return s;
}

Work working_image(const RgbImage& image, const CodeDecoder& decode, double clip_level, double megapixels, StepShare& progress) {
  const int W = image.width, H = image.height;
  Work work;
  std::tie(work.w, work.h) = working_size(W, H, megapixels);
  const Spans sx = spans(W, work.w), sy = spans(H, work.h);
  const std::size_t n = work.size();
  // Per working pixel: weighted sums of valid colour, valid weight, clipped weight, total weight.
  std::vector<double> colour(n * 3, 0.0), valid(n, 0.0), clip(n, 0.0), total(n, 0.0);
  // Bands of working rows side by side: each adds the source rows that reach its rows, in the order a single
  // pass would (by source row, then column), so that the sums are the same whatever the thread count.
  const std::size_t bands = std::min<std::size_t>(static_cast<std::size_t>(work.h), 64);
  parallel_for(bands, 0, [&](std::size_t band) {
  const int wy0 = static_cast<int>(band * static_cast<std::size_t>(work.h) / bands), wy1 = static_cast<int>((band + 1) * static_cast<std::size_t>(work.h) / bands);
  for (int y = 0; y < H; ++y) {
    const int wy = sy.first[static_cast<std::size_t>(y)];
    if (wy + 1 < wy0 || wy >= wy1) continue;
    const float fy = sy.share_first[static_cast<std::size_t>(y)];
    for (int x = 0; x < W; ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * static_cast<std::size_t>(W) + static_cast<std::size_t>(x);
      const float* v = &image.rgb[p * 3];
      const bool ok = std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
      const bool clipped = ok && clip_level > 0 && std::max({v[0], v[1], v[2]}) >= clip_level;
      float c[3] = {0, 0, 0};
      if (ok)
        for (int k = 0; k < 3; ++k) c[k] = decode(v[k]);
      const int wx = sx.first[static_cast<std::size_t>(x)];
      const float fx = sx.share_first[static_cast<std::size_t>(x)];
      for (int dy = 0; dy < 2; ++dy) {
        const double wyw = dy == 0 ? fy : 1.0 - fy;
        if (wyw <= 0 || wy + dy < wy0 || wy + dy >= wy1) continue;
        for (int dx = 0; dx < 2; ++dx) {
          const double wgt = wyw * (dx == 0 ? fx : 1.0 - fx);
          if (wgt <= 0) continue;
          const std::size_t q = static_cast<std::size_t>(wy + dy) * static_cast<std::size_t>(work.w) + static_cast<std::size_t>(wx + dx);
          total[q] += wgt;
          if (!ok) continue;
          valid[q] += wgt;
          if (clipped) clip[q] += wgt;
          for (int k = 0; k < 3; ++k) colour[q * 3 + static_cast<std::size_t>(k)] += wgt * c[k];
        }
      }
    }
  }
  progress.advance();
  });
  work.rgb.assign(n * 3, 0.0f);
  work.state.assign(n, kInvalid);
  work.clipped.assign(n, 0);
  for (std::size_t q = 0; q < n; ++q) {
    if (!(valid[q] >= 0.5 * total[q]) || valid[q] <= 0) continue;
    work.state[q] = kOk;
    ++work.valid;
    work.clipped[q] = clip[q] >= 0.25 * valid[q];
    for (std::size_t k = 0; k < 3; ++k) work.rgb[q * 3 + k] = static_cast<float>(colour[q * 3 + k] / valid[q]);
  }
  return work;
}

// σ² = a + b·v + c·v² over the bands (levels v, variances), a, b, c ≥ 0: the camera's three terms (read or
// dark noise; shot noise; a part proportional to the signal — pixel gain differences, film grain, an HDR merge's
// exposure steps), as EMVA 1288 writes them. Least squares in relative terms (each residual over its band's
// variance): a band's σ is measured to about the same relative precision at every level, so the dark bands count
// as much as the bright ones, where an absolute fit would let the brightest band set the whole line. The
// non-negative solution is the best of the subsets of terms whose unconstrained fit is non-negative.
struct NoiseTerms {
  double a = 0, b = 0, c = 0;
};

NoiseTerms fit_noise_terms(const std::vector<double>& level, const std::vector<double>& variance) {
  NoiseTerms best;
  double best_cost = std::numeric_limits<double>::infinity();
  const std::size_t n = level.size();
  if (n == 0) return best;
  for (int subset = 1; subset < 8; ++subset) {
    std::vector<int> terms;
    for (int t = 0; t < 3; ++t)
      if (subset & (1 << t)) terms.push_back(t);
    if (terms.size() > n) continue;
    Eigen::MatrixXd A(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(terms.size()));
    Eigen::VectorXd y(static_cast<Eigen::Index>(n));
    for (std::size_t k = 0; k < n; ++k) {
      const double w = 1 / variance[k];
      for (std::size_t t = 0; t < terms.size(); ++t) A(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(t)) = w * std::pow(level[k], terms[t]);
      y(static_cast<Eigen::Index>(k)) = 1;  // variance[k] · w
    }
    const Eigen::VectorXd x = A.colPivHouseholderQr().solve(y);
    if ((x.array() < 0).any() || !x.allFinite()) continue;
    const double cost = (A * x - y).squaredNorm();
    if (cost < best_cost) {
      best_cost = cost;
      best = {};
      for (std::size_t t = 0; t < terms.size(); ++t) (terms[t] == 0 ? best.a : terms[t] == 1 ? best.b : best.c) = x(static_cast<Eigen::Index>(t));
    }
  }
  return best;
}

// Immerkær's 3×3 mask (immerkaer_response, analyzer/noise_level.h) cancels any locally planar signal and leaves
// 6σ of white noise; where the image is flat it holds noise only. Unlike the image's noise for the clusters'
// extents (estimate_image_noise), the segmentation's is measured per channel, on the working image, in the stored
// values, and fitted by a curve over the brightness. Per channel and per band of 16 equal-count brightness
// bands, the 25th percentile of its magnitude (0.3186 × 6σ for Gaussian noise) weights the flat pixels of the
// band; σ² = a + b·I + c·I² is fitted over the bands (fit_noise_terms).
// The noise is estimated where it lives: in the values as the file stores them. A linear camera file's are
// read and shot noise and a part proportional to the signal; an encoded file's (sRGB, a gamma) are what the
// encoding's steps and the compression did to the stored values, which the same curve describes there and no
// such curve does in linear light (at the dark end the curve's slope shrinks them many times). `model` brings the curve.
NoiseModel estimate_noise(const Work& work, NoiseModel model, StepShare& progress) {
  std::vector<double> brightest;
  for (std::size_t q = 0; q < work.size(); ++q)
    if (work.state[q] == kOk && !work.clipped[q]) {
      const double m = std::max({work.rgb[q * 3], work.rgb[q * 3 + 1], work.rgb[q * 3 + 2]});
      if (m > 0) brightest.push_back(m);
    }
  model.floor = 1e-3 * quantile(brightest, 0.5);
  std::vector<double> stored(work.rgb.size());
  for (std::size_t k = 0; k < stored.size(); ++k) stored[k] = model.encode(work.rgb[k]);
  const int w = work.w;
  for (int c = 0; c < 3; ++c) {
    std::vector<std::pair<double, double>> samples;  // (value, |mask response|)
    // Clipped values hold no noise: at the top, and a channel at black (0: a camera's offset or a gamut's edge
    // clamped it there).
    const auto value = [&](std::size_t q) { return stored[q * 3 + static_cast<std::size_t>(c)]; };
    const auto usable = [&](std::size_t q) { return work.state[q] != kInvalid && !work.clipped[q] && value(q) > 0; };
    for (int y = 1; y + 1 < work.h; ++y)
      for (int x = 1; x + 1 < w; ++x) {
        const std::size_t p = static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
        if (const auto m = immerkaer_response(p, static_cast<std::size_t>(w), 1, value, usable)) samples.emplace_back(value(p), std::abs(*m));
      }
    model.samples = std::max(model.samples, samples.size());
    if (samples.size() < 64) continue;
    std::sort(samples.begin(), samples.end());
    constexpr int kBands = 16;
    std::vector<double> level, variance;
    for (int band = 0; band < kBands; ++band) {
      const std::size_t lo = samples.size() * static_cast<std::size_t>(band) / kBands, hi = samples.size() * static_cast<std::size_t>(band + 1) / kBands;
      std::vector<double> m;
      for (std::size_t k = lo; k < hi; ++k) m.push_back(samples[k].second);
      const double sigma = quantile(m, 0.25) / (kImmerkaerGain * kQuartileAbs);
      if (!(sigma > 0)) continue;  // a band of one constant value: no noise to measure there
      level.push_back(samples[(lo + hi) / 2].first);
      variance.push_back(sigma * sigma);
    }
    const NoiseTerms terms = fit_noise_terms(level, variance);
    model.a[c] = terms.a;
    model.b[c] = terms.b;
    model.c[c] = terms.c;
    progress.advance();
  }
  return model;
}

struct DisjointSets {
  std::vector<std::uint32_t> parent, size;
  explicit DisjointSets(std::size_t n) : parent(n), size(n, 1) { std::iota(parent.begin(), parent.end(), 0u); }
  std::uint32_t find(std::uint32_t a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  }
  // Joins the two sets; the smaller index stays the root (deterministic, whatever the sizes). Returns it.
  std::uint32_t join(std::uint32_t a, std::uint32_t b) {
    a = find(a), b = find(b);
    if (a == b) return a;
    if (a > b) std::swap(a, b);
    parent[b] = a;
    size[a] += size[b];
    return a;
  }
};

double angle(const float* a, const float* b) {
  const double d = double(a[0]) * b[0] + double(a[1]) * b[1] + double(a[2]) * b[2];
  const double na = std::sqrt(double(a[0]) * a[0] + double(a[1]) * a[1] + double(a[2]) * a[2]);
  const double nb = std::sqrt(double(b[0]) * b[0] + double(b[1]) * b[1] + double(b[2]) * b[2]);
  return std::acos(std::clamp(d / std::max(1e-300, na * nb), -1.0, 1.0));
}

double angle(const Vec3& a, const Vec3& b) { return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)); }

// What the dichromatic tests need to know of a part of the working image.
struct PartStats {
  std::size_t n = 0;
  Vec3 body = Vec3::Zero();       // the principal direction of Σ c cᵀ: the body colour of a matte line
  Vec3 direction = Vec3::Zero();  // the mean unit colour
  double upper = 0;               // the 90th percentile along `body`
  double brightness = 0;          // the median |c|
  double spread = 0;              // the 90th percentile angle of its colours from `direction`
  double clipped = 0;             // the fraction of clipped pixels
  double noise = 0;               // the noise σ (length of the per-channel vector) at its mean colour
};

Vec3 colour_at(const Work& work, std::size_t q) { return {work.rgb[q * 3], work.rgb[q * 3 + 1], work.rgb[q * 3 + 2]}; }

PartStats part_stats(const Work& work, const std::vector<std::uint32_t>& pixels, const NoiseModel& noise) {
  PartStats s;
  s.n = pixels.size();
  Mat3 scatter = Mat3::Zero();
  Vec3 unit_sum = Vec3::Zero(), sum = Vec3::Zero();
  std::vector<double> lengths;
  lengths.reserve(pixels.size());
  std::size_t clipped = 0;
  for (const std::uint32_t q : pixels) {
    const Vec3 c = colour_at(work, q);
    scatter += c * c.transpose();
    sum += c;
    const double l = c.norm();
    lengths.push_back(l);
    if (l > 0) unit_sum += c / l;
    clipped += work.clipped[q];
  }
  const Eigen::SelfAdjointEigenSolver<Mat3> eigen(scatter);
  s.body = eigen.eigenvectors().col(2);
  if (s.body.sum() < 0) s.body = -s.body;
  s.direction = unit_sum.norm() > 0 ? Vec3(unit_sum.normalized()) : s.body;
  std::vector<double> along, off;
  along.reserve(pixels.size());
  off.reserve(pixels.size());
  for (const std::uint32_t q : pixels) {
    const Vec3 c = colour_at(work, q);
    along.push_back(c.dot(s.body));
    off.push_back(c.norm() > 0 ? angle(c, s.direction) : 0.0);
  }
  s.upper = quantile(along, 0.9);
  s.brightness = quantile(lengths, 0.5);
  s.spread = quantile(off, 0.9);
  s.clipped = s.n ? double(clipped) / double(s.n) : 0.0;
  const Vec3 mean = s.n ? Vec3(sum / double(s.n)) : Vec3::Zero();
  double v = 0;
  for (int c = 0; c < 3; ++c) v += std::pow(noise.sigma(c, mean[c]), 2);
  s.noise = std::sqrt(v);
  return s;
}

// Is B (a brighter neighbour of A) A's highlight? B's colours c = m_b·body_A + m_s·h: their part off A's
// body line, x = |c − (c·body_A) body_A| = m_s·|h⊥|, grows with the highlight while their part along it,
// y = c·body_A = m_b + m_s·(h·body_A), starts from the body level where the highlight is: the line
// y = α + κ·x meets the body line at α, in A's upper range. Another matte surface's colours lie on a line
// through black: α ≈ 0. The line is fitted to the mean colours of B's rings (pixels at the same distance
// from B's edge): a highlight grows from its edge to its peak, and the ring means are far less noisy than
// single pixels.
// The parts B encloses whole (in holes of B's mask: not reachable from outside B's bounding box without
// crossing B), e.g. the brighter core of a highlight whose fringe is B. Their pixels are appended to `pixels`.
std::vector<std::int32_t> enclosed_parts(const Work& work, const std::vector<std::int32_t>& part_of, const std::vector<std::vector<std::uint32_t>>& part_pixels,
                                         std::int32_t b_id, const std::vector<std::uint32_t>& b_pixels, std::vector<std::uint32_t>& pixels) {
  const auto w = static_cast<std::size_t>(work.w);
  std::size_t x0 = w, x1 = 0, y0 = work.size(), y1 = 0;
  for (const std::uint32_t q : b_pixels) x0 = std::min(x0, q % w), x1 = std::max(x1, q % w), y0 = std::min(y0, q / w), y1 = std::max(y1, q / w);
  // A box one pixel larger on each side, flooded from its border over everything but B.
  const std::size_t bx0 = x0 > 0 ? x0 - 1 : 0, by0 = y0 > 0 ? y0 - 1 : 0, bx1 = std::min(w - 1, x1 + 1), by1 = std::min(work.size() / w - 1, y1 + 1);
  const std::size_t bw = bx1 - bx0 + 1, bh = by1 - by0 + 1;
  std::vector<std::uint8_t> outside(bw * bh, 0);
  std::vector<std::size_t> stack;
  auto global = [&](std::size_t i) { return (by0 + i / bw) * w + bx0 + i % bw; };
  for (std::size_t i = 0; i < bw * bh; ++i) {
    const std::size_t bx = i % bw, by = i / bw;
    if ((bx == 0 || by == 0 || bx + 1 == bw || by + 1 == bh) && part_of[global(i)] != b_id) outside[i] = 1, stack.push_back(i);
  }
  while (!stack.empty()) {
    const std::size_t i = stack.back();
    stack.pop_back();
    const std::size_t bx = i % bw, by = i / bw;
    const std::size_t next[4] = {bx > 0 ? i - 1 : i, bx + 1 < bw ? i + 1 : i, by > 0 ? i - bw : i, by + 1 < bh ? i + bw : i};
    for (const std::size_t j : next)
      if (!outside[j] && part_of[global(j)] != b_id) outside[j] = 1, stack.push_back(j);
  }
  std::map<std::int32_t, std::size_t> in_holes;
  for (std::size_t i = 0; i < bw * bh; ++i)
    if (!outside[i] && part_of[global(i)] != b_id && part_of[global(i)] >= 0) ++in_holes[part_of[global(i)]];
  std::vector<std::int32_t> parts;
  for (const auto& [id, count] : in_holes)
    if (count == part_pixels[static_cast<std::size_t>(id)].size()) {
      parts.push_back(id);
      pixels.insert(pixels.end(), part_pixels[static_cast<std::size_t>(id)].begin(), part_pixels[static_cast<std::size_t>(id)].end());
    }
  return parts;
}

// `b_pixels`: B's pixels, `inside(q)` whether working pixel q is one of them.
template <typename Inside>
bool is_highlight(const Work& work, const Inside& inside, const std::vector<std::uint32_t>& b_pixels, const PartStats& a, const PartStats& b) {
  // A highlight is brighter than its object and a small part of it (at most a quarter of the object's size).
  if (!(b.brightness > a.brightness) || 4 * b_pixels.size() > a.n) return false;
  // Distance from B's edge (4-neighbour steps), by breadth-first search inside B.
  const auto w = static_cast<std::size_t>(work.w);
  std::map<std::uint32_t, int> ring;
  std::vector<std::uint32_t> frontier;
  for (const std::uint32_t q : b_pixels) {
    const std::size_t x = q % w;
    const bool edge = x == 0 || x + 1 == w || q < w || q + w >= work.size() || !inside(q - 1) || !inside(q + 1) || !inside(q - w) || !inside(q + w);
    if (edge) ring[q] = 0, frontier.push_back(q);
  }
  for (int d = 1; !frontier.empty(); ++d) {
    std::vector<std::uint32_t> next;
    for (const std::uint32_t q : frontier)
      for (const std::size_t r : {std::size_t(q) - 1, std::size_t(q) + 1, std::size_t(q) - w, std::size_t(q) + w})
        if (r < work.size() && inside(r) && !ring.contains(static_cast<std::uint32_t>(r))) ring[static_cast<std::uint32_t>(r)] = d, next.push_back(static_cast<std::uint32_t>(r));
    frontier = std::move(next);
  }
  std::map<int, std::pair<Vec3, std::size_t>> sums;
  for (const auto& [q, d] : ring) {
    if (work.clipped[q]) continue;
    auto& [sum, count] = sums.try_emplace(d, Vec3::Zero(), 0).first->second;
    sum += colour_at(work, q);
    ++count;
  }
  // Rings of at least 4 pixels (the innermost ones pooled).
  std::vector<Vec3> means;
  std::vector<double> counts;
  Vec3 pool = Vec3::Zero();
  std::size_t pooled = 0;
  for (auto it = sums.rbegin(); it != sums.rend(); ++it) {
    pool += it->second.first, pooled += it->second.second;
    if (pooled >= 4) means.push_back(pool / double(pooled)), counts.push_back(double(pooled)), pool.setZero(), pooled = 0;
  }
  if (means.size() < 2) return false;
  // A highlight grows from its edge: its most turned ring is turned from A's body colour by more than the
  // outermost one (beyond 3 σ of a ring mean's direction). A whole other object (with a highlight of its
  // own) keeps its own colour out to its edge, and its highlight turns it towards the illuminant, not away
  // from A's body.
  double edge_turn = angle(means.back(), a.body), peak_turn = 0;
  for (const Vec3& m : means) peak_turn = std::max(peak_turn, angle(m, a.body));
  const double ring_angle_noise = b.noise / std::max(1e-300, b.brightness) / std::sqrt(double(b.n) / double(means.size()));
  if (peak_turn <= edge_turn + 3 * ring_angle_noise) return false;
  double sw = 0, mx = 0, my = 0;
  std::vector<double> xs, ys;
  Mat3 off_scatter = Mat3::Zero();
  for (std::size_t k = 0; k < means.size(); ++k) {
    const double y = means[k].dot(a.body);
    const Vec3 r = means[k] - y * a.body;
    xs.push_back(r.norm()), ys.push_back(y);
    sw += counts[k], mx += counts[k] * xs.back(), my += counts[k] * y;
    off_scatter += counts[k] * r * r.transpose();
  }
  mx /= sw, my /= sw;
  double vxx = 0, vxy = 0;
  for (std::size_t k = 0; k < xs.size(); ++k) vxx += counts[k] * (xs[k] - mx) * (xs[k] - mx), vxy += counts[k] * (xs[k] - mx) * (ys[k] - my);
  vxx /= sw, vxy /= sw;
  const double mean_count = sw / double(means.size());
  const double x_noise = b.noise / std::sqrt(mean_count);  // of one ring mean
  const Eigen::SelfAdjointEigenSolver<Mat3> eigen(off_scatter / sw);
  const double second = std::sqrt(std::max(0.0, eigen.eigenvalues()[1])), first = std::sqrt(std::max(0.0, eigen.eigenvalues()[2]));
  const double kappa = vxx > 0 ? vxy / vxx : 0, alpha = my - kappa * mx;
  // The highlight must turn the colour measurably and grow along its line, else nothing tells a highlight
  // from a brighter patch of another colour; and it adds one colour: the off-body parts lie along one direction.
  if (mx < 3 * x_noise || std::sqrt(vxx) < 2 * x_noise) return false;
  if (second > 3 * x_noise + 0.15 * first) return false;
  return kappa > -0.2 && alpha >= 0.3 * a.upper && alpha <= 1.5 * a.upper;
}

struct Parts {
  std::vector<std::int32_t> id;                    // per working pixel, -1 for none
  std::vector<std::vector<std::uint32_t>> pixels;  // per part, in increasing order; empty once folded into another part
  bool alive(std::size_t k) const { return !pixels[k].empty(); }
};

// The parts of the disjoint sets' pixels, numbered in the order of their first pixel.
Parts parts_of(const Work& work, DisjointSets& sets) {
  Parts parts;
  parts.id.assign(work.size(), -1);
  std::vector<std::int32_t> index(work.size(), -1);  // per root
  for (std::size_t q = 0; q < work.size(); ++q) {
    if (work.state[q] != kOk) continue;
    std::int32_t& k = index[sets.find(static_cast<std::uint32_t>(q))];
    if (k < 0) k = static_cast<std::int32_t>(parts.pixels.size()), parts.pixels.emplace_back();
    parts.id[q] = k;
    parts.pixels[static_cast<std::size_t>(k)].push_back(static_cast<std::uint32_t>(q));
  }
  return parts;
}

// Shared 4-neighbour boundary lengths between parts, and each part's whole boundary (to anything else): per part,
// the parts it meets and the length of boundary it shares with each, counted in one pass over the pixels.
// merge() folds one part into another and updates only their neighbours' entries, so that the adjacency of the
// merged parts costs the two parts' degrees, not a pass over the image.
class Adjacency {
 public:
  Adjacency(const Work& work, const Parts& parts) : perimeter(parts.pixels.size(), 0), shared_(parts.pixels.size()) {
    auto pair = [&](std::size_t p, std::size_t q) {
      const std::int32_t a = parts.id[p], b = parts.id[q];
      if (a == b) return;
      if (a >= 0) ++perimeter[static_cast<std::size_t>(a)];
      if (b >= 0) ++perimeter[static_cast<std::size_t>(b)];
      if (a >= 0 && b >= 0) ++shared_[static_cast<std::size_t>(a)][b], ++shared_[static_cast<std::size_t>(b)][a];
    };
    const auto w = static_cast<std::size_t>(work.w);
    for (std::size_t q = 0; q < work.size(); ++q) {
      if (q % w + 1 < w) pair(q, q + 1);
      if (q + w < work.size()) pair(q, q + w);
    }
  }

  std::vector<std::size_t> perimeter;

  std::size_t between(std::int32_t a, std::int32_t b) const {
    const auto& m = shared_[static_cast<std::size_t>(a)];
    const auto it = m.find(b);
    return it == m.end() ? 0 : it->second;
  }

  // a's neighbours by decreasing shared boundary, then increasing id.
  std::vector<std::int32_t> neighbours(std::int32_t a) const {
    std::vector<std::pair<std::size_t, std::int32_t>> list;
    list.reserve(shared_[static_cast<std::size_t>(a)].size());
    for (const auto& [b, count] : shared_[static_cast<std::size_t>(a)]) list.emplace_back(count, b);
    std::sort(list.begin(), list.end(), [](const auto& x, const auto& y) { return x.first != y.first ? x.first > y.first : x.second < y.second; });
    std::vector<std::int32_t> out;
    out.reserve(list.size());
    for (const auto& [count, b] : list) out.push_back(b);
    return out;
  }

  // `from` becomes part of `into`: the boundary between them is inside now, and what each shared with a third
  // part, the union shares with it.
  void merge(std::int32_t into, std::int32_t from) {
    auto& to = shared_[static_cast<std::size_t>(into)];
    auto& gone = shared_[static_cast<std::size_t>(from)];
    perimeter[static_cast<std::size_t>(into)] = perimeter[static_cast<std::size_t>(into)] + perimeter[static_cast<std::size_t>(from)] - 2 * between(into, from);
    perimeter[static_cast<std::size_t>(from)] = 0;
    to.erase(from);
    for (const auto& [n, count] : gone) {
      if (n == into) continue;
      to[n] += count;
      auto& other = shared_[static_cast<std::size_t>(n)];
      other.erase(from);
      other[into] += count;
    }
    std::unordered_map<std::int32_t, std::size_t>().swap(gone);
  }

 private:
  std::vector<std::unordered_map<std::int32_t, std::size_t>> shared_;  // per part: neighbour → shared boundary
};

// The parts of the working image with their adjacency and (while kept) statistics, from the start of step 5 to the
// end of step 6. A round or pass joins parts in the disjoint sets while it reads the parts as they stood at its
// start; fold() then brings them up to date: each group of joined parts becomes the one of them with the lowest id
// (the one with the first pixel, which parts_of would number first), its pixels in increasing order, its statistics
// measured afresh, its adjacency merged from the group's. The other parts keep their ids, in the order parts_of
// would give them, and their statistics: parts, adjacency and statistics are those a rebuild from the sets would
// give, at the cost of the joined parts' pixels and neighbours only.
struct PartGraph {
  Parts parts;
  Adjacency adj;
  std::vector<PartStats> stats;  // per part, while `keep_stats`
  bool keep_stats = true;

  PartGraph(const Work& work, DisjointSets& sets, const NoiseModel& noise) : parts(parts_of(work, sets)), adj(work, parts) {
    stats.reserve(parts.pixels.size());
    for (const auto& pixels : parts.pixels) stats.push_back(part_stats(work, pixels, noise));
  }

  // `joined`: every part that took part in a join since the last fold (either side).
  void fold(const Work& work, const NoiseModel& noise, DisjointSets& sets, std::vector<std::int32_t> joined) {
    std::sort(joined.begin(), joined.end());
    joined.erase(std::unique(joined.begin(), joined.end()), joined.end());
    std::vector<std::pair<std::uint32_t, std::int32_t>> groups;  // (root, part), parts in increasing id per root
    groups.reserve(joined.size());
    for (const std::int32_t k : joined) groups.emplace_back(sets.find(parts.pixels[static_cast<std::size_t>(k)].front()), k);
    std::sort(groups.begin(), groups.end());
    for (std::size_t i = 0; i < groups.size();) {
      std::size_t j = i + 1;
      while (j < groups.size() && groups[j].first == groups[i].first) ++j;
      if (j - i > 1) {
        const std::int32_t into = groups[i].second;
        auto& pixels = parts.pixels[static_cast<std::size_t>(into)];
        for (std::size_t k = i + 1; k < j; ++k) {
          const std::int32_t from = groups[k].second;
          adj.merge(into, from);
          auto& moved = parts.pixels[static_cast<std::size_t>(from)];
          for (const std::uint32_t q : moved) parts.id[q] = into;
          pixels.insert(pixels.end(), moved.begin(), moved.end());
          std::vector<std::uint32_t>().swap(moved);
          if (keep_stats) stats[static_cast<std::size_t>(from)] = PartStats{};
        }
        std::sort(pixels.begin(), pixels.end());
        if (keep_stats) stats[static_cast<std::size_t>(into)] = part_stats(work, pixels, noise);
      }
      i = j;
    }
  }
};

// Step 2: the noise model's encoding — an integer file's codes, the curve of an encoded file as a table — and
// then its terms, measured on the working image.
NoiseModel measure_noise(const Work& work, const CodeDecoder& decode, double full_scale, double averaged, StepShare& progress) {
  NoiseModel model;
  model.integer = full_scale > 1;
  model.codes = decode.table;
  model.averaged = averaged;
  if (decode.curve) {
    // The curve as a table of the linear value of each stored value: an integer file's codes, else 4096 steps
    // over the full scale.
    if (!decode.table.empty()) {
      model.curve = decode.table;
    } else {
      constexpr int kSteps = 4096;
      model.curve_step = decode.full_scale / kSteps;
      for (int k = 0; k <= kSteps; ++k) model.curve.push_back(static_cast<float>(decode.curve->decode(k * model.curve_step, decode.full_scale)));
    }
  }
  return estimate_noise(work, std::move(model), progress);
}

// Step 3: each pixel's angular noise; the dark ones are set aside.
void set_aside_dark(Work& work, const NoiseModel& noise, double dark) {
  work.angle_sigma.assign(work.size(), 0.0f);
  for (std::size_t q = 0; q < work.size(); ++q) {
    if (work.state[q] != kOk) continue;
    const float* c = &work.rgb[q * 3];
    double v = 0;
    for (int k = 0; k < 3; ++k) v += std::pow(noise.sigma(k, c[k]), 2);
    const double length = std::sqrt(double(c[0]) * c[0] + double(c[1]) * c[1] + double(c[2]) * c[2]);
    if (!work.clipped[q] && !(length > dark * std::sqrt(v))) {
      work.state[q] = kDark;
      continue;
    }
    work.angle_sigma[q] = static_cast<float>(std::max(kMinAngle, std::sqrt(v) / length));
  }
}

// Step 4: linear colour clusters over the pixel graph. Each part's colour is its mean colour direction — each
// pixel's unit colour weighted by the inverse variance of its direction — with that mean's own noise. Two parts
// join when their mean directions differ by less than `tolerance` times the noise of the two means plus `angle`:
// a part is a linear colour cluster, and a gradual drift cannot chain it into its neighbours.
class ColourClusters {
 public:
  ColourClusters(const Work& work, const NoiseModel& noise, const SegmentationOptions& options)
      : sets(work.size()), tolerance_(options.tolerance), angle_tolerance_(options.angle_deg * M_PI / 180) {
    collect_edges(work);
    const std::size_t n = work.size();
    // Quantisation does not average out over a smooth part: its mean colour may be off by half a code step per
    // channel, an angle of up to 3·σ_q/|c| (σ_q = step/√12), which the comparison of means allows for.
    unit_sum_.assign(n, Vec3::Zero());
    precision_.assign(n, 0.0);
    bias_sum_.assign(n, 0.0);
    for (std::size_t q = 0; q < n; ++q) {
      if (work.state[q] != kOk) continue;
      precision_[q] = 1.0 / (double(work.angle_sigma[q]) * work.angle_sigma[q]);
      const Vec3 c = colour_at(work, q);
      unit_sum_[q] = c.normalized() * precision_[q];
      bias_sum_[q] = precision_[q] * 3 * noise.quantisation(c.mean()) * std::sqrt(noise.averaged) / c.norm();
    }
  }

  // Graph merging over 8-neighbour edges, lightest first (Felzenszwalb & Huttenlocher).
  void merge_along_edges(StepShare& progress) {
    const std::size_t chunk = edges_.size() / 16 + 1;
    for (std::size_t k = 0; k < edges_.size(); ++k) {
      const Edge& e = edges_[k];
      try_join(e.a, e.b, 0.0);
      if ((k + 1) % chunk == 0) progress.advance();
    }
  }

  // Parts of one surface that a slow drift of its colour split (shading by light of two colours, skin) meet
  // along a boundary without an edge: where the median step across it is at the noise level, or no larger than
  // 2.5 times the median step within the smoother of the two (their texture: a boundary no sharper than the
  // surface's own grain is no edge; Felzenszwalb & Huttenlocher compare a boundary with the parts' insides so),
  // they join if their mean directions differ by less than 3 · angle_deg beyond their noise.
  void join_across_weak_boundaries(StepShare& progress) {
    const double extra = 2 * angle_tolerance_;
    // The parts as they stand before these joins whose mean colour is known well enough to tell the difference
    // this forgives (anchors): a join must keep every two of them within it, so that a run of joins, each small,
    // cannot carry one surface's colour into another's (a dark background into a bread roll through its shade).
    std::map<std::uint32_t, std::vector<Anchor>> anchors;
    for (std::uint32_t q = 0; q < sets.parent.size(); ++q)
      if (sets.find(q) == q && precision_[q] > 0 && tolerance_ / std::sqrt(precision_[q]) <= extra)
        anchors[q].push_back({unit_sum_[q].normalized(), 1 / precision_[q], bias_sum_[q] / precision_[q]});
    constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
    std::vector<std::uint32_t> edge_part(edges_.size());          // per edge: the part holding both ends, else kNone
    std::vector<std::uint32_t> within_start(sets.parent.size() + 1);  // per part: where its steps start in within_steps
    std::vector<float> within_steps(edges_.size());
    std::vector<double> texture_of(sets.parent.size());
    for (int round = 0; round < 4; ++round) {
      // The steps across each boundary between two parts, grouped by sorting, and within each part, grouped by
      // counting (a group's median is its step of rank ⌊(n − 1)/2⌋ in increasing order, core/statistics.h's rule).
      std::vector<std::pair<std::uint64_t, float>> across;
      std::fill(within_start.begin(), within_start.end(), 0u);
      for (std::size_t k = 0; k < edges_.size(); ++k) {
        const Edge& e = edges_[k];
        const std::uint32_t a = sets.find(e.a), b = sets.find(e.b);
        edge_part[k] = a == b ? a : kNone;
        if (a != b) across.emplace_back(std::uint64_t{std::min(a, b)} << 32 | std::max(a, b), e.weight);
        else ++within_start[a + 1];
      }
      std::partial_sum(within_start.begin(), within_start.end(), within_start.begin());
      std::vector<std::uint32_t> fill(within_start.begin(), within_start.end() - 1);
      for (std::size_t k = 0; k < edges_.size(); ++k)
        if (edge_part[k] != kNone) within_steps[fill[edge_part[k]]++] = edges_[k].weight;
      std::sort(across.begin(), across.end());
      // Each part's texture, once: the median step between its own neighbours (0 when too few to say).
      std::fill(texture_of.begin(), texture_of.end(), 0.0);
      for (std::size_t part = 0; part < texture_of.size(); ++part) {
        const auto lo = within_steps.begin() + within_start[part], hi = within_steps.begin() + within_start[part + 1];
        if (hi - lo < 8) continue;
        const auto middle = lo + (hi - lo - 1) / 2;
        std::nth_element(lo, middle, hi);
        texture_of[part] = *middle;
      }
      std::vector<std::tuple<double, std::uint32_t, std::uint32_t>> weak;
      for (std::size_t i = 0, j = 0; i < across.size(); i = j) {
        while (j < across.size() && across[j].first == across[i].first) ++j;
        if (j - i < 4) continue;
        const double median = across[i + (j - i - 1) / 2].second;
        const auto a = static_cast<std::uint32_t>(across[i].first >> 32), b = static_cast<std::uint32_t>(across[i].first & 0xffffffffu);
        if (median <= std::max(kWeakBoundary, kTextureSteps * std::min(texture_of[a], texture_of[b]))) weak.emplace_back(median, a, b);
      }
      std::sort(weak.begin(), weak.end());
      std::size_t joined = 0;
      for (const auto& [median, a, b] : weak) {
        const std::uint32_t ra = sets.find(a), rb = sets.find(b);
        if (ra == rb) continue;
        auto& xa = anchors[ra];
        auto& xb = anchors[rb];
        if (!compatible(xa, xb, extra)) continue;
        if (!try_join(ra, rb, extra)) continue;
        ++joined;
        const std::uint32_t root = sets.find(ra), other = root == ra ? rb : ra;
        auto& into = anchors[root];
        auto& from = anchors[other];
        into.insert(into.end(), from.begin(), from.end());
        anchors.erase(other);
      }
      progress.advance();
      if (joined == 0) break;
    }
  }

  DisjointSets sets;

 private:
  struct Anchor {
    Vec3 direction;
    double variance, bias;  // of the direction, radians²; the quantisation's allowance, radians
  };

  // Every anchor of one part within `extra` (beyond the noise of the two means) of every anchor of the other.
  bool compatible(const std::vector<Anchor>& a, const std::vector<Anchor>& b, double extra) const {
    for (const Anchor& x : a)
      for (const Anchor& y : b)
        if (angle(x.direction, y.direction) > tolerance_ * std::sqrt(x.variance + y.variance) + x.bias + y.bias + angle_tolerance_ + extra)
          return false;
    return true;
  }

  struct Edge {
    float weight;  // the angle between the two colours, in units of its noise σ
    std::uint32_t a, b;
  };

  // 8-neighbour edges no steeper than `tolerance`, lightest first (ties by position: deterministic).
  void collect_edges(const Work& work) {
    edges_.reserve(work.size() * 4);
    const int w = work.w, h = work.h;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const std::size_t p = static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
        if (work.state[p] != kOk) continue;
        const int offsets[4][2] = {{1, 0}, {0, 1}, {1, 1}, {-1, 1}};
        for (const auto& o : offsets) {
          const int nx = x + o[0], ny = y + o[1];
          if (nx < 0 || nx >= w || ny >= h) continue;
          const std::size_t q = static_cast<std::size_t>(ny) * static_cast<std::size_t>(w) + static_cast<std::size_t>(nx);
          if (work.state[q] != kOk) continue;
          const double sigma = std::hypot(work.angle_sigma[p], work.angle_sigma[q]);
          const double weight = angle(&work.rgb[p * 3], &work.rgb[q * 3]) / sigma;
          if (weight <= tolerance_) edges_.push_back({static_cast<float>(weight), static_cast<std::uint32_t>(p), static_cast<std::uint32_t>(q)});
        }
      }
    std::sort(edges_.begin(), edges_.end(), [](const Edge& x, const Edge& y) {
      return x.weight != y.weight ? x.weight < y.weight : (x.a != y.a ? x.a < y.a : x.b < y.b);
    });
  }

  bool try_join(std::uint32_t a, std::uint32_t b, double extra) {
    a = sets.find(a), b = sets.find(b);
    if (a == b) return false;
    const double spread = std::sqrt(1 / precision_[a] + 1 / precision_[b]), bias = bias_sum_[a] / precision_[a] + bias_sum_[b] / precision_[b];
    if (angle(unit_sum_[a], unit_sum_[b]) > tolerance_ * spread + bias + angle_tolerance_ + extra) return false;
    const std::uint32_t root = sets.join(a, b), other = root == a ? b : a;
    unit_sum_[root] += unit_sum_[other];
    precision_[root] += precision_[other];
    bias_sum_[root] += bias_sum_[other];
    return true;
  }

  std::vector<Edge> edges_;
  std::vector<Vec3> unit_sum_;
  std::vector<double> precision_, bias_sum_;
  double tolerance_, angle_tolerance_;
};

// Step 5: highlights (and clipped highlights) join their objects — whole parts, a few rounds. Each round reads the
// parts, their adjacency and statistics as they stood at its start; its joins are folded in at its end.
void extend_over_dichromatic_planes(const Work& work, const NoiseModel& noise, DisjointSets& sets, PartGraph& graph, Segmentation& out,
                                    StepShare& progress) {
  const Parts& parts = graph.parts;
  const Adjacency& adj = graph.adj;
  const std::vector<PartStats>& stats = graph.stats;
  std::vector<std::uint8_t> in_inside(parts.pixels.size(), 0);  // the parts of B and those it encloses, while B is tried
  for (int round = 0; round < 4; ++round) {
    std::vector<std::int32_t> order;
    for (std::size_t k = 0; k < parts.pixels.size(); ++k)
      if (parts.alive(k)) order.push_back(static_cast<std::int32_t>(k));
    std::stable_sort(order.begin(), order.end(), [&](std::int32_t x, std::int32_t y) { return stats[static_cast<std::size_t>(x)].n < stats[static_cast<std::size_t>(y)].n; });
    std::vector<std::uint8_t> touched(parts.pixels.size(), 0);  // 1: grew this round, 2: merged away
    std::vector<std::int32_t> joined;
    std::size_t merges = 0;
    for (const std::int32_t bi : order) {
      const PartStats& b = stats[static_cast<std::size_t>(bi)];
      if (touched[static_cast<std::size_t>(bi)] != 0 || b.n < 2) continue;
      // B with the parts it encloses, found once for B (they do not depend on the neighbour A), when first needed.
      std::optional<std::pair<std::vector<std::uint32_t>, std::vector<std::int32_t>>> enclosing;
      for (const std::int32_t ai : adj.neighbours(bi)) {
        const PartStats& a = stats[static_cast<std::size_t>(ai)];
        if (touched[static_cast<std::size_t>(ai)] == 2) continue;
        const double shared = static_cast<double>(adj.between(ai, bi)), perimeter = static_cast<double>(adj.perimeter[static_cast<std::size_t>(bi)]);
        if (shared < 0.3 * perimeter) break;  // neighbours are in decreasing order of shared boundary
        bool join = false;
        if (b.clipped >= 0.5) {
          join = shared >= 0.5 * perimeter && b.n <= a.n;
          if (join) ++out.clipped_merges;
        } else if (b.brightness > a.brightness && 4 * b.n <= a.n) {  // else no highlight, whatever B encloses (is_highlight)
          if (!enclosing) {
            enclosing.emplace(parts.pixels[static_cast<std::size_t>(bi)], std::vector<std::int32_t>{});
            auto& [pixels, inside] = *enclosing;
            inside = enclosed_parts(work, parts.id, parts.pixels, bi, parts.pixels[static_cast<std::size_t>(bi)], pixels);
            inside.push_back(bi);
          }
          const auto& [pixels, inside] = *enclosing;
          const bool free = std::none_of(inside.begin(), inside.end(), [&](std::int32_t k) { return touched[static_cast<std::size_t>(k)] == 2 || k == ai; });
          for (const std::int32_t k : inside) in_inside[static_cast<std::size_t>(k)] = 1;
          const auto in_b = [&](std::size_t q) { return parts.id[q] >= 0 && in_inside[static_cast<std::size_t>(parts.id[q])] != 0; };
          const bool highlight = free && is_highlight(work, in_b, pixels, a, b);
          for (const std::int32_t k : inside) in_inside[static_cast<std::size_t>(k)] = 0;
          if (highlight) {
            join = true;
            ++out.highlight_merges;
            for (const std::int32_t k : inside)
              if (k != bi) {
                sets.join(parts.pixels[static_cast<std::size_t>(ai)].front(), parts.pixels[static_cast<std::size_t>(k)].front());
                touched[static_cast<std::size_t>(k)] = 2;
                joined.push_back(k);
              }
          }
        }
        if (!join) continue;
        sets.join(parts.pixels[static_cast<std::size_t>(ai)].front(), parts.pixels[static_cast<std::size_t>(bi)].front());
        touched[static_cast<std::size_t>(bi)] = 2;
        touched[static_cast<std::size_t>(ai)] = std::max<std::uint8_t>(touched[static_cast<std::size_t>(ai)], 1);
        joined.push_back(ai), joined.push_back(bi);
        ++merges;
        break;
      }
    }
    graph.fold(work, noise, sets, std::move(joined));
    progress.advance();
    if (merges == 0) break;
  }
}

// Step 6: parts smaller than `min_area` join the neighbour whose colours they share; then those one segment
// encloses join it as details finer than the smallest segment; the rest stay unassigned.
void absorb_small_parts(const Work& work, const NoiseModel& noise, double min_area, DisjointSets& sets, PartGraph& graph, StepShare& progress) {
  const Parts& parts = graph.parts;
  const Adjacency& adj = graph.adj;
  {
    const std::vector<PartStats>& stats = graph.stats;
    std::vector<std::int32_t> joined;
    for (std::size_t bi = 0; bi < parts.pixels.size(); ++bi) {
      if (!parts.alive(bi) || static_cast<double>(stats[bi].n) >= min_area) continue;
      for (const std::int32_t ai : adj.neighbours(static_cast<std::int32_t>(bi))) {
        const PartStats& a = stats[static_cast<std::size_t>(ai)];
        if (static_cast<double>(a.n) < min_area) continue;
        if (angle(stats[bi].direction, a.direction) <= std::max(a.spread, 3 * kMinAngle)) {
          sets.join(parts.pixels[static_cast<std::size_t>(ai)].front(), parts.pixels[bi].front());
          joined.push_back(ai), joined.push_back(static_cast<std::int32_t>(bi));
          break;
        }
      }
    }
    graph.keep_stats = false;  // not read again
    graph.fold(work, noise, sets, std::move(joined));
    progress.advance();
  }
  // Small parts that one segment encloses — nine tenths of their boundary with segments is with it, and at least
  // half their boundary is with segments (the rest with unassigned pixels) — are details of that object finer
  // than the smallest segment (speckle, embroidery, texture): they join it. A few passes take in clusters of them.
  for (int pass = 0; pass < 3; ++pass) {
    std::vector<std::int32_t> joined;
    for (std::size_t bi = 0; bi < parts.pixels.size(); ++bi) {
      if (!parts.alive(bi) || static_cast<double>(parts.pixels[bi].size()) >= min_area) continue;
      std::size_t best = 0, big = 0;
      std::int32_t to = -1;
      for (const std::int32_t ai : adj.neighbours(static_cast<std::int32_t>(bi))) {
        if (static_cast<double>(parts.pixels[static_cast<std::size_t>(ai)].size()) < min_area) continue;
        const std::size_t shared = adj.between(ai, static_cast<std::int32_t>(bi));
        big += shared;
        if (shared > best) best = shared, to = ai;
      }
      if (to >= 0 && double(best) >= kEnclosed * double(big) && 2 * big >= adj.perimeter[bi]) {
        sets.join(parts.pixels[static_cast<std::size_t>(to)].front(), parts.pixels[bi].front());
        joined.push_back(to), joined.push_back(static_cast<std::int32_t>(bi));
      }
    }
    const bool any = !joined.empty();
    graph.fold(work, noise, sets, std::move(joined));
    progress.advance();
    if (!any) break;
  }
}

// The segments of the working image: parts of at least `min_area` numbered by decreasing size (0 for the rest),
// with each segment's mean colour direction (index 0 unused).
struct WorkingLabels {
  std::vector<std::int32_t> label;  // per working pixel
  std::vector<Vec3> direction;      // per label
  std::vector<std::uint8_t> mixed;  // per working pixel: another label among its 8 neighbours
  std::size_t count() const { return direction.size() - 1; }
};

WorkingLabels number_segments(const Work& work, const Parts& parts, const NoiseModel& noise, double min_area) {
  std::vector<std::int32_t> order;
  for (std::size_t k = 0; k < parts.pixels.size(); ++k)
    if (static_cast<double>(parts.pixels[k].size()) >= min_area) order.push_back(static_cast<std::int32_t>(k));
  std::stable_sort(order.begin(), order.end(), [&](std::int32_t x, std::int32_t y) { return parts.pixels[static_cast<std::size_t>(x)].size() > parts.pixels[static_cast<std::size_t>(y)].size(); });
  std::vector<std::int32_t> label_of_part(parts.pixels.size(), 0);
  for (std::size_t k = 0; k < order.size(); ++k) label_of_part[static_cast<std::size_t>(order[k])] = static_cast<std::int32_t>(k) + 1;
  WorkingLabels out;
  out.label.assign(work.size(), 0);
  for (std::size_t q = 0; q < work.size(); ++q)
    if (parts.id[q] >= 0) out.label[q] = label_of_part[static_cast<std::size_t>(parts.id[q])];
  out.direction.assign(order.size() + 1, Vec3::Zero());
  for (std::size_t k = 0; k < order.size(); ++k) out.direction[k + 1] = part_stats(work, parts.pixels[static_cast<std::size_t>(order[k])], noise).direction;
  const int w = work.w, h = work.h;
  out.mixed.assign(work.size(), 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t q = static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
      for (int j = -1; j <= 1 && !out.mixed[q]; ++j)
        for (int i = -1; i <= 1; ++i) {
          const int nx = x + i, ny = y + j;
          if (nx >= 0 && ny >= 0 && nx < w && ny < h && out.label[static_cast<std::size_t>(ny) * static_cast<std::size_t>(w) + static_cast<std::size_t>(nx)] != out.label[q]) {
            out.mixed[q] = 1;
            break;
          }
        }
    }
  return out;
}

// Step 7 for one full-size pixel of colour `c` (linear) on working pixel (wx, wy) whose label and a neighbour's
// differ: the segment among the 3×3 working neighbourhood's labels whose colour direction is nearest; beside
// unassigned pixels, none if the pixel is too dark for a colour at full size (one full-size pixel has
// `area_factor` times the noise σ of a working pixel).
std::int32_t boundary_label(const Work& work, const WorkingLabels& labels, int wx, int wy, const Vec3& c, const NoiseModel& noise,
                            double area_factor, double dark) {
  const int w = work.w, h = work.h;
  std::int32_t label = labels.label[static_cast<std::size_t>(wy) * static_cast<std::size_t>(w) + static_cast<std::size_t>(wx)];
  std::int32_t candidates[9];
  int count = 0;
  bool beside_unassigned = false;
  for (int j = -1; j <= 1; ++j)
    for (int i = -1; i <= 1; ++i) {
      const int nx = wx + i, ny = wy + j;
      if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
      const std::int32_t l = labels.label[static_cast<std::size_t>(ny) * static_cast<std::size_t>(w) + static_cast<std::size_t>(nx)];
      if (l == 0) beside_unassigned = true;
      if (l > 0 && std::find(candidates, candidates + count, l) == candidates + count) candidates[count++] = l;
    }
  if (label > 0 && beside_unassigned) {
    double variance = 0;
    for (int k = 0; k < 3; ++k) variance += std::pow(noise.sigma(k, c[k]) * area_factor, 2);
    if (!(c.norm() > dark * std::sqrt(variance))) label = 0;
  }
  if (label > 0 && (count > 1 || candidates[0] != label) && c.norm() > 0) {
    double best = angle(c, labels.direction[static_cast<std::size_t>(label)]);
    for (int k = 0; k < count; ++k) {
      const double a = angle(c, labels.direction[static_cast<std::size_t>(candidates[k])]);
      if (a < best || (a == best && candidates[k] < label)) best = a, label = candidates[k];
    }
  }
  return label;
}

// Step 7: the labels carried back to full size, and the segments and the unassigned pixels as regions. Bands of
// rows run side by side, each with its own counts, added afterwards: the same whatever the thread count.
void labels_at_full_size(const RgbImage& image, const CodeDecoder& decode, const Work& work, const WorkingLabels& labels,
                         const NoiseModel& noise, double dark, Segmentation& out, StepShare& progress) {
  const int W = image.width, H = image.height, w = work.w, h = work.h;
  out.labels.assign(image.pixel_count(), 0);
  const bool same = W == w && H == h;
  const double area_factor = std::sqrt(static_cast<double>(image.pixel_count()) / static_cast<double>(work.size()));
  struct Counts {
    std::vector<std::size_t> per_label;
    std::size_t valid = 0, unassigned = 0, dark = 0, small = 0;
  };
  const std::size_t row_bands = std::min<std::size_t>(static_cast<std::size_t>(H), 64);
  std::vector<Counts> band_counts(row_bands);
  parallel_for(row_bands, 0, [&](std::size_t band) {
    Counts& bc = band_counts[band];
    bc.per_label.assign(labels.count() + 1, 0);
    for (int y = static_cast<int>(band * static_cast<std::size_t>(H) / row_bands); y < static_cast<int>((band + 1) * static_cast<std::size_t>(H) / row_bands); ++y) {
      const int wy = same ? y : std::min(h - 1, static_cast<int>((y + 0.5) * h / H));
      for (int x = 0; x < W; ++x) {
        const std::size_t p = static_cast<std::size_t>(y) * static_cast<std::size_t>(W) + static_cast<std::size_t>(x);
        const float* v = &image.rgb[p * 3];
        if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) continue;
        ++bc.valid;
        const int wx = same ? x : std::min(w - 1, static_cast<int>((x + 0.5) * w / W));
        const std::size_t q = static_cast<std::size_t>(wy) * static_cast<std::size_t>(w) + static_cast<std::size_t>(wx);
        std::int32_t label = labels.label[q];
        if (!same && labels.mixed[q]) label = boundary_label(work, labels, wx, wy, Vec3(decode(v[0]), decode(v[1]), decode(v[2])), noise, area_factor, dark);
        out.labels[p] = static_cast<std::uint16_t>(label);
        ++bc.per_label[static_cast<std::size_t>(label)];
        if (label == 0) {
          ++bc.unassigned;
          if (work.state[q] == kDark) ++bc.dark;
          else ++bc.small;
        }
      }
    }
    progress.advance();
  });
  std::vector<std::size_t> counts(labels.count() + 1, 0);
  for (const Counts& bc : band_counts) {
    for (std::size_t k = 0; k < counts.size(); ++k) counts[k] += bc.per_label[k];
    out.valid_pixels += bc.valid, out.unassigned_pixels += bc.unassigned, out.dark_pixels += bc.dark, out.small_pixels += bc.small;
  }
  for (std::size_t k = 1; k < counts.size(); ++k) {
    Region r{fmt::format("segment {}", k), "segment", static_cast<std::int64_t>(k), {}};
    r.pixels.reserve(counts[k]);
    out.regions.push_back(std::move(r));
  }
  Region unassigned{"unassigned", "unassigned", 0, {}};
  unassigned.pixels.reserve(counts[0]);
  for (std::size_t p = 0; p < out.labels.size(); ++p) {
    const std::int32_t l = out.labels[p];
    if (l > 0) out.regions[static_cast<std::size_t>(l - 1)].pixels.push_back(static_cast<std::uint32_t>(p));
    else if (std::isfinite(image.rgb[p * 3]) && std::isfinite(image.rgb[p * 3 + 1]) && std::isfinite(image.rgb[p * 3 + 2]))
      unassigned.pixels.push_back(static_cast<std::uint32_t>(p));
  }
  // A segment that lost every pixel to its neighbours on the boundaries keeps its number but is left out.
  std::erase_if(out.regions, [](const Region& r) { return r.pixels.empty(); });
  if (!unassigned.pixels.empty()) out.regions.push_back(std::move(unassigned));
}

}  // namespace

double NoiseModel::quantisation(double value) const {
  if (!integer) return 0.0;
  double step = 1.0;
  if (!codes.empty()) {
    const auto k = static_cast<std::size_t>(std::upper_bound(codes.begin(), codes.end(), static_cast<float>(value)) - codes.begin());
    const std::size_t hi = std::min(k, codes.size() - 1), lo = k > 0 ? std::min(k - 1, codes.size() - 2) : 0;
    step = double(codes[std::max(hi, lo + 1)]) - double(codes[lo]);
  }
  return step / std::sqrt(12.0 * averaged);
}

double NoiseModel::encode(double value) const {
  if (curve.empty()) return value;
  if (!(value > curve.front())) return 0.0;
  if (value >= curve.back()) return (static_cast<double>(curve.size()) - 1) * curve_step;
  const auto k = static_cast<std::size_t>(std::upper_bound(curve.begin(), curve.end(), static_cast<float>(value)) - curve.begin());
  const double lo = curve[k - 1], hi = curve[k];
  return (static_cast<double>(k - 1) + (hi > lo ? (value - lo) / (hi - lo) : 0.0)) * curve_step;
}

double NoiseModel::slope(double value) const {
  if (curve.empty()) return 1.0;
  const double code = encode(value) / curve_step;
  const auto k = std::min(static_cast<std::size_t>(std::max(0.0, code)), curve.size() - 2);
  return (double(curve[k + 1]) - double(curve[k])) / curve_step;
}

double NoiseModel::sigma(int channel, double value) const {
  const double q = quantisation(value);
  const double v = std::max(0.0, encode(value));
  const double measured = std::sqrt(std::max(0.0, a[channel] + b[channel] * v + c[channel] * v * v)) * slope(value);
  return std::max(floor, std::sqrt(measured * measured + q * q));
}

void check_segmentation_options(const SegmentationOptions& o) {
  auto check = [](bool ok, const char* option, double value, const char* range) {
    if (!ok) throw InputError(fmt::format("{}: must be {}, got {}", option, range, value));
  };
  check(o.working_megapixels >= 0.01 && o.working_megapixels <= 100, "--segment-size", o.working_megapixels, "in [0.01, 100] megapixels");
  check(o.min_area >= 2e-5 && o.min_area < 1, "--segment-min-area", o.min_area, "in [2e-5, 1)");
  check(o.tolerance > 0 && std::isfinite(o.tolerance), "--segment-tolerance", o.tolerance, "> 0");
  check(o.angle_deg >= 0 && o.angle_deg < 90, "--segment-angle", o.angle_deg, "in [0, 90) degrees");
  check(o.dark >= 0 && std::isfinite(o.dark), "--segment-dark", o.dark, ">= 0");
}

// The progress bar's shares of the steps, about their wall time in microseconds on a 2-core machine: steps 1 and 7
// (on every core) per pixel of the image, the others per working pixel, as measured on photographs from 0.06 to 24
// megapixels and synthetic mosaics (bench/README.md), so that the bar moves about evenly in time.
constexpr double kWorkingImageCost = 0.025, kFullSizeCost = 0.03;  // per pixel of the image
constexpr double kNoiseCost = 0.5, kDarkCost = 0.15, kEdgesCost = 0.7, kMergeCost = 0.5, kWeakCost = 0.6, kPartsCost = 0.2,
                 kExtendCost = 0.5, kSmallCost = 0.3;  // per working pixel

Segmentation segment_image(const RgbImage& image, const std::optional<ToneCurve>& curve, double full_scale, double clip_level,
                           const SegmentationOptions& options, bool progress) {
  const auto start = std::chrono::steady_clock::now();
  Segmentation out;
  out.options = options;
  out.width = image.width;
  out.height = image.height;
  const auto [ww, wh] = working_size(image.width, image.height, options.working_megapixels);
  const double pixels = static_cast<double>(image.pixel_count()), working = static_cast<double>(ww) * static_cast<double>(wh);
  Progress bar("segment",
               static_cast<std::size_t>(std::round(std::max(1.0, (kWorkingImageCost + kFullSizeCost) * pixels +
                                                              (kNoiseCost + kDarkCost + kEdgesCost + kMergeCost + kWeakCost + kPartsCost + kExtendCost + kSmallCost) * working))),
               progress);
  const CodeDecoder decode(curve, full_scale);
  std::optional<StepShare> step;  // the step under way (emplacing the next gives the bar the rest of its share)
  step.emplace(bar, kWorkingImageCost * pixels, 64);
  Work work = working_image(image, decode, clip_level, options.working_megapixels, *step);
  out.working_width = work.w;
  out.working_height = work.h;
  step.emplace(bar, kNoiseCost * working, 3);
  out.noise = measure_noise(work, decode, full_scale, pixels / static_cast<double>(work.size()), *step);
  step.emplace(bar, kDarkCost * working, 1);
  set_aside_dark(work, out.noise, options.dark);
  step.emplace(bar, kEdgesCost * working, 1);
  ColourClusters clusters(work, out.noise, options);
  step.emplace(bar, kMergeCost * working, 16);
  clusters.merge_along_edges(*step);
  step.emplace(bar, kWeakCost * working, 4);
  clusters.join_across_weak_boundaries(*step);
  step.emplace(bar, kPartsCost * working, 1);
  PartGraph graph(work, clusters.sets, out.noise);
  out.parts = graph.parts.pixels.size();
  step.emplace(bar, kExtendCost * working, 4);
  extend_over_dichromatic_planes(work, out.noise, clusters.sets, graph, out, *step);
  const double min_area = std::max(1.0, options.min_area * static_cast<double>(work.valid));
  step.emplace(bar, kSmallCost * working, 4);
  absorb_small_parts(work, out.noise, min_area, clusters.sets, graph, *step);
  step.emplace(bar, kFullSizeCost * pixels, 64);
  labels_at_full_size(image, decode, work, number_segments(work, graph.parts, out.noise, min_area), out.noise, options.dark, out, *step);
  step.reset();
  bar.finish();
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace ct::analyzer
