// SPDX-License-Identifier: Apache-2.0
#include "calibrate/calibration.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>

#include <fmt/format.h>

#include "calibrate/frames.h"
#include "core/error.h"
#include "core/spectrum.h"
#include "sensor_sim/spectral_response.h"

namespace ct::calibrate {
namespace {

Json estimate_json(const Estimate& e) { return {{"value", e.value}, {"standard_error", e.standard_error}}; }

Json nonuniformity_json(const Nonuniformity& n) {
  return {{"total", estimate_json(n.total)}, {"row", estimate_json(n.row)}, {"column", estimate_json(n.column)}, {"pixel", estimate_json(n.pixel)}};
}

Json channel_json(const ChannelCalibration& c) {
  Json dark_points = Json::array();
  for (const TransferPoint& p : c.dark_points)
    dark_points.push_back({{"exposure_s", p.exposure_s}, {"dark_mean_dn", p.dark_mean_dn}, {"dark_variance_dn2", p.dark_variance_dn2}});
  Json points = Json::array();
  for (const TransferPoint& p : c.points)
    points.push_back({{"exposure_s", p.exposure_s},
                      {"photons_per_pixel", p.photons_per_pixel ? Json(*p.photons_per_pixel) : Json(nullptr)},
                      {"mean_dn", p.mean_dn},
                      {"variance_dn2", p.variance_dn2},
                      {"dark_mean_dn", p.dark_mean_dn},
                      {"dark_variance_dn2", p.dark_variance_dn2}});
  const Sensitivity figures = sensitivity(c);
  Json linearity = nullptr;
  if (c.linearity) {
    Json deviations = Json::array();
    for (const auto& [x, d] : c.linearity->deviations) deviations.push_back({x, d});
    linearity = {{"intercept_dn", c.linearity->intercept}, {"slope", c.linearity->slope}, {"min", c.linearity->min},
                 {"max", c.linearity->max}, {"deviations", deviations}};
  }
  Json datasheet = {{"inverse_gain_e_per_dn", figures.inverse_gain},
                    {"dark_sigma_dn", figures.dark_sigma_dn},
                    {"threshold_e", figures.threshold_e},
                    {"threshold_photons", figures.threshold_photons ? Json(*figures.threshold_photons) : Json(nullptr)},
                    {"saturation_photons", c.saturation_photons ? Json(*c.saturation_photons) : Json(nullptr)},
                    {"snr_max", figures.snr_max},
                    {"snr_max_db", 20 * std::log10(figures.snr_max)},
                    {"snr_max_bits", std::log2(figures.snr_max)},
                    {"dynamic_range", figures.dynamic_range},
                    {"dynamic_range_db", 20 * std::log10(figures.dynamic_range)},
                    {"dynamic_range_bits", std::log2(figures.dynamic_range)},
                    {"dsnu_dn", figures.dsnu_dn}};
  return {{"channel", c.channel},
          {"gain_dn_per_e", estimate_json(c.gain_dn_per_e)},
          {"dark_noise_e", estimate_json(c.dark_noise_e)},
          {"dark_noise_is_upper_limit", c.dark_noise_upper_limit},
          {"saturation_capacity_e", estimate_json(c.saturation_capacity_e)},
          {"saturation_mean_dn", c.saturation_mean_dn},
          {"clip_level_e", c.clip_level_e ? estimate_json(*c.clip_level_e) : Json(nullptr)},
          {"clips_at_adc", c.clips_at_adc},
          {"dark_current_e_per_s", estimate_json(c.dark_current_e_per_s)},
          {"dark_current_from_variance_e_per_s",
           c.dark_current_from_variance_e_per_s ? estimate_json(*c.dark_current_from_variance_e_per_s) : Json(nullptr)},
          {"black_level_dn", estimate_json(c.black_level_dn)},
          {"dsnu_e", nonuniformity_json(c.dsnu_e)},
          {"prnu", nonuniformity_json(c.prnu)},
          {"prnu_level_fraction", c.prnu_level_fraction},
          {"linearity_error", c.linearity_error},
          {"linearity", linearity},
          {"dark_variance_dn2", c.dark_variance_dn2},
          {"responsivity_dn_per_photon", c.responsivity ? estimate_json(*c.responsivity) : Json(nullptr)},
          {"datasheet", datasheet},
          {"quantum_efficiency", c.quantum_efficiency ? estimate_json(*c.quantum_efficiency) : Json(nullptr)},
          {"points", points},
          {"dark_points", dark_points},
          {"notes", c.notes}};
}

bool dark_current_from_variance(const ChannelCalibration& c) {
  if (!c.dark_current_from_variance_e_per_s) return false;
  const Estimate &m = c.dark_current_e_per_s, &v = *c.dark_current_from_variance_e_per_s;
  return std::abs(v.value - m.value) > 3 * std::hypot(v.standard_error, m.standard_error);
}

// The mean of the channels' values.
template <typename Get>
double channel_mean(const std::vector<ChannelCalibration>& channels, Get get) {
  double sum = 0;
  for (const ChannelCalibration& c : channels) sum += get(c);
  return sum / static_cast<double>(channels.size());
}

// The correlation of the temporal noise between neighbouring pixels and between channels: in the difference of each
// pair of flats (consecutive frames of a step), less its mean, products of neighbours summed over every pair and
// set against the variance. Pooled so, the bright steps (most noise) weigh most.
NoiseCorrelation noise_correlation(const std::vector<std::vector<const Frame*>>& steps) {
  const Frame& first = *steps.front().front();
  const std::size_t channels = first.channels.size();
  const auto w = static_cast<std::size_t>(first.channels[0].width), h = static_cast<std::size_t>(first.channels[0].height);
  std::vector<double> squares(channels, 0.0), horizontal(channels, 0.0), vertical(channels, 0.0);
  std::vector<std::vector<double>> cross(channels, std::vector<double>(channels, 0.0));
  std::size_t pairs = 0;
  std::vector<std::vector<double>> d(channels, std::vector<double>(w * h));
  for (const std::vector<const Frame*>& step : steps)
    for (std::size_t k = 0; k + 1 < step.size(); k += 2, ++pairs) {
      for (std::size_t c = 0; c < channels; ++c) {
        const std::vector<double>&a = step[k]->channels[c].values, &b = step[k + 1]->channels[c].values;
        double mean = 0;
        for (std::size_t i = 0; i < d[c].size(); ++i) mean += (d[c][i] = a[i] - b[i]);
        mean /= static_cast<double>(d[c].size());
        for (double& v : d[c]) v -= mean;
        for (std::size_t y = 0; y < h; ++y)
          for (std::size_t x = 0; x < w; ++x) {
            const double v = d[c][y * w + x];
            squares[c] += v * v;
            if (x + 1 < w) horizontal[c] += v * d[c][y * w + x + 1];
            if (y + 1 < h) vertical[c] += v * d[c][(y + 1) * w + x];
          }
      }
      for (std::size_t c = 0; c < channels; ++c)
        for (std::size_t e = c + 1; e < channels; ++e)
          for (std::size_t i = 0; i < w * h; ++i) cross[c][e] += d[c][i] * d[e][i];
    }
  NoiseCorrelation nc;
  nc.horizontal = nc.vertical = nc.between_channels = -1;
  auto name = [&](std::size_t c) { return first.channel_names[c]; };
  const auto n = static_cast<double>(w * h);
  for (std::size_t c = 0; c < channels; ++c) {
    if (!(squares[c] > 0)) continue;  // no noise at all: the same-image check names such pairs
    const double var = squares[c] / n;
    if (const double r = horizontal[c] / (n - static_cast<double>(h)) / var; r > nc.horizontal) nc.horizontal = r, nc.horizontal_channel = name(c);
    if (const double r = vertical[c] / (n - static_cast<double>(w)) / var; r > nc.vertical) nc.vertical = r, nc.vertical_channel = name(c);
    for (std::size_t e = c + 1; e < channels; ++e)
      if (const double r = cross[c][e] / std::sqrt(squares[c] * squares[e]); squares[e] > 0 && r > nc.between_channels)
        nc.between_channels = r, nc.channel_pair = name(c) + " and " + name(e);
  }
  nc.horizontal = std::max(nc.horizontal, 0.0), nc.vertical = std::max(nc.vertical, 0.0), nc.between_channels = std::max(nc.between_channels, 0.0);
  nc.standard_error = 1 / std::sqrt(n * static_cast<double>(std::max<std::size_t>(pairs, 1)));
  return nc;
}

// The peak QE from each channel's η at the flats' wavelength, through the camera's curves.
PeakQe peak_qe_of(const std::vector<ChannelCalibration>& channels, double wavelength_nm, const std::string& camera, const std::string& basis) {
  const sensor::CameraCurves curves = sensor::camera_curves(camera, {"r", "g", "b"}, "--camera");
  const sensor::ResponseBasis b = basis == "photon" ? sensor::ResponseBasis::Photon : sensor::ResponseBasis::Energy;
  // η_c(λ) for a peak QE of 1: the electrons per photon of a band 0.1 nm wide at λ, through the simulator's own
  // normalisation.
  const double half = 0.05;
  const Bands band = Bands::from_edges({wavelength_nm - half, wavelength_nm + half});
  sensor::check_band_coverage(band, curves, "--wavelength");
  const auto q = sensor::photon_response(band, curves, b, 1.0, PiecewiseLinearSpectrum::constant(1.0));
  const double photons = wavelength_nm * 1e-9 / (kPlanck * kLightSpeed) * 2 * half;
  PeakQe p;
  double weights = 0, sum = 0;
  for (std::size_t c = 0; c < channels.size(); ++c) {
    const double relative = q[c][0] / photons;
    if (!(relative > 0))
      throw InputError(fmt::format("--camera: channel {} of {} does not respond at {:g} nm, where the flats' light is", curves.channels[c],
                                   camera, wavelength_nm));
    const Estimate& eta = *channels[c].quantum_efficiency;
    p.relative_qe.push_back(relative);
    p.per_channel.push_back({eta.value / relative, eta.standard_error / relative});
    const double w = 1 / std::pow(std::max(p.per_channel.back().standard_error, 1e-12), 2);
    weights += w, sum += w * p.per_channel.back().value;
  }
  p.value = {sum / weights, 1 / std::sqrt(weights)};
  for (const Estimate& e : p.per_channel) p.channels_agree = p.channels_agree && std::abs(e.value - p.value.value) <= 3 * std::hypot(e.standard_error, p.value.standard_error);
  return p;
}

}  // namespace

double simulated_dark_current(const ChannelCalibration& c) {
  return dark_current_from_variance(c) ? c.dark_current_from_variance_e_per_s->value : c.dark_current_e_per_s.value;
}

Calibration calibrate(const CalibrationInput& input) {
  if (input.flats.empty() && input.flat_frames.empty()) throw InputError("--flat: no flat frames");
  if (input.darks.empty() && input.dark_frames.empty()) throw InputError("--dark: no dark frames");
  if (input.photons_per_s && !(*input.photons_per_s > 0 && std::isfinite(*input.photons_per_s)))
    throw InputError(fmt::format("--photons-per-s: must be a positive number, got {}", *input.photons_per_s));
  if (input.wavelength_nm.has_value() != !input.camera.empty())
    throw InputError(input.camera.empty() ? "--wavelength: needs the camera's curves too (--camera), to turn η there into a peak QE"
                                          : "--camera: needs the flats' wavelength too (--wavelength), where η is measured");
  if (input.wavelength_nm && !input.photons_per_s && input.photons_per_pixel.empty())
    throw InputError("--wavelength: the quantum efficiency needs the photons per pixel (--photons-per-s or --photons-per-pixel)");
  if (input.wavelength_nm && !(*input.wavelength_nm > 0 && std::isfinite(*input.wavelength_nm)))
    throw InputError(fmt::format("--wavelength: must be a positive number of nanometres, got {}", *input.wavelength_nm));
  if (input.pixel_pitch_um && !(*input.pixel_pitch_um > 0 && std::isfinite(*input.pixel_pitch_um)))
    throw InputError(fmt::format("--pixel-um: must be a positive number of micrometres, got {}", *input.pixel_pitch_um));
  if (input.temperature_c && !(*input.temperature_c > -273.15 && std::isfinite(*input.temperature_c)))
    throw InputError(fmt::format("--temperature: must be a temperature in °C above absolute zero, got {}", *input.temperature_c));
  if (input.basis != "energy" && input.basis != "photon")
    throw InputError(fmt::format("--basis: \"{}\" is not energy or photon", input.basis));

  // Every frame, then the odd one out named against the most common camera and size (the first frame may be the odd
  // one: naming it as the norm would point at a good file).
  std::vector<std::pair<int, Frame>> frames;  // kind (0 flat, 1 dark), frame
  for (int kind = 0; kind < 2; ++kind) {
    for (const auto& file : kind == 0 ? input.flats : input.darks) frames.emplace_back(kind, read_frame(file, input.input_transfer));
    for (const Frame& f : kind == 0 ? input.flat_frames : input.dark_frames) frames.emplace_back(kind, f);
  }
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
  std::vector<double> flat_times;
  for (const auto& [t, sets] : by_time)
    if (!sets[0].empty()) flat_times.push_back(t);
  for (const auto& [t, sets] : by_time) {
    const std::size_t flats = sets[0].size(), darks = sets[1].size();
    if (flats == 1)
      throw InputError(fmt::format("--flat: 1 flat frame at {:.6g} s, where the series needs at least two (a pair: their difference "
                                   "cancels the fixed pattern)",
                                   t));
    if (flats > 0 && darks < 2)
      throw InputError(fmt::format("--dark: {} dark frame{} at {:.6g} s, where the series needs at least two (a pair: their difference "
                                   "cancels the fixed pattern)",
                                   darks, darks == 1 ? "" : "s", t));
    if (flats == 0 && darks < 2)
      throw InputError(fmt::format("--dark: 1 dark frame at {:.6g} s, where no flat was taken: darks alone at a time (for the dark "
                                   "current) need a pair",
                                   t));
  }
  if (flat_times.empty()) throw InputError("--flat: no flat frames");

  // The steps: one per exposure time of the flats (the first method), or, at one exposure time, one per pair of flats
  // in the order given (the second: the irradiance varied).
  const bool one_time = flat_times.size() == 1;
  std::vector<std::vector<const Frame*>> step_flats;
  std::vector<double> step_times;
  if (one_time) {
    const std::vector<Frame>& set = by_time[flat_times[0]][0];
    if (set.size() % 2 != 0)
      throw InputError(fmt::format("--flat: {} flat frames at {:.6g} s: at one exposure time the flats are taken in pairs in the order "
                                   "given (one pair per irradiance), and the last, {}, has no partner",
                                   set.size(), flat_times[0], set.back().file));
    if (set.size() == 2)
      throw InputError(fmt::format("--flat: one pair of flats, at {:.6g} s: the photon transfer needs a series of exposures (exposure "
                                   "times, or pairs at one exposure time under different irradiances)",
                                   flat_times[0]));
    for (std::size_t k = 0; k < set.size(); k += 2) {
      step_flats.push_back({&set[k], &set[k + 1]});
      step_times.push_back(flat_times[0]);
    }
  } else {
    for (const double t : flat_times) {
      step_flats.emplace_back();
      for (const Frame& f : by_time[t][0]) step_flats.back().push_back(&f);
      step_times.push_back(t);
    }
  }
  if (one_time && input.photons_per_s)
    throw InputError(fmt::format("--photons-per-s: every flat has the exposure time {:.6g} s, so the irradiance varied: give the "
                                 "photons per pixel of each pair (--photons-per-pixel)",
                                 flat_times[0]));
  if (!one_time && !input.photons_per_pixel.empty())
    throw InputError("--photons-per-pixel: is for flats at one exposure time (a pair per irradiance); these vary the exposure time, "
                     "so give the irradiance as --photons-per-s");
  if (!input.photons_per_pixel.empty() && input.photons_per_pixel.size() != step_flats.size())
    throw InputError(fmt::format("--photons-per-pixel: {} value{} for {} pairs of flats (one per pair, in their order)",
                                 input.photons_per_pixel.size(), input.photons_per_pixel.size() == 1 ? "" : "s", step_flats.size()));
  for (const double p : input.photons_per_pixel)
    if (!(p > 0 && std::isfinite(p))) throw InputError(fmt::format("--photons-per-pixel: must be positive numbers, got {}", p));

  // A frame grabber that hands the same buffer twice makes a pair of one image: its difference holds no noise. (Two
  // frames that hold one code everywhere, clipped at the ADC's top code beyond saturation, are equal as they should be.)
  auto same_image = [](const Frame& a, const Frame& b) {
    const bool uniform = std::all_of(a.channels.begin(), a.channels.end(), [](const Plane& p) {
      return std::all_of(p.values.begin(), p.values.end(), [&](double v) { return v == p.values.front(); });
    });
    return !uniform &&
           std::equal(a.channels.begin(), a.channels.end(), b.channels.begin(), [](const Plane& x, const Plane& y) { return x.values == y.values; });
  };
  for (const auto& [t, sets] : by_time)
    for (int kind = 0; kind < 2; ++kind) {
      const std::vector<Frame>& set = sets[static_cast<std::size_t>(kind)];
      for (std::size_t a = 0; a < set.size(); ++a)
        for (std::size_t b = a + 1; b < set.size(); ++b)
          if (same_image(set[a], set[b]))
            throw InputError(fmt::format("{}: the same image as {} (both {} frames at {:.6g} s): the frames of a pair must be two "
                                         "exposures, whose difference holds the temporal noise",
                                         set[b].file, set[a].file, kind == 0 ? "flat" : "dark", t));
    }
  // At one exposure time a pair is one irradiance: its two means agree far better than 5 % of their signal (a lamp's
  // drift is a fraction of a per cent), where two irradiances of the series differ by more; or, near black, within five
  // standard errors of their difference's mean (the temporal noise over the pixels).
  const std::size_t channel_count = step_flats.front().front()->channels.size();
  if (one_time) {
    const std::vector<Frame>& darks = by_time[flat_times[0]][1];
    for (const std::vector<const Frame*>& pair : step_flats)
      for (std::size_t c = 0; c < channel_count; ++c) {
        auto mean = [&](const Frame& f) {
          const std::vector<double>& v = f.channels[c].values;
          return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
        };
        const double black = (mean(darks[0]) + mean(darks[1])) / 2, a = mean(*pair[0]) - black, b = mean(*pair[1]) - black;
        const std::vector<double>&x = pair[0]->channels[c].values, &y = pair[1]->channels[c].values;
        double d2 = 0;
        for (std::size_t i = 0; i < x.size(); ++i) d2 += (x[i] - y[i] - (a - b)) * (x[i] - y[i] - (a - b));
        const double difference_se = std::sqrt(d2 / static_cast<double>(x.size() - 1) / static_cast<double>(x.size()));
        if (std::abs(a - b) > std::max(0.05 * std::max(std::abs(a), std::abs(b)), 5 * difference_se))
          throw InputError(fmt::format("{}: its channel {} is {:.4g} DN above black where {}, its partner, is {:.4g}: at one exposure time "
                                       "the flats are taken in pairs in the order given, each pair one irradiance",
                                       pair[1]->file, pair[1]->channel_names[c], b, pair[0]->file, a));
      }
  }

  // One channel that is a colour camera's mosaic (a raw file written as a grey TIFF, as dcraw -D does): its flats'
  // 2 × 2 phases differ as the filters' colours do, which its PRNU would report as the pixels' own. A monochrome
  // sensor's phases agree to a fraction of a per cent (its PRNU averaged over a quarter of the pixels; an even/odd
  // column amplifier's offset a per cent or so). Measured at the flat step nearest half of the brightest.
  if (channel_count == 1) {
    std::size_t mid = 0;
    double brightest = 0;
    std::vector<double> means;
    for (const auto& pair : step_flats) {
      const std::vector<double>& v = pair[0]->channels[0].values;
      means.push_back(std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size()));
      brightest = std::max(brightest, means.back());
    }
    for (std::size_t k = 0; k < means.size(); ++k)
      if (std::abs(means[k] - brightest / 2) < std::abs(means[mid] - brightest / 2)) mid = k;
    const Plane& plane = step_flats[mid][0]->channels[0];
    const std::vector<Frame>& mid_darks = by_time[step_times[mid]][1];
    std::array<double, 4> phase{};
    std::array<std::size_t, 4> count{};
    for (int y = 0; y < plane.height; ++y)
      for (int x = 0; x < plane.width; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(plane.width) + static_cast<std::size_t>(x);
        const std::size_t p = static_cast<std::size_t>(2 * (y % 2) + x % 2);
        for (const Frame* f : step_flats[mid]) phase[p] += f->channels[0].values[i];
        for (const Frame& d : mid_darks) phase[p] -= d.channels[0].values[i] * static_cast<double>(step_flats[mid].size()) / static_cast<double>(mid_darks.size());
        count[p] += step_flats[mid].size();
      }
    for (std::size_t p = 0; p < 4; ++p) phase[p] /= static_cast<double>(count[p]);
    const auto [lo, hi] = std::minmax_element(phase.begin(), phase.end());
    if (*lo > 0 && *hi / *lo - 1 > 0.05)
      throw InputError(fmt::format("{}: its one channel's 2 × 2 phases differ by {:.0f} % in the flats (from {:.4g} to {:.4g} DN above "
                                   "black): a colour camera's mosaic, whose filters would count as the pixels' non-uniformity; "
                                   "calibrate from the camera raw itself, which is read a colour at a time",
                                   step_flats[mid][0]->file, 100 * (*hi / *lo - 1), *lo, *hi));
  }

