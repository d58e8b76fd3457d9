// SPDX-License-Identifier: Apache-2.0
#pragma once
// `chromatrace calibrate`: a photon-transfer series of frames in, the camera's EMVA 1288 parameters out — per
// colour channel with their standard errors (calibration.json), and as sensor settings the simulator takes
// (chromatrace-sensor/1: the channels' mean, since one ADC and one pixel design serve them all).

#include <array>
#include <filesystem>
#include <optional>
#include <vector>

#include "calibrate/photon_transfer.h"
#include "core/json_input.h"

namespace ct::calibrate {

struct CalibrationInput {
  std::vector<std::filesystem::path> flats, darks;
  std::optional<double> photons_per_s;  // photons per pixel and second reaching each pixel of the flats
};

struct Calibration {
  std::array<ChannelCalibration, 3> channels;
  std::size_t flats = 0, darks = 0, exposures = 0;
  Json sensor;  // chromatrace-sensor/1 settings
  Json report;  // every estimate with its standard error, per channel, and the measured curves
};

// InputError, one line naming the file or the option, for a series that cannot support the estimates: no flats
// or no darks, one exposure time only, an exposure with flats but fewer than two darks (or the reverse), frames of
// different sizes or from another camera or mosaic, or a channel whose flats never saturate or leave fewer than three exposures below 70 % of
// saturation.
Calibration calibrate(const CalibrationInput& input);

// The dark current the sensor settings take for a channel: the dark mean's estimate, unless the dark variance's
// disagrees with it by more than three standard errors (a camera that subtracts its dark offset on chip keeps the
// mean flat while the dark electrons' shot noise grows); then the variance's, the noise the histograms show.
double simulated_dark_current(const ChannelCalibration& c);

}  // namespace ct::calibrate
