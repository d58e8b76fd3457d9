// SPDX-License-Identifier: Apache-2.0
#include "calibrate/photon_transfer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>

#include <fmt/format.h>

#include "calibrate/spatial.h"
#include "core/error.h"

namespace ct::calibrate {
namespace {

constexpr double kQuantisationVariance = 1.0 / 12.0;  // σ_q², DN²
// Below this dark variance (DN²) EMVA 1288 gives only an upper limit of the temporal dark noise.
constexpr double kQuantisationLimit = 0.24;
constexpr double kGainFitTop = 0.7;                    // the gain is fitted up to this share of saturation
constexpr double kLinearityLow = 0.05, kLinearityHigh = 0.95;
// The brightest flats' signal may exceed the signal at saturation by this factor at most (see its use).
constexpr double kSaturationHeadroom = 1.2;

double mean_of(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size()); }

double variance_of(const std::vector<double>& v) {
  const double m = mean_of(v);
  double s = 0;
  for (const double x : v) s += (x - m) * (x - m);
  return s / static_cast<double>(v.size() - 1);
}

// The standard error of a variance s² estimated from n values (Gaussian: var(s²) = 2σ⁴/(n − 1)).
double variance_se(double variance, std::size_t n) { return variance * std::sqrt(2.0 / static_cast<double>(n - 1)); }

// Temporal statistics of a set of frames of one scene: the mean over every frame, and the temporal variance from
// the differences of consecutive pairs, var(A − B)/2, averaged over the pairs (the fixed pattern cancels).
struct Temporal {
  double mean = 0, variance = 0;
};
Temporal temporal(const std::vector<Plane>& frames) {
  Temporal t;
  for (const Plane& f : frames) t.mean += mean_of(f.values);
  t.mean /= static_cast<double>(frames.size());
  std::size_t pairs = 0;
  for (std::size_t k = 0; k + 1 < frames.size(); k += 2, ++pairs) {
    std::vector<double> d(frames[k].values.size());
    for (std::size_t p = 0; p < d.size(); ++p) d[p] = frames[k].values[p] - frames[k + 1].values[p];
    t.variance += variance_of(d) / 2;
  }
  t.variance /= static_cast<double>(pairs);
  return t;
}

// The mean of the frames, pixel by pixel: what the spatial non-uniformity is measured on.
Plane average(const std::vector<Plane>& frames) {
  Plane m{frames[0].width, frames[0].height, std::vector<double>(frames[0].values.size(), 0.0)};
  for (const Plane& f : frames)
    for (std::size_t p = 0; p < m.values.size(); ++p) m.values[p] += f.values[p];
  for (double& v : m.values) v /= static_cast<double>(frames.size());
  return m;
}

// Spatial variance of a mean image split into row, column and pixel parts (DN²), less the temporal variance the
// mean still holds (temporal_variance / frames). With y_ij = μ + a_i + b_j + e_ij: var(row means) = s_row² + X/N,
// var(column means) = s_col² + X/M and var(y) = s_row² + s_col² + X, X the pixel part with the temporal rest, for
// M rows of N columns.
struct SpatialVariance {
  double total = 0, row = 0, column = 0, pixel = 0;
  double total_se = 0, row_se = 0, column_se = 0, pixel_se = 0;  // var(s²) = 2σ⁴/(n − 1) of what each is measured on
};
SpatialVariance spatial_variance(const Plane& mean, double temporal_variance, std::size_t frames) {
  const auto M = static_cast<std::size_t>(mean.height), N = static_cast<std::size_t>(mean.width);
  std::vector<double> rows(M, 0.0), columns(N, 0.0);
  for (std::size_t i = 0; i < M; ++i)
    for (std::size_t j = 0; j < N; ++j) {
      rows[i] += mean.values[i * N + j] / static_cast<double>(N);
      columns[j] += mean.values[i * N + j] / static_cast<double>(M);
    }
  const double all = variance_of(mean.values), vr = variance_of(rows), vc = variance_of(columns);
  const double rest = temporal_variance / static_cast<double>(frames);
  const double x = (all - vr - vc) / (1.0 - 1.0 / static_cast<double>(N) - 1.0 / static_cast<double>(M));
  SpatialVariance s;
  s.row = std::max(0.0, vr - x / static_cast<double>(N));
  s.column = std::max(0.0, vc - x / static_cast<double>(M));
  s.pixel = std::max(0.0, x - rest);
  s.total = s.row + s.column + s.pixel;
  s.total_se = s.pixel_se = variance_se(all, mean.values.size());
  s.row_se = variance_se(vr, M);
  s.column_se = variance_se(vc, N);
  return s;
}

// Least squares y = a + b·x (or y = b·x through the origin) with the standard errors from the residuals; the line
// not through the origin optionally with a weight per squared residual (none: all 1).
struct LineFit {
  double intercept = 0, slope = 0, intercept_se = 0, slope_se = 0;
};
LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y, bool through_origin,
                 const std::vector<double>& weights = {}) {
  const auto n = static_cast<double>(x.size());
  LineFit f;
  if (through_origin) {
    double sxx = 0, sxy = 0;
    for (std::size_t i = 0; i < x.size(); ++i) sxx += x[i] * x[i], sxy += x[i] * y[i];
    f.slope = sxy / sxx;
    double r = 0;
    for (std::size_t i = 0; i < x.size(); ++i) r += std::pow(y[i] - f.slope * x[i], 2);
    f.slope_se = n > 1 ? std::sqrt(r / (n - 1) / sxx) : 0.0;
    return f;
  }
  auto w = [&](std::size_t i) { return weights.empty() ? 1.0 : weights[i]; };
  double sw = 0, swx = 0, swy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) sw += w(i), swx += w(i) * x[i], swy += w(i) * y[i];
  const double mx = swx / sw, my = swy / sw;
  double sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) sxx += w(i) * (x[i] - mx) * (x[i] - mx), sxy += w(i) * (x[i] - mx) * (y[i] - my);
  f.slope = sxy / sxx;
  f.intercept = my - f.slope * mx;
  double r = 0;
  for (std::size_t i = 0; i < x.size(); ++i) r += w(i) * std::pow(y[i] - f.intercept - f.slope * x[i], 2);
  const double s2 = n > 2 ? r / (n - 2) : 0.0;
  f.slope_se = std::sqrt(s2 / sxx);
  f.intercept_se = std::sqrt(s2 * (1.0 / sw + mx * mx / sxx));
  return f;
}

