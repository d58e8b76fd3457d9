// SPDX-License-Identifier: Apache-2.0
#pragma once
// One streamed pass over a spectral EXR's pixels: non-finite values per channel, per-band statistics of
// the total, and whether each family of component layers sums to the total (docs/spectral-exr.md).

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/spectral_channel_name.h"
#include "core/spectral_exr.h"

namespace ct {

// NaN or ±Inf values in one channel; the first in reading order (row by row, top to bottom).
struct NonFiniteCount {
  std::string channel;
  std::uint64_t count = 0;
  int first_x = 0;
  int first_y = 0;
};

// Over the finite values of one band.
struct BandStatistics {
  double min = 0;
  double mean = 0;
  double max = 0;
  std::uint64_t finite = 0;  // how many values were finite
};

// One family of components (path types, light groups or bounces) of one quantity against the total.
struct ComponentSumCheck {
  ComponentFamily family = ComponentFamily::PathType;
  SpectralQuantity quantity = SpectralQuantity::S0;
  std::vector<std::string> components;
  // Path types are checked only when all seven are present; a partial set need not sum to anything.
  bool checked = false;
  // The largest |Σ components − total| / tolerance over pixels and bands (pixels with a NaN/Inf in any
  // of the values are skipped: they are reported as non-finite), and where it was.
  double worst_ratio = 0;
  std::string channel;  // the total's channel there
  int x = 0;
  int y = 0;
  double sum = 0;
  double total = 0;
  double tolerance = 0;

  bool passed() const { return !checked || worst_ratio <= 1.0; }
};

struct SpectralExrScan {
  // Channels with at least one NaN/Inf: the layers in info order, then re-radiation, then object_id.
  std::vector<NonFiniteCount> non_finite;
  std::vector<BandStatistics> total_statistics;   // per band of the total
  std::vector<ComponentSumCheck> component_sums;  // when asked, one per family and quantity present
};

struct ScanOptions {
  bool check_components = false;
  std::function<void(int rows_done)> progress;  // after each block of rows
};

// NaN and Inf values in every channel of any OpenEXR file, spectral or not (a camera RGB image from `sensor`):
// per channel with a value that is not finite, how many and the first pixel, in the file's channel order.
std::vector<NonFiniteCount> scan_non_finite(SpectralExrReader& reader);

// Reads every spectral channel and object_id once, block by block (R, G, B and other channels are not
// spectral data and are skipped). A file without spectral channels is an InputError.
SpectralExrScan scan_spectral_exr(SpectralExrReader& reader, const ScanOptions& options = {});

// How far n float components may sum from a float total by rounding alone, where `magnitude` is
// Σ|component|: (n + 1) · (2^-23 · magnitude + 2^-149). See the derivation in the source.
double component_sum_tolerance(std::size_t component_count, double magnitude);

}  // namespace ct
