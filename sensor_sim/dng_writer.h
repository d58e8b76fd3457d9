#pragma once
// The sensor simulator's Bayer mosaic as a DNG 1.4 file (Adobe Digital Negative, libtiff), so that raw
// developers (dcraw, LibRaw, darktable, RawTherapee) open a simulated capture as they open a camera's
// (docs/sensor.md, "DNG").
//
// One full-resolution IFD (NewSubFileType 0, PhotometricInterpretation CFA), 16 bits per sample,
// uncompressed strips, and only what the simulation knows: the CFA pattern, black and white levels, the
// as-shot neutral, one colour matrix under D65, the camera's name, and, in an EXIF IFD, the exposure time
// and f-number. Written through core/file_io's AtomicFile: nothing half-written is left behind.

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
  Eigen::Matrix3d colour_matrix = Eigen::Matrix3d::Identity();  // CIE XYZ → camera RGB under D65
  std::string camera;             // Model and UniqueCameraModel ("chromatrace <camera>")
  double exposure_s = 0;          // EXIF ExposureTime (0: not written)
  std::optional<double> f_number;  // EXIF FNumber (none with the optics off)
};

// The EXIF LightSource code of ColorMatrix1's calibration illuminant (21 = D65).
constexpr int kDngCalibrationIlluminant = 21;

// AsShotNeutral: the camera's signal of a perfect white lit by `illuminant` (band values), through the
// per-band weights w[c][b] of linear_signal.h, divided by its largest channel.
Eigen::Vector3d dng_neutral(const std::array<std::vector<double>, 3>& weights, const std::vector<double>& illuminant);

// ColorMatrix1 (CIE XYZ → camera RGB under D65): with M the white-preserving least-squares fit of
// display.h (white-balanced camera RGB → XYZ over 64 smooth reflectances lit by D65) and c_w the camera's
// signal of a white lit by D65, diag(c_w)·M⁻¹, scaled so that D65's white (M·(1,1,1)) maps to a neutral whose
// largest channel is 1, as the DNG specification normalises it.
Eigen::Matrix3d dng_colour_matrix(const std::array<std::vector<double>, 3>& weights, const Bands& bands);

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
