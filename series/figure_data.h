// SPDX-License-Identifier: Apache-2.0
#pragma once
// What the figure page (series/figure.h) shows of one variant: its entry in series.json, its findings, and,
// read from its files, the camera image and the whole image's histogram plots.

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/json_input.h"
#include "series/figure_plots.h"

namespace ct::series {

// One object judged against one expectation (series.json expect[].objects[]).
struct FindingView {
  std::string target;                // the expectation's target: an object, a group or "image"
  std::string object;                // the object judged
  std::vector<std::string> any_of;   // the classes expected
  std::string bent_by;               // the cause of its bend expected, or ""
  std::string thickened_by;          // the cause of its spread off the direct light's structure expected, or ""
  std::string paper;                 // the paper's word, when the series expects what the scene shows instead
  std::string found;                 // the analyzer's class, or "absent"
  bool ok = false;
  std::string explanation;           // the light paths that built it; empty without component layers
};

struct VariantView {
  std::string name, description, error;
  std::vector<std::string> figure;   // the paper's panels it reproduces ("3a", …)
  bool ok = false;                   // every step of the run went through
  std::string report, preview, camera_exr, analysis;  // relative to the output directory; empty when failed
  std::optional<std::array<int, 2>> size;
  std::vector<FindingView> findings;
  int met = 0, expectations = 0;
  double seconds = 0;                // render + camera + analysis

  // Filled by load_images. A variant whose files cannot be read keeps ok and gets image_error.
  std::string image_error;
  cv::Mat camera;                     // camera.png as a person sees it (8-bit BGR)
  std::string camera_png;             // its PNG bytes (the file's own, or re-encoded when it was too large)
  cv::Mat oblique, projection;        // the histogram plots (8-bit BGR)
  std::string oblique_png, projection_png;
  HistogramPoints points;             // what the plots hold (points.rgb cleared after drawing)
  plot::PrincipalPlane plane;
};

// The variants of series.json in its order; malformed entries become failed variants naming what is wrong.
std::vector<VariantView> read_variants(const Json& result);

// Reads the variant's camera.exr and camera.png from `dir` and draws its plots; any failure is kept in
// image_error, not thrown.
void load_images(VariantView& variant, const std::filesystem::path& dir, std::size_t max_points);

// A small PNG of the camera image for the table (long side ≤ `side`); empty when there is none.
std::string thumbnail_png(const std::filesystem::path& dir, const VariantView& variant, int side);

// What a finding expects, for a person: "thickened or P, bent by the highlight lobe (the paper: curved)".
std::string expected_text(const FindingView& finding);

// The paper's panel captions: "(a) Diffusely reflecting surfaces under direct illumination" for "3a"; empty
// for a panel the paper does not have.
std::string panel_caption(const std::string& panel);
// "Figure 3: Simulations of color histogram." etc., as the paper's captions begin.
std::string figure_title(int figure);
// "3a" … "3d" or "4a" … "4d": the paper's four panels of a figure.
const std::array<std::string, 4>& figure_panels(int figure);
// Panels beyond the paper shown beside a figure's four when a variant of the run reproduces them ("3e", the banana
// of a concave object, beside 3d); empty when the figure has none.
const std::vector<std::string>& extra_panels(int figure);

// The camera image shown scaled by a whole factor (or reduced) so that its long side is near `box`.
cv::Size display_size(const cv::Mat& camera, int box);

}  // namespace ct::series
