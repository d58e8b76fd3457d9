// SPDX-License-Identifier: Apache-2.0
#pragma once
// Straight lines in colour space: the total-least-squares line through points, and a robust search
// (RANSAC) for the line that most points lie near, which finds a body (matte) line among highlight pixels
// and then the highlight line among the rest.

#include <cstdint>
#include <optional>
#include <vector>

#include "analyzer/moments.h"

namespace ct::analyzer {

struct Line {
  Vec3 point = Vec3::Zero();      // the inliers' centroid
  Vec3 direction = Vec3::UnitX();  // unit, oriented so that its components sum to >= 0 (towards brighter)
  double t_min = 0, t_max = 0;    // the inliers' extent along direction, from point
  std::size_t inliers = 0;
  double rms = 0;                 // rms distance of the inliers from the line

  Vec3 at(double t) const { return point + t * direction; }
  double distance(const Vec3& x) const { return (x - point - (x - point).dot(direction) * direction).norm(); }
  double position(const Vec3& x) const { return (x - point).dot(direction); }
};

// The total-least-squares line through points[i] for i in subset (the principal axis of their scatter).
Line fit_line(const std::vector<Vec3>& points, const std::vector<std::size_t>& subset);

struct LineSearch {
  Line line;
  std::vector<std::size_t> inliers;  // indices into points, increasing
};

// Among points[i], i in `candidates`: the line with the most points within `max_distance`, from pairs of
// candidates drawn with a fixed seed, then refit on its inliers with the distance narrowed to
// max(`min_distance`, 3 × the inliers' rms) so that points of a neighbouring structure that happen to lie
// within the first tolerance do not tilt it. nullopt when fewer than two candidates are distinct.
std::optional<LineSearch> find_line(const std::vector<Vec3>& points, const std::vector<std::size_t>& candidates,
                                    double max_distance, double min_distance, std::uint64_t seed);

// The angle between two lines' directions in degrees, in [0, 90].
double line_angle_degrees(const Vec3& a, const Vec3& b);

// The parameters (s on a, t on b) of the closest points of two lines.
std::pair<double, double> closest_parameters(const Line& a, const Line& b);

}  // namespace ct::analyzer
