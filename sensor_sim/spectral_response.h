// SPDX-License-Identifier: Apache-2.0
#pragma once
// Stage 3 of the sensor model (paper eq. 3, docs/sensor.md): a camera's spectral sensitivities and the
// electrons that each band of irradiance makes in each channel.
//
// Curves are relative. Their basis says what they are proportional to:
//  - Energy: response per unit of spectral power — how the CIE defines its observer and how pbrt-v4 uses
//    the shipped camera curves (pixel value = ∫ L(λ)·r̄(λ) dλ);
//  - Photon: quantum efficiency, response per photon.
// The quantum efficiency of channel c is then η_c(λ) = peak_qe · p_c(λ) / max p, with p_c = s_c (photon
// basis) or s_c(λ)/λ (energy basis), the maximum taken over all channels and table wavelengths; so peak_qe is
// the largest QE of any channel at any wavelength, and an energy-basis camera counts electrons in proportion
// to ∫ E(λ)·s_c(λ) dλ exactly.

#include <array>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/spectrum.h"

namespace ct::sensor {

enum class ResponseBasis { Energy, Photon };

struct CameraCurves {
  std::string name;                               // shipped camera, "cie1931", or the CSV file as given
  std::array<std::string, 3> channels;            // "r", "g", "b" (CIE: "X", "Y", "Z")
  std::array<PiecewiseLinearSpectrum, 3> curves;  // relative, zero outside their table

  // The wavelengths all three curves cover.
  double min_wavelength() const;
  double max_wavelength() const;
};

// The 17 shipped cameras (sensor_sim/cameras/, compiled in), e.g. "nikon_d850".
const std::vector<std::string>& shipped_cameras();

// A camera by name: a shipped camera, "cie1931" (the CIE 1931 2° observer x̄, ȳ, z̄: an ideal XYZ camera),
// or a CSV file (a name containing '/' or ending in ".csv") with the three `columns`. InputError naming
// `where` (e.g. "cam.json: spectral_response.camera") for an unknown camera or a bad file.
CameraCurves camera_curves(std::string_view camera, const std::array<std::string, 3>& columns,
                           const std::string& where);

// Whether the bands lie within the curves' table; if not, an InputError naming `file` and `where`.
void check_band_coverage(const Bands& bands, const CameraCurves& camera, const std::string& file);

// Electrons per band value of irradiance, per m² of pixel and per second:
//   Q[c][b] = ∫_band τ(λ)·η_c(λ)·λ/(h·c) dλ      (λ in m in λ/(hc); the integral over nm)
// so that a pixel of area A exposed for T to band irradiances E_b (W·m⁻²·nm⁻¹) collects
// μ_e,c = A·T·Σ_b E_b·Q[c][b] electrons. Exact for piecewise-linear τ and curves (bands are step functions).
std::array<std::vector<double>, 3> photon_response(const Bands& bands, const CameraCurves& camera, ResponseBasis basis,
                                                   double peak_qe, const PiecewiseLinearSpectrum& transmittance);

// Each pixel's tristimulus values through the camera's curves (photon_response in the energy basis, unit QE, no
// filter): `spectra` holds `pixels` × bands.size() values, [pixel][band]. What render comparisons (compare, plan's
// measured ΔE00) turn a spectral image into.
std::vector<std::array<double, 3>> camera_tristimulus(std::span<const float> spectra, const Bands& bands,
                                                      const CameraCurves& camera, std::size_t pixels);
std::vector<std::array<double, 3>> camera_tristimulus(std::span<const double> spectra, const Bands& bands,
                                                      const CameraCurves& camera, std::size_t pixels);

}  // namespace ct::sensor
