// SPDX-License-Identifier: Apache-2.0
#include "core/spectrum.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include <fmt/core.h>

#include "core/error.h"
#include "core/limits.h"

namespace ct {

PiecewiseLinearSpectrum::PiecewiseLinearSpectrum(std::vector<double> wavelengths, std::vector<double> values,
                                                 Extrapolation outside, const std::string& what)
    : lambda_(std::move(wavelengths)), value_(std::move(values)), outside_(outside) {
  if (lambda_.size() != value_.size())
    throw InputError(fmt::format("{}: {} wavelengths but {} values", what, lambda_.size(), value_.size()));
  if (lambda_.empty()) throw InputError(fmt::format("{}: no samples", what));
  for (std::size_t i = 0; i < lambda_.size(); ++i) {
    if (!std::isfinite(lambda_[i]) || !std::isfinite(value_[i]))
      throw InputError(fmt::format("{}: sample {} is not finite", what, i));
    if (i > 0 && lambda_[i] <= lambda_[i - 1])
      throw InputError(fmt::format("{}: wavelengths must increase, but {} nm follows {} nm", what, lambda_[i],
                                   lambda_[i - 1]));
  }
  // A single sample describes a constant: only clamping gives it meaning over a range.
  if (lambda_.size() == 1) outside_ = Extrapolation::Clamp;
}

PiecewiseLinearSpectrum PiecewiseLinearSpectrum::constant(double value) {
  return PiecewiseLinearSpectrum({560.0}, {value}, Extrapolation::Clamp, "constant spectrum");
}

double PiecewiseLinearSpectrum::operator()(double nm) const {
  if (nm <= lambda_.front()) return (nm == lambda_.front() || outside_ == Extrapolation::Clamp) ? value_.front() : 0.0;
  if (nm >= lambda_.back()) return (nm == lambda_.back() || outside_ == Extrapolation::Clamp) ? value_.back() : 0.0;
  const std::size_t i = static_cast<std::size_t>(std::upper_bound(lambda_.begin(), lambda_.end(), nm) - lambda_.begin());
  const double t = (nm - lambda_[i - 1]) / (lambda_[i] - lambda_[i - 1]);
  return value_[i - 1] + t * (value_[i] - value_[i - 1]);
}

double PiecewiseLinearSpectrum::integral(double lo, double hi) const {
  if (hi < lo) return -integral(hi, lo);
  double sum = 0.0;
  // Parts outside the table: constant end values when clamping, zero otherwise.
  if (outside_ == Extrapolation::Clamp) {
    if (lo < lambda_.front()) sum += value_.front() * (std::min(hi, lambda_.front()) - lo);
    if (hi > lambda_.back()) sum += value_.back() * (hi - std::max(lo, lambda_.back()));
  }
  const double a = std::max(lo, lambda_.front());
  const double b = std::min(hi, lambda_.back());
  if (a >= b) return sum;
  // Trapezoids are exact on each linear segment; the first and last are cut at a and b.
  std::size_t i = static_cast<std::size_t>(std::upper_bound(lambda_.begin(), lambda_.end(), a) - lambda_.begin());
  double x0 = a, f0 = (*this)(a);
  for (; i < lambda_.size() && lambda_[i] < b; ++i) {
    sum += 0.5 * (lambda_[i] - x0) * (f0 + value_[i]);
    x0 = lambda_[i];
    f0 = value_[i];
  }
  sum += 0.5 * (b - x0) * (f0 + (*this)(b));
  return sum;
}

double PiecewiseLinearSpectrum::average(double lo, double hi) const {
  if (hi == lo) return (*this)(lo);
  return integral(lo, hi) / (hi - lo);
}

PiecewiseLinearSpectrum PiecewiseLinearSpectrum::scaled(double factor) const {
  PiecewiseLinearSpectrum s = *this;
  for (double& v : s.value_) v *= factor;
  return s;
}

// ---- Bands ----

Bands Bands::from_edges(std::vector<double> edges, const std::string& what) {
  if (edges.size() < 2) throw InputError(fmt::format("{}: need at least two band edges, got {}", what, edges.size()));
  if (edges.size() - 1 > kMaxBands)
    throw InputError(fmt::format("{}: {} bands, more than the limit of {}", what, edges.size() - 1, kMaxBands));
  for (std::size_t i = 0; i < edges.size(); ++i) {
    if (!std::isfinite(edges[i]) || edges[i] <= 0)
      throw InputError(fmt::format("{}: band edge {} must be a positive wavelength, got {}", what, i, edges[i]));
    if (i > 0 && edges[i] <= edges[i - 1])
      throw InputError(fmt::format("{}: band edges must increase, but {} nm follows {} nm", what, edges[i],
                                   edges[i - 1]));
  }
  Bands b;
  b.edges_ = std::move(edges);
  return b;
}

Bands Bands::uniform(double lo, double hi, double width, const std::string& what) {
  if (!(width > 0)) throw InputError(fmt::format("{}: band width must be > 0, got {}", what, width));
  if (!(hi > lo)) throw InputError(fmt::format("{}: range end {} must exceed start {}", what, hi, lo));
  const double count = (hi - lo) / width;
  const double n = std::round(count);
  if (std::abs(count - n) * width > 1e-9)
    throw InputError(fmt::format("{}: range {}–{} nm is not a whole number of {} nm bands", what, lo, hi, width));
  if (n > static_cast<double>(kMaxBands))  // before allocating the edges
    throw InputError(fmt::format("{}: {} nm bands over {}–{} nm are {:.0f} bands, more than the limit of {}", what,
                                 width, lo, hi, n, kMaxBands));
  std::vector<double> edges(static_cast<std::size_t>(n) + 1);
  for (std::size_t i = 0; i < edges.size(); ++i) edges[i] = lo + width * static_cast<double>(i);
  edges.back() = hi;
  return from_edges(std::move(edges), what);
}

Bands Bands::parse(const std::string& spec, const std::string& what) {
  std::array<double, 3> v{};
  std::istringstream in(spec);
  char c1 = 0, c2 = 0;
  if (!(in >> v[0] >> c1 >> v[1] >> c2 >> v[2]) || c1 != ':' || c2 != ':' || !(in >> std::ws).eof())
    throw InputError(fmt::format("{}: expected lo:hi:width in nm (e.g. 380:780:10), got \"{}\"", what, spec));
  return uniform(v[0], v[1], v[2], what);
}

Bands Bands::from_centres(const std::vector<double>& centres, const std::string& what) {
  if (centres.empty()) throw InputError(fmt::format("{}: no bands", what));
  for (std::size_t i = 1; i < centres.size(); ++i)
    if (!(centres[i] > centres[i - 1]))
      throw InputError(fmt::format("{}: band centres must increase, but {} nm follows {} nm", what, centres[i],
                                   centres[i - 1]));
  if (centres.size() == 1) return from_edges({centres[0] - 0.5, centres[0] + 0.5}, what);
  std::vector<double> edges(centres.size() + 1);
  for (std::size_t i = 1; i < centres.size(); ++i) edges[i] = 0.5 * (centres[i - 1] + centres[i]);
  edges.front() = centres.front() - (edges[1] - centres.front());
  edges.back() = centres.back() + (centres.back() - edges[centres.size() - 1]);
  return from_edges(std::move(edges), what);
}

Bands Bands::with_reconstruction(BandReconstruction r, const std::string& what) const {
  // Held at float precision, as the EXR header stores it, so that a plan and the renders made with it agree (and
  // checked so: a double beyond a float's range is no entry).
  for (double& m : r.matrix) m = static_cast<float>(m);
  r.lo_nm = static_cast<float>(r.lo_nm);
  r.step_nm = static_cast<float>(r.step_nm);
  if (!std::isfinite(r.lo_nm) || !std::isfinite(r.step_nm) || !(r.step_nm > 0) || r.lo_nm <= 0)
    throw InputError(fmt::format("{}: fine bands need a positive start and step, got {} and {} nm", what, r.lo_nm, r.step_nm));
  if (r.fine == 0 || r.fine > kMaxBands)
    throw InputError(fmt::format("{}: {} fine bands, must be 1 to {}", what, r.fine, kMaxBands));
  if (r.matrix.size() != r.fine * size())
    throw InputError(fmt::format("{}: the matrix has {} entries, needs {} fine bands × {} bands = {}", what,
                                 r.matrix.size(), r.fine, size(), r.fine * size()));
  for (std::size_t k = 0; k < r.matrix.size(); ++k)
    if (!std::isfinite(r.matrix[k]))
      throw InputError(fmt::format("{}: matrix entry [{}][{}] is not finite", what, k / size(), k % size()));
  Bands b = *this;
  b.reconstruction_ = std::make_shared<const BandReconstruction>(std::move(r));
  return b;
}

std::vector<double> band_weights(const Bands& bands, const std::function<double(double, double)>& integral) {
  std::vector<double> w(bands.size(), 0.0);
  if (const BandReconstruction* r = bands.reconstruction()) {
    for (std::size_t j = 0; j < r->fine; ++j) {
      const double lo = r->lo_nm + r->step_nm * static_cast<double>(j);
      const double f = integral(lo, lo + r->step_nm);
      for (std::size_t i = 0; i < w.size(); ++i) w[i] += r->matrix[j * w.size() + i] * f;
    }
    return w;
  }
  for (std::size_t i = 0; i < w.size(); ++i) w[i] = integral(bands.lo(i), bands.hi(i));
  return w;
}

std::vector<double> band_averages(const PiecewiseLinearSpectrum& s, const Bands& bands) {
  std::vector<double> out(bands.size());
  for (std::size_t i = 0; i < bands.size(); ++i) out[i] = s.average(bands.lo(i), bands.hi(i));
  return out;
}

std::vector<double> band_averages(const std::function<double(double)>& f, const Bands& bands) {
  // Composite 5-point Gauss–Legendre on sub-intervals of at most 1 nm: for functions as smooth as Planck's
  // law the error is far below double rounding of the result.
  static constexpr std::array<double, 5> node = {-0.9061798459386640, -0.5384693101056831, 0.0,
                                                 0.5384693101056831, 0.9061798459386640};
  static constexpr std::array<double, 5> weight = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                                                   0.4786286704993665, 0.2369268850561891};
  std::vector<double> out(bands.size());
  for (std::size_t i = 0; i < bands.size(); ++i) {
    const int pieces = std::max(1, static_cast<int>(std::ceil(bands.width(i))));
    const double h = bands.width(i) / pieces;
    double sum = 0.0;
    for (int p = 0; p < pieces; ++p) {
      const double mid = bands.lo(i) + (p + 0.5) * h;
      for (std::size_t k = 0; k < node.size(); ++k) sum += weight[k] * f(mid + 0.5 * h * node[k]);
    }
    out[i] = sum * 0.5 * h / bands.width(i);
  }
  return out;
}

