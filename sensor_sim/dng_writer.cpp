// SPDX-License-Identifier: Apache-2.0
#include "sensor_sim/dng_writer.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <Eigen/LU>
#include <fmt/core.h>
#include <tiffio.h>

#include "core/cie.h"
#include "core/error.h"
#include "core/file_io.h"
#include "sensor_sim/display.h"

namespace ct::sensor {
namespace {

constexpr int kStripRows = 16;

// CFAPattern's colour codes (0 red, 1 green, 2 blue) of the top-left 2×2 tile, row by row.
std::array<std::uint8_t, 4> cfa_codes(const std::string& pattern) {
  std::array<std::uint8_t, 4> codes{};
  for (std::size_t i = 0; i < 4; ++i) codes[i] = pattern.at(i) == 'R' ? 0 : pattern.at(i) == 'G' ? 1 : 2;
  return codes;
}

}  // namespace

Eigen::Vector3d dng_neutral(const std::array<std::vector<double>, 3>& weights, const std::vector<double>& illuminant) {
  const Eigen::Vector3d white = white_response(weights, illuminant);
  return white / white.maxCoeff();
}

Eigen::Matrix3d dng_colour_matrix(const std::array<std::vector<double>, 3>& weights, const Bands& bands,
                                  const std::string& illuminant) {
  const std::vector<double> light = band_averages(cie::illuminant(illuminant), bands);
  const Eigen::Vector3d white = white_response(weights, light);
  // Under D65 the display's fit (objects as they look in daylight) is the unadapted one; under another illuminant
  // the matrix must map the XYZ of objects lit by it.
  const Eigen::Matrix3d m = illuminant == "D65" ? camera_to_xyz(weights, bands, light)
                                                : camera_to_xyz_unadapted(weights, bands, cie::illuminant(illuminant));
  return (white / white.maxCoeff()).asDiagonal() * m.inverse();
}

struct DngWriter::File {
  std::unique_ptr<AtomicFile> output;  // declared before the TIFF handle: destroyed after it is closed
  TIFF* tiff = nullptr;
  int rows_written = 0;
  ~File() {
    if (tiff != nullptr) TIFFClose(tiff);
  }
};

DngWriter::DngWriter(const std::filesystem::path& path, int width, int height, DngMetadata metadata)
    : path_(path), width_(width), height_(height), metadata_(std::move(metadata)) {
  auto file = std::make_unique<File>();
  file->output = std::make_unique<AtomicFile>(path_);
  TIFF* tif = file->tiff = TIFFOpen(file->output->temporary().c_str(), "w");
  if (tif == nullptr) throw std::runtime_error(fmt::format("{}: libtiff cannot create the file", path_.string()));
  const DngMetadata& m = metadata_;

  TIFFSetField(tif, TIFFTAG_SUBFILETYPE, 0);  // the main image
  TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, static_cast<std::uint32_t>(width_));
  TIFFSetField(tif, TIFFTAG_IMAGELENGTH, static_cast<std::uint32_t>(height_));
  TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, 16);
  TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, 1);
  TIFFSetField(tif, TIFFTAG_COMPRESSION, COMPRESSION_NONE);
  TIFFSetField(tif, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_CFA);
  TIFFSetField(tif, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
  TIFFSetField(tif, TIFFTAG_ORIENTATION, ORIENTATION_TOPLEFT);
  TIFFSetField(tif, TIFFTAG_ROWSPERSTRIP, kStripRows);
  TIFFSetField(tif, TIFFTAG_MAKE, "chromatrace");
  TIFFSetField(tif, TIFFTAG_MODEL, m.camera.c_str());
  TIFFSetField(tif, TIFFTAG_SOFTWARE, "chromatrace sensor");

  const std::uint8_t version[4] = {1, 4, 0, 0}, backward[4] = {1, 3, 0, 0};
  TIFFSetField(tif, TIFFTAG_DNGVERSION, version);
  TIFFSetField(tif, TIFFTAG_DNGBACKWARDVERSION, backward);
  const std::string unique = "chromatrace " + m.camera;
  TIFFSetField(tif, TIFFTAG_UNIQUECAMERAMODEL, unique.c_str());

  const std::uint16_t repeat[2] = {2, 2};
  const std::array<std::uint8_t, 4> codes = cfa_codes(m.pattern);
  TIFFSetField(tif, TIFFTAG_CFAREPEATPATTERNDIM, repeat);
  TIFFSetField(tif, TIFFTAG_CFAPATTERN, 4, codes.data());

  const float black = static_cast<float>(m.black_level);
  const std::uint32_t white = static_cast<std::uint32_t>(std::lround(m.white_level));
  TIFFSetField(tif, TIFFTAG_BLACKLEVEL, 1, &black);
  TIFFSetField(tif, TIFFTAG_WHITELEVEL, 1, &white);

  float neutral[3];
  for (int c = 0; c < 3; ++c) neutral[c] = static_cast<float>(m.as_shot_neutral[c]);
  TIFFSetField(tif, TIFFTAG_ASSHOTNEUTRAL, 3, neutral);
  const auto set_matrix = [&](int tag, int illuminant_tag, const Eigen::Matrix3d& matrix, int illuminant) {
    float values[9];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) values[3 * r + c] = static_cast<float>(matrix(r, c));
    TIFFSetField(tif, tag, 9, values);
    TIFFSetField(tif, illuminant_tag, illuminant);
  };
  if (m.colour_matrix_a) {
    set_matrix(TIFFTAG_COLORMATRIX1, TIFFTAG_CALIBRATIONILLUMINANT1, *m.colour_matrix_a, kDngCalibrationIlluminantA);
    set_matrix(TIFFTAG_COLORMATRIX2, TIFFTAG_CALIBRATIONILLUMINANT2, m.colour_matrix, kDngCalibrationIlluminant);
  } else {
    set_matrix(TIFFTAG_COLORMATRIX1, TIFFTAG_CALIBRATIONILLUMINANT1, m.colour_matrix, kDngCalibrationIlluminant);
  }
  if (m.noise_profile) {
    // libtiff does not know DNG 1.3's NoiseProfile: a variable count of doubles.
    static const TIFFFieldInfo noise_profile{kDngNoiseProfileTag, TIFF_VARIABLE, TIFF_VARIABLE, TIFF_DOUBLE, FIELD_CUSTOM, 1, 1,
                                             const_cast<char*>("NoiseProfile")};
    TIFFMergeFieldInfo(tif, &noise_profile, 1);
    const double profile[2] = {m.noise_profile->first, m.noise_profile->second};
    TIFFSetField(tif, kDngNoiseProfileTag, std::uint16_t{2}, profile);
  }
  // The EXIF directory's offset is known only once it is written (finish()); a placeholder keeps its slot.
  TIFFSetField(tif, TIFFTAG_EXIFIFD, std::uint64_t{0});
  file_ = std::move(file);
}

