// SPDX-License-Identifier: Apache-2.0
#pragma once
// Band-plan files (`chromatrace-bands/1`): bands that a `lo:hi:width` plan cannot express, e.g. narrower
// bands where a spectrum changes fast, and optionally the reconstruction that turns their values into a finer
// spectrum (core/spectrum.h: BandReconstruction; `chromatrace plan` fits it):
//
//   {"format": "chromatrace-bands/1", "edges_nm": [380, 400, 420, 440, 450, 460, 480, 520, 600, 780],
//    "reconstruction": {"lo_nm": 380, "step_nm": 1, "matrix": [[m_00, ..., m_08], ...]}}
//
// N + 1 strictly increasing edges give N contiguous bands [edge_i, edge_i+1) that must overlap the visible
// range 360–830 nm. The reconstruction's matrix has one row per fine band [lo + j·step, lo + (j+1)·step) and one
// column per band. Errors name the file and the JSON path ("plan.json: edges_nm[3]: ...").

#include <filesystem>

#include "core/json_input.h"
#include "core/spectrum.h"

namespace ct {

Bands read_band_plan(const std::filesystem::path& file);
// The chromatrace-bands/1 document of `bands` (with its reconstruction, if any).
Json band_plan_document(const Bands& bands);

// A reconstruction as JSON ({"lo_nm", "step_nm", "matrix"}), for the band-plan file and the assembly manifest,
// and back onto `bands` (errors name the node's path).
Json reconstruction_json(const BandReconstruction& r);
Bands read_reconstruction(const JsonNode& node, const Bands& bands);

}  // namespace ct
