#include "core/rgb_to_spectrum.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "core/cie.h"
#include "core/colour.h"

namespace ct {
namespace {

constexpr double kLo = 360.0;
constexpr double kHi = 830.0;
constexpr int kSamples = 471;  // 1 nm grid over the CMF range

double sigmoid(double x) {
  if (std::isinf(x)) return x > 0 ? 1.0 : 0.0;
  return 0.5 + x / (2.0 * std::sqrt(1.0 + x * x));
}
double sigmoid_derivative(double x) { return 0.5 / std::pow(1.0 + x * x, 1.5); }
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
      out += weight.col(i) * sigmoid(x);
      if (jacobian) *jacobian += weight.col(i) * (sigmoid_derivative(x) * basis.col(i).transpose());
    }
    return out;
  }
};

const ForwardModel& model() {
  static const ForwardModel m;
  return m;
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

}  // namespace

double SigmoidPolynomial::operator()(double nm) const {
  const double t = (std::clamp(nm, kLo, kHi) - kLo) / (kHi - kLo);
  const double x = c[2] + t * (c[1] + t * c[0]);
  return sigmoid(std::isnan(x) ? c[2] : x);
}

SigmoidPolynomial fit_rgb_reflectance(const std::array<double, 3>& rgb_in) {
  const Eigen::Vector3d target(std::clamp(rgb_in[0], 0.0, 1.0), std::clamp(rgb_in[1], 0.0, 1.0),
                               std::clamp(rgb_in[2], 0.0, 1.0));
  // Greys are flat spectra; black and white are the limits c2 -> ∓∞.
  if (target.maxCoeff() - target.minCoeff() < 1e-12) {
    const double g = target[0];
    if (g <= 0.0) return {{0.0, 0.0, -std::numeric_limits<double>::infinity()}};
    if (g >= 1.0) return {{0.0, 0.0, std::numeric_limits<double>::infinity()}};
    return {{0.0, 0.0, sigmoid_inverse(g)}};
  }
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

PiecewiseLinearSpectrum ScaledSigmoid::tabulated() const {
  std::vector<double> lambda, value;
  for (double nm = kLo; nm <= kHi; nm += 1.0) {
    lambda.push_back(nm);
    value.push_back(scale == 1.0 ? poly(nm) : scale * poly(nm));
  }
  return PiecewiseLinearSpectrum(std::move(lambda), std::move(value), Extrapolation::Clamp, "rgb spectrum");
}

double ScaledSigmoid::tabulated_at(double nm) const {
  const double x = std::clamp(nm, kLo, kHi) - kLo;
  const double i = std::min(std::floor(x), kHi - kLo - 1.0);
  const double t = x - i;
  const double a = (*this)(kLo + i), b = (*this)(kLo + i + 1.0);
  return a + t * (b - a);
}

PiecewiseLinearSpectrum rgb_to_spectrum(const std::array<double, 3>& linear_srgb) {
  return ScaledSigmoid{1.0, fit_rgb_reflectance(linear_srgb)}.tabulated();
}

ScaledSigmoid fit_rgb_unbounded(const std::array<double, 3>& linear_srgb) {
  const std::array<double, 3> rgb = {std::max(0.0, linear_srgb[0]), std::max(0.0, linear_srgb[1]),
                                     std::max(0.0, linear_srgb[2])};
  const double m = std::max({rgb[0], rgb[1], rgb[2]});
  if (!(m > 0.0)) return {0.0, fit_rgb_reflectance({0.0, 0.0, 0.0})};
  const double scale = 2.0 * m;
  return {scale, fit_rgb_reflectance({rgb[0] / scale, rgb[1] / scale, rgb[2] / scale})};
}

}  // namespace ct
