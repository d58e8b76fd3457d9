// SPDX-License-Identifier: Apache-2.0
#pragma once
// Cross-validation of two spectral renders of one scene (docs/compare.md): per object × band × component
// the two means, their ratio with its Monte Carlo standard error, the z-score and a pass/fail against a
// tolerance; image-level ΔE00 through a camera; compare.json, compare.png and compare.html.
//
// Either side may be several renders with independent seeds (A1.exr,A2.exr): the side's mean is the
// average of the renders' object means. The standard error of the difference of the two means, which the
// z-score and the test use, is from the seeds when both sides have several renders (their spread / √k, each
// side), else from the per-pixel variance within the object of the difference image A − B (its standard
// deviation / √n): both renderers render the same image, so its structure cancels and what remains is the
// two renders' per-pixel noise, independent from pixel to pixel. se_a and se_b are reported per side: from
// the seeds, or, for a single render, from differences of neighbouring pixels of the object (an upper bound:
// shading gradients add to it).
//
// Bad or incomparable input (different scenes, cameras, sizes, band plans that do not nest) is an
// InputError naming the file and what differs.

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/spectrum.h"
#include "core/statistics.h"

namespace ct::cmp {

struct CompareOptions {
  std::vector<std::string> a;  // renders of side A (one, or several with independent seeds)
  std::vector<std::string> b;
  // Relative tolerance for every cell; unset: by BRDF type (Lambert and emitters 1 %, anything glossy 2 %).
  std::optional<double> tolerance;
  double sigmas = kSigmasPerItem;  // a cell passes when |mean_a − mean_b| ≤ tolerance·|mean_b| + sigmas·se
  // Pixels of an object: "matched" (the id is the same in both renders) or "interior" (also every
  // 8-neighbour has that id in both).
  std::string pixels = "matched";
  std::string camera = "cie1931";  // for ΔE00: the CIE observer, or a camera the sensor simulator ships
  // The image level's colours: "common" — both sides on the common (coarser) band plan, so that only what the
  // renderers do differently counts; "own" — each side through the camera over its own bands, so that a coarser
  // plan's colour error counts too (how far a cheap render's colours are from a fine reference's).
  std::string colour = "common";
  // The white the image level's CIELAB is under: "scene" — the scene's light (plan::scene_light_spectrum of A's
  // chromatrace.scene, else B's: its lights by radiance × area, its environment's mean), the white `plan` predicts
  // under and `study` measures under; where neither header holds a scene whose light can be read, D65, and
  // compare.json says why. "d65": D65 whatever the scene's light.
  std::string white = "scene";
};

struct Cell {
  std::int32_t object_id = 0;  // -1: the whole image
  std::string object;
  std::string brdf;  // lambert, dichromatic, mirror, ggx, phong, emitter, image
  std::string component;  // "total", "diffuse_direct", "light.ceiling", …
  std::size_t band = 0;
  double lo_nm = 0, hi_nm = 0;
  std::size_t pixels = 0;
  double mean_a = 0, mean_b = 0, se_a = 0, se_b = 0;
  double se = 0;  // standard error of mean_a − mean_b, which z and the test use (see se_method)
  std::optional<double> ratio, se_ratio;  // unset when mean_b is 0
  double z = 0;                           // (mean_a − mean_b) / √(se_a² + se_b²); 0 when both are exact
  double tolerance = 0;
  bool pass = true;
};

struct SideSummary {
  std::vector<std::string> files;
  std::string renderer, samples, seeds;
};

struct Comparison {
  SideSummary a, b;
  std::string scene_name;
  int width = 0, height = 0;
  Bands bands;  // the common (coarser) plan
  std::string colour = "common";  // how the image level's colours were made (CompareOptions::colour)
  std::string white;  // the white's light, said: "the scene's light (A's chromatrace.scene)", "D65", or "D65: … why"
  std::vector<std::string> components;  // compared: "total" and the components both have
  std::vector<std::string> only_a, only_b;
  std::size_t id_mismatch_pixels = 0;  // pixels whose object id differs between A and B
  std::vector<Cell> cells;
  std::size_t failed = 0;
  double sigmas = kSigmasPerItem;
  std::string tolerance_mode;  // "by BRDF type" or "fixed 1%"
  std::string pixels_mode;
  // "seeds" (both sides several renders: the spread of their means) or "paired pixels" (the spread of the
  // per-pixel differences A − B within the object, which removes the image's own structure).
  std::string se_method;
  // Image level.
  std::string camera;
  std::vector<double> delta_e;  // per pixel, [y][x]
  double delta_e_mean = 0, delta_e_p95 = 0, delta_e_max = 0;
  // Mean ΔE00 over each object's pixels (its id in both renders), by object id.
  std::map<std::int32_t, double> delta_e_by_object;
  // Linear sRGB previews of A, B (row-major RGB), scaled so the reference white is 1.
  std::vector<float> rgb_a, rgb_b;
};

Comparison compare(const CompareOptions& options);

// compare.json, compare.png (A | B | difference | ΔE00), compare.html in `dir` (created if missing; its
// parent must exist); each written atomically.
void write_outputs(const Comparison& c, const std::filesystem::path& dir);

// The one-screen verdict for stderr.
std::string verdict(const Comparison& c, std::size_t max_lines = 12);

}  // namespace ct::cmp
