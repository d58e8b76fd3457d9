// SPDX-License-Identifier: Apache-2.0
#include "sensor_sim/exposure.h"

#include <algorithm>

#include <fmt/core.h>

#include "core/error.h"
#include "core/statistics.h"

namespace ct::sensor {
namespace {

// Sensor rows the display's exposure statistics sample: every row of small images; of larger ones the rows
// of every n-th group of 16 rendered rows (one ZIP chunk), n = ⌊groups / 8⌋, so that about 8 groups are read.
bool display_sample_row(int y, int k, int height) {
  const int groups = (k * height + kChunkRows - 1) / kChunkRows;
  const int stride = std::max(1, groups / 8);
  return (k * y / kChunkRows) % stride == 0;
}

}  // namespace

std::vector<RowRange> survey_rows(bool all_rows, int k, int height, int rows_per_block) {
  std::vector<RowRange> ranges;
  for (int y = 0; y < height;) {
    if (!all_rows && !display_sample_row(y, k, height)) {
      ++y;
      continue;
    }
    int end = y + 1;
    while (end < height && end - y < rows_per_block && (all_rows || display_sample_row(end, k, height))) ++end;
    ranges.push_back({y, end});
    y = end;
  }
  return ranges;
}

Survey survey_image(SpectralExrReader& reader, const SensorRun& unit_run, const SpectralLayer& total,
                    const SpectralLayer* emission, const std::set<std::int32_t>& lights,
                    const std::vector<RowRange>& ranges, bool want_display, Progress& progress) {
  const SpectralExrInfo& info = reader.info();
  const int k = unit_run.model.supersample, width = unit_run.width(), height = unit_run.height();
  const std::size_t bands = info.bands.size();
  const bool ids_needed = info.has_object_ids && (!lights.empty() || want_display);
  Survey s;
  for (const RowRange& range : ranges) {
    const int y0 = range.first, y1 = range.last;
    const std::vector<float> total_spectra = read_sensor_rows(reader, total, k, y0, y1, unit_run.lighting);
    const std::vector<float> linear = linear_rows(unit_run, total_spectra, y0, y1);
    std::vector<float> emission_spectra, emission_linear;
    if (emission != nullptr) {
      emission_spectra = read_sensor_rows(reader, *emission, k, y0, y1, unit_run.lighting);
      emission_linear = linear_rows(unit_run, emission_spectra, y0, y1);
    }
    std::vector<std::int32_t> ids;
    if (ids_needed) {
      std::vector<std::int32_t> rendered(to_size(k * (y1 - y0)) * to_size(info.width));
      reader.read_object_ids(k * y0, k * y1, rendered);
      ids = k == 1 ? rendered : sensor_ids(rendered, info.width, k, width, y1 - y0);
    }
    for (int r = 0; r < y1 - y0; ++r) {
      const bool sampled = want_display && display_sample_row(y0 + r, k, height);
      for (int x = 0; x < width; ++x) {
        const std::size_t p = to_size(r) * to_size(width) + to_size(x);
        const float* c = linear.data() + 3 * p;
        const double sum = double(c[0]) + c[1] + c[2];
        for (int ch = 0; ch < 3; ++ch) s.signal_sum[to_size(ch)] += c[ch];
        ++s.pixels;
        bool emitter = false;
        if (!emission_linear.empty()) {
          const float* e = emission_linear.data() + 3 * p;
          emitter = sum > 0 && double(e[0]) + e[1] + e[2] > 0.5 * sum;
        }
        const std::int32_t id = ids.empty() ? -1 : ids[p];
        if (!ids.empty() && lights.contains(id)) emitter = true;
        (emitter ? s.emitters : s.surfaces).push_back(std::max({c[0], c[1], c[2]}));
        if (!want_display) continue;
        if (!emitter) {
          if (sampled) s.display_samples.insert(s.display_samples.end(), c, c + 3);
          continue;
        }
        // A white to balance on is a light's: where the file names its objects, only the scene's lights seen
        // directly count, never a surface or the environment showing through at an edge.
        if (!ids.empty() && !lights.contains(id)) continue;
        // The emitter's spectrum as seen: its emission (or, without that layer, its total) over the k×k
        // rendered pixels.
        const std::vector<float>& spectra = emission_spectra.empty() ? total_spectra : emission_spectra;
        auto& [sum_bands, count] = s.emitter_spectra[id];
        sum_bands.resize(bands, 0.0);
        for (int sy = 0; sy < k; ++sy)
          for (int sx = 0; sx < k; ++sx) {
            const float* l = spectra.data() +
                             (to_size(r * k + sy) * to_size(info.width) + to_size(x * k + sx)) * bands;
            for (std::size_t b = 0; b < bands; ++b) sum_bands[b] += l[b] / double(k * k);
          }
        ++count;
      }
    }
    progress.advance();
  }
  return s;
}

double auto_exposure(Survey& survey, const SensorConfig& config, const std::string& file,
                     std::vector<std::string>& notes) {
  const ExposureConfig& e = config.exposure;
  std::vector<float>& values = survey.surfaces;
  std::string what = "of the brightest channel";
  if (!e.auto_exclude_emitters || survey.surfaces.empty()) {
    if (e.auto_exclude_emitters && !survey.emitters.empty())
      notes.push_back("exposure.time_s \"auto\": every pixel is an emitter seen directly; the exposure is keyed on them");
    values.insert(values.end(), survey.emitters.begin(), survey.emitters.end());
  } else if (!survey.emitters.empty()) {
    what = fmt::format("of the brightest channel of the surfaces ({} emitter pixel{} left out)", survey.emitters.size(),
                       survey.emitters.size() == 1 ? "" : "s");
  }
  // The configuration says percentiles (0–100); core/statistics.h takes quantiles (0–1), by the same rule.
  const double per_second = quantile_in_place(values, e.auto_percentile / 100.0);
  if (!(per_second > 0))
    throw InputError(fmt::format("{}: exposure.time_s \"auto\": the image is black (its {}th percentile is {})", file,
                                 e.auto_percentile, per_second));
  const double time = e.auto_level * saturation_electrons(config).value_or(1.0) / per_second;
  notes.push_back(fmt::format(
      "exposure.time_s \"auto\": {:.6g} s puts the {:g}th percentile {} at {:g} of {}", time, e.auto_percentile, what,
      e.auto_level,
      saturation_electrons(config) ? fmt::format("saturation ({:.6g} e-)", *saturation_electrons(config))
                                   : std::string("1 e- (the ideal sensor does not saturate)")));
  return time;
}

}  // namespace ct::sensor
