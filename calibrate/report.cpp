// SPDX-License-Identifier: Apache-2.0
#include "calibrate/report.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>

#include <fmt/format.h>

#include "core/file_io.h"
#include "core/html_text.h"
#include "core/json_input.h"
#include "plot/ticks.h"

namespace ct::calibrate {
namespace {

// Channel colours (a colour-blind-safe set: vermillion, bluish green, blue); a monochrome camera's channel black.
const char* channel_colour(const Calibration& cal, std::size_t c) {
  static constexpr const char* kRgb[3] = {"#d55e00", "#009e73", "#0072b2"};
  return cal.channels.size() == 1 ? "#222222" : kRgb[c % 3];
}

// An x–y plot: linear or logarithmic axes with the plotting kit's ticks (plot/ticks.h), series of points (markers)
// and of lines (the model), as SVG.
class Plot {
 public:
  Plot(std::string title, std::string x_label, std::string y_label, bool log_x, bool log_y)
      : title_(std::move(title)), x_label_(std::move(x_label)), y_label_(std::move(y_label)), log_x_(log_x), log_y_(log_y) {}

  void points(const std::vector<std::pair<double, double>>& xy, const char* colour, std::string label) {
    series_.push_back({xy, colour, std::move(label), false});
  }
  // Filled markers: a point of note (saturation).
  void marks(const std::vector<std::pair<double, double>>& xy, const char* colour, std::string label) {
    series_.push_back({xy, colour, std::move(label), false, false, true});
  }
  // A line; dashed for a reference (an ideal, a threshold) rather than a fitted model.
  void line(const std::vector<std::pair<double, double>>& xy, const char* colour, std::string label, bool dashed = false) {
    series_.push_back({xy, colour, std::move(label), true, dashed});
  }

