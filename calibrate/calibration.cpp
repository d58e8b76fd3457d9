// SPDX-License-Identifier: Apache-2.0
#include "calibrate/calibration.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/format.h>

#include "calibrate/frames.h"
#include "core/error.h"

namespace ct::calibrate {
namespace {

Json estimate_json(const Estimate& e) { return {{"value", e.value}, {"standard_error", e.standard_error}}; }

Json nonuniformity_json(const Nonuniformity& n) {
  return {{"total", estimate_json(n.total)}, {"row", estimate_json(n.row)}, {"column", estimate_json(n.column)}, {"pixel", estimate_json(n.pixel)}};
}

Json channel_json(const ChannelCalibration& c) {
  Json points = Json::array();
  for (const TransferPoint& p : c.points)
    points.push_back({{"exposure_s", p.exposure_s},
                      {"photons_per_pixel", p.photons_per_pixel ? Json(*p.photons_per_pixel) : Json(nullptr)},
                      {"mean_dn", p.mean_dn},
                      {"variance_dn2", p.variance_dn2},
                      {"dark_mean_dn", p.dark_mean_dn},
                      {"dark_variance_dn2", p.dark_variance_dn2}});
  return {{"channel", c.channel},
          {"gain_dn_per_e", estimate_json(c.gain_dn_per_e)},
          {"dark_noise_e", estimate_json(c.dark_noise_e)},
          {"dark_noise_is_upper_limit", c.dark_noise_upper_limit},
          {"saturation_capacity_e", estimate_json(c.saturation_capacity_e)},
          {"saturation_mean_dn", c.saturation_mean_dn},
          {"clip_level_e", c.clip_level_e ? estimate_json(*c.clip_level_e) : Json(nullptr)},
          {"dark_current_e_per_s", estimate_json(c.dark_current_e_per_s)},
          {"dark_current_from_variance_e_per_s",
           c.dark_current_from_variance_e_per_s ? estimate_json(*c.dark_current_from_variance_e_per_s) : Json(nullptr)},
          {"black_level_dn", estimate_json(c.black_level_dn)},
          {"dsnu_e", nonuniformity_json(c.dsnu_e)},
          {"prnu", nonuniformity_json(c.prnu)},
          {"prnu_level_fraction", c.prnu_level_fraction},
          {"linearity_error", c.linearity_error},
          {"quantum_efficiency", c.quantum_efficiency ? estimate_json(*c.quantum_efficiency) : Json(nullptr)},
          {"points", points},
          {"notes", c.notes}};
}

bool dark_current_from_variance(const ChannelCalibration& c) {
  if (!c.dark_current_from_variance_e_per_s) return false;
  const Estimate &m = c.dark_current_e_per_s, &v = *c.dark_current_from_variance_e_per_s;
  return std::abs(v.value - m.value) > 3 * std::hypot(v.standard_error, m.standard_error);
}

// The mean of the three channels' values.
template <typename Get>
double channel_mean(const std::array<ChannelCalibration, 3>& channels, Get get) {
  double sum = 0;
  for (const ChannelCalibration& c : channels) sum += get(c);
  return sum / 3.0;
}

}  // namespace

double simulated_dark_current(const ChannelCalibration& c) {
  return dark_current_from_variance(c) ? c.dark_current_from_variance_e_per_s->value : c.dark_current_e_per_s.value;
}

Calibration calibrate(const CalibrationInput& input) {
  if (input.flats.empty()) throw InputError("--flat: no flat frames");
  if (input.darks.empty()) throw InputError("--dark: no dark frames");
  if (input.photons_per_s && !(*input.photons_per_s > 0 && std::isfinite(*input.photons_per_s)))
    throw InputError(fmt::format("--photons-per-s: must be a positive number, got {}", *input.photons_per_s));

  // Every frame, then the odd one out named against the most common camera and size (the first frame may be the odd
  // one: naming it as the norm would point at a good file).
  std::vector<std::pair<int, Frame>> frames;  // kind (0 flat, 1 dark), frame
  for (int kind = 0; kind < 2; ++kind)
    for (const auto& file : kind == 0 ? input.flats : input.darks) frames.emplace_back(kind, read_frame(file));
  auto most_common = [&](auto key) {
    std::map<decltype(key(frames[0].second)), std::size_t> count;
    for (const auto& [kind, f] : frames) ++count[key(f)];
    return std::max_element(count.begin(), count.end(), [](const auto& a, const auto& b) { return a.second < b.second; })->first;
  };
  const std::string sensor = most_common([](const Frame& f) { return f.sensor; });
  const auto size = most_common([](const Frame& f) { return std::pair{f.channels[0].width, f.channels[0].height}; });
  const auto norm = [&](auto matches) {
    return std::find_if(frames.begin(), frames.end(), [&](const auto& kf) { return matches(kf.second); })->second.file;
  };
  for (const auto& [kind, f] : frames) {
    const Plane& p = f.channels[0];
    if (f.sensor != sensor)
      throw InputError(fmt::format("{}: {}, but {} is {}: every frame must come from the same camera and mosaic", f.file,
                                   f.sensor, norm([&](const Frame& g) { return g.sensor == sensor; }), sensor));
    if (std::pair{p.width, p.height} != size)
      throw InputError(fmt::format("{}: {} x {} values per channel, but {} has {} x {}: every frame must come from the same "
                                   "sensor area",
                                   f.file, p.width, p.height,
                                   norm([&](const Frame& g) { return std::pair{g.channels[0].width, g.channels[0].height} == size; }),
                                   size.first, size.second));
  }

  // Frames by exposure time.
  std::map<double, std::array<std::vector<Frame>, 2>> by_time;  // [0] flats, [1] darks
  std::optional<int> bits;
  for (auto& [kind, f] : frames) {
    if (f.adc_bits && *f.adc_bits > 0) bits = f.adc_bits;
    else if (!bits && f.white_level_dn) bits = static_cast<int>(std::ceil(std::log2(*f.white_level_dn + 1)));
    by_time[f.exposure_s][static_cast<std::size_t>(kind)].push_back(std::move(f));
  }
  if (by_time.size() < 2)
    throw InputError(fmt::format("--flat: every frame has the exposure time {:.6g} s; the photon transfer needs a series of exposures",
                                 by_time.begin()->first));
  for (const auto& [t, sets] : by_time)
    for (int kind = 0; kind < 2; ++kind)
      if (sets[static_cast<std::size_t>(kind)].size() < 2)
        throw InputError(fmt::format("{}: {} {} frame{} at {:.6g} s, where the series needs at least two (a pair: their difference "
                                     "cancels the fixed pattern)",
                                     kind == 0 ? "--flat" : "--dark", sets[static_cast<std::size_t>(kind)].size(),
                                     kind == 0 ? "flat" : "dark", sets[static_cast<std::size_t>(kind)].size() == 1 ? "" : "s", t));

  // A frame grabber that hands the same buffer twice makes a pair of one image: its difference holds no noise.
  for (const auto& [t, sets] : by_time)
    for (int kind = 0; kind < 2; ++kind) {
      const std::vector<Frame>& set = sets[static_cast<std::size_t>(kind)];
      for (std::size_t a = 0; a < set.size(); ++a)
        for (std::size_t b = a + 1; b < set.size(); ++b)
          if (std::equal(set[a].channels.begin(), set[a].channels.end(), set[b].channels.begin(),
                         [](const Plane& x, const Plane& y) { return x.values == y.values; }))
            throw InputError(fmt::format("{}: the same image as {} (both {} frames at {:.6g} s): the frames of a pair must be two "
                                         "exposures, whose difference holds the temporal noise",
                                         set[b].file, set[a].file, kind == 0 ? "flat" : "dark", t));
    }

  Calibration result;
  result.flats = input.flats.size();
  result.darks = input.darks.size();
  result.exposures = by_time.size();
  for (std::size_t c = 0; c < 3; ++c) {
    std::vector<ExposureStep> steps;
    for (const auto& [t, sets] : by_time) {
      ExposureStep s;
      s.exposure_s = t;
      if (input.photons_per_s) s.photons_per_pixel = *input.photons_per_s * t;
      for (const Frame& f : sets[0]) s.flats.push_back(f.channels[c]);
      for (const Frame& f : sets[1]) s.darks.push_back(f.channels[c]);
      steps.push_back(std::move(s));
    }
    try {
      result.channels[c] = calibrate_channel(kChannelNames[c], steps);
      ChannelCalibration& cc = result.channels[c];
      if (dark_current_from_variance(cc))
        cc.notes.push_back(fmt::format(
            "the dark current from the dark frames' variance, {:.4g} ± {:.2g} e⁻/s, is not the dark mean's, {:.4g} ± {:.2g} "
            "e⁻/s (a camera that subtracts its dark offset on chip keeps the mean flat): the sensor settings take the "
            "variance's, the dark electrons' shot noise",
            cc.dark_current_from_variance_e_per_s->value, cc.dark_current_from_variance_e_per_s->standard_error,
            cc.dark_current_e_per_s.value, cc.dark_current_e_per_s.standard_error));
    } catch (const InputError& e) {
      throw InputError(fmt::format("--flat: {}", e.what()));
    }
  }

  const auto& ch = result.channels;
  Json noise = {{"enabled", true},
                {"shot", true},
                {"read_e", channel_mean(ch, [](const auto& c) { return c.dark_noise_e.value; })},
                {"dark_current_e_per_s", std::max(0.0, channel_mean(ch, [](const auto& c) { return simulated_dark_current(c); }))},
                {"dsnu_e", channel_mean(ch, [](const auto& c) { return c.dsnu_e.pixel.value; })},
                {"dsnu_row_e", channel_mean(ch, [](const auto& c) { return c.dsnu_e.row.value; })},
                {"dsnu_column_e", channel_mean(ch, [](const auto& c) { return c.dsnu_e.column.value; })},
                {"prnu", channel_mean(ch, [](const auto& c) { return c.prnu.pixel.value; })},
                {"prnu_row", channel_mean(ch, [](const auto& c) { return c.prnu.row.value; })},
                {"prnu_column", channel_mean(ch, [](const auto& c) { return c.prnu.column.value; })}};
  Json adc = {{"enabled", true},
              {"gain_dn_per_e", channel_mean(ch, [](const auto& c) { return c.gain_dn_per_e.value; })},
              {"black_level_dn", channel_mean(ch, [](const auto& c) { return c.black_level_dn.value; })}};
  std::string bits_from = "the frames' own";
  if (!bits) {
    // A TIFF or EXR says no ADC depth: the largest value any frame holds (the top code where frames clip) sets it,
    // so that the simulated camera clips where this one does rather than at 16 bits.
    double largest = 0;
    for (const auto& [t, sets] : by_time)
      for (const auto& set : sets)
        for (const Frame& f : set)
          for (const Plane& p : f.channels)
            for (double v : p.values) largest = std::max(largest, v);
    bits = std::max(1, static_cast<int>(std::ceil(std::log2(std::floor(largest) + 1))));
    bits_from = fmt::format("from the largest value in the frames, {:g} DN", largest);
  }
  adc["bits"] = *bits;
  result.sensor = {{"format", "chromatrace-sensor/1"},
                   {"description", fmt::format("Calibrated with chromatrace calibrate (EMVA 1288 Linear) from {} flat and {} dark frames "
                                               "at {} exposure times; the mean of the R, G and B channels; adc.bits {}",
                                               result.flats, result.darks, result.exposures, bits_from)},
                   {"noise", noise},
                   {"full_well", {{"enabled", true}, {"electrons", channel_mean(ch, [](const auto& c) {
                                   return c.clip_level_e ? c.clip_level_e->value : c.saturation_capacity_e.value;
                                 })}}},
                   {"adc", adc}};
  Json channels = Json::array();
  for (const ChannelCalibration& c : ch) channels.push_back(channel_json(c));
  result.report = {{"format", "chromatrace-calibration/1"},
                   {"standard", "EMVA 1288 Release 4.0 Linear"},
                   {"flats", result.flats},
                   {"darks", result.darks},
                   {"exposures", result.exposures},
                   {"photons_per_s", input.photons_per_s ? Json(*input.photons_per_s) : Json(nullptr)},
                   {"frame_size", {size.first, size.second}},
                   {"channels", channels},
                   {"sensor", result.sensor}};
  return result;
}

}  // namespace ct::calibrate
