// SPDX-License-Identifier: Apache-2.0
#pragma once
// `chromatrace calibrate`: a photon-transfer series of frames in, the camera's EMVA 1288 parameters out — per
// colour channel with their standard errors (calibration.json), and as sensor settings the simulator takes
// (chromatrace-sensor/1: the channels' mean, since one ADC and one pixel design serve them all).

#include <array>
#include <filesystem>
#include <optional>
#include <vector>

#include "calibrate/frames.h"
#include "calibrate/photon_transfer.h"
#include "core/json_input.h"

namespace ct::calibrate {

// The series: flats and darks at several exposure times (EMVA 1288's first method), or flats at one exposure time
// under several irradiances (its second method: the flats taken in pairs in the order given, A1 A2 B1 B2 …), with
// darks at the flats' exposure times and, optionally, darks alone at further times (for the dark current).
struct CalibrationInput {
  std::vector<std::filesystem::path> flats, darks;
  std::vector<Frame> flat_frames, dark_frames;  // frames already in memory, after the files' (frame_in_memory)
  std::optional<double> photons_per_s;    // photons per pixel and second reaching each pixel of the flats (first method)
  std::vector<double> photons_per_pixel;  // per pair of flats, in their order (second method)
  std::string input_transfer = "auto";    // what the frames' values are (analyzer::parse_input_transfer)
  // The flats' light (monochromatic, as EMVA 1288 measures η) and the camera's spectral curves: with the photons,
  // the measured η at that wavelength sets the settings' spectral_response.peak_qe (η over the curves' relative
  // value there).
  std::optional<double> wavelength_nm;
  std::string camera;              // a shipped camera, cie1931, or a CSV file (sensor::camera_curves)
  std::string basis = "energy";    // what the curves are proportional to: energy or photon (docs/sensor.md)
  // The operating point as the user measured it (the datasheet states them; the frames do not say): the pixel pitch
  // (µm; gives the thresholds per area) and the sensor's temperature (°C).
  std::optional<double> pixel_pitch_um, temperature_c;
};

// The peak quantum efficiency the simulator takes (spectral_response.peak_qe): per channel, η measured at the
// flats' wavelength over the camera curves' relative QE there; and their mean weighted by 1/SE².
struct PeakQe {
  std::vector<Estimate> per_channel;
  std::vector<double> relative_qe;  // η_c(λ) / peak_qe of the curves
  Estimate value;
  bool channels_agree = true;       // each within 3 of its standard errors (and the mean's) of the mean
};

// The temporal noise's correlation between neighbouring pixels and between channels, in the difference of each pair
// of flats (their fixed pattern cancels): about 0 where each pixel is read on its own; a demosaiced or filtered
// frame's pixels share noise.
struct NoiseCorrelation {
  double horizontal = 0, vertical = 0, between_channels = 0;  // the largest over the channels (pairs of channels)
  std::string horizontal_channel, vertical_channel, channel_pair;
  double standard_error = 0;                                  // of each: 1/√(pixels compared)
};

struct Calibration {
  std::vector<ChannelCalibration> channels;  // R, G, B, or the one channel of a monochrome camera
  std::size_t flats = 0, darks = 0, exposures = 0;
  std::string series;  // "16 exposure times" or "12 irradiances at 0.01 s" (and "; darks alone at 2 further times")
  // The operating point: what took the frames ("camera raw, <camera>, CFA RGGB", "linear TIFF, R, G, B"), their size
  // per channel, the flats' exposure times, the light's wavelength (when given), and the first frame's date (EXIF).
  std::string camera;
  std::pair<int, int> frame_size;
  double flat_exposure_min_s = 0, flat_exposure_max_s = 0;
  std::optional<double> wavelength_nm;
  std::optional<double> pixel_pitch_um, temperature_c;
  std::string date;
  NoiseCorrelation noise_correlation;
  std::optional<PeakQe> peak_qe;
  std::vector<std::string> notes;  // of the series as a whole
  Json sensor;  // chromatrace-sensor/1 settings
  Json report;  // every estimate with its standard error, per channel, and the measured curves
};

// Pixels of frames that are not a camera raw's (which are photosites) whose temporal noise correlates by more than
// this with a neighbour's or another channel's are refused: they were interpolated or filtered, so a pixel's
// variance is not its own. Bilinear demosaicing gives 0.25 or more; a sensor's own crosstalk a few per cent.
inline constexpr double kMaxNoiseCorrelation = 0.1;

// InputError, one line naming the file or the option, for a series that cannot support the estimates: no flats
// or no darks, one exposure time and one pair of flats only, an exposure with flats but fewer than two darks, one
// flat or dark alone at its time, a pair at one exposure time whose means differ by more than 5 % (not one
// irradiance), photons given the wrong way for the series, frames of different sizes or from another camera or
// mosaic, pixels whose noise correlates (above), or a channel whose flats never saturate or leave fewer than three
// steps below 70 % of saturation.
Calibration calibrate(const CalibrationInput& input);

// The dark current the sensor settings take for a channel: the dark mean's estimate, unless the dark variance's
// disagrees with it by more than three standard errors (a camera that subtracts its dark offset on chip keeps the
// mean flat while the dark electrons' shot noise grows); then the variance's, the noise the histograms show.
double simulated_dark_current(const ChannelCalibration& c);

}  // namespace ct::calibrate
