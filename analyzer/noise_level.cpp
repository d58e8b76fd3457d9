// SPDX-License-Identifier: Apache-2.0
#include "analyzer/noise_level.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>

#include "core/statistics.h"

namespace ct::analyzer {
namespace {

constexpr int kBands = 16;
constexpr std::size_t kPerBand = 4096;         // residuals kept per band, at an even stride
constexpr double kClip = 3;                    // the clip, in σ
constexpr double kTruncatedMedianAbs = 0.6727;  // the median of |N(0, 1)| given |N| < 3

}  // namespace

std::size_t ImageNoise::band_of(double brightness) const {
  if (bands.empty()) return 0;
  // The first band whose top is not below the brightness (the last for anything brighter; the first for NaN).
  const auto k = std::partition_point(bands.begin(), bands.end() - 1, [&](const Band& b) { return brightness > b.hi; });
  return static_cast<std::size_t>(k - bands.begin());
}

namespace {

// The noise σ of values |x| of which the flat areas' are Gaussian: from the lower quartile, then the median within
// kClip σ iterated to its fixed point (noise_level.h).
double clipped_sigma(std::vector<double>& a) {
  if (a.empty()) return 0.0;
  double sigma = quantile_in_place(a, 0.25) / kQuartileAbs;
  std::vector<double> inside;
  for (int iteration = 0; iteration < 50 && sigma > 0; ++iteration) {
    inside.clear();
    for (const double x : a)
      if (x <= kClip * sigma) inside.push_back(x);
    if (inside.size() < 8) break;
    const double next = quantile_in_place(inside, 0.5) / kTruncatedMedianAbs;
    const bool settled = std::abs(next - sigma) <= 1e-4 * sigma;
    sigma = next;
    if (settled) break;
  }
  return sigma;
}

}  // namespace

double ImageNoise::band_sigma(std::size_t band, const Vec3& u) const {
  if (const auto& v = bands[band].model_variance) return std::sqrt(u.cwiseAbs2().dot(*v));
  const std::vector<float>& r = bands[band].residuals;
  std::vector<double> a(r.size() / 3);
  for (std::size_t i = 0; i < a.size(); ++i) a[i] = std::abs(r[i * 3] * u[0] + r[i * 3 + 1] * u[1] + r[i * 3 + 2] * u[2]);
  return clipped_sigma(a);
}

namespace {

// A deterministic dither in [−½, ½) for value `index` (SplitMix64 of it).
double dither(std::uint64_t index) {
  std::uint64_t z = index + 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) / 9007199254740992.0 - 0.5;
}

// Residual pairs at one spacing: each sampled pixel's residual over its band's σ with its neighbour's s pixels to the
// right and s pixels down, per channel, and the 4 × 4 tile each pair lies in.
struct Pairs {
  std::array<std::vector<double>, 3> u, v;
  std::vector<std::uint8_t> tile;
};

// Gnanadesikan–Kettenring: the correlation of u and v from the robust σ of their sum and difference.
double robust_correlation(const std::vector<double>& u, const std::vector<double>& v, const std::vector<std::uint8_t>& tile, int left_out) {
  std::vector<double> plus, minus;
  plus.reserve(u.size()), minus.reserve(u.size());
  for (std::size_t i = 0; i < u.size(); ++i) {
    if (tile[i] == left_out) continue;
    plus.push_back(std::abs(u[i] + v[i]) / std::numbers::sqrt2);
    minus.push_back(std::abs(u[i] - v[i]) / std::numbers::sqrt2);
  }
  const double p = clipped_sigma(plus), m = clipped_sigma(minus);
  return p * p + m * m > 0 ? (p * p - m * m) / (p * p + m * m) : 0.0;
}

SpacingTest test_spacing(const RgbImage& image, const std::array<double, 3>& low, const std::array<double, 3>& high, double step, int spacing) {
  constexpr double kWhite = -2.0 / 3.0;
  constexpr int kTiles = 4;
  constexpr std::size_t kMaxSamples = std::size_t{1} << 15;
  SpacingTest t;
  t.spacing = spacing;
  const std::size_t w = static_cast<std::size_t>(std::max(0, image.width)), h = static_cast<std::size_t>(std::max(0, image.height));
  const std::size_t s = static_cast<std::size_t>(spacing);
  if (w < 4 * s + 1 || h < 4 * s + 1) return t;
  const auto value = [&](std::size_t q, std::size_t c) {
    const double v = image.rgb[q * 3 + c];
    return step > 0 ? v + step * dither(q * 3 + c) : v;
  };
  const auto usable = [&](std::size_t q) {
    for (std::size_t c = 0; c < 3; ++c) {
      const double v = image.rgb[q * 3 + c];
      if (!std::isfinite(v) || !(v > low[c]) || !(v < high[c])) return false;
    }
    return true;
  };
  // Pixels whose own and both neighbours' masks lie inside the image: [s, w − 2s) × [s, h − 2s).
  const std::size_t iw = w - 3 * s, ih = h - 3 * s, interior = iw * ih;
  const std::size_t stride = std::max<std::size_t>(1, interior / kMaxSamples);
  struct Sample {
    double brightness;
    std::array<double, 9> r;  // own, right, down × R, G, B
    std::uint8_t tile;
  };
  std::vector<Sample> samples;
  for (std::size_t i = 0; i < interior; i += stride) {
    const std::size_t x = s + i % iw, y = s + i / iw, p = y * w + x;
    Sample a{};
    bool ok = true;
    const std::size_t at[3] = {p, p + s, p + s * w};
    for (std::size_t k = 0; k < 3 && ok; ++k)
      for (std::size_t c = 0; c < 3 && ok; ++c) {
        const auto m = immerkaer_response(at[k], w, s, [&](std::size_t q) { return value(q, c); }, usable);
        ok = m.has_value();
        if (ok) a.r[k * 3 + c] = *m / kImmerkaerGain;
      }
    if (!ok) continue;
    a.brightness = (double(image.rgb[p * 3]) + image.rgb[p * 3 + 1] + image.rgb[p * 3 + 2]) / 3;
    a.tile = static_cast<std::uint8_t>((y * kTiles / h) * kTiles + x * kTiles / w);
    samples.push_back(a);
  }
  if (samples.size() < static_cast<std::size_t>(kBands) * 64) return t;
  // Bands of brightness, each its own σ per channel.
  std::stable_sort(samples.begin(), samples.end(), [](const Sample& a, const Sample& b) { return a.brightness < b.brightness; });
  std::array<std::vector<double>, 3> band_sigma;
  std::vector<std::size_t> band_of(samples.size());
  for (int band = 0; band < kBands; ++band) {
    const std::size_t from = samples.size() * static_cast<std::size_t>(band) / kBands, to = samples.size() * static_cast<std::size_t>(band + 1) / kBands;
    for (std::size_t i = from; i < to; ++i) band_of[i] = static_cast<std::size_t>(band);
    for (std::size_t c = 0; c < 3; ++c) {
      std::vector<double> a;
      for (std::size_t i = from; i < to; ++i) a.push_back(std::abs(samples[i].r[c]));
      band_sigma[c].push_back(clipped_sigma(a));
    }
  }
  // The rounding and the dither are white and add 2 · step²/12 to each pixel's variance: they pull the correlation
  // towards −2/3 by their share of it, undone here; a channel where they are most of it (or whose residuals are
  // exactly 0 in most bands: compressed away) tells nothing.
  std::array<double, 3> scale{1, 1, 1};
  for (std::size_t c = 0; c < 3; ++c) {
    std::vector<double> squares;
    std::size_t zero = 0;
    for (const double b : band_sigma[c]) squares.push_back(b * b), zero += b == 0;
    const double variance = quantile(squares, 0.5), rounding = step > 0 ? 2 * step * step / 12 : 0.0;
    if (2 * zero > band_sigma[c].size() || !(variance > 1.5 * rounding) || !(variance > 0)) return t;
    scale[c] = variance / (variance - rounding);
  }
  // Pairs of samples whose band has a σ in every channel, so that the channels' pairs share their tiles.
  Pairs pairs;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const std::size_t band = band_of[i];
    if (!(band_sigma[0][band] > 0 && band_sigma[1][band] > 0 && band_sigma[2][band] > 0)) continue;
    for (const std::size_t k : {std::size_t{1}, std::size_t{2}}) {  // right, down
      for (std::size_t c = 0; c < 3; ++c) {
        pairs.u[c].push_back(samples[i].r[c] / band_sigma[c][band]);
        pairs.v[c].push_back(samples[i].r[k * 3 + c] / band_sigma[c][band]);
      }
      pairs.tile.push_back(samples[i].tile);
    }
  }
  const auto departure = [&](int left_out) {
    double d = 0;
    for (std::size_t c = 0; c < 3; ++c) d = std::max(d, std::abs(robust_correlation(pairs.u[c], pairs.v[c], pairs.tile, left_out) - kWhite) * scale[c]);
    return d;
  };
  t.departure = departure(-1);
  std::vector<double> jack;
  for (int k = 0; k < kTiles * kTiles; ++k) jack.push_back(departure(k));
  const double mean = std::accumulate(jack.begin(), jack.end(), 0.0) / static_cast<double>(jack.size());
  double ss = 0;
  for (const double d : jack) ss += (d - mean) * (d - mean);
  t.standard_error = std::sqrt(static_cast<double>(jack.size() - 1) / static_cast<double>(jack.size()) * ss);
  t.measurable = true;
  return t;
}

}  // namespace