void check_steps(const std::vector<ExposureStep>& steps) {
  if (steps.empty()) throw InputError("no frames");
  const auto first = std::find_if(steps.begin(), steps.end(), [](const ExposureStep& s) { return !s.flats.empty(); });
  if (first == steps.end()) throw InputError("no flat frames");
  const int w = first->flats[0].width, h = first->flats[0].height;
  for (const ExposureStep& s : steps) {
    if ((!s.flats.empty() && s.flats.size() < 2) || s.darks.size() < 2)
      throw InputError(fmt::format("exposure {:.6g} s has {} flat and {} dark frames; every exposure needs at least two darks, and "
                                   "none or at least two flats (a pair: their difference cancels the fixed pattern)",
                                   s.exposure_s, s.flats.size(), s.darks.size()));
    for (const std::vector<Plane>* set : {&s.flats, &s.darks})
      for (const Plane& p : *set)
        if (p.width != w || p.height != h)
          throw InputError(fmt::format("frames of different sizes: {} x {} and {} x {}", w, h, p.width, p.height));
  }
  if (w < 8 || h < 8) throw InputError(fmt::format("frames of {} x {} pixels per channel are too small (at least 8 x 8)", w, h));
}

}  // namespace

ChannelCalibration calibrate_channel(const std::string& channel, const std::vector<ExposureStep>& input) {
  check_steps(input);
  ChannelCalibration c;
  c.channel = channel;

  // The dark frames by exposure time (a series at one exposure time shares its darks between its irradiances;
  // darks alone at further times measure the dark current).
  std::map<double, Temporal> dark_at;
  std::map<double, const ExposureStep*> darks_of;
  for (const ExposureStep& s : input)
    if (!dark_at.contains(s.exposure_s)) dark_at[s.exposure_s] = temporal(s.darks), darks_of[s.exposure_s] = &s;
  for (const auto& [t, d] : dark_at) c.dark_points.push_back({t, std::nullopt, 0, 0, d.mean, d.variance});
  const Temporal& shortest = dark_at.begin()->second;

  // The flats' steps, by exposure time and then by signal (one exposure time: the irradiance's order).
  std::vector<ExposureStep> steps;
  for (const ExposureStep& s : input)
    if (!s.flats.empty()) steps.push_back(s);
  std::vector<Temporal> flat, dark;
  for (const ExposureStep& s : steps) flat.push_back(temporal(s.flats));
  {
    std::vector<std::size_t> order(steps.size());
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return std::pair{steps[a].exposure_s, flat[a].mean} < std::pair{steps[b].exposure_s, flat[b].mean};
    });
    std::vector<ExposureStep> sorted_steps;
    std::vector<Temporal> sorted_flat;
    for (const std::size_t k : order) sorted_steps.push_back(std::move(steps[k])), sorted_flat.push_back(flat[k]);
    steps = std::move(sorted_steps), flat = std::move(sorted_flat);
  }
  const std::size_t n = steps[0].flats[0].values.size();
  const bool one_time = steps.front().exposure_s == steps.back().exposure_s;
  for (std::size_t k = 0; k < steps.size(); ++k) {
    dark.push_back(dark_at[steps[k].exposure_s]);
    c.points.push_back({steps[k].exposure_s, steps[k].photons_per_pixel, flat[k].mean, flat[k].variance, dark[k].mean, dark[k].variance});
  }

  // Flats no brighter than the darks (by 3 standard errors of the mean at every exposure) show no light at all.
  bool none_brighter = true;
  for (std::size_t k = 0; k < steps.size(); ++k)
    none_brighter = none_brighter && !(flat[k].mean - dark[k].mean > 3 * std::sqrt((flat[k].variance + dark[k].variance) / static_cast<double>(n)));
  if (none_brighter)
    throw InputError(fmt::format("channel {}: no flat is brighter than the dark frames of its exposure time (by 3 standard errors of "
                                 "the mean): are the flats dark frames?",
                                 channel));

  // Saturation: where the temporal variance of the flats is largest. A series whose last step is the largest has
  // not shown it.
  const auto top = static_cast<std::size_t>(std::max_element(flat.begin(), flat.end(), [](const Temporal& a, const Temporal& b) {
                                              return a.variance < b.variance;
                                            }) - flat.begin());
  // Every exposure beyond saturation, each pixel clipped: the flats' temporal variance no more than twice the darks'
  // (as for the clip level below) while they are brighter.
  bool all_clipped = true;
  for (std::size_t k = 0; k < steps.size(); ++k)
    all_clipped = all_clipped && flat[k].variance <= 2 * dark[k].variance && flat[k].mean > dark[k].mean;
  if (all_clipped)
    throw InputError(fmt::format("channel {}: every exposure clips every pixel (the flats' temporal variance is no more than twice "
                                 "the dark frames'); add shorter exposures, from a few per cent of saturation",
                                 channel));
  if (top + 1 == steps.size()) {
    if (one_time)
      throw InputError(fmt::format("channel {}: no irradiance saturates (the flats' temporal variance still grows at the brightest "
                                   "pair); add irradiances up to and beyond saturation",
                                   channel));
    throw InputError(fmt::format("channel {}: no exposure saturates (the flats' temporal variance still grows at the longest, "
                                 "{:.6g} s); add exposures up to and beyond saturation",
                                 channel, steps.back().exposure_s));
  }
  const double signal_sat = flat[top].mean - dark[top].mean;
  c.saturation_mean_dn = flat[top].mean;
  // Beyond saturation the mean can only approach the clip level: at the exposure of largest variance it lies within a
  // few spatial standard deviations of it (a few per cent). A series whose signal goes on well beyond that point either
  // jumps from below saturation to beyond it (its brighter flats clip every pixel: the variance's peak was missed), or
  // has a variance that falls while the signal still grows (they are not clipped): a response curve, not saturation.
  {
    double brightest = signal_sat;
    bool beyond_all_clipped = true;
    for (std::size_t k = top + 1; k < steps.size(); ++k) {
      const double s = flat[k].mean - dark[k].mean;
      if (s > kSaturationHeadroom * signal_sat) beyond_all_clipped = beyond_all_clipped && flat[k].variance <= 2 * dark[k].variance;
      brightest = std::max(brightest, s);
    }
    const std::string where = one_time ? std::string("an irradiance") : fmt::format("{:.6g} s", steps[top].exposure_s);
    if (brightest > kSaturationHeadroom * signal_sat && beyond_all_clipped)
      throw InputError(fmt::format("channel {}: the series jumps from {} ({:.4g} DN above dark, the largest temporal variance) to flats "
                                   "that clip every pixel ({:.4g} DN): saturation lies between, unmeasured; add exposures up to and "
                                   "through saturation in steps of a few per cent",
                                   channel, where, signal_sat, brightest));
    if (brightest > kSaturationHeadroom * signal_sat)
      throw InputError(fmt::format("channel {}: the temporal variance is largest at {}, where the signal ({:.4g} DN above dark) is far "
                                   "below what the brighter flats reach ({:.4g} DN): the variance falls while the signal still grows, as "
                                   "in frames encoded with a response curve (sRGB, a gamma), or under a light far from uniform over the "
                                   "sensor (EMVA 1288 asks for 3 %); calibration needs the camera's linear digital numbers (its raw "
                                   "frames) under a uniform light",
                                   channel, where, signal_sat, brightest));
  }

  // The system gain K from the photon transfer below 70 % of saturation.
  std::vector<double> x, y;
  for (std::size_t k = 0; k < top; ++k) {
    const double signal = flat[k].mean - dark[k].mean;
    if (signal > 0 && signal <= kGainFitTop * signal_sat) {
      x.push_back(signal);
      y.push_back(flat[k].variance - dark[k].variance);
    }
  }
  if (x.size() < 3) {
    // Why there are so few: saturation at the shortest exposure, or too few steps below 70 % of it.
    if (top == 0 && one_time)
      throw InputError(fmt::format("channel {}: the dimmest pair of flats already saturates (its temporal variance is the largest "
                                   "of the series); add lower irradiances",
                                   channel));
    if (top == 0)
      throw InputError(fmt::format("channel {}: the shortest exposure, {:.6g} s, already saturates (its flats' temporal variance is "
                                   "the largest of the series); add shorter exposures",
                                   channel, steps[0].exposure_s));
    throw InputError(fmt::format("channel {}: {} exposure{} between black and 70 % of saturation; the gain needs at least three",
                                 channel, x.size(), x.size() == 1 ? "" : "s"));
  }
  const LineFit gain = fit_line(x, y, true);
  const double K = gain.slope;
  // A gain is a measurement only when it is positive and well away from zero: three standard errors.
  if (!(K > 3 * gain.slope_se))
    throw InputError(fmt::format("channel {}: the photon transfer gives a gain of {:.4g} ± {:.2g} DN/e⁻, which is no measurement: "
                                 "the flats' temporal variance does not grow in proportion to their signal",
                                 channel, K, gain.slope_se));
  c.gain_dn_per_e = {K, gain.slope_se};
  auto relative = [](double se, double value) { return value != 0 ? se / std::abs(value) : 0.0; };
  const double rK = relative(gain.slope_se, K);

  c.saturation_capacity_e = {signal_sat / K, signal_sat / K * rK};

  // Dark signal against exposure time: the dark current (slope / K), the black level (intercept), and the dark
  // noise from the intercept of the dark variance.
  std::vector<double> times, dark_means, dark_variances;
  for (const auto& [t, d] : dark_at) {
    times.push_back(t);
    dark_means.push_back(d.mean);
    dark_variances.push_back(d.variance);
  }
  const bool several_times = times.front() < times.back();
  double dark_variance_0 = shortest.variance, dark_variance_0_se = variance_se(shortest.variance, n);
  if (several_times) {
    const LineFit dm = fit_line(times, dark_means, false);
    c.dark_current_e_per_s = {dm.slope / K, std::hypot(dm.slope_se / K, dm.slope / K * rK)};
    c.black_level_dn = {dm.intercept, dm.intercept_se};
    const LineFit dv = fit_line(times, dark_variances, false);
    const double K2 = K * K;
    c.dark_current_from_variance_e_per_s = Estimate{dv.slope / K2, std::hypot(dv.slope_se / K2, dv.slope / K2 * 2 * rK)};
    dark_variance_0 = dv.intercept;
    c.dark_variance_slope = dv.slope;
    dark_variance_0_se = std::max(dv.intercept_se, variance_se(shortest.variance, n) / std::sqrt(double(times.size())));
  } else {
    c.black_level_dn = {shortest.mean, std::sqrt(shortest.variance / double(n))};
    c.notes.push_back("every dark frame has one exposure time: no dark current measured");
  }
  c.dark_variance_dn2 = dark_variance_0;
  if (dark_variance_0 < kQuantisationLimit) {
    c.dark_noise_upper_limit = true;
    c.dark_noise_e = {std::sqrt(kQuantisationLimit - kQuantisationVariance) / K, 0.0};
    c.notes.push_back(fmt::format("the dark frames' temporal variance, {:.3g} DN², is below 0.24 DN²: quantisation hides "
                                  "the temporal dark noise, whose upper limit √(0.24 − 1/12)/K is given (EMVA 1288)",
                                  dark_variance_0));
  } else {
    const double read_variance = dark_variance_0 - kQuantisationVariance;
    const double sigma_d = std::sqrt(read_variance) / K;
    c.dark_noise_e = {sigma_d, sigma_d * std::hypot(dark_variance_0_se / (2 * read_variance), rK)};
  }

  // DSNU at the shortest exposure, PRNU at the flat level nearest half of saturation. A spread √v from a variance v
  // with standard error se has the standard error se / (2√v), or, where v is not above its error, is bounded by √se.
  auto spread = [](double variance, double se, double scale, double scale_relative_se) {
    if (variance <= se) return Estimate{std::sqrt(std::max(0.0, variance)) * scale, std::sqrt(se) * scale};
    const double v = std::sqrt(variance) * scale;
    return Estimate{v, v * std::hypot(se / (2 * variance), scale_relative_se)};
  };
  const std::vector<Plane>& shortest_darks = darks_of.begin()->second->darks;
  const Plane dark_average = average(shortest_darks);
  const SpatialVariance ds = spatial_variance(dark_average, shortest.variance, shortest_darks.size());
  c.dsnu_curves = spatial_curves(dark_average, 1, shortest.variance / double(shortest_darks.size()));
  c.dsnu_e = {spread(ds.total, ds.total_se, 1 / K, rK), spread(ds.row, ds.row_se, 1 / K, rK),
              spread(ds.column, ds.column_se, 1 / K, rK), spread(ds.pixel, ds.pixel_se, 1 / K, rK)};

  std::size_t half = 0;
  for (std::size_t k = 0; k < top; ++k)
    if (std::abs(flat[k].mean - dark[k].mean - 0.5 * signal_sat) < std::abs(flat[half].mean - dark[half].mean - 0.5 * signal_sat)) half = k;
  const double signal_half = flat[half].mean - dark[half].mean;
  c.prnu_level_fraction = signal_half / signal_sat;
  const Plane flat_mean = average(steps[half].flats), dark_mean = average(steps[half].darks);
  const SpatialVariance fs = spatial_variance(flat_mean, flat[half].variance, steps[half].flats.size());
  const SpatialVariance dh = spatial_variance(dark_mean, dark[half].variance, steps[half].darks.size());
  {
    Plane light = flat_mean;
    for (std::size_t p = 0; p < light.values.size(); ++p) light.values[p] -= dark_mean.values[p];
    c.prnu_curves = spatial_curves(light, 100 / signal_half,
                                   flat[half].variance / double(steps[half].flats.size()) + dark[half].variance / double(steps[half].darks.size()));
  }
  auto prnu_part = [&](double flat_part, double flat_se, double dark_part, double dark_se) {
    return spread(flat_part - dark_part, std::hypot(flat_se, dark_se), 1 / signal_half, 0.0);
  };
  c.prnu = {prnu_part(fs.total, fs.total_se, dh.total, dh.total_se), prnu_part(fs.row, fs.row_se, dh.row, dh.row_se),
            prnu_part(fs.column, fs.column_se, dh.column, dh.column_se), prnu_part(fs.pixel, fs.pixel_se, dh.pixel, dh.pixel_se)};

  // The clip level, from the exposures beyond saturation at which every pixel is clipped.
  double clipped_sum = 0, clipped_variance = 0;
  std::size_t clipped = 0;
  for (std::size_t k = top + 1; k < steps.size(); ++k)
    if (flat[k].variance <= 2 * dark[k].variance)
      clipped_sum += flat[k].mean, clipped_variance += flat[k].variance, ++clipped;
  // Pixels clipped by the well still carry the read noise added after it (the dark variance at no exposure: the
  // dark current's shot noise is clipped away with the signal's); clipped by the ADC, they hold its top code and no
  // variance.
  c.clips_at_adc = clipped > 0 && clipped_variance / double(clipped) < 0.5 * c.dark_variance_dn2;
  if (clipped > 0) {
    const double level = (clipped_sum / double(clipped) - c.black_level_dn.value) / K;
    c.clip_level_e = Estimate{level, level * std::hypot(rK, c.black_level_dn.standard_error / (level * K))};
  } else {
    c.notes.push_back("no exposure clips every pixel: no clip level (the full well written is EMVA's saturation capacity)");
  }

  // Linearity between 5 % and 95 % of saturation, against the photons (or the exposure time).
  const bool photons = std::all_of(steps.begin(), steps.end(), [](const ExposureStep& s) { return s.photons_per_pixel.has_value(); });
  std::vector<double> u, signal;
  for (std::size_t k = 0; k < top; ++k) {
    const double s = flat[k].mean - dark[k].mean;
    if (s >= kLinearityLow * signal_sat && s <= kLinearityHigh * signal_sat) {
      u.push_back(photons ? *steps[k].photons_per_pixel : steps[k].exposure_s);
      signal.push_back(s);
    }
  }
  if (one_time && !photons) {
    c.notes.push_back("the flats have one exposure time, and the photons per pixel of each pair were not given (--photons-per-pixel): "
                      "no linearity error, no quantum efficiency");
  } else if (u.size() >= 3 && u.front() < u.back()) {
    // EMVA 1288's fit: least squares of the relative deviations, each squared residual weighted by 1/y² (so a
    // bright point, whose absolute residual is large, weighs no more than a dim one); LE = (δmax − δmin)/2.
    std::vector<double> weights;
    for (const double y : signal) weights.push_back(1 / (y * y));
    const LineFit lin = fit_line(u, signal, false, weights);
    ChannelCalibration::Linearity l{lin.intercept, lin.slope, std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(), {}};
    for (std::size_t i = 0; i < u.size(); ++i) {
      const double fitted = lin.intercept + lin.slope * u[i];
      const double d = (signal[i] - fitted) / fitted;
      l.min = std::min(l.min, d), l.max = std::max(l.max, d);
      l.deviations.emplace_back(u[i], d);
    }
    c.linearity_error = (l.max - l.min) / 2;
    c.linearity = std::move(l);
  } else {
    c.notes.push_back("fewer than three exposures between 5 % and 95 % of saturation: no linearity error");
  }
  if (!photons && !one_time) c.notes.push_back("the photons per pixel were not given (--photons-per-s): no quantum efficiency, linearity against exposure time");

  // Quantum efficiency η = R / K, R the responsivity (DN per photon) over the gain's range.
  if (photons) {
    std::vector<double> p, s;
    for (std::size_t k = 0; k < top; ++k) {
      const double v = flat[k].mean - dark[k].mean;
      if (v > 0 && v <= kGainFitTop * signal_sat) {
        p.push_back(*steps[k].photons_per_pixel);
        s.push_back(v);
      }
    }
    const LineFit r = fit_line(p, s, true);
    c.responsivity = Estimate{r.slope, r.slope_se};
    c.quantum_efficiency = Estimate{r.slope / K, r.slope / K * std::hypot(relative(r.slope_se, r.slope), rK)};
    c.saturation_photons = *steps[top].photons_per_pixel;
    // With the photons known, EMVA 1288 gives the saturation capacity as η·μp.sat (its reference implementation too),
    // which differs from the signal's (μy.sat − μy.dark)/K where the response is not linear up to saturation.
    const Estimate& eta = *c.quantum_efficiency;
    c.saturation_capacity_e = {eta.value * *c.saturation_photons, eta.standard_error * *c.saturation_photons};
  }
  return c;
}

Sensitivity sensitivity(const ChannelCalibration& c) {
  Sensitivity s;
  const double K = c.gain_dn_per_e.value;
  s.inverse_gain = 1 / K;
  s.dark_sigma_dn = std::sqrt(std::max(c.dark_variance_dn2, kQuantisationLimit));
  s.threshold_e = s.dark_sigma_dn / K + 0.5;
  if (c.quantum_efficiency) s.threshold_photons = s.threshold_e / c.quantum_efficiency->value;
  s.snr_max = std::sqrt(c.saturation_capacity_e.value);
  s.dynamic_range = c.saturation_capacity_e.value / s.threshold_e;
  s.dsnu_dn = c.dsnu_e.total.value * K;
  return s;
}

}  // namespace ct::calibrate
