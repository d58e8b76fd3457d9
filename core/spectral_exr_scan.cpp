// SPDX-License-Identifier: Apache-2.0
#include "core/spectral_exr_scan.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <tuple>

#include "core/exr_vocabulary.h"

namespace ct {
namespace {

// Blocks of about this many bytes keep memory flat for any image size; whole multiples of 32 rows keep
// reads on chunk boundaries for the usual compressions (ZIP: 16 rows, PIZ/B44: 32).
constexpr std::size_t kBlockBytes = std::size_t{64} << 20;

int block_rows(const SpectralExrInfo& info, std::size_t channel_count) {
  const std::size_t row_bytes = static_cast<std::size_t>(info.width) * channel_count * sizeof(float);
  std::size_t rows = std::max<std::size_t>(1, kBlockBytes / std::max<std::size_t>(row_bytes, 1));
  if (rows >= 32) rows -= rows % 32;
  return static_cast<int>(std::min<std::size_t>(rows, static_cast<std::size_t>(info.height)));
}

// Where in a pixel's channel values the total and the components of one sum check sit.
struct SumPlan {
  ComponentSumCheck check;
  const std::vector<std::string>* total_channels = nullptr;
  std::size_t total_offset = 0;
  std::vector<std::size_t> component_offsets;
};

std::vector<SumPlan> plan_sum_checks(const SpectralExrInfo& info, const std::vector<std::size_t>& layer_offsets) {
  std::vector<SumPlan> plans;
  for (std::size_t l = 0; l < info.layers.size(); ++l) {
    const SpectralLayer& layer = info.layers[l];
    const ComponentFamily family = component_family(layer.component);
    if (layer.component.empty() || family == ComponentFamily::Unknown) continue;
    auto plan = std::find_if(plans.begin(), plans.end(), [&](const SumPlan& p) {
      return p.check.family == family && p.check.quantity == layer.quantity;
    });
    if (plan == plans.end()) {
      plans.emplace_back();
      plan = plans.end() - 1;
      plan->check.family = family;
      plan->check.quantity = layer.quantity;
    }
    plan->check.components.push_back(layer.component);
    plan->component_offsets.push_back(layer_offsets[l]);
  }
  for (SumPlan& plan : plans) {
    const auto total = std::find_if(info.layers.begin(), info.layers.end(), [&](const SpectralLayer& layer) {
      return layer.component.empty() && layer.quantity == plan.check.quantity;
    });
    const bool complete =
        plan.check.family != ComponentFamily::PathType || path_types_complete(plan.check.components);
    plan.check.checked = complete && total != info.layers.end();
    if (total != info.layers.end()) {
      plan.total_channels = &total->channels;
      plan.total_offset = layer_offsets[static_cast<std::size_t>(total - info.layers.begin())];
    }
  }
  std::sort(plans.begin(), plans.end(), [](const SumPlan& a, const SumPlan& b) {
    return std::tie(a.check.family, a.check.quantity) < std::tie(b.check.family, b.check.quantity);
  });
  return plans;
}

void check_sums(SumPlan& plan, const float* pixel, std::size_t bands, int x, int y) {
  for (std::size_t i = 0; i < bands; ++i) {
    const double total = pixel[plan.total_offset + i];
    bool finite = std::isfinite(total);
    double sum = 0;
    double magnitude = 0;
    for (std::size_t offset : plan.component_offsets) {
      const double value = pixel[offset + i];
      finite = finite && std::isfinite(value);
      sum += value;
      magnitude += std::abs(value);
    }
    if (!finite) continue;
    const double tolerance = component_sum_tolerance(plan.component_offsets.size(), magnitude);
    const double ratio = std::abs(sum - total) / tolerance;
    ComponentSumCheck& check = plan.check;
    if (ratio > check.worst_ratio || check.channel.empty()) {
      check.worst_ratio = ratio;
      check.channel = (*plan.total_channels)[i];
      check.x = x;
      check.y = y;
      check.sum = sum;
      check.total = total;
      check.tolerance = tolerance;
    }
  }
}

}  // namespace

double component_sum_tolerance(std::size_t component_count, double magnitude) {
  // Each stored float is its exact value rounded once: relative error <= u = 2^-24 for normal numbers,
  // absolute <= 2^-150 in the subnormal range. If the renderer rounds n components and their (exactly
  // summed) total, |Σ c − total| <= (n + 1)(u·Σ|c| + 2^-150). If it instead sums the float components
  // in float, recursive summation puts the total within (n − 1)·u·Σ|c| (first order). Twice the first
  // bound covers both; the sum here is taken in double, whose own error (n·2^-53·Σ|c|) is negligible.
  const double n = static_cast<double>(component_count);
  return (n + 1) * (std::ldexp(magnitude, -23) + std::ldexp(1.0, -149));
}

SpectralExrScan scan_spectral_exr(SpectralExrReader& reader, const ScanOptions& options) {
  const SpectralExrInfo& info = reader.info();
  const SpectralLayer& total = info.total();  // an InputError for a file without spectral channels

  std::vector<std::string> channels;
  std::vector<std::size_t> layer_offsets;
  std::size_t total_offset = 0;
  for (const SpectralLayer& layer : info.layers) {
    if (&layer == &total) total_offset = channels.size();
    layer_offsets.push_back(channels.size());
    channels.insert(channels.end(), layer.channels.begin(), layer.channels.end());
  }
  channels.insert(channels.end(), info.reradiation_channels.begin(), info.reradiation_channels.end());
  if (info.has_object_ids) channels.push_back("object_id");

  const std::size_t bands = total.channels.size();
  const std::size_t width = static_cast<std::size_t>(info.width);
  std::vector<SumPlan> plans;
  if (options.check_components) plans = plan_sum_checks(info, layer_offsets);

  std::vector<std::uint64_t> non_finite(channels.size(), 0);
  std::vector<std::pair<int, int>> first_non_finite(channels.size());
  std::vector<double> minimum(bands, std::numeric_limits<double>::infinity());
  std::vector<double> maximum(bands, -std::numeric_limits<double>::infinity());
  std::vector<double> sum(bands, 0.0);
  std::vector<std::uint64_t> finite(bands, 0);

  const int rows_per_block = block_rows(info, channels.size());
  std::vector<float> block(static_cast<std::size_t>(rows_per_block) * width * channels.size());
  for (int y0 = 0; y0 < info.height; y0 += rows_per_block) {
    const int y1 = std::min(info.height, y0 + rows_per_block);
    const std::size_t pixels = static_cast<std::size_t>(y1 - y0) * width;
    const std::span<float> values(block.data(), pixels * channels.size());
    reader.read_channels(channels, y0, y1, values);
    for (std::size_t p = 0; p < pixels; ++p) {
      const float* pixel = values.data() + p * channels.size();
      const int x = static_cast<int>(p % width);
      const int y = y0 + static_cast<int>(p / width);
      for (std::size_t c = 0; c < channels.size(); ++c)
        if (!std::isfinite(pixel[c]) && non_finite[c]++ == 0) first_non_finite[c] = {x, y};
      if (info.has_object_ids && std::isfinite(pixel[channels.size() - 1]))  // a NaN is counted as non-finite
        exr::check_object_id(pixel[channels.size() - 1], info.file, static_cast<std::size_t>(x),
                             static_cast<std::size_t>(y));
      for (std::size_t i = 0; i < bands; ++i) {
        const double value = pixel[total_offset + i];
        if (!std::isfinite(value)) continue;
        minimum[i] = std::min(minimum[i], value);
        maximum[i] = std::max(maximum[i], value);
        sum[i] += value;
        ++finite[i];
      }
      for (SumPlan& plan : plans)
        if (plan.check.checked) check_sums(plan, pixel, bands, x, y);
    }
    if (options.progress) options.progress(y1);
  }

  SpectralExrScan scan;
  for (std::size_t c = 0; c < channels.size(); ++c)
    if (non_finite[c] > 0)
      scan.non_finite.push_back({channels[c], non_finite[c], first_non_finite[c].first, first_non_finite[c].second});
  for (std::size_t i = 0; i < bands; ++i) {
    if (finite[i] == 0)
      scan.total_statistics.push_back({});
    else
      scan.total_statistics.push_back({minimum[i], sum[i] / static_cast<double>(finite[i]), maximum[i], finite[i]});
  }
  for (SumPlan& plan : plans) scan.component_sums.push_back(std::move(plan.check));
  return scan;
}

std::vector<NonFiniteCount> scan_non_finite(SpectralExrReader& reader) {
  const SpectralExrInfo& info = reader.info();
  std::vector<std::string> channels;
  for (const ExrChannel& c : info.channels) channels.push_back(c.name);
  const std::size_t width = static_cast<std::size_t>(info.width);
  std::vector<std::uint64_t> count(channels.size(), 0);
  std::vector<std::pair<int, int>> first(channels.size());
  const int rows_per_block = block_rows(info, channels.size());
  std::vector<float> block(static_cast<std::size_t>(rows_per_block) * width * channels.size());
  for (int y0 = 0; y0 < info.height; y0 += rows_per_block) {
    const int y1 = std::min(info.height, y0 + rows_per_block);
    const std::size_t pixels = static_cast<std::size_t>(y1 - y0) * width;
    reader.read_channels(channels, y0, y1, std::span<float>(block.data(), pixels * channels.size()));
    for (std::size_t p = 0; p < pixels; ++p)
      for (std::size_t c = 0; c < channels.size(); ++c)
        if (!std::isfinite(block[p * channels.size() + c]) && count[c]++ == 0)
          first[c] = {static_cast<int>(p % width), y0 + static_cast<int>(p / width)};
  }
  std::vector<NonFiniteCount> found;
  for (std::size_t c = 0; c < channels.size(); ++c)
    if (count[c] > 0) found.push_back({channels[c], count[c], first[c].first, first[c].second});
  return found;
}

}  // namespace ct
