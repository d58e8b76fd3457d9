// SPDX-License-Identifier: Apache-2.0
#include "analyzer/colour_constancy.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "core/random.h"

namespace ct::analyzer {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

int gaussian_radius(double sigma) { return static_cast<int>(std::ceil(3.0 * sigma)); }

// The per-pixel magnitude of the order-n derivative of one smoothed channel.
cv::Mat derivative_magnitude(const cv::Mat& channel, int order, double sigma) {
  cv::Mat smooth;
  if (sigma > 0) {  // the kernel cut at 3σ, as the literature's code has it (and as the usable mask's erosion assumes)
    const int side = 2 * gaussian_radius(sigma) + 1;
    cv::GaussianBlur(channel, smooth, cv::Size(side, side), sigma, sigma, cv::BORDER_REFLECT);
  }
  else
    smooth = channel;
  if (order == 0) return cv::abs(smooth);
  // Central differences (OpenCV's Sobel with ksize 1 is [-1 0 1] along one axis, no smoothing across it), halved.
  const auto derivative = [&](const cv::Mat& m, int dx, int dy) {
    cv::Mat d;
    cv::Sobel(m, d, CV_64F, dx, dy, 1, dx + dy == 1 ? 0.5 : 1.0, 0.0, cv::BORDER_REFLECT);
    return d;
  };
  cv::Mat out;
  if (order == 1) {
    const cv::Mat fx = derivative(smooth, 1, 0), fy = derivative(smooth, 0, 1);
    cv::sqrt(fx.mul(fx) + fy.mul(fy), out);
  } else {
    const cv::Mat fxx = derivative(smooth, 2, 0), fyy = derivative(smooth, 0, 2);
    const cv::Mat fxy = derivative(derivative(smooth, 1, 0), 0, 1);
    cv::sqrt(fxx.mul(fxx) + 4.0 * fxy.mul(fxy) + fyy.mul(fyy), out);
  }
  return out;
}

}  // namespace

const std::vector<MinkowskiSettings>& baseline_methods() {
  static const std::vector<MinkowskiSettings> methods = {
      {"grey world", 0, 1.0, 0.0, "the scene's surfaces average to grey"},
      {"white patch", 0, kInfinity, 0.0, "the brightest unclipped surface in each channel is white"},
      {"shades of grey", 0, 6.0, 0.0, "the surfaces' sixth-power mean is grey (between grey world and white patch)"},
      {"grey edge 1", 1, 6.0, 1.0, "the differences between neighbouring surfaces average to grey"},
      {"grey edge 2", 2, 6.0, 1.0, "the surfaces' second differences average to grey"}};
  return methods;
}

Vec3 minkowski_estimate(std::span<const float> rgb, int width, int height, std::span<const std::uint8_t> usable,
                        const MinkowskiSettings& method) {
  return baseline_estimate(rgb, width, height, usable, method, 0).rgb;
}

