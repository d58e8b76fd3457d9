// SPDX-License-Identifier: Apache-2.0
// The oblique view of the RGB cube: where its corners are seen (closed forms in the azimuth and elevation), which
// lies nearest, its twelve edges and its placement on an image.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>
#include <utility>

#include <gtest/gtest.h>

#include "plot/oblique_cube.h"

namespace ct::plot {
namespace {

using Vec3 = Eigen::Vector3d;

constexpr double az = ObliqueCube::kAzimuthDeg * std::numbers::pi / 180, el = ObliqueCube::kElevationDeg * std::numbers::pi / 180;

// The screen's axes are right = (cos az, −sin az, 0) and up = (sin az sin el, cos az sin el, cos el), so a corner
// q is seen at ((q − ½)·right, (q − ½)·up).
TEST(ObliqueCube, CornersAreSeenWhereTheAnglesPutThem) {
  const ObliqueCube view;
  const double s = std::sin(az), c = std::cos(az), se = std::sin(el), ce = std::cos(el);
  const Eigen::Vector2d black = view.project(cube_corner(0)), white = view.project(cube_corner(7));
  EXPECT_NEAR(black.x(), (s - c) / 2, 1e-15);
  EXPECT_NEAR(black.y(), -((s + c) * se + ce) / 2, 1e-15);
  EXPECT_NEAR((white + black).norm(), 0, 1e-15);  // the centre is the cube's centre
  const Eigen::Vector2d r = view.project(cube_corner(1)), g = view.project(cube_corner(2)), b = view.project(cube_corner(4));
  EXPECT_NEAR(r.x(), (c + s) / 2, 1e-15);
  EXPECT_NEAR(r.y(), ((s - c) * se - ce) / 2, 1e-15);
  EXPECT_NEAR(g.x(), -(c + s) / 2, 1e-15);
  EXPECT_NEAR(g.y(), ((c - s) * se - ce) / 2, 1e-15);
  EXPECT_NEAR(b.x(), (s - c) / 2, 1e-15);
  EXPECT_NEAR(b.y(), (ce - (s + c) * se) / 2, 1e-15);
  // Black is the lowest corner and white the highest; R is seen to the right of black, G to the left, B above.
  for (int k = 1; k < 7; ++k) {
    EXPECT_GT(view.project(cube_corner(k)).y(), black.y()) << k;
    EXPECT_LT(view.project(cube_corner(k)).y(), white.y()) << k;
  }
  EXPECT_GT(r.x(), black.x());
  EXPECT_LT(g.x(), black.x());
  EXPECT_NEAR(b.x(), black.x(), 1e-15);
  EXPECT_NEAR(b.y() - black.y(), ce, 1e-15);  // B's edge is upright, foreshortened by the elevation
}

// An orthographic view: the screen axes are orthonormal, so no projected length exceeds the length in the cube,
// and a length along the line of sight vanishes.
TEST(ObliqueCube, ProjectionIsOrthographic) {
  const ObliqueCube view;
  const Vec3 towards(-std::sin(az) * std::cos(el), -std::cos(az) * std::cos(el), std::sin(el));
  const Vec3 q(0.3, 0.6, 0.2);
  EXPECT_NEAR((view.project(q + 0.25 * towards) - view.project(q)).norm(), 0, 1e-15);
  EXPECT_NEAR(view.nearness(q + 0.25 * towards) - view.nearness(q), 0.25, 1e-15);
  for (int a = 0; a < 8; ++a)
    for (int b = 0; b < 8; ++b)
      EXPECT_LE((view.project(cube_corner(a)) - view.project(cube_corner(b))).norm(),
                (cube_corner(a) - cube_corner(b)).norm() + 1e-15);
}

// Seen from above and from black's side: blue is the nearest corner, yellow the farthest.
TEST(ObliqueCube, NearestCornerIsBlueFarthestYellow) {
  const ObliqueCube view;
  int nearest = 0, farthest = 0;
  for (int k = 1; k < 8; ++k) {
    if (view.nearness(cube_corner(k)) > view.nearness(cube_corner(nearest))) nearest = k;
    if (view.nearness(cube_corner(k)) < view.nearness(cube_corner(farthest))) farthest = k;
  }
  EXPECT_EQ(nearest, 4);
  EXPECT_EQ(farthest, 3);
  EXPECT_NEAR(view.nearness(Vec3::Constant(0.5)), 0, 1e-15);
}

TEST(ObliqueCube, TwelveEdgesEachAlongOneChannelThreeFromBlackFirst) {
  const auto& edges = cube_edges();
  std::set<std::pair<int, int>> seen;
  for (const CubeEdge& e : edges) {
    EXPECT_EQ(e.from & (1 << e.channel), 0);
    EXPECT_EQ((cube_corner(e.to()) - cube_corner(e.from)), Vec3::Unit(e.channel));
    seen.insert({e.from, e.to()});
  }
  EXPECT_EQ(seen.size(), 12u);
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(edges[static_cast<std::size_t>(c)].from, 0);
    EXPECT_EQ(edges[static_cast<std::size_t>(c)].channel, c);
  }
}

// The cube fitted to an area: centred in it, filling its width (the view is wider than high for this area) and
// inside it; R's corner at the right edge, G's at the left.
TEST(ObliqueCube, FitPlacesTheCubeInsideTheAreaCentred) {
  const ObliqueCube view;
  const cv::Rect area(10, 20, 100, 200);
  const CubePlacement p = fit_cube(view, area);
  EXPECT_NEAR(p.scale, 100 / (std::sin(az) + std::cos(az)), 1e-12);
  EXPECT_NEAR(p.at(view, Vec3::Constant(0.5)).x, 60, 1e-12);
  EXPECT_NEAR(p.at(view, Vec3::Constant(0.5)).y, 120, 1e-12);
  EXPECT_NEAR(p.at(view, cube_corner(1)).x, 110, 1e-12);
  EXPECT_NEAR(p.at(view, cube_corner(2)).x, 10, 1e-12);
  for (int k = 0; k < 8; ++k) {
    const cv::Point2d at = p.at(view, cube_corner(k));
    EXPECT_GE(at.y, 20 - 1e-9);
    EXPECT_LE(at.y, 220 + 1e-9);
  }
  EXPECT_LT(p.at(view, cube_corner(7)).y, p.at(view, cube_corner(0)).y);  // white above black: y grows down
}

TEST(ObliqueCube, DrawsTwelveEdgesInTheirColours) {
  cv::Mat img(200, 200, CV_8UC3, cv::Scalar(0, 0, 0));
  const ObliqueCube view;
  const CubePlacement p = fit_cube(view, cv::Rect(10, 10, 180, 180));
  int drawn = 0;
  draw_cube_edges(img, [&](const Vec3& q) { return cv::Point(p.at(view, q)); },
                  [&](const CubeEdge& e) {
                    ++drawn;
                    return e.from == 0 ? cv::Scalar(0, 0, 255) : cv::Scalar(255, 0, 0);
                  });
  EXPECT_EQ(drawn, 12);
  // The middle of the edge from black along R is drawn red, that of the top edge from cyan to white blue.
  const cv::Point2d mid_r = p.at(view, Vec3(0.5, 0, 0)), mid_top = p.at(view, Vec3(0.5, 1, 1));
  EXPECT_GT(img.at<cv::Vec3b>(cv::Point(mid_r))[2], 100);
  EXPECT_GT(img.at<cv::Vec3b>(cv::Point(mid_top))[0], 100);
}

}  // namespace
}  // namespace ct::plot
