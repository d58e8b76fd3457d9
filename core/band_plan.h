#pragma once
// Band-plan files (`chromatrace-bands/1`): bands that a `lo:hi:width` plan cannot express, e.g. narrower
// bands where a spectrum changes fast.
//
//   {"format": "chromatrace-bands/1", "edges_nm": [380, 400, 420, 440, 450, 460, 480, 520, 600, 780]}
//
// N + 1 strictly increasing edges give N contiguous bands [edge_i, edge_i+1) that must overlap the visible
// range 360–830 nm. Errors name the file and the JSON path ("plan.json: edges_nm[3]: ...").

#include <filesystem>

#include "core/spectrum.h"

namespace ct {

Bands read_band_plan(const std::filesystem::path& file);

}  // namespace ct