BaselineEstimate baseline_estimate(std::span<const float> rgb, int width, int height, std::span<const std::uint8_t> usable,
                                   const MinkowskiSettings& method, int replicates, std::uint64_t seed) {
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  if (rgb.size() != 3 * pixels || (!usable.empty() && usable.size() != pixels) || method.order < 0 || method.order > 2)
    throw std::invalid_argument("baseline_estimate: sizes or order out of range");
  // Which pixels count: usable and finite, and for derivatives their whole neighbourhood so.
  cv::Mat keep(height, width, CV_8U);
  for (std::size_t i = 0; i < pixels; ++i) {
    const bool finite = std::isfinite(rgb[3 * i]) && std::isfinite(rgb[3 * i + 1]) && std::isfinite(rgb[3 * i + 2]);
    keep.data[i] = (usable.empty() || usable[i]) && finite ? 1 : 0;
  }
  if (method.order > 0) {
    const int reach = (method.sigma > 0 ? gaussian_radius(method.sigma) : 0) + method.order;
    cv::erode(keep, keep, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * reach + 1, 2 * reach + 1)),
              cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  }
  // Per block (about 8 × 8 of them) and channel: Σ m^p, or the maximum of m, and the pixels counted.
  const bool maximum = std::isinf(method.p);
  const auto power = [&](double m) {  // m^p: by multiplications for the usual p (1 and 6), std::pow otherwise
    if (method.p == 1.0) return m;
    if (method.p == 6.0) {
      const double m3 = m * m * m;
      return m3 * m3;
    }
    return std::pow(m, method.p);
  };
  const int side = std::max(1, (std::max(width, height) + 7) / 8);
  const int bx = (width + side - 1) / side, by = (height + side - 1) / side;
  const std::size_t blocks = static_cast<std::size_t>(bx) * static_cast<std::size_t>(by);
  std::vector<std::array<double, 3>> block_sum(blocks, {0.0, 0.0, 0.0});
  std::vector<std::size_t> block_count(blocks, 0);
  for (int c = 0; c < 3; ++c) {
    cv::Mat channel(height, width, CV_64F);
    for (std::size_t i = 0; i < pixels; ++i) {
      const float v = rgb[3 * i + static_cast<std::size_t>(c)];
      channel.at<double>(static_cast<int>(i)) = std::isfinite(v) ? v : 0.0;
    }
    const cv::Mat magnitude = derivative_magnitude(channel, method.order, method.sigma);
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
        if (!keep.data[i]) continue;
        const std::size_t b = static_cast<std::size_t>(y / side) * static_cast<std::size_t>(bx) + static_cast<std::size_t>(x / side);
        const double m = magnitude.at<double>(y, x);
        double& sum = block_sum[b][static_cast<std::size_t>(c)];
        sum = maximum ? std::max(sum, m) : sum + power(m);
        if (c == 0) ++block_count[b];
      }
  }
  // The estimate from a multiset of blocks (each block's weight: how often it was drawn).
  const auto estimate = [&](const std::vector<std::size_t>& weight) {
    Vec3 e = Vec3::Zero();
    std::size_t counted = 0;
    for (std::size_t b = 0; b < blocks; ++b) {
      if (weight[b] == 0 || block_count[b] == 0) continue;
      counted += weight[b] * block_count[b];
      for (int c = 0; c < 3; ++c) {
        const double v = block_sum[b][static_cast<std::size_t>(c)];
        e[c] = maximum ? std::max(e[c], v) : e[c] + static_cast<double>(weight[b]) * v;
      }
    }
    if (counted == 0) return std::pair<Vec3, std::size_t>(Vec3::Zero(), 0);
    if (!maximum)
      for (int c = 0; c < 3; ++c) e[c] = std::pow(e[c] / static_cast<double>(counted), 1.0 / method.p);
    const double norm = e.norm();
    return std::pair<Vec3, std::size_t>(norm > 0 ? Vec3(e / norm) : Vec3::Zero(), counted);
  };
  BaselineEstimate out;
  const auto [full, counted] = estimate(std::vector<std::size_t>(blocks, 1));
  out.rgb = full;
  out.pixels = counted;
  if (counted == 0 || replicates <= 0) return out;
  Random random(seed, 0x636f6c6f7572ull);  // "colour"
  double sum_squares = 0.0;
  int made = 0;
  for (int r = 0; r < replicates; ++r) {
    std::vector<std::size_t> weight(blocks, 0);
    for (std::size_t k = 0; k < blocks; ++k)
      ++weight[std::min(blocks - 1, static_cast<std::size_t>(random.uniform() * static_cast<double>(blocks)))];
    const Vec3 e = estimate(weight).first;
    if (e.isZero()) continue;
    const double angle = std::acos(std::clamp(e.dot(full), -1.0, 1.0)) * 180.0 / std::numbers::pi;
    sum_squares += angle * angle;
    ++made;
  }
  out.uncertainty_deg = made > 0 ? std::sqrt(sum_squares / made) : 0.0;
  return out;
}

}  // namespace ct::analyzer
