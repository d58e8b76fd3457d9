// SPDX-License-Identifier: Apache-2.0
#pragma once
// Band-plan files (`chromatrace-bands/1`): bands that a `lo:hi:width` plan cannot express, e.g. narrower
// bands where a spectrum changes fast, and optionally the reconstruction that turns their values into a finer
// spectrum (core/spectrum.h: BandReconstruction; `chromatrace plan` fits it):
//
//   {"format": "chromatrace-bands/1", "edges_nm": [380, 400, 420, 440, 450, 460, 480, 520, 600, 780],
//    "reconstruction": {"lo_nm": 380, "step_nm": 1, "matrix": [[m_00, ..., m_08], ...]},
//    "cycles_samples": [256, 32, 32], "cycles_guided_groups": [1, 2], "cycles_guided_threshold": 0.01,
//    "cycles_light_tree": false}
//
// N + 1 strictly increasing edges give N contiguous bands [edge_i, edge_i+1) that must overlap the visible
// range 360–830 nm. The reconstruction's matrix has one row per fine band [lo + j·step, lo + (j+1)·step) and one
// column per band. cycles_samples, optional, gives Cycles' samples per pixel for each band group, the bands
// 3g, 3g + 1, 3g + 2 that one Cycles render carries (⌈N / 3⌉ whole numbers ≥ 1); the Blender add-on renders each
// group with its own, and the tracer, which carries every band along each path, has no use for them.
// cycles_guided_groups, optional (with cycles_samples), names the groups rendered with few samples and then
// reconstructed from the others (core/guided.h); at least one group must be left to guide them.
// cycles_guided_threshold, optional (with cycles_guided_groups), renders the guided groups with Cycles' adaptive
// sampling: every pixel gets the group's samples, and a pixel whose noise stays above the threshold (Cycles'
// adaptive_threshold: objects' edges and highlights, which the reconstruction leaves at their own samples) gets
// more, up to the guides' samples. cycles_light_tree, optional, turns Cycles' light tree (Blender 3.5 on) on or off in
// the add-on's renders of the bands, whatever the scene has: the add-on's plan turns it off where its pilots found the
// scene less noisy without it (docs/plan.md, "Cycles' light tree, planned"). Errors name the file and the JSON path
// ("plan.json: edges_nm[3]: ...").

#include <cstddef>
#include <filesystem>
#include <optional>
#include <vector>

#include "core/json_input.h"
#include "core/spectrum.h"

namespace ct {

// What a band-plan file holds: its bands (with their reconstruction) and the Cycles samples of each band group
// (empty when the file gives none).
struct BandPlanFile {
  Bands bands;
  std::vector<int> cycles_samples;
  std::vector<std::size_t> cycles_guided_groups;  // in increasing order
  double cycles_guided_threshold = 0;             // 0: the guided groups render their samples, no more
  std::optional<bool> cycles_light_tree;          // absent: Cycles' light tree as the scene has it
};
BandPlanFile read_band_plan_file(const std::filesystem::path& file);
Bands read_band_plan(const std::filesystem::path& file);  // the bands alone

// The number of Cycles renders, of three bands each, that `band_count` bands take.
constexpr std::size_t cycles_band_groups(std::size_t band_count) { return (band_count + 2) / 3; }

// The renders' bands, `per_render` (1 to 3) to a render: interleaved, render g of G = ⌈band_count / per_render⌉
// holding bands g, g + G, g + 2G (7 bands, 3 to a render: [0, 3, 6], [1, 4], [2, 5]), so that every render spans the
// spectrum. Cycles picks a Principled BSDF's lobe (and a Mix Shader's side) with a probability that follows the
// lobe's colour weight averaged over the render's three channels; renders of neighbouring bands (one blue, one red)
// would pick differently for the same random numbers, their paths part at the first such surface, and the groups'
// noise would stop moving together and add up as chroma: on a scene of Principled BSDFs, two renders of consecutive
// bands were 1.1–1.5 times as noisy as one render of three bands or as a plain RGB render at equal samples, two
// interleaved ones as noisy as either (docs/plan.md, "Why band groups were noisier than an RGB render").
// The band plan's groups (cycles_samples, cycles_guided_groups) are these with per_render 3.
std::vector<std::vector<std::size_t>> cycles_render_groups(std::size_t band_count, int per_render = 3);
// The band plan's group (cycles_render_groups with 3 to a render) that holds `band`.
constexpr std::size_t cycles_band_group_of(std::size_t band_count, std::size_t band) {
  return band % cycles_band_groups(band_count);
}

// The chromatrace-bands/1 document of `bands` (with its reconstruction, if any, and the groups' samples if given).
Json band_plan_document(const Bands& bands, const std::vector<int>& cycles_samples = {},
                        const std::vector<std::size_t>& cycles_guided_groups = {}, double cycles_guided_threshold = 0);

// A reconstruction as JSON ({"lo_nm", "step_nm", "matrix"}), for the band-plan file and the assembly manifest,
// and back onto `bands` (errors name the node's path).
Json reconstruction_json(const BandReconstruction& r);
Bands read_reconstruction(const JsonNode& node, const Bands& bands);

}  // namespace ct