PiecewiseLinearSpectrum resample(const PiecewiseLinearSpectrum& s, const std::vector<double>& wavelengths) {
  const Bands cells = Bands::from_centres(wavelengths, "resample");
  std::vector<double> values(wavelengths.size());
  for (std::size_t i = 0; i < wavelengths.size(); ++i) values[i] = s.average(cells.lo(i), cells.hi(i));
  return PiecewiseLinearSpectrum(wavelengths, std::move(values), s.extrapolation(), "resample");
}

double integrate_band_values(const std::vector<double>& values, const Bands& bands) {
  double sum = 0.0;
  for (std::size_t i = 0; i < bands.size(); ++i) sum += values[i] * bands.width(i);
  return sum;
}

double planck(double nm, double kelvin) {
  if (!(nm > 0) || !(kelvin > 0)) return 0.0;
  const double lambda = nm * 1e-9;  // m
  const double radiance_per_m =
      2.0 * kPlanck * kLightSpeed * kLightSpeed / (std::pow(lambda, 5) * std::expm1(kPlanck * kLightSpeed / (lambda * kBoltzmann * kelvin)));
  return radiance_per_m * 1e-9;  // per nm
}

PiecewiseLinearSpectrum blackbody(double kelvin, double lo, double hi, double step_nm, bool normalise) {
  if (!(kelvin > 0)) throw InputError(fmt::format("blackbody: temperature must be > 0 K, got {}", kelvin));
  // The peak (Wien) is a sample of its own, so a normalised spectrum reaches exactly 1 there.
  const double peak_nm = kWien / kelvin * 1e9;
  std::vector<double> lambda;
  for (double nm = lo; nm <= hi + 1e-9; nm += step_nm) lambda.push_back(nm);
  if (peak_nm > lo && peak_nm < hi) {
    const auto at = std::lower_bound(lambda.begin(), lambda.end(), peak_nm);
    if (*at != peak_nm) lambda.insert(at, peak_nm);
  }
  std::vector<double> value;
  for (double nm : lambda) value.push_back(planck(nm, kelvin));
  if (normalise) {
    const double peak = *std::max_element(value.begin(), value.end());
    for (double& v : value) v /= peak;
  }
  return PiecewiseLinearSpectrum(std::move(lambda), std::move(value), Extrapolation::Zero, "blackbody");
}

}  // namespace ct

