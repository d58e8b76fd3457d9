// SPDX-License-Identifier: Apache-2.0
#include "sensor_sim/sensor_rows.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/core.h>

#include "core/error.h"
#include "core/parallel.h"

namespace ct::sensor {

std::vector<float> read_sensor_rows(SpectralExrReader& reader, const SpectralLayer& layer, int k, int y0, int y1,
                                    const std::vector<double>& lighting) {
  const SpectralExrInfo& info = reader.info();
  std::vector<float> values(to_size(k * (y1 - y0)) * to_size(info.width) * layer.channels.size());
  reader.read_rows(layer, k * y0, k * y1, values);
  const bool total = layer.component.empty();
  const auto bad = std::find_if(values.begin(), values.end(),
                                [total](float v) { return !std::isfinite(v) || (total && v < 0.0f); });
  if (bad != values.end()) {
    const std::size_t i = static_cast<std::size_t>(bad - values.begin()), bands = layer.channels.size();
    const std::size_t pixel = i / bands;
    throw InputError(fmt::format("{}: channel {}: value {} at pixel ({}, {}) is {}", info.file,
                                 layer.channels[i % bands], *bad, pixel % to_size(info.width),
                                 to_size(k * y0) + pixel / to_size(info.width),
                                 std::isfinite(*bad) ? "negative: a radiance is >= 0" : "not finite"));
  }
  if (!lighting.empty())
    for (std::size_t i = 0; i < values.size(); ++i)
      values[i] = static_cast<float>(values[i] * lighting[i % lighting.size()]);
  return values;
}

std::vector<float> linear_rows(const SensorRun& run, std::span<const float> spectral, int y0, int y1) {
  const std::size_t in_row = spectral.size() / to_size(y1 - y0);
  const std::size_t out_row = to_size(run.width()) * 3;
  std::vector<float> out(to_size(y1 - y0) * out_row);
  parallel_for(to_size(y1 - y0), run.threads, [&](std::size_t r) {
    const int y = y0 + static_cast<int>(r);
    linear_signal(run.model, spectral.subspan(r * in_row, in_row), y, y + 1,
                  std::span<float>(out).subspan(r * out_row, out_row));
  });
  return out;
}

std::vector<std::int32_t> sensor_ids(const std::vector<std::int32_t>& rendered, int in_width, int k, int width,
                                     int rows) {
  std::vector<std::int32_t> ids(to_size(width) * to_size(rows));
  std::map<std::int32_t, int> count;
  for (int r = 0; r < rows; ++r)
    for (int x = 0; x < width; ++x) {
      count.clear();
      for (int sy = 0; sy < k; ++sy)
        for (int sx = 0; sx < k; ++sx) ++count[rendered[to_size(r * k + sy) * to_size(in_width) + to_size(x * k + sx)]];
      ids[to_size(r) * to_size(width) + to_size(x)] =
          std::max_element(count.begin(), count.end(), [](auto& a, auto& b) { return a.second < b.second; })->first;
    }
  return ids;
}

}  // namespace ct::sensor
