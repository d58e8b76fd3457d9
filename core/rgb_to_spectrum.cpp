// SPDX-License-Identifier: Apache-2.0
#include "core/rgb_to_spectrum.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <stdexcept>

#include <Eigen/Dense>

#include "core/cie.h"
#include "core/colour.h"
#include "core/parallel.h"

namespace ct {
namespace {

constexpr double kLo = 360.0;
constexpr double kHi = 830.0;
constexpr int kSamples = 471;  // 1 nm grid over the CMF range

double sigmoid(double x) {
  if (std::isinf(x)) return x > 0 ? 1.0 : 0.0;
  return 0.5 + x / (2.0 * std::sqrt(1.0 + x * x));
}
double sigmoid_inverse(double s) {
  const double u = 2.0 * s - 1.0;
  return u / std::sqrt(1.0 - u * u);
}

// Linear sRGB seen for a reflectance lit by D65: rgb = Σ_λ W(λ) s(λ). The rows of W are scaled so that the
// perfect reflector gives exactly (1, 1, 1) (the tabulated D65 differs from the sRGB white point by ~1e-4),
// which makes every grey an exactly flat spectrum.
struct ForwardModel {
  Eigen::Matrix<double, 3, kSamples> weight;
  Eigen::Matrix<double, 3, kSamples> basis;  // rows: λ'², λ', 1

  ForwardModel() {
    const PiecewiseLinearSpectrum& d65 = cie::illuminant("D65");
    Eigen::Matrix<double, 3, kSamples> xyz;
    for (int i = 0; i < kSamples; ++i) {
      const double nm = kLo + i;
      // Trapezoid weights on the 1 nm grid (half weight at the ends).
      const double dl = (i == 0 || i == kSamples - 1) ? 0.5 : 1.0;
      xyz.col(i) << d65(nm) * cie::x_bar()(nm) * dl, d65(nm) * cie::y_bar()(nm) * dl, d65(nm) * cie::z_bar()(nm) * dl;
      const double t = (nm - kLo) / (kHi - kLo);
      basis.col(i) << t * t, t, 1.0;
    }
    Eigen::Matrix3d m;  // XYZ -> linear sRGB, column by column
    for (int r = 0; r < 3; ++r) {
      Vec3d unit{};
      unit[r] = 1.0;
      const Vec3d column = xyz_to_linear_srgb(unit);
      for (int c = 0; c < 3; ++c) m(c, r) = column[c];
    }
    weight = m * xyz;
    const Eigen::Vector3d white = weight.rowwise().sum();
    weight = white.cwiseInverse().asDiagonal() * weight;
  }

