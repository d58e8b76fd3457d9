// SPDX-License-Identifier: Apache-2.0
#pragma once
// Closed-form view factors for tests that check renderers against known answers.

#include <cmath>
#include <numbers>

namespace ct::test {

// Irradiance view factor from a point to a rectangle in a parallel plane at height h, the point below one
// corner and the rectangle extending a × b from it (Howell's catalogue, configuration B-3).
inline double corner_view_factor(double a, double b, double h) {
  if (a == 0.0 || b == 0.0) return 0.0;
  const double sign = (a < 0) != (b < 0) ? -1.0 : 1.0;
  const double A = std::abs(a) / h, B = std::abs(b) / h;
  const double sa = std::sqrt(1 + A * A), sb = std::sqrt(1 + B * B);
  return sign / (2 * std::numbers::pi) * (A / sa * std::atan(B / sa) + B / sb * std::atan(A / sb));
}

// View factor to the rectangle [x0, x1] × [y0, y1] at height h from the point (px, py) by superposition.
inline double rectangle_view_factor(double px, double py, double x0, double x1, double y0, double y1, double h) {
  return corner_view_factor(x1 - px, y1 - py, h) - corner_view_factor(x0 - px, y1 - py, h) -
         corner_view_factor(x1 - px, y0 - py, h) + corner_view_factor(x0 - px, y0 - py, h);
}

}  // namespace ct::test
