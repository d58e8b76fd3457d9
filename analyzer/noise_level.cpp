#include "analyzer/noise_level.h"

#include <algorithm>
#include <cmath>
#include <limits>
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

double ImageNoise::band_sigma(std::size_t band, const Vec3& u) const {
  if (const auto& v = bands[band].model_variance) return std::sqrt(u.cwiseAbs2().dot(*v));
  const std::vector<float>& r = bands[band].residuals;
  std::vector<double> a(r.size() / 3);
  for (std::size_t i = 0; i < a.size(); ++i) a[i] = std::abs(r[i * 3] * u[0] + r[i * 3 + 1] * u[1] + r[i * 3 + 2] * u[2]);
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

std::vector<double> band_weights(const ImageNoise& noise, std::span<const float> rgb) {
  std::vector<double> weights(noise.bands.size(), 0.0);
  const std::size_t n = rgb.size() / 3;
  if (n == 0 || weights.empty()) return weights;
  for (std::size_t i = 0; i < n; ++i)
    weights[noise.band_of((double(rgb[i * 3]) + rgb[i * 3 + 1] + rgb[i * 3 + 2]) / 3.0)] += 1.0 / static_cast<double>(n);
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
