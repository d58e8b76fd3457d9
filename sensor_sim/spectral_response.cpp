// SPDX-License-Identifier: Apache-2.0
#include "sensor_sim/spectral_response.h"

#include <algorithm>
#include <stdexcept>

#include <fmt/core.h>
#include <fmt/format.h>

#include "core/cie.h"
#include "core/csv.h"
#include "core/error.h"
#include "core/spectrum.h"
#include "sensor_sim/embedded_cameras.h"

namespace ct::sensor {
namespace {

// Both ends of a band plan lie on the curves' table when they are within this of its ends (nm): band edges
// travel through float EXR attributes, which round 380 nm by up to 3e-5 nm.
constexpr double kCoverageSlack = 1e-3;

bool is_csv_path(std::string_view camera) {
  return camera.find('/') != std::string_view::npos || camera.ends_with(".csv");
}

CameraCurves from_table(const CsvTable& table, std::string name, const std::array<std::string, 3>& columns) {
  CameraCurves camera;
  camera.name = std::move(name);
  for (std::size_t c = 0; c < 3; ++c) {
    camera.channels[c] = columns[c];
    camera.curves[c] = table.spectrum(columns[c]);
  }
  return camera;
}

}  // namespace

double CameraCurves::min_wavelength() const {
  return std::max({curves[0].min_wavelength(), curves[1].min_wavelength(), curves[2].min_wavelength()});
}

double CameraCurves::max_wavelength() const {
  return std::min({curves[0].max_wavelength(), curves[1].max_wavelength(), curves[2].max_wavelength()});
}

const std::vector<std::string>& shipped_cameras() {
  static const std::vector<std::string> names = {
      "canon_eos_100d",     "canon_eos_1dx_mkii", "canon_eos_200d",    "canon_eos_200d_mkii", "canon_eos_5d",
      "canon_eos_5d_mkii",  "canon_eos_5d_mkiii", "canon_eos_5d_mkiv", "canon_eos_5ds",       "canon_eos_m",
      "hasselblad_l1d_20c", "nikon_d810",         "nikon_d850",        "sony_ilce_6400",      "sony_ilce_7m3",
      "sony_ilce_7rm3",     "sony_ilce_9"};
  return names;
}

CameraCurves camera_curves(std::string_view camera, const std::array<std::string, 3>& columns,
                           const std::string& where) {
  if (camera == "cie1931") {
    CameraCurves cie;
    cie.name = "cie1931";
    cie.channels = {"X", "Y", "Z"};
    cie.curves = {cie::x_bar(), cie::y_bar(), cie::z_bar()};
    return cie;
  }
  if (is_csv_path(camera)) {
    try {
      return from_table(read_csv(std::string(camera)), std::string(camera), columns);
    } catch (const InputError& e) {
      throw InputError(fmt::format("{}: {}", where, e.what()));
    }
  }
  const auto& names = shipped_cameras();
  if (std::find(names.begin(), names.end(), camera) == names.end())
    throw InputError(fmt::format("{}: unknown camera \"{}\" (cameras: cie1931, {}; or a CSV file)", where, camera,
                                 fmt::join(names, ", ")));
  const std::string file = fmt::format("{}.csv", camera);
  const std::string_view bytes = cameras_embedded::file(file);
  if (bytes.empty()) throw std::logic_error(fmt::format("embedded camera file {} is missing", file));
  return from_table(parse_csv(bytes, "cameras/" + file), std::string(camera), {"r", "g", "b"});
}

void check_band_coverage(const Bands& bands, const CameraCurves& camera, const std::string& file) {
  const double lo = camera.min_wavelength(), hi = camera.max_wavelength();
  if (bands.min_wavelength() >= lo - kCoverageSlack && bands.max_wavelength() <= hi + kCoverageSlack) return;
  throw InputError(
      fmt::format("{}: bands {:g}-{:g} nm reach outside the camera curves of {} ({:g}-{:g} nm); set "
                  "spectral_response.outside_curve to \"zero\" (--outside-curve zero) to count no response there",
                  file, bands.min_wavelength(), bands.max_wavelength(), camera.name, lo, hi));
}

std::array<std::vector<double>, 3> photon_response(const Bands& bands, const CameraCurves& camera, ResponseBasis basis,
                                                   double peak_qe, const PiecewiseLinearSpectrum& transmittance) {
  // p_c(λ) = s_c(λ) (photon) or s_c(λ)/λ (energy); s/λ is monotonic between samples of a piecewise-linear s
  // ((a + bλ)/λ = a/λ + b), so its largest value lies on a table wavelength.
  double max_p = 0;
  for (const PiecewiseLinearSpectrum& s : camera.curves)
    for (std::size_t i = 0; i < s.wavelengths().size(); ++i)
      max_p = std::max(max_p, s.values()[i] / (basis == ResponseBasis::Energy ? s.wavelengths()[i] : 1.0));
  if (!(max_p > 0)) throw InputError(fmt::format("camera {}: its curves are zero everywhere", camera.name));

  // η_c(λ)·λ/(hc) = peak_qe/max_p · s_c(λ) · w(λ)·1e-9/(hc), with w = 1 (energy) or λ in nm (photon).
  const double scale = peak_qe / max_p * 1e-9 / (kPlanck * kLightSpeed);
  const PiecewiseLinearSpectrum weight = basis == ResponseBasis::Energy
                                             ? PiecewiseLinearSpectrum::constant(1.0)
                                             : PiecewiseLinearSpectrum({0.0, 1e5}, {0.0, 1e5});
  std::array<std::vector<double>, 3> q;
  for (std::size_t c = 0; c < 3; ++c) {
    q[c] = band_weights(bands, [&](double lo, double hi) {
      return scale * integral_of_product(transmittance, camera.curves[c], weight, lo, hi);
    });
  }
  return q;
}

namespace {

template <typename T>
std::vector<std::array<double, 3>> tristimulus_of(std::span<const T> spectra, const Bands& bands,
                                                  const CameraCurves& camera, std::size_t pixels) {
  const auto q = photon_response(bands, camera, ResponseBasis::Energy, 1.0, PiecewiseLinearSpectrum::constant(1.0));
  const std::size_t nb = bands.size();
  std::vector<std::array<double, 3>> out(pixels);
  for (std::size_t p = 0; p < pixels; ++p)
    for (int c = 0; c < 3; ++c) {
      double s = 0;
      for (std::size_t b = 0; b < nb; ++b) s += q[c][b] * spectra[p * nb + b];
      out[p][c] = s;
    }
  return out;
}

}  // namespace

std::vector<std::array<double, 3>> camera_tristimulus(std::span<const float> spectra, const Bands& bands,
                                                      const CameraCurves& camera, std::size_t pixels) {
  return tristimulus_of(spectra, bands, camera, pixels);
}
std::vector<std::array<double, 3>> camera_tristimulus(std::span<const double> spectra, const Bands& bands,
                                                      const CameraCurves& camera, std::size_t pixels) {
  return tristimulus_of(spectra, bands, camera, pixels);
}

}  // namespace ct::sensor