  Eigen::Vector3d rgb(const Eigen::Vector3d& c, Eigen::Matrix3d* jacobian) const {
    Eigen::Vector3d out = Eigen::Vector3d::Zero();
    if (jacobian) jacobian->setZero();
    for (int i = 0; i < kSamples; ++i) {
      const double x = c.dot(basis.col(i));
      // sigmoid(x) = ½ + ½ x r and sigmoid'(x) = ½ r³, with r = 1 / sqrt(1 + x²).
      const double r = 1.0 / std::sqrt(1.0 + x * x);
      out += weight.col(i) * (0.5 + 0.5 * x * r);
      if (jacobian) *jacobian += weight.col(i) * ((0.5 * r * r * r) * basis.col(i).transpose());
    }
    return out;
  }
};

const ForwardModel& model() {
  static const ForwardModel m;
  return m;
}

// rgb_white_at's samples at kLo + i.
const std::array<double, kSamples>& white_samples() {
  static const std::array<double, kSamples> white = [] {
    const PiecewiseLinearSpectrum& d65 = cie::illuminant("D65");
    std::array<double, kSamples> w{};
    double d65_y = 0.0, flat_y = 0.0;
    for (int i = 0; i < kSamples; ++i) {
      const double nm = kLo + i, dl = (i == 0 || i == kSamples - 1) ? 0.5 : 1.0;
      w[static_cast<std::size_t>(i)] = d65(nm);
      d65_y += d65(nm) * cie::y_bar()(nm) * dl;
      flat_y += cie::y_bar()(nm) * dl;
    }
    for (double& v : w) v *= flat_y / d65_y;
    return w;
  }();
  return white;
}

// A function known at the grid wavelengths kLo + k (`sample(k)`), linear between them and clamped outside, at nm.
template <typename Sample>
double on_grid(double nm, Sample sample) {
  const double x = std::clamp(nm, kLo, kHi) - kLo;
  const double i = std::min(std::floor(x), kHi - kLo - 1.0);
  const int k = static_cast<int>(i);
  const double a = sample(k), b = sample(k + 1);
  return a + (x - i) * (b - a);
}

// ScaledSigmoid's value at the grid wavelength kLo + i from the sigmoid's value p there: the one product every
// evaluation (operator(), tabulated(), tabulated_band_averages) forms, so that they agree bit for bit.
double scaled_sample(const ScaledSigmoid& s, double p, int i) {
  const double v = s.scale == 1.0 ? p : s.scale * p;
  return s.illuminant ? v * white_samples()[static_cast<std::size_t>(i)] : v;
}

// Damped Newton steps towards `target` from `c`; returns the residual norm reached.
double solve(const Eigen::Vector3d& target, Eigen::Vector3d& c, int max_iterations) {
  Eigen::Matrix3d jac;
  Eigen::Vector3d residual = model().rgb(c, &jac) - target;
  double norm = residual.norm();
  for (int it = 0; it < max_iterations && norm > 1e-12; ++it) {
    const Eigen::Vector3d step = jac.fullPivLu().solve(-residual);
    if (!step.allFinite()) break;
    double scale = 1.0;
    bool improved = false;
    while (scale > 1e-4) {
      const Eigen::Vector3d trial = c + scale * step;
      Eigen::Matrix3d trial_jac;
      const Eigen::Vector3d trial_residual = model().rgb(trial, &trial_jac) - target;
      if (trial_residual.norm() < norm) {
        c = trial;
        jac = trial_jac;
        residual = trial_residual;
        norm = trial_residual.norm();
        improved = true;
        break;
      }
      scale *= 0.5;
    }
    if (!improved) break;
  }
  return norm;
}

// Greys are flat spectra; black and white are the limits c2 -> ∓∞.
std::optional<SigmoidPolynomial> grey_fit(const Eigen::Vector3d& rgb) {
  if (rgb.maxCoeff() - rgb.minCoeff() >= 1e-12) return std::nullopt;
  const double g = rgb[0];
  if (g <= 0.0) return SigmoidPolynomial{{0.0, 0.0, -std::numeric_limits<double>::infinity()}};
  if (g >= 1.0) return SigmoidPolynomial{{0.0, 0.0, std::numeric_limits<double>::infinity()}};
  return SigmoidPolynomial{{0.0, 0.0, sigmoid_inverse(g)}};
}

double smoothstep(double t) { return t * t * (3.0 - 2.0 * t); }

constexpr std::string_view kTableMagic = "CTRGBT01";  // 8 bytes, then the resolution as 8 bytes, then floats
constexpr int kNodeIterations = 100;

}  // namespace

double SigmoidPolynomial::operator()(double nm) const {
  const double t = (std::clamp(nm, kLo, kHi) - kLo) / (kHi - kLo);
  const double x = c[2] + t * (c[1] + t * c[0]);
  return sigmoid(std::isnan(x) ? c[2] : x);
}

SigmoidPolynomial fit_rgb_reflectance(const std::array<double, 3>& rgb_in) {
  const Eigen::Vector3d target(std::clamp(rgb_in[0], 0.0, 1.0), std::clamp(rgb_in[1], 0.0, 1.0),
                               std::clamp(rgb_in[2], 0.0, 1.0));
  if (const auto grey = grey_fit(target)) return *grey;
  // Continuation from the grey of the same mean, as Jakob and Hanika fill their table outward from the
  // cube's centre: each step starts from the previous solution, well inside Newton's basin.
  const double grey = std::clamp(target.mean(), 1e-3, 1.0 - 1e-3);
  Eigen::Vector3d c(0.0, 0.0, sigmoid_inverse(grey));
  constexpr int kSteps = 16;
  for (int k = 1; k <= kSteps; ++k) {
    const double t = static_cast<double>(k) / kSteps;
    solve(Eigen::Vector3d::Constant(grey) * (1.0 - t) + target * t, c, k == kSteps ? 100 : 20);
  }
  return {{c[0], c[1], c[2]}};
}

PiecewiseLinearSpectrum ScaledSigmoid::tabulated() const { return tabulated(kLo, kHi); }

PiecewiseLinearSpectrum ScaledSigmoid::tabulated(double lo_nm, double hi_nm) const {
  // Samples at kLo + i, i in [first, last]: the same values as the whole table's (integer wavelengths, exact).
  const int first = static_cast<int>(std::clamp(std::floor(lo_nm - kLo) - 1.0, 0.0, kHi - kLo));
  const int last = static_cast<int>(std::clamp(std::ceil(hi_nm - kLo) + 1.0, 0.0, kHi - kLo));
  std::vector<double> lambda, value;
  lambda.reserve(static_cast<std::size_t>(last - first + 1));
  value.reserve(static_cast<std::size_t>(last - first + 1));
  for (int i = first; i <= last; ++i) {
    const double nm = kLo + i;
    lambda.push_back(nm);
    value.push_back(scaled_sample(*this, poly(nm), i));
  }
  return PiecewiseLinearSpectrum(std::move(lambda), std::move(value), Extrapolation::Clamp, "rgb spectrum");
}

void tabulated_band_averages(const ScaledSigmoid& s, const Bands& bands, double* out) {
  const std::size_t nb = bands.size();
  for (const double c : s.poly.c)
    if (!std::isfinite(c)) {  // black and white: the general path (sigmoid's limits)
      const std::vector<double> a = band_averages(s.tabulated(bands.min_wavelength(), bands.max_wavelength()), bands);
      std::copy(a.begin(), a.end(), out);
      return;
    }
  // The samples tabulated(lo, hi) holds: kLo + i for i in [first, last].
  const int first = static_cast<int>(std::clamp(std::floor(bands.min_wavelength() - kLo) - 1.0, 0.0, kHi - kLo));
  const int last = static_cast<int>(std::clamp(std::ceil(bands.max_wavelength() - kLo) + 1.0, 0.0, kHi - kLo));
  const int count = last - first + 1;
  std::array<double, kSamples> v;
  const std::array<double, 3>& c = s.poly.c;
  for (int i = 0; i < count; ++i) {
    // SigmoidPolynomial::operator() and sigmoid(), term for term (finite coefficients, nm inside the range).
    const double t = (kLo + (first + i) - kLo) / (kHi - kLo);
    const double x = c[2] + t * (c[1] + t * c[0]);
    const double p = 0.5 + x / (2.0 * std::sqrt(1.0 + x * x));
    v[static_cast<std::size_t>(i)] = scaled_sample(s, p, first + i);
  }
  // PiecewiseLinearSpectrum's operator() and integral() with clamping, on wavelengths front + i.
  const double front = kLo + first, back = kLo + last;
  const auto value_at = [&](double nm) {
    if (nm <= front) return v[0];
    if (nm >= back) return v[static_cast<std::size_t>(count - 1)];
    const std::size_t k = static_cast<std::size_t>(std::floor(nm - front)) + 1;  // the first wavelength above nm
    const double t = (nm - (front + static_cast<double>(k - 1))) / ((front + static_cast<double>(k)) - (front + static_cast<double>(k - 1)));
    return v[k - 1] + t * (v[k] - v[k - 1]);
  };
  const auto integral = [&](double lo, double hi) {
    double sum = 0.0;
    if (lo < front) sum += v[0] * (std::min(hi, front) - lo);
    if (hi > back) sum += v[static_cast<std::size_t>(count - 1)] * (hi - std::max(lo, back));
    const double a = std::max(lo, front), b = std::min(hi, back);
    if (a >= b) return sum;
    std::size_t i = static_cast<std::size_t>(std::floor(a - front)) + 1;
    double x0 = a, f0 = value_at(a);
    for (; i < static_cast<std::size_t>(count) && front + static_cast<double>(i) < b; ++i) {
      const double li = front + static_cast<double>(i);
      sum += 0.5 * (li - x0) * (f0 + v[i]);
      x0 = li;
      f0 = v[i];
    }
    sum += 0.5 * (b - x0) * (f0 + value_at(b));
    return sum;
  };
  for (std::size_t b = 0; b < nb; ++b) {
    const double lo = bands.lo(b), hi = bands.hi(b);
    out[b] = hi == lo ? value_at(lo) : integral(lo, hi) / (hi - lo);
  }
}

double ScaledSigmoid::tabulated_at(double nm) const {
  return on_grid(nm, [&](int k) { return scaled_sample(*this, poly(kLo + k), k); });
}

double rgb_white_at(double nm) {
  return on_grid(nm, [](int k) { return white_samples()[static_cast<std::size_t>(k)]; });
}

std::array<double, 3> reflectance_linear_srgb(const SigmoidPolynomial& poly) {
  for (const double c : poly.c)
    if (std::isinf(c)) return poly.c[2] > 0 ? std::array<double, 3>{1.0, 1.0, 1.0} : std::array<double, 3>{0.0, 0.0, 0.0};
  const Eigen::Vector3d rgb = model().rgb(Eigen::Vector3d(poly.c[0], poly.c[1], poly.c[2]), nullptr);
  return {rgb[0], rgb[1], rgb[2]};
}

ScaledSigmoid fit_rgb_unbounded(const std::array<double, 3>& linear_srgb) {
  const std::array<double, 3> rgb = {std::max(0.0, linear_srgb[0]), std::max(0.0, linear_srgb[1]),
                                     std::max(0.0, linear_srgb[2])};
  const double m = std::max({rgb[0], rgb[1], rgb[2]});
  if (!(m > 0.0)) return {0.0, fit_rgb_reflectance({0.0, 0.0, 0.0})};
  const double scale = 2.0 * m;
  return {scale, fit_rgb_reflectance({rgb[0] / scale, rgb[1] / scale, rgb[2] / scale})};
}

double RgbCoefficientTable::z_node(int k) const { return smoothstep(smoothstep(static_cast<double>(k) / (n_ - 1))); }

double RgbCoefficientTable::xy_node(int i) const { return smoothstep(static_cast<double>(i) / (n_ - 1)); }

std::size_t RgbCoefficientTable::offset(int l, int k, int j, int i) const {
  const std::size_t n = static_cast<std::size_t>(n_);
  return 3 * (((static_cast<std::size_t>(l) * (n - 1) + static_cast<std::size_t>(k - 1)) * n + static_cast<std::size_t>(j)) * n +
              static_cast<std::size_t>(i));
}

std::array<double, 3> RgbCoefficientTable::node(int l, int k, int j, int i) const {
  const float* p = data_.data() + offset(l, k, j, i);
  const double root_z = std::sqrt(z_node(k));
  return {p[0] / root_z, p[1] / root_z, p[2] / root_z};
}

RgbCoefficientTable RgbCoefficientTable::compute(int resolution, int threads) {
  if (resolution < 3 || resolution % 2 == 0)
    throw std::invalid_argument("RgbCoefficientTable: the resolution must be odd and at least 3");
  RgbCoefficientTable table;
  table.n_ = resolution;
  const int n = resolution, mid = (n - 1) / 2;
  table.data_.assign(3 * static_cast<std::size_t>(n - 1) * static_cast<std::size_t>(n) * static_cast<std::size_t>(n) * 3, 0.0f);
  const auto colour = [&](int l, int k, int j, int i) {
    const double z = table.z_node(k), x = table.xy_node(i), y = table.xy_node(j);
    Eigen::Vector3d rgb;
    rgb[l] = z;
    rgb[(l + 1) % 3] = x * z;
    rgb[(l + 2) % 3] = y * z;
    return rgb;
  };
  const auto store = [&](int l, int k, int j, int i, const Eigen::Vector3d& c) {
    float* p = table.data_.data() + table.offset(l, k, j, i);
    const double root_z = std::sqrt(table.z_node(k));
    for (int q = 0; q < 3; ++q) p[q] = static_cast<float>(c[q] * root_z);
  };
  // The middle plane z = ½ of each l, swept from white (x = y = 1, a grey: c = 0) outward, each node
  // warm-started from its neighbour towards white. Sequential within an l, so independent of the threads.
  std::vector<Eigen::Vector3d> middle(3 * static_cast<std::size_t>(n) * static_cast<std::size_t>(n));
  const auto mid_at = [&](int l, int j, int i) -> Eigen::Vector3d& {
    return middle[(static_cast<std::size_t>(l) * static_cast<std::size_t>(n) + static_cast<std::size_t>(j)) * static_cast<std::size_t>(n) +
                  static_cast<std::size_t>(i)];
  };
  parallel_for(3, threads, [&](std::size_t ls) {
    const int l = static_cast<int>(ls);
    for (int j = n - 1; j >= 0; --j)
      for (int i = n - 1; i >= 0; --i) {
        Eigen::Vector3d c = i < n - 1 ? mid_at(l, j, i + 1) : j < n - 1 ? mid_at(l, j + 1, i) : Eigen::Vector3d::Zero();
        if (i < n - 1 || j < n - 1) solve(colour(l, mid, j, i), c, kNodeIterations);
        mid_at(l, j, i) = c;
      }
  });
  // Each column (l, j, i) from its middle node up to z = 1 and down to z_1, each node warm-started from the
  // previous one. Greys (x = y = 1) are set exactly; white's coefficients are infinite and never used (lookup).
  parallel_for(3 * static_cast<std::size_t>(n) * static_cast<std::size_t>(n), threads, [&](std::size_t index) {
    const int l = static_cast<int>(index / (static_cast<std::size_t>(n) * static_cast<std::size_t>(n)));
    const int j = static_cast<int>(index / static_cast<std::size_t>(n) % static_cast<std::size_t>(n));
    const int i = static_cast<int>(index % static_cast<std::size_t>(n));
    if (i == n - 1 && j == n - 1) {
      for (int k = 1; k < n - 1; ++k) store(l, k, j, i, Eigen::Vector3d(0.0, 0.0, sigmoid_inverse(table.z_node(k))));
      store(l, n - 1, j, i, Eigen::Vector3d::Zero());
      return;
    }
    store(l, mid, j, i, mid_at(l, j, i));
    for (const int direction : {1, -1}) {
      Eigen::Vector3d c = mid_at(l, j, i);
      for (int k = mid + direction; k >= 1 && k <= n - 1; k += direction) {
        solve(colour(l, k, j, i), c, kNodeIterations);
        store(l, k, j, i, c);
      }
    }
  });
  return table;
}

std::string RgbCoefficientTable::bytes() const {
  std::string out(kTableMagic);
  const std::int64_t n = n_;
  out.append(reinterpret_cast<const char*>(&n), sizeof n);
  out.append(reinterpret_cast<const char*>(data_.data()), data_.size() * sizeof(float));
  return out;
}

RgbCoefficientTable RgbCoefficientTable::from_bytes(std::string_view bytes) {
  const std::size_t header = kTableMagic.size() + sizeof(std::int64_t);
  if (bytes.size() < header || bytes.substr(0, kTableMagic.size()) != kTableMagic)
    throw std::runtime_error("not an RGB coefficient table");
  std::int64_t n = 0;
  std::memcpy(&n, bytes.data() + kTableMagic.size(), sizeof n);
  if (n < 3 || n % 2 == 0 || n > 1024) throw std::runtime_error("RGB coefficient table: bad resolution");
  RgbCoefficientTable table;
  table.n_ = static_cast<int>(n);
  table.data_.resize(3 * static_cast<std::size_t>(n - 1) * static_cast<std::size_t>(n) * static_cast<std::size_t>(n) * 3);
  if (bytes.size() != header + table.data_.size() * sizeof(float))
    throw std::runtime_error("RGB coefficient table: wrong size");
  std::memcpy(table.data_.data(), bytes.data() + header, table.data_.size() * sizeof(float));
  return table;
}

SigmoidPolynomial RgbCoefficientTable::lookup(const std::array<double, 3>& rgb_in) const {
  const Eigen::Vector3d rgb(std::clamp(rgb_in[0], 0.0, 1.0), std::clamp(rgb_in[1], 0.0, 1.0),
                            std::clamp(rgb_in[2], 0.0, 1.0));
  if (const auto grey = grey_fit(rgb)) return *grey;
  int l = 0;
  for (int q = 1; q < 3; ++q)
    if (rgb[q] > rgb[l]) l = q;
  const double z = rgb[l];
  const double x = std::min(rgb[(l + 1) % 3] / z, 1.0), y = std::min(rgb[(l + 2) % 3] / z, 1.0);
  const int last = n_ - 1;
  // The x and y nodes are smoothstep(t) on a uniform t: invert it in closed form, then settle the cell against
  // the nodes themselves (rounding).
  const auto cell = [&](double v, int& index, double& fraction) {
    const double t = 0.5 - std::sin(std::asin(1.0 - 2.0 * v) / 3.0);
    index = std::clamp(static_cast<int>(t * last), 0, last - 1);
    while (index > 0 && xy_node(index) > v) --index;
    while (index < last - 1 && xy_node(index + 1) <= v) ++index;
    const double lo = xy_node(index), hi = xy_node(index + 1);
    fraction = std::clamp((v - lo) / (hi - lo), 0.0, 1.0);
  };
  int i = 0, j = 0, k = 1;
  double fx = 0.0, fy = 0.0, fz = 0.0;
  cell(x, i, fx);
  cell(y, j, fy);
  const auto bilinear = [&](int kk, int q) {
    const float* p00 = data_.data() + offset(l, kk, j, i);
    const float* p01 = data_.data() + offset(l, kk, j, i + 1);
    const float* p10 = data_.data() + offset(l, kk, j + 1, i);
    const float* p11 = data_.data() + offset(l, kk, j + 1, i + 1);
    return (1.0 - fy) * ((1.0 - fx) * p00[q] + fx * p01[q]) + fy * ((1.0 - fx) * p10[q] + fx * p11[q]);
  };
  const double root_z = std::sqrt(z);
  if (z < z_node(1)) {
    // Far below z_1 the sigmoid is 1/(4 q²) to relative O(1/q²), so scaling the colour by a scales q by 1/√a:
    // the stored c·√z is constant there.
    return {{bilinear(1, 0) / root_z, bilinear(1, 1) / root_z, bilinear(1, 2) / root_z}};
  }
  // z_k <= z < z_{k+1} (z = 1: the last cell, fz = 1).
  int lo = 1, hi = last;
  while (hi - lo > 1) {
    const int m = (lo + hi) / 2;
    (z_node(m) <= z ? lo : hi) = m;
  }
  k = lo;
  const double zk = z_node(k), zk1 = z_node(k + 1);
  fz = std::min((z - zk) / (zk1 - zk), 1.0);
  if (k == last - 1 && i == last - 1 && j == last - 1 && fz > 0.0 && fx > 0.0 && fy > 0.0)
    return fit_rgb_reflectance(rgb_in);  // next to white, whose coefficients are infinite
  SigmoidPolynomial out;
  for (int q = 0; q < 3; ++q)
    out.c[static_cast<std::size_t>(q)] = ((1.0 - fz) * bilinear(k, q) + (fz > 0.0 ? fz * bilinear(k + 1, q) : 0.0)) / root_z;
  return out;
}

}  // namespace ct
