// SPDX-License-Identifier: Apache-2.0
#pragma once
// The sensor simulator's Bayer mosaic as a DNG 1.4 file (Adobe Digital Negative, libtiff), so that raw
// developers (dcraw, LibRaw, darktable, RawTherapee) open a simulated capture as they open a camera's
// (docs/sensor.md, "DNG").
//
// One full-resolution IFD (NewSubFileType 0, PhotometricInterpretation CFA), 16 bits per sample,
// uncompressed strips, and only what the simulation knows: the CFA pattern, black and white levels, the
// as-shot neutral, colour matrices under D65 and illuminant A, the noise profile of the sensor model, the camera's
// name, and, in an EXIF IFD, the exposure time and f-number. Written through core/file_io's AtomicFile: nothing half-written is left behind.

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include <Eigen/Core>
#include <vector>

#include "core/spectrum.h"

namespace ct::sensor {

struct DngMetadata {
  std::string pattern = "RGGB";   // the filters of the top-left 2×2 tile, row by row
  double black_level = 0;         // DN
  double white_level = 65535;     // DN at which the values clip
  Eigen::Vector3d as_shot_neutral = Eigen::Vector3d::Ones();  // camera RGB of a neutral, largest = 1
  // CIE XYZ → camera RGB under D65, and under illuminant A. With both, as Adobe's converter writes them,
  // ColorMatrix1 is A's and ColorMatrix2 D65's (a reader that takes one matrix, as dcraw does, takes the last, D65's);
  // with D65's alone it is ColorMatrix1.
  Eigen::Matrix3d colour_matrix = Eigen::Matrix3d::Identity();
  std::optional<Eigen::Matrix3d> colour_matrix_a;
  // NoiseProfile (DNG 1.3, tag 51041): the variance of a value x normalised to [0, 1] (black 0, white 1) is
  // scale·x + offset, the same for every CFA plane. Absent without noise.
  std::optional<std::pair<double, double>> noise_profile;
  std::string camera;             // Model and UniqueCameraModel ("chromatrace <camera>")
  double exposure_s = 0;          // EXIF ExposureTime (0: not written)
  std::optional<double> f_number;  // EXIF FNumber (none with the optics off)
};

// The EXIF LightSource codes of the calibration illuminants: 21 = D65, 17 = standard light A.
constexpr int kDngCalibrationIlluminant = 21;
constexpr int kDngCalibrationIlluminantA = 17;
constexpr std::uint32_t kDngNoiseProfileTag = 51041;

// AsShotNeutral: the camera's signal of a perfect white lit by `illuminant` (band values), through the
// per-band weights w[c][b] of linear_signal.h, divided by its largest channel.
Eigen::Vector3d dng_neutral(const std::array<std::vector<double>, 3>& weights, const std::vector<double>& illuminant);

// A ColorMatrix (CIE XYZ → camera RGB under a CIE illuminant, "D65" or "A"): with M the white-preserving
// least-squares fit of display.h (white-balanced camera RGB → XYZ over 64 smooth reflectances lit by it) and c_w the
// camera's signal of a white lit by it, diag(c_w)·M⁻¹, scaled so that its white (M·(1,1,1)) maps to a neutral whose
// largest channel is 1, as the DNG specification normalises it.
Eigen::Matrix3d dng_colour_matrix(const std::array<std::vector<double>, 3>& weights, const Bands& bands,
                                  const std::string& illuminant = "D65");

class DngWriter {
 public:
  // Creates the temporary file beside `path` (an InputError naming it if that is impossible).
  DngWriter(const std::filesystem::path& path, int width, int height, DngMetadata metadata);
  ~DngWriter();
  DngWriter(const DngWriter&) = delete;
  DngWriter& operator=(const DngWriter&) = delete;

  // The next rows of digital numbers, top to bottom: rows·width values, rounded and clamped to [0, 65535].
  void write_rows(int y0, int rows, std::span<const float> mosaic);
  // After the last row: writes the directories and renames the file into place.
  void finish();

 private:
  struct File;
  std::filesystem::path path_;
  int width_ = 0, height_ = 0;
  DngMetadata metadata_;
  std::unique_ptr<File> file_;
};

}  // namespace ct::sensor