  // Pixels read on their own: the noise of each pair's difference uncorrelated between neighbours and channels.
  Calibration result;
  result.noise_correlation = noise_correlation(step_flats);
  if (const NoiseCorrelation& nc = result.noise_correlation; !step_flats.front().front()->photosites) {
    const double limit = kMaxNoiseCorrelation + 3 * nc.standard_error;
    for (const auto& [rho, what] : {std::pair{nc.horizontal, "horizontal neighbours in " + nc.horizontal_channel},
                                    std::pair{nc.vertical, "vertical neighbours in " + nc.vertical_channel},
                                    std::pair{nc.between_channels, "channels " + nc.channel_pair}})
      if (rho > limit)
        throw InputError(fmt::format("--flat: the temporal noise of the flats correlates by {:.2f} between {} (each pixel read on its "
                                     "own gives 0 ± {:.2g}): the frames were interpolated or filtered, as a demosaiced colour "
                                     "camera's are, so a pixel's variance is not its own; calibrate from the camera raw, or from "
                                     "frames whose pixels were each read on their own",
                                     rho, what, nc.standard_error));
  }

  result.flats = input.flats.size() + input.flat_frames.size();
  result.darks = input.darks.size() + input.dark_frames.size();
  result.exposures = by_time.size();
  result.camera = sensor;
  result.frame_size = size;
  result.flat_exposure_min_s = flat_times.front();
  result.flat_exposure_max_s = flat_times.back();
  result.wavelength_nm = input.wavelength_nm;
  result.pixel_pitch_um = input.pixel_pitch_um;
  result.temperature_c = input.temperature_c;
  for (const auto& [t, sets] : by_time)
    for (const auto& set : sets)
      for (const Frame& f : set)
        if (result.date.empty()) result.date = f.date;
  const std::size_t dark_only = by_time.size() - flat_times.size();
  result.series = one_time ? fmt::format("{} irradiances at {:.6g} s", step_flats.size(), flat_times[0])
                           : fmt::format("{} exposure times", flat_times.size());
  if (dark_only > 0) result.series += fmt::format("; darks alone at {} further time{}", dark_only, dark_only == 1 ? "" : "s");
  for (std::size_t c = 0; c < channel_count; ++c) {
    std::vector<ExposureStep> steps;
    for (std::size_t k = 0; k < step_flats.size(); ++k) {
      ExposureStep s;
      s.exposure_s = step_times[k];
      if (input.photons_per_s) s.photons_per_pixel = *input.photons_per_s * s.exposure_s;
      if (!input.photons_per_pixel.empty()) s.photons_per_pixel = input.photons_per_pixel[k];
      for (const Frame* f : step_flats[k]) s.flats.push_back(f->channels[c]);
      for (const Frame& f : by_time[s.exposure_s][1]) s.darks.push_back(f.channels[c]);
      steps.push_back(std::move(s));
    }
    for (const auto& [t, sets] : by_time)
      if (sets[0].empty()) {
        ExposureStep s;
        s.exposure_s = t;
        for (const Frame& f : sets[1]) s.darks.push_back(f.channels[c]);
        steps.push_back(std::move(s));
      }
    const std::string& name = step_flats.front().front()->channel_names[c];
    try {
      ChannelCalibration& cc = result.channels.emplace_back(calibrate_channel(name, steps));
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
  // The full well: the clip level (else EMVA's saturation capacity). Where the ADC's top code clips the pixels, the
  // well lies beyond it: placed six standard deviations of the read noise and DSNU above the clip, so that the
  // simulated pixels reach the top code and stay there, one code, as this camera's do (at the clip itself, the read
  // noise added after the well would spread them below it).
  double full_well = channel_mean(ch, [](const auto& c) { return c.clip_level_e ? c.clip_level_e->value : c.saturation_capacity_e.value; });
  if (std::all_of(ch.begin(), ch.end(), [](const ChannelCalibration& c) { return c.clips_at_adc; })) {
    // In the settings' own terms (the channels' mean gain and black level), where the top code lies.
    const double top_dn = channel_mean(ch, [](const auto& c) { return c.black_level_dn.value + c.gain_dn_per_e.value * c.clip_level_e->value; });
    const double spread = channel_mean(ch, [](const auto& c) { return std::hypot(c.dark_noise_e.value, c.dsnu_e.total.value); });
    full_well = (top_dn - adc["black_level_dn"].get<double>()) / adc["gain_dn_per_e"].get<double>() + 6 * spread;
    result.notes.push_back(fmt::format("the clipped flats hold one code (the ADC's top code clips the pixels before their full well, which "
                                       "is not measured): the settings' full well, {:.6g} e⁻, lies six standard deviations of the read noise "
                                       "and DSNU above the clip level, so that the simulated ADC clips as this one does",
                                       full_well));
  }
  if (input.wavelength_nm) {
    if (ch.size() != 3)
      throw InputError("--camera: a monochrome camera has one channel, where the simulator's camera curves have three");
    result.peak_qe = peak_qe_of(ch, *input.wavelength_nm, input.camera, input.basis);
    const PeakQe& p = *result.peak_qe;
    std::string per_channel;
    for (std::size_t c = 0; c < ch.size(); ++c)
      per_channel += fmt::format("{}{} {:.4g} ± {:.2g}", c ? ", " : "", ch[c].channel, p.per_channel[c].value, p.per_channel[c].standard_error);
    result.notes.push_back(
        p.channels_agree
            ? fmt::format("peak QE {:.4g} ± {:.2g} (spectral_response.peak_qe): each channel's η at {:g} nm over the relative QE of {}'s "
                          "curves there ({})",
                          p.value.value, p.value.standard_error, *input.wavelength_nm, input.camera, per_channel)
            : fmt::format("the channels' η at {:g} nm over the relative QE of {}'s curves there disagree ({}): the curves' ratios at "
                          "that wavelength are not this camera's; the settings take their weighted mean, {:.4g} ± {:.2g}",
                          *input.wavelength_nm, input.camera, per_channel, p.value.value, p.value.standard_error));
  } else if (ch.front().quantum_efficiency) {
    result.notes.push_back("η is the flats' light's; give its wavelength and the camera's curves (--wavelength, --camera) to set the "
                           "simulator's peak QE from it (the settings leave spectral_response as the preset has it)");
  }
  result.sensor = {{"format", "chromatrace-sensor/1"},
                   {"description", fmt::format("Calibrated with chromatrace calibrate (EMVA 1288 Linear) from {} flat and {} dark frames "
                                               "({}); {}; adc.bits {}",
                                               result.flats, result.darks, result.series,
                                               ch.size() == 1 ? "one channel (monochrome)" : "the mean of the R, G and B channels", bits_from)},
                   {"noise", noise},
                   {"full_well", {{"enabled", true}, {"electrons", full_well}}},
                   {"adc", adc}};
  if (result.peak_qe) {
    // A CSV file named relative to here would be read relative to the settings file: give it whole.
    const bool file = input.camera.find('/') != std::string::npos || input.camera.ends_with(".csv");
    result.sensor["spectral_response"] = {{"camera", file ? std::filesystem::absolute(input.camera).string() : input.camera},
                                          {"basis", input.basis},
                                          {"peak_qe", result.peak_qe->value.value}};
  }
  Json channels = Json::array();
  for (const ChannelCalibration& c : ch) channels.push_back(channel_json(c));
  Json peak_qe_json = nullptr;
  if (const auto& p = result.peak_qe) {
    Json per_channel = Json::array();
    for (std::size_t c = 0; c < ch.size(); ++c)
      per_channel.push_back({{"channel", ch[c].channel}, {"relative_qe", p->relative_qe[c]}, {"peak_qe", estimate_json(p->per_channel[c])}});
    peak_qe_json = {{"wavelength_nm", *input.wavelength_nm}, {"camera", input.camera}, {"basis", input.basis},
                    {"value", estimate_json(p->value)}, {"channels_agree", p->channels_agree}, {"per_channel", per_channel}};
  }
  result.report = {{"format", "chromatrace-calibration/1"},
                   {"standard", "EMVA 1288 Release 4.0 Linear"},
                   {"flats", result.flats},
                   {"darks", result.darks},
                   {"exposures", result.exposures},
                   {"series", result.series},
                   {"operating_point",
                    {{"camera", result.camera},
                     {"frame_size", {size.first, size.second}},
                     {"flat_exposure_s", {result.flat_exposure_min_s, result.flat_exposure_max_s}},
                     {"wavelength_nm", result.wavelength_nm ? Json(*result.wavelength_nm) : Json(nullptr)},
                     {"pixel_pitch_um", result.pixel_pitch_um ? Json(*result.pixel_pitch_um) : Json(nullptr)},
                     {"temperature_c", result.temperature_c ? Json(*result.temperature_c) : Json(nullptr)},
                     {"date", result.date.empty() ? Json(nullptr) : Json(result.date)}}},
                   {"photons_per_s", input.photons_per_s ? Json(*input.photons_per_s) : Json(nullptr)},
                   {"photons_per_pixel", input.photons_per_pixel.empty() ? Json(nullptr) : Json(input.photons_per_pixel)},
                   {"noise_correlation",
                    {{"horizontal", result.noise_correlation.horizontal},
                     {"vertical", result.noise_correlation.vertical},
                     {"between_channels", result.noise_correlation.channel_pair.empty() ? Json(nullptr)
                                                                                           : Json(result.noise_correlation.between_channels)},
                     {"standard_error", result.noise_correlation.standard_error}}},
                   {"frame_size", {size.first, size.second}},
                   {"channels", channels},
                   {"peak_qe", peak_qe_json},
                   {"notes", result.notes},
                   {"sensor", result.sensor}};
  return result;
}

}  // namespace ct::calibrate