DngWriter::~DngWriter() = default;

void DngWriter::write_rows(int y0, int rows, std::span<const float> mosaic) {
  if (!file_ || y0 != file_->rows_written || y0 + rows > height_ ||
      mosaic.size() != static_cast<std::size_t>(rows) * static_cast<std::size_t>(width_))
    throw std::invalid_argument(fmt::format("{}: DNG rows do not fit the image", path_.string()));
  std::vector<std::uint16_t> line(static_cast<std::size_t>(width_));
  for (int r = 0; r < rows; ++r) {
    for (int x = 0; x < width_; ++x)
      line[static_cast<std::size_t>(x)] = static_cast<std::uint16_t>(
          std::clamp(std::round(double(mosaic[static_cast<std::size_t>(r) * line.size() + static_cast<std::size_t>(x)])),
                     0.0, 65535.0));
    if (TIFFWriteScanline(file_->tiff, line.data(), static_cast<std::uint32_t>(y0 + r), 0) != 1)
      throw std::runtime_error(fmt::format("{}: cannot write row {}", path_.string(), y0 + r));
  }
  file_->rows_written += rows;
}

void DngWriter::finish() {
  if (!file_ || file_->rows_written != height_)
    throw std::logic_error(fmt::format("{}: DNG finished before its last row", path_.string()));
  TIFF* tif = file_->tiff;
  const auto fail = [&](const char* what) {
    throw std::runtime_error(fmt::format("{}: cannot write the {}", path_.string(), what));
  };
  if (!TIFFWriteDirectory(tif)) fail("main directory");
  // The EXIF directory: exposure time and f-number, then its offset into the main directory.
  if (TIFFCreateEXIFDirectory(tif) != 0) fail("EXIF directory");
  if (metadata_.exposure_s > 0) TIFFSetField(tif, EXIFTAG_EXPOSURETIME, metadata_.exposure_s);
  if (metadata_.f_number) TIFFSetField(tif, EXIFTAG_FNUMBER, *metadata_.f_number);
  std::uint64_t exif_offset = 0;
  if (!TIFFWriteCustomDirectory(tif, &exif_offset)) fail("EXIF directory");
  if (!TIFFSetDirectory(tif, 0)) fail("main directory");
  TIFFSetField(tif, TIFFTAG_EXIFIFD, exif_offset);
  if (!TIFFRewriteDirectory(tif)) fail("main directory");
  TIFFClose(tif);
  file_->tiff = nullptr;
  file_->output->commit();
  file_.reset();
}

}  // namespace ct::sensor