SpacingChoice choose_noise_spacing(const RgbImage& image, const std::array<double, 3>& low_levels,
                                   const std::array<double, 3>& high_levels, double step) {
  SpacingChoice choice;
  for (int s = 1; s <= kInterpolatedNoiseSpacing; ++s) choice.tests.push_back(test_spacing(image, low_levels, high_levels, step, s));
  choice.spacing = kInterpolatedNoiseSpacing;
  for (const SpacingTest& t : choice.tests)
    if (t.measurable && t.departure + 2 * t.standard_error <= kSpacingTolerance) {
      choice.spacing = t.spacing;
      choice.confirmed = true;
      break;
    }
  // Still shared at the farthest spacing (only asked when no spacing was shown independent).
  const SpacingTest& last = choice.tests.back();
  choice.correlated_beyond = !choice.confirmed && last.measurable && last.departure > kCorrelatedBeyond + 3 * last.standard_error;
  return choice;
}

ImageNoise estimate_image_noise(const RgbImage& image, const std::array<double, 3>& low_levels, const std::array<double, 3>& high_levels,
                                double floor, int spacing, std::size_t max_pixels) {
  ImageNoise noise;
  noise.floor = floor;
  noise.spacing = std::max(1, spacing);
  const std::size_t w = static_cast<std::size_t>(std::max(0, image.width)), h = static_cast<std::size_t>(std::max(0, image.height));
  const std::size_t s = static_cast<std::size_t>(noise.spacing);
  if (w < 2 * s + 1 || h < 2 * s + 1) return noise;
  // Whether each pixel may enter a neighbourhood: finite and strictly between every channel's limits.
  std::vector<std::uint8_t> usable(w * h);
  for (std::size_t p = 0; p < w * h; ++p) {
    bool ok = true;
    for (std::size_t c = 0; c < 3; ++c) ok = ok && std::isfinite(image.rgb[p * 3 + c]) && image.rgb[p * 3 + c] > low_levels[c] && image.rgb[p * 3 + c] < high_levels[c];
    usable[p] = ok;
  }
  const std::size_t interior = (w - 2 * s) * (h - 2 * s);
  const std::size_t stride = std::max<std::size_t>(1, interior / std::max<std::size_t>(1, max_pixels));
  std::vector<std::pair<double, std::array<float, 3>>> found;  // (brightness, residual / 6)
  std::vector<double> brightness;  // of every finite pixel visited: the bands are its quantiles
  for (std::size_t i = 0; i < interior; i += stride) {
    const std::size_t x = s + i % (w - 2 * s), y = s + i / (w - 2 * s);
    const float* centre = &image.rgb[(y * w + x) * 3];
    const double level = (double(centre[0]) + centre[1] + centre[2]) / 3.0;
    if (!std::isfinite(level)) continue;
    brightness.push_back(level);
    std::array<float, 3> r{};
    bool ok = true;
    for (std::size_t c = 0; c < 3 && ok; ++c) {
      const auto m = immerkaer_response(y * w + x, w, s, [&](std::size_t q) { return image.rgb[q * 3 + c]; }, [&](std::size_t q) { return usable[q] != 0; });
      ok = m.has_value();
      if (ok) r[c] = static_cast<float>(*m / kImmerkaerGain);
    }
    if (ok) found.push_back({level, r});
  }
  noise.pixels = found.size();
  if (found.size() < static_cast<std::size_t>(kBands) * 16) return noise;
  // The bands are brightness quantiles of every finite pixel, so that which pixels have a residual (clamped or
  // clipped ones have none) does not move them.
  std::sort(brightness.begin(), brightness.end());
  noise.bands.resize(kBands);
  for (int band = 0; band < kBands; ++band) {
    noise.bands[static_cast<std::size_t>(band)].lo = brightness[brightness.size() * static_cast<std::size_t>(band) / kBands];
    noise.bands[static_cast<std::size_t>(band)].hi = brightness[(brightness.size() * static_cast<std::size_t>(band + 1) - 1) / kBands];
  }
  std::stable_sort(found.begin(), found.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<std::vector<std::size_t>> members(kBands);
  for (std::size_t i = 0; i < found.size(); ++i) members[noise.band_of(found[i].first)].push_back(i);
  for (std::size_t band = 0; band < members.size(); ++band) {
    const std::size_t step = std::max<std::size_t>(1, members[band].size() / kPerBand);
    for (std::size_t k = 0; k < members[band].size(); k += step)
      noise.bands[band].residuals.insert(noise.bands[band].residuals.end(), found[members[band][k]].second.begin(), found[members[band][k]].second.end());
  }
  // A band with too few residuals (its pixels clamped, clipped or all of one brightness) takes the nearest band's.
  const std::vector<ImageNoise::Band> measured = noise.bands;
  for (std::size_t band = 0; band < noise.bands.size(); ++band) {
    if (measured[band].residuals.size() >= 16 * 3) continue;
    for (std::size_t d = 1; d < measured.size(); ++d) {
      if (band >= d && measured[band - d].residuals.size() >= 16 * 3) {
        noise.bands[band].residuals = measured[band - d].residuals;
        break;
      }
      if (band + d < measured.size() && measured[band + d].residuals.size() >= 16 * 3) {
        noise.bands[band].residuals = measured[band + d].residuals;
        break;
      }
    }
  }
  return noise;
}

constexpr std::size_t kWeightSamples = std::size_t{1} << 20;

std::vector<double> band_weights(const ImageNoise& noise, std::span<const float> rgb) {
  std::vector<double> weights(noise.bands.size(), 0.0);
  const std::size_t n = rgb.size() / 3;
  if (n == 0 || weights.empty()) return weights;
  // Shares of the samples: from at most 2²⁰ of them at an even stride (a share's standard error under 0.001).
  const std::size_t stride = (n + kWeightSamples - 1) / kWeightSamples;
  std::size_t used = 0;
  for (std::size_t i = 0; i < n; i += stride, ++used)
    weights[noise.band_of((double(rgb[i * 3]) + rgb[i * 3 + 1] + rgb[i * 3 + 2]) / 3.0)] += 1.0;
  for (double& w : weights) w /= static_cast<double>(used);
  return weights;
}

void use_camera_noise(ImageNoise& noise, const RgbImage& layer, const CameraNoiseModel& model) {
  const std::size_t n = layer.pixel_count();
  if (noise.bands.empty()) {
    ImageNoise::Band all;
    all.lo = std::numeric_limits<double>::infinity(), all.hi = -all.lo;
    for (std::size_t p = 0; p < n; ++p) {
      const double b = (double(layer.rgb[3 * p]) + layer.rgb[3 * p + 1] + layer.rgb[3 * p + 2]) / 3;
      if (std::isfinite(b)) all.lo = std::min(all.lo, b), all.hi = std::max(all.hi, b);
    }
    if (!(all.lo <= all.hi)) all.lo = all.hi = 0;
    noise.bands.push_back(std::move(all));
  }
  std::vector<Vec3> sum(noise.bands.size(), Vec3::Zero());
  std::vector<double> count(noise.bands.size(), 0.0);
  for (std::size_t p = 0; p < n; ++p) {
    const Vec3 v(layer.rgb[3 * p], layer.rgb[3 * p + 1], layer.rgb[3 * p + 2]);
    if (!v.allFinite()) continue;
    const std::size_t k = noise.band_of(v.mean());
    sum[k] += v;
    count[k] += 1;
  }
  for (std::size_t k = 0; k < noise.bands.size(); ++k) {
    ImageNoise::Band& band = noise.bands[k];
    const Vec3 mean = count[k] > 0 ? Vec3(sum[k] / count[k]) : Vec3::Constant((band.lo + band.hi) / 2);
    band.model_variance = Vec3(model.variance(mean[0]), model.variance(mean[1]), model.variance(mean[2]));
  }
  noise.camera = model;
}

double noise_sigma(const ImageNoise& noise, std::span<const double> weights, const Vec3& u) {
  double variance = 0;
  for (std::size_t k = 0; k < weights.size() && k < noise.bands.size(); ++k)
    if (weights[k] > 0) variance += weights[k] * std::pow(noise.band_sigma(k, u), 2);
  return std::max(noise.floor, std::sqrt(variance));
}

}  // namespace ct::analyzer