namespace ct {
namespace {

double product_integral(std::initializer_list<const PiecewiseLinearSpectrum*> factors, double lo, double hi) {
  if (!(hi > lo)) return 0.0;
  std::vector<double> breaks{lo, hi};
  for (const PiecewiseLinearSpectrum* f : factors)
    for (double x : f->wavelengths())
      if (x > lo && x < hi) breaks.push_back(x);
  std::sort(breaks.begin(), breaks.end());
  breaks.erase(std::unique(breaks.begin(), breaks.end()), breaks.end());

  static constexpr double node = 0.7745966692414834;  // sqrt(3/5)
  static constexpr std::array<double, 3> xs = {-node, 0.0, node};
  static constexpr std::array<double, 3> ws = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
  double sum = 0.0;
  for (std::size_t i = 0; i + 1 < breaks.size(); ++i) {
    const double mid = 0.5 * (breaks[i] + breaks[i + 1]);
    const double half = 0.5 * (breaks[i + 1] - breaks[i]);
    for (std::size_t k = 0; k < 3; ++k) {
      double p = ws[k] * half;
      for (const PiecewiseLinearSpectrum* f : factors) p *= (*f)(mid + half * xs[k]);
      sum += p;
    }
  }
  return sum;
}

}  // namespace

double integral_of_product(const PiecewiseLinearSpectrum& f1, const PiecewiseLinearSpectrum& f2, double lo, double hi) {
  return product_integral({&f1, &f2}, lo, hi);
}

double integral_of_product(const PiecewiseLinearSpectrum& f1, const PiecewiseLinearSpectrum& f2,
                           const PiecewiseLinearSpectrum& f3, double lo, double hi) {
  return product_integral({&f1, &f2, &f3}, lo, hi);
}

}  // namespace ct