  std::string svg() const {
    double x0 = kInf, x1 = -kInf, y0 = kInf, y1 = -kInf;
    for (const Series& s : series_)
      for (const auto& [x, y] : s.xy)
        if (usable(x, log_x_) && usable(y, log_y_)) x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    // Fewer than two distinct values: a decade either side of the one there is, or [1, 10] on a logarithmic axis
    // (whose ticks need a positive range), [0, 1] on a linear one.
    auto widen = [](double& lo, double& hi, bool log) {
      if (lo < hi) return;
      const bool one = std::isfinite(lo) && (!log || lo > 0);
      if (log) lo = one ? lo / 10 : 1, hi = one ? hi * 10 : 10;
      else lo = one ? lo - 1 : 0, hi = one ? hi + 1 : 1;
    };
    widen(x0, x1, log_x_);
    widen(y0, y1, log_y_);
    if (!log_x_) x0 = std::min(x0, 0.0);
    if (!log_y_) y0 = std::min(y0, 0.0);
    const Axis ax = axis(x0, x1, log_x_), ay = axis(y0, y1, log_y_);
    auto X = [&](double v) { return kLeft + (ax.map(v)) * (kWidth - kLeft - kRight); };
    auto Y = [&](double v) { return kHeight - kBottom - ay.map(v) * (kHeight - kTop - kBottom); };

    std::string s = fmt::format(R"svg(<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {} {}" width="{}" height="{}" font-family="sans-serif" font-size="12">)svg",
                                kWidth, kHeight, kWidth, kHeight);
    s += fmt::format(R"svg(<rect width="{}" height="{}" fill="white"/>)svg", kWidth, kHeight);
    s += fmt::format(R"svg(<text x="{}" y="18" font-size="14" font-weight="bold">{}</text>)svg", kLeft, escape_html(title_));
    for (const double t : ax.ticks) {
      s += fmt::format(R"svg(<line x1="{0:.1f}" y1="{1}" x2="{0:.1f}" y2="{2}" stroke="#e4e4e4"/>)svg", X(t), kTop, kHeight - kBottom);
      s += fmt::format(R"svg(<text x="{:.1f}" y="{}" text-anchor="middle">{}</text>)svg", X(t), kHeight - kBottom + 16, ax.label(t));
    }
    for (const double t : ay.ticks) {
      s += fmt::format(R"svg(<line x1="{0}" y1="{1:.1f}" x2="{2}" y2="{1:.1f}" stroke="#e4e4e4"/>)svg", kLeft, Y(t), kWidth - kRight);
      s += fmt::format(R"svg(<text x="{}" y="{:.1f}" text-anchor="end">{}</text>)svg", kLeft - 6, Y(t) + 4, ay.label(t));
    }
    s += fmt::format(R"svg(<rect x="{}" y="{}" width="{}" height="{}" fill="none" stroke="#555"/>)svg", kLeft, kTop, kWidth - kLeft - kRight,
                     kHeight - kTop - kBottom);
    s += fmt::format(R"svg(<text x="{}" y="{}" text-anchor="middle">{}</text>)svg", (kLeft + kWidth - kRight) / 2, kHeight - 8, escape_html(x_label_));
    s += fmt::format(R"svg(<text transform="translate(16 {}) rotate(-90)" text-anchor="middle">{}</text>)svg", (kTop + kHeight - kBottom) / 2,
                     escape_html(y_label_));
    int legend = 0;
    for (const Series& series : series_) {
      std::string path;
      for (const auto& [x, y] : series.xy) {
        if (!usable(x, log_x_) || !usable(y, log_y_)) continue;
        if (series.is_line) {
          path += fmt::format("{}{:.1f},{:.1f}", path.empty() ? "M" : " L", X(x), Y(y));
        } else {
          s += fmt::format(R"svg(<circle cx="{:.1f}" cy="{:.1f}" r="{}" fill="{}" stroke="{}"/>)svg", X(x), Y(y), series.filled ? 4 : 3,
                           series.filled ? series.colour : "none", series.colour);
        }
      }
      if (series.is_line && !path.empty())
        s += fmt::format(R"svg(<path d="{}" fill="none" stroke="{}" stroke-width="1.2"{}/>)svg", path, series.colour,
                         series.dashed ? R"( stroke-dasharray="5 4")" : "");
      if (!series.label.empty()) {
        const double ly = kTop + 14 + 16 * legend++;
        s += series.is_line ? fmt::format(R"svg(<line x1="{}" y1="{:.1f}" x2="{}" y2="{:.1f}" stroke="{}"{}/>)svg", kLeft + 10, ly - 4, kLeft + 28,
                                          ly - 4, series.colour, series.dashed ? R"( stroke-dasharray="5 4")" : "")
                            : fmt::format(R"svg(<circle cx="{}" cy="{:.1f}" r="3" fill="{}" stroke="{}"/>)svg", kLeft + 19, ly - 4,
                                          series.filled ? series.colour : "none", series.colour);
        s += fmt::format(R"svg(<text x="{}" y="{:.1f}">{}</text>)svg", kLeft + 34, ly, escape_html(series.label));
      }
    }
    return s + "</svg>\n";
  }

 private:
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  // kRight leaves room for half the last x tick's label ("60000" centred on the frame's edge).
  static constexpr int kWidth = 520, kHeight = 360, kLeft = 70, kRight = 36, kTop = 30, kBottom = 46;
  struct Series {
    std::vector<std::pair<double, double>> xy;
    const char* colour;
    std::string label;
    bool is_line;
    bool dashed = false;
    bool filled = false;
  };
  struct Axis {
    double lo, hi;
    bool log;
    double step = 1;  // of a linear axis
    std::vector<double> ticks;
    double map(double v) const { return log ? (std::log10(v) - std::log10(lo)) / (std::log10(hi) - std::log10(lo)) : (v - lo) / (hi - lo); }
    std::string label(double t) const { return log ? plot::superscript_exponent(plot::log_tick_label(t)) : plot::tick_label(t, step); }
  };
  static bool usable(double v, bool log) { return std::isfinite(v) && (!log || v > 0); }
  // A logarithmic axis spans whole decades, a linear one whole steps.
  static Axis axis(double lo, double hi, bool log) {
    Axis a{lo, hi, log, 1, {}};
    if (log) {
      a.lo = std::pow(10.0, std::floor(std::log10(lo)));
      a.hi = std::pow(10.0, std::ceil(std::log10(hi)));
      a.ticks = plot::log_ticks(a.lo, a.hi);
    } else {
      const plot::NiceRange r = plot::nice_range(lo, hi, 5);
      a.lo = r.lo, a.hi = r.hi, a.step = r.step;
      a.ticks = plot::multiples_in(r.lo, r.hi, r.step);
    }
    return a;
  }
  std::string title_, x_label_, y_label_;
  bool log_x_, log_y_;
  std::vector<Series> series_;
};

// The x axis of the signal plots: photons per pixel when known, else the signal in electrons.
bool have_photons(const ChannelCalibration& c) {
  return std::all_of(c.points.begin(), c.points.end(), [](const TransferPoint& p) { return p.photons_per_pixel.has_value(); });
}

std::string photon_transfer(const Calibration& cal) {
  Plot plot("Photon transfer", "mean signal above dark, μy − μy.dark (DN)", "temporal variance above dark, σ²y − σ²y.dark (DN²)", false, false);
  for (std::size_t c = 0; c < cal.channels.size(); ++c) {
    const ChannelCalibration& ch = cal.channels[c];
    std::vector<std::pair<double, double>> xy;
    double top = 0;
    for (const TransferPoint& p : ch.points) {
      xy.emplace_back(p.mean_dn - p.dark_mean_dn, p.variance_dn2 - p.dark_variance_dn2);
      top = std::max(top, p.mean_dn - p.dark_mean_dn);
    }
    plot.points(xy, channel_colour(cal, c), fmt::format("{}: K = {:.4g} DN/e⁻", ch.channel, ch.gain_dn_per_e.value));
    const double fit_top = 0.7 * (ch.saturation_mean_dn - ch.points.back().dark_mean_dn);
    plot.line({{0.0, 0.0}, {fit_top, ch.gain_dn_per_e.value * fit_top}}, channel_colour(cal, c), "");
  }
  // The saturation point of each channel: the exposure of largest temporal variance.
  for (std::size_t c = 0; c < cal.channels.size(); ++c) {
    const ChannelCalibration& ch = cal.channels[c];
    for (const TransferPoint& p : ch.points)
      if (p.mean_dn == ch.saturation_mean_dn)
        plot.marks({{p.mean_dn - p.dark_mean_dn, p.variance_dn2 - p.dark_variance_dn2}}, channel_colour(cal, c),
                   c == 0 ? "saturation, μy.sat (filled)" : "");
  }
  return plot.svg();
}

std::string snr(const Calibration& cal) {
  const bool photons = have_photons(cal.channels[0]);
  Plot plot("Signal-to-noise ratio", photons ? "photons per pixel, μp" : "signal, μe (e⁻)", "SNR", true, true);
  for (std::size_t c = 0; c < cal.channels.size(); ++c) {
    const ChannelCalibration& ch = cal.channels[c];
    const double K = ch.gain_dn_per_e.value, eta = ch.quantum_efficiency ? ch.quantum_efficiency->value : 1.0;
    std::vector<std::pair<double, double>> measured, model;
    for (const TransferPoint& p : ch.points) {
      const double signal = p.mean_dn - p.dark_mean_dn, x = photons ? *p.photons_per_pixel : signal / K;
      if (p.mean_dn < ch.saturation_mean_dn) measured.emplace_back(x, signal / std::sqrt(p.variance_dn2));
    }
    // The EMVA 1288 model: SNR = η μp / √(σd² + σq²/K² + η μp), up to saturation.
    const double x_sat = photons ? ch.saturation_capacity_e.value / eta : ch.saturation_capacity_e.value;
    for (double x = x_sat / 1e4; x <= x_sat * 1.0001; x *= 1.2) {
      const double e = photons ? eta * x : x;
      model.emplace_back(x, e / std::sqrt(ch.dark_noise_e.value * ch.dark_noise_e.value + 1.0 / 12.0 / (K * K) + e));
    }
    plot.points(measured, channel_colour(cal, c), ch.channel + (photons ? fmt::format(": η = {:.3g}", eta) : ""));
    plot.line(model, channel_colour(cal, c), "");
  }
  // The ideal sensor (η = 1, no noise but the photons' own: SNR = √μp), and the first channel's absolute sensitivity
  // threshold (SNR = 1) and saturation, as EMVA 1288's SNR plot marks them.
  const ChannelCalibration& first = cal.channels[0];
  const Sensitivity f = sensitivity(first);
  const double eta = first.quantum_efficiency ? first.quantum_efficiency->value : 1.0;
  const double lo = f.threshold_e / eta / 10, hi = first.saturation_capacity_e.value / eta * 1.0001;
  std::vector<std::pair<double, double>> ideal;
  for (double x = lo; x <= hi * 1.2; x *= 1.2) ideal.emplace_back(x, std::sqrt(x));
  plot.line(ideal, "#888888", photons ? "ideal: √μp" : "ideal: √μe", true);
  const double threshold = photons && f.threshold_photons ? *f.threshold_photons : f.threshold_e;
  const double saturation = photons && first.saturation_photons ? *first.saturation_photons : first.saturation_capacity_e.value;
  auto number = [](double v) { return v >= 1000 ? fmt::format("{:.0f}", v) : fmt::format("{:.3g}", v); };
  plot.line({{threshold, 0.1}, {threshold, std::sqrt(hi * 1.2)}}, "#444444",
            fmt::format("{}: {} ({})", photons ? "μp.min" : "μe.min", number(threshold), first.channel), true);
  plot.line({{saturation, 0.1}, {saturation, std::sqrt(hi * 1.2)}}, "#aaaaaa",
            fmt::format("{}: {} ({})", photons ? "μp.sat" : "μe.sat", number(saturation), first.channel), true);
  return plot.svg();
}

std::string linearity(const Calibration& cal) {
  const bool photons = have_photons(cal.channels[0]);
  Plot plot("Linearity", photons ? "photons per pixel, μp" : "exposure time (s)", "mean signal above dark (DN)", false, false);
  for (std::size_t c = 0; c < cal.channels.size(); ++c) {
    const ChannelCalibration& ch = cal.channels[c];
    std::vector<std::pair<double, double>> xy;
    for (const TransferPoint& p : ch.points) xy.emplace_back(photons ? *p.photons_per_pixel : p.exposure_s, p.mean_dn - p.dark_mean_dn);
    plot.points(xy, channel_colour(cal, c), fmt::format("{}: linearity error {:.2g} %", ch.channel, 100 * ch.linearity_error));
    if (ch.linearity) {
      const double x0 = ch.linearity->deviations.front().first, x1 = ch.linearity->deviations.back().first;
      plot.line({{x0, ch.linearity->intercept + ch.linearity->slope * x0}, {x1, ch.linearity->intercept + ch.linearity->slope * x1}},
                channel_colour(cal, c), "");
    }
  }
  return plot.svg();
}

// EMVA 1288's deviation plot: each fitted point's relative deviation from the linearity fit, in per cent.
std::string linearity_deviation(const Calibration& cal) {
  const bool photons = have_photons(cal.channels[0]);
  Plot plot("Deviation from linearity", photons ? "photons per pixel, μp" : "exposure time (s)", "deviation (%)", false, false);
  for (std::size_t c = 0; c < cal.channels.size(); ++c) {
    const ChannelCalibration& ch = cal.channels[c];
    if (!ch.linearity) continue;
    std::vector<std::pair<double, double>> xy;
    for (const auto& [x, d] : ch.linearity->deviations) xy.emplace_back(x, 100 * d);
    plot.points(xy, channel_colour(cal, c),
                fmt::format("{}: LE min {:.3g} %, max {:.3g} %", ch.channel, 100 * ch.linearity->min, 100 * ch.linearity->max));
    plot.line(xy, channel_colour(cal, c), "");
  }
  return plot.svg();
}

// The dark variance against exposure time: its slope over K² is the dark current from the variance, its intercept
// the temporal dark noise.
std::string dark_variance(const Calibration& cal) {
  Plot plot("Dark noise", "exposure time (s)", "temporal dark variance, σ²y.dark (DN²)", false, false);
  for (std::size_t c = 0; c < cal.channels.size(); ++c) {
    const ChannelCalibration& ch = cal.channels[c];
    std::vector<std::pair<double, double>> xy;
    for (const TransferPoint& p : ch.dark_points) xy.emplace_back(p.exposure_s, p.dark_variance_dn2);
    plot.points(xy, channel_colour(cal, c),
                ch.dark_current_from_variance_e_per_s
                    ? fmt::format("{}: {:.3g} e⁻/s from the variance", ch.channel, ch.dark_current_from_variance_e_per_s->value)
                    : ch.channel);
    if (ch.dark_variance_slope) {
      const double t1 = ch.dark_points.back().exposure_s;
      plot.line({{0.0, ch.dark_variance_dn2}, {t1, ch.dark_variance_dn2 + *ch.dark_variance_slope * t1}}, channel_colour(cal, c), "");
    }
  }
  return plot.svg();
}

std::string dark_signal(const Calibration& cal) {
  Plot plot("Dark signal", "exposure time (s)", "mean dark signal, μy.dark (DN)", false, false);
  for (std::size_t c = 0; c < cal.channels.size(); ++c) {
    const ChannelCalibration& ch = cal.channels[c];
    std::vector<std::pair<double, double>> xy;
    for (const TransferPoint& p : ch.dark_points) xy.emplace_back(p.exposure_s, p.dark_mean_dn);
    plot.points(xy, channel_colour(cal, c), fmt::format("{}: {:.3g} e⁻/s", ch.channel, ch.dark_current_e_per_s.value));
    const double t1 = ch.dark_points.back().exposure_s;
    plot.line({{0.0, ch.black_level_dn.value}, {t1, ch.black_level_dn.value + ch.gain_dn_per_e.value * ch.dark_current_e_per_s.value * t1}},
              channel_colour(cal, c), "");
  }
  return plot.svg();
}

// The spatial plots (calibrate/spatial.h): for DSNU (`prnu` false, in DN) or PRNU (in %), one line per channel,
// horizontal solid and vertical dashed where both are drawn.
using Curves = SpatialCurves ChannelCalibration::*;
std::string spectrogram(const Calibration& cal, Curves curves, const std::string& what, const std::string& unit) {
  Plot plot(what + " spectrogram", "spatial frequency (cycles per pixel)", "standard deviation (" + unit + ")", false, true);
  for (std::size_t c = 0; c < cal.channels.size(); ++c) {
    const SpatialCurves& s = cal.channels[c].*curves;
    for (const bool vertical : {false, true}) {
      const std::vector<double>& sigma = vertical ? s.spectrum_vertical : s.spectrum_horizontal;
      std::vector<std::pair<double, double>> xy;
      const double n = 2.0 * static_cast<double>(sigma.size());
      for (std::size_t k = 0; k < sigma.size(); ++k) xy.emplace_back(static_cast<double>(k + 1) / n, sigma[k]);
      plot.line(xy, channel_colour(cal, c),
                vertical ? (c == 0 ? "vertical (dashed)" : "") : cal.channels[c].channel + (c == 0 ? " horizontal (solid)" : ""), vertical);
    }
  }
  const SpatialCurves& first = cal.channels[0].*curves;
  plot.line({{0.0, first.temporal_floor}, {0.5, first.temporal_floor}}, "#888888", "temporal noise left in the mean", true);
  return plot.svg();
}

std::string profiles(const Calibration& cal, Curves curves, const std::string& what, const std::string& unit) {
  Plot plot(what + " profiles", "column (solid) or row (dashed)", "mean deviation (" + unit + ")", false, false);
  for (std::size_t c = 0; c < cal.channels.size(); ++c) {
    const SpatialCurves& s = cal.channels[c].*curves;
    for (const bool vertical : {false, true}) {
      const std::vector<double>& p = vertical ? s.profile_vertical : s.profile_horizontal;
      std::vector<std::pair<double, double>> xy;
      for (std::size_t i = 0; i < p.size(); ++i) xy.emplace_back(static_cast<double>(i), p[i]);
      plot.line(xy, channel_colour(cal, c), vertical ? "" : cal.channels[c].channel, vertical);
    }
  }
  return plot.svg();
}

std::string histogram(const Calibration& cal, Curves curves, const std::string& what, const std::string& unit, bool accumulated) {
  Plot plot(what + (accumulated ? " accumulated histogram" : " histogram"),
            accumulated ? "deviation from the mean, at least (" + unit + ")" : "deviation from the mean (" + unit + ")",
            accumulated ? "pixels (%)" : "pixels", false, true);
  for (std::size_t c = 0; c < cal.channels.size(); ++c) {
    const SpatialCurves& s = cal.channels[c].*curves;
    plot.line(accumulated ? s.accumulated : s.histogram, channel_colour(cal, c), cal.channels[c].channel);
  }
  return plot.svg();
}

std::string cell(const Estimate& e, double scale = 1) {
  const double v = e.value * scale, se = e.standard_error * scale;
  return std::abs(v) >= 1000 ? fmt::format("{:.0f} ± {:.0f}", v, se) : fmt::format("{:.4g} ± {:.2g}", v, se);
}

std::string page(const Calibration& cal, const std::vector<std::pair<std::string, std::string>>& plots) {
  std::string html = R"svg(<!DOCTYPE html><html lang="en"><head><meta charset="utf-8"><title>Camera calibration (EMVA 1288)</title>
<style>body{font-family:sans-serif;margin:24px;color:#222;max-width:1120px}table{border-collapse:collapse;margin:12px 0}
td,th{border-bottom:1px solid #ddd;padding:4px 10px;text-align:right}th:first-child,td:first-child{text-align:left}
.plots{display:flex;flex-wrap:wrap;gap:12px}figure{margin:0}.note{color:#555;font-size:13px}</style></head><body>)svg";
  html += "<h1>Camera calibration (EMVA 1288 Release 4.0, Linear)</h1>";
  html += fmt::format("<p class=\"note\">{} flat and {} dark frames ({}); each estimate with its standard error. "
                      "Every number, and the sensor settings for <code>chromatrace sensor --config</code> (its <code>sensor</code>), in "
                      "<a href=\"calibration.json\">calibration.json</a>.</p>",
                      cal.flats, cal.darks, escape_html(cal.series));
  // The operating point, as a datasheet opens with it.
  html += "<table><tr><th>operating point</th><th></th></tr>";
  auto fact = [&](const std::string& name, const std::string& value) {
    html += "<tr><td>" + name + "</td><td style=\"text-align:left\">" + escape_html(value) + "</td></tr>";
  };
  fact("camera (the frames)", cal.camera);
  fact("pixels per channel", fmt::format("{} × {}", cal.frame_size.first, cal.frame_size.second));
  fact("series", cal.series);
  fact("flats' exposure time", cal.flat_exposure_min_s == cal.flat_exposure_max_s
                                   ? fmt::format("{:.6g} s", cal.flat_exposure_min_s)
                                   : fmt::format("{:.6g} – {:.6g} s", cal.flat_exposure_min_s, cal.flat_exposure_max_s));
  fact("light", cal.wavelength_nm ? fmt::format("{:g} nm", *cal.wavelength_nm) : std::string("wavelength not given (--wavelength)"));
  fact("pixel pitch", cal.pixel_pitch_um ? fmt::format("{:g} µm", *cal.pixel_pitch_um) : std::string("not given (--pixel-um)"));
  fact("temperature", cal.temperature_c ? fmt::format("{:g} °C", *cal.temperature_c) : std::string("not given (--temperature)"));
  if (!cal.date.empty()) fact("date (EXIF, first frame)", cal.date);
  html += "</table>";

  html += "<table><tr><th>quantity</th>";
  for (const ChannelCalibration& c : cal.channels) html += "<th>" + escape_html(c.channel) + "</th>";
  html += "</tr>";
  auto row = [&](const std::string& name, auto get) {
    html += "<tr><td>" + name + "</td>";
    for (const ChannelCalibration& c : cal.channels) html += "<td>" + get(c) + "</td>";
    html += "</tr>";
  };
  auto optional_cell = [](const std::optional<Estimate>& e, double scale = 1) { return e ? cell(*e, scale) : std::string("—"); };
  auto ratio = [](double v) { return fmt::format("{:.4g} = {:.1f} dB = {:.1f} bits", v, 20 * std::log10(v), std::log2(v)); };
  row("system gain K (DN/e⁻)", [](const auto& c) { return cell(c.gain_dn_per_e); });
  row("&nbsp;&nbsp;1/K (e⁻/DN)", [](const auto& c) { return fmt::format("{:.4g}", sensitivity(c).inverse_gain); });
  row("quantum efficiency η", [&](const auto& c) { return optional_cell(c.quantum_efficiency); });
  row("responsivity R = ηK (DN/photon)", [&](const auto& c) { return optional_cell(c.responsivity); });
  row("temporal dark noise σd (e⁻)", [](const auto& c) {
    return c.dark_noise_upper_limit ? fmt::format("≤ {:.3g} (quantisation)", c.dark_noise_e.value) : cell(c.dark_noise_e);
  });
  row("&nbsp;&nbsp;σy.dark (DN)", [](const auto& c) { return fmt::format("{:.4g}", sensitivity(c).dark_sigma_dn); });
  row("absolute sensitivity threshold μe.min (e⁻)", [](const auto& c) { return fmt::format("{:.4g}", sensitivity(c).threshold_e); });
  row("&nbsp;&nbsp;μp.min (photons)", [](const auto& c) {
    const auto t = sensitivity(c).threshold_photons;
    return t ? fmt::format("{:.4g}", *t) : std::string("—");
  });
  if (cal.pixel_pitch_um) {
    const double area = *cal.pixel_pitch_um * *cal.pixel_pitch_um;
    row("&nbsp;&nbsp;μp.min per area (photons/µm²)", [&](const auto& c) {
      const auto t = sensitivity(c).threshold_photons;
      return t ? fmt::format("{:.4g}", *t / area) : std::string("—");
    });
  }
  row("saturation capacity μe.sat (e⁻)", [](const auto& c) { return cell(c.saturation_capacity_e); });
  if (cal.pixel_pitch_um) {
    const double area = *cal.pixel_pitch_um * *cal.pixel_pitch_um;
    row("&nbsp;&nbsp;μe.sat per area (e⁻/µm²)", [&](const auto& c) { return fmt::format("{:.4g}", c.saturation_capacity_e.value / area); });
  }
  row("&nbsp;&nbsp;μp.sat (photons)", [](const auto& c) { return c.saturation_photons ? fmt::format("{:.6g}", *c.saturation_photons) : std::string("—"); });
  row("clip level (e⁻)", [](const auto& c) {
    return c.clip_level_e ? cell(*c.clip_level_e) + (c.clips_at_adc ? " (the ADC's top code)" : "") : std::string("—");
  });
  row("maximum SNR", [&](const auto& c) { return ratio(sensitivity(c).snr_max); });
  row("dynamic range μe.sat / μe.min", [&](const auto& c) { return ratio(sensitivity(c).dynamic_range); });
  row("dark current from the dark mean (e⁻/s)", [](const auto& c) { return cell(c.dark_current_e_per_s); });
  row("dark current from the dark variance (e⁻/s)", [&](const auto& c) { return optional_cell(c.dark_current_from_variance_e_per_s); });
  row("black level (DN)", [](const auto& c) { return cell(c.black_level_dn); });
  row("DSNU (e⁻): total", [](const auto& c) { return cell(c.dsnu_e.total); });
  row("&nbsp;&nbsp;row / column / pixel", [](const auto& c) {
    return fmt::format("{:.3g} / {:.3g} / {:.3g}", c.dsnu_e.row.value, c.dsnu_e.column.value, c.dsnu_e.pixel.value);
  });
  row("&nbsp;&nbsp;DSNU (DN)", [](const auto& c) { return fmt::format("{:.4g}", sensitivity(c).dsnu_dn); });
  row("PRNU (%): total", [](const auto& c) { return cell(c.prnu.total, 100); });
  row("&nbsp;&nbsp;row / column / pixel", [](const auto& c) {
    return fmt::format("{:.3g} / {:.3g} / {:.3g}", 100 * c.prnu.row.value, 100 * c.prnu.column.value, 100 * c.prnu.pixel.value);
  });
  row("linearity error LE (%)", [](const auto& c) { return c.linearity ? fmt::format("{:.2g}", 100 * c.linearity_error) : std::string("—"); });
  row("&nbsp;&nbsp;LE min / max (%)", [](const auto& c) {
    return c.linearity ? fmt::format("{:.3g} / {:.3g}", 100 * c.linearity->min, 100 * c.linearity->max) : std::string("—");
  });
  html += "</table>";
  for (const std::string& n : cal.notes) html += fmt::format("<p class=\"note\">{}</p>", escape_html(n));
  const NoiseCorrelation& nc = cal.noise_correlation;
  html += fmt::format("<p class=\"note\">The temporal noise's correlation (the flats' pair differences): {:.3f} between horizontal "
                      "and {:.3f} between vertical neighbours{}, ± {:.2g}; about 0 where each pixel is read on its own.</p>",
                      nc.horizontal, nc.vertical,
                      nc.channel_pair.empty() ? "" : fmt::format(", {:.3f} between channels ({})", nc.between_channels, escape_html(nc.channel_pair)),
                      nc.standard_error);
  html += "<div class=\"plots\">";
  for (const auto& [name, svg] : plots) html += "<figure>" + svg + "</figure>";
  html += "</div>";
  for (const ChannelCalibration& c : cal.channels)
    for (const std::string& n : c.notes) html += fmt::format("<p class=\"note\">{}: {}</p>", escape_html(c.channel), escape_html(n));
  return html + "</body></html>\n";
}

void write_text(const std::filesystem::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  out << text;
  if (!out.flush()) throw std::runtime_error(fmt::format("{}: cannot write", file.string()));
}

}  // namespace

std::vector<std::pair<std::string, std::string>> report_plots(const Calibration& calibration) {
  std::vector<std::pair<std::string, std::string>> plots = {{"photon_transfer.svg", photon_transfer(calibration)},
                                                            {"snr.svg", snr(calibration)}};
  // Linearity against exposure time needs times that vary; at one time, against the photons when they are given.
  const std::vector<TransferPoint>& points = calibration.channels[0].points;
  if (have_photons(calibration.channels[0]) || points.front().exposure_s < points.back().exposure_s)
    plots.emplace_back("linearity.svg", linearity(calibration));
  if (std::any_of(calibration.channels.begin(), calibration.channels.end(), [](const ChannelCalibration& c) { return c.linearity.has_value(); }))
    plots.emplace_back("linearity_deviation.svg", linearity_deviation(calibration));
  plots.emplace_back("dark_signal.svg", dark_signal(calibration));
  plots.emplace_back("dark_variance.svg", dark_variance(calibration));
  const Curves dsnu = &ChannelCalibration::dsnu_curves, prnu = &ChannelCalibration::prnu_curves;
  plots.emplace_back("dsnu_spectrogram.svg", spectrogram(calibration, dsnu, "DSNU", "DN"));
  plots.emplace_back("prnu_spectrogram.svg", spectrogram(calibration, prnu, "PRNU", "%"));
  plots.emplace_back("dsnu_profiles.svg", profiles(calibration, dsnu, "DSNU", "DN"));
  plots.emplace_back("prnu_profiles.svg", profiles(calibration, prnu, "PRNU", "%"));
  plots.emplace_back("dsnu_histogram.svg", histogram(calibration, dsnu, "DSNU", "DN", false));
  plots.emplace_back("prnu_histogram.svg", histogram(calibration, prnu, "PRNU", "%", false));
  plots.emplace_back("dsnu_accumulated.svg", histogram(calibration, dsnu, "DSNU", "DN", true));
  plots.emplace_back("prnu_accumulated.svg", histogram(calibration, prnu, "PRNU", "%", true));
  return plots;
}

std::vector<std::string> report_files() {
  return {"index.html",           "calibration.json",     "photon_transfer.svg",  "snr.svg",
          "linearity.svg",        "linearity_deviation.svg", "dark_signal.svg",   "dark_variance.svg",
          "dsnu_spectrogram.svg", "prnu_spectrogram.svg", "dsnu_profiles.svg",    "prnu_profiles.svg",
          "dsnu_histogram.svg",   "prnu_histogram.svg",   "dsnu_accumulated.svg", "prnu_accumulated.svg"};
}

void write_report(const Calibration& calibration, const std::filesystem::path& staging) {
  const auto plots = report_plots(calibration);
  write_text(staging / "calibration.json", calibration.report.dump(2, ' ', false, kReplaceInvalidUtf8) + "\n");
  for (const auto& [name, svg] : plots) write_text(staging / name, svg);
  write_text(staging / "index.html", page(calibration, plots));
}

}  // namespace ct::calibrate
