// SPDX-License-Identifier: Apache-2.0
#pragma once
// A reference-tracer render split into independent parts that differ only in their seed, and their exact
// combination (docs/farm.md).
//
// Part i of a K-part split of N samples traces N/K samples (one more for the first N mod K parts) with seed
// first_seed + i. The tracer's random streams are keyed by (seed, pixel, sample), so parts are independent
// estimates of the same pixel means, and their sample-weighted mean is an estimate with all N samples:
//   combined = Σ nᵢ·vᵢ / Σ nᵢ   (summed in double, in part order, then rounded to float once).
// `chromatrace render --seeds K` and the farm's assembly both write the parts to files and combine them with
// combine_parts, so a split run on one machine and on a cluster gives the same bytes.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace ct::rt {

struct SeedSplit {
  int parts = 1;
  int samples = 1;              // all parts together
  std::uint64_t first_seed = 0;

  // InputError naming --seeds when parts < 1 or parts > samples (a part without samples).
  SeedSplit(int parts, int samples, std::uint64_t first_seed);
  int part_samples(int part) const;
  std::uint64_t part_seed(int part) const { return first_seed + static_cast<std::uint64_t>(part); }
};

// "part_<i>.exr": the file name of part i in a directory of parts.
std::string part_file_name(int part);

// The parts' files that do not exist, in order (the assembly names them; --resume renders them again).
std::vector<std::filesystem::path> missing_parts(const std::vector<std::filesystem::path>& parts);

// Combines spectral EXRs written by the tracer from one scene and settings with different seeds into one
// EXR at `output` (atomically), each part weighted by its chromatrace.samples. The header is the first
// part's, with chromatrace.samples the total, chromatrace.seed the first part's seed and chromatrace.parts
// listing every part's seed and samples. InputError naming the file and the field when a part is missing,
// is not a tracer render, or differs from the first in size, bands, layers, object ids, scene, camera or
// renderer settings, or repeats another part's seed.
void combine_parts(const std::vector<std::filesystem::path>& parts, const std::filesystem::path& output,
                   bool progress);

}  // namespace ct::rt
