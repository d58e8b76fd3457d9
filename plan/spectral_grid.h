// SPDX-License-Identifier: Apache-2.0
#pragma once
// The 1 nm grid on which plan's model (plan/radiosity.h) and the band-plan check (plan/spectral_check.h) evaluate
// spectra, and tristimulus values on it: the one place where a spectrum is sampled every nanometre and integrated
// against an observer's curves.

#include <array>
#include <cstddef>
#include <functional>
#include <vector>

#include "core/colour.h"

namespace ct::plan {

// A spectrum sampled every 1 nm on a grid, with its running integral (trapezoids).
struct Sampled {
  std::vector<double> v, cum;
};

// The 1 nm grid [lo, hi] (whole nm).
struct Grid {
  int lo = 380, hi = 780;
  std::size_t n() const { return static_cast<std::size_t>(hi - lo + 1); }

  Sampled sample(const std::function<double(double)>& f) const {
    Sampled s;
    s.v.resize(n());
    for (std::size_t i = 0; i < n(); ++i) s.v[i] = f(lo + static_cast<double>(i));
    finish(s);
    return s;
  }
  Sampled constant(double value) const { return sample([value](double) { return value; }); }
  // Fills s.cum from s.v.
  static void finish(Sampled& s) {
    s.cum.assign(s.v.size(), 0.0);
    for (std::size_t i = 1; i < s.v.size(); ++i) s.cum[i] = s.cum[i - 1] + 0.5 * (s.v[i - 1] + s.v[i]);
  }
  // Average over [a, b] (grid indices).
  static double average(const Sampled& s, int a, int b) { return (s.cum[b] - s.cum[a]) / (b - a); }
  static double integral(const Sampled& s, int a, int b) { return s.cum[b] - s.cum[a]; }
};

// An observer's three curves on the grid.
using Observer = std::array<Sampled, 3>;

// The weight of each 1 nm sample in an integral over the grid by trapezoids: 1, the two ends ½.
inline double trapezoid_weight(std::size_t i, std::size_t n) { return (i == 0 || i + 1 == n) ? 0.5 : 1.0; }

// Tristimulus values of a spectrum sampled on the grid, through the observer (trapezoids).
inline Vec3d tristimulus(const std::vector<double>& f, const Observer& obs) {
  Vec3d out{};
  for (int c = 0; c < 3; ++c) {
    double s = 0;
    for (std::size_t i = 0; i < f.size(); ++i) s += trapezoid_weight(i, f.size()) * f[i] * obs[c].v[i];
    out[c] = s;
  }
  return out;
}

}  // namespace ct::plan
