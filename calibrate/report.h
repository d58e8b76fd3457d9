// SPDX-License-Identifier: Apache-2.0
#pragma once
// The calibration's report directory (`chromatrace calibrate --report DIR`): calibration.json (every estimate per
// channel with its standard error, and the measured points) and index.html, a datasheet page as EMVA 1288 lays one
// out — the photon-transfer curve, the SNR curve, the linearity and the dark signal against exposure time, one curve
// per channel with the fitted model, as inline SVG (also written as photon_transfer.svg, snr.svg, linearity.svg and
// dark_signal.svg) — and the table of results.

#include <filesystem>
#include <string>

#include "calibrate/calibration.h"

namespace ct::calibrate {

// The plots as SVG documents, by file name (photon_transfer.svg, …).
std::vector<std::pair<std::string, std::string>> report_plots(const Calibration& calibration);

// The files the report writes (index.html, calibration.json and the plots).
std::vector<std::string> report_files();

// Writes the report's files into `staging`, a StagedDirectory's path (core/file_io.h), which the caller commits.
void write_report(const Calibration& calibration, const std::filesystem::path& staging);

}  // namespace ct::calibrate
