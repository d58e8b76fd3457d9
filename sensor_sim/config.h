// SPDX-License-Identifier: Apache-2.0
#pragma once
// The sensor simulator's settings (docs/sensor.md): one plain struct per stage of the sensor model, presets,
// and reading them from JSON (`chromatrace-sensor/1`).
//
// A configuration is a preset (default `ideal`, the defaults below) patched by JSON documents — a config
// file, then command-line overrides — as JSON Merge Patches (RFC 7386). Unknown keys are errors, and every
// error names the document and the JSON path, e.g. "cam.json: adc.bits: must be in [1, 32], got 40".

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "core/json_input.h"
#include "core/spectrum.h"
#include "sensor_sim/spectral_response.h"

namespace ct::sensor {

inline constexpr std::string_view kSensorFormat = "chromatrace-sensor/1";

// Stage 1 (paper eq. 2): E = (π/4)·(1/N)²·cos⁴α·τ(λ)·L. Off: E = L × 1 sr.
struct OpticsConfig {
  bool enabled = true;
  double f_number = 4.0;
  bool cos4 = true;
  // Horizontal field of view for cos⁴ when the image's header has no camera (chromatrace.camera).
  std::optional<double> fov_deg;
  // Lens transmittance τ(λ); none: 1. `transmittance_spec` is the JSON it came from (for the record).
  std::optional<PiecewiseLinearSpectrum> transmittance;
  Json transmittance_spec;
  // Veiling glare: light scattered inside the lens spreads over the whole sensor. Modelled as a uniform
  // irradiance of `flare` × the image's mean (the veiling glare index of ISO 9358; 0.5–3 % for real lenses).
  double flare = 0.0;
};

// Stage 2: exposure time T. Auto: the time that puts the `auto_percentile` of the brightest channel's
// noise-free signal at `auto_level` × the saturation signal (docs/sensor.md); `scale` multiplies either.
struct ExposureConfig {
  std::optional<double> time_s = 0.01;  // nullopt: auto
  double scale = 1.0;
  double auto_percentile = 99.0;
  double auto_level = 0.9;
  // Leave emitters seen directly out of the percentile: pixels whose `emission` component carries more than
  // half of their signal, or whose object id names a light of the scene (docs/sensor.md).
  bool auto_exclude_emitters = true;
};

// Stage 2: pixel area A = pitch² × fill factor; `supersample` k averages k×k rendered pixels into one.
struct PixelConfig {
  double pitch_um = 5.0;
  double fill_factor = 1.0;
  int supersample = 1;

  double area_m2() const { return pitch_um * pitch_um * 1e-12 * fill_factor; }
};

// Stage 3 (paper eq. 3): η_c(λ) = peak_qe × the camera's relative curve (see spectral_response.h).
enum class CurveOutside { Error, Zero };
struct SpectralResponseConfig {
  std::string camera = "cie1931";                        // a shipped camera, "cie1931", or a CSV file
  std::array<std::string, 3> columns = {"r", "g", "b"};  // of a CSV file
  ResponseBasis basis = ResponseBasis::Energy;
  double peak_qe = 1.0;
  CurveOutside outside_curve = CurveOutside::Error;  // bands beyond the curve's table: an error, or zero
  CameraCurves curves;                               // resolved from the above
};

// Stage 4: a Bayer colour filter array and OpenCV's demosaicing of the digital numbers.
enum class BayerPattern { RGGB, BGGR, GRBG, GBRG };
enum class DemosaicMethod { Bilinear, Vng, EdgeAware };
struct CfaConfig {
  bool enabled = false;
  BayerPattern pattern = BayerPattern::RGGB;
  DemosaicMethod demosaic = DemosaicMethod::Bilinear;
};

// Stage 5 (EMVA 1288). Off: every pixel takes its expected value (dark current's mean included).
struct NoiseConfig {
  bool enabled = false;
  bool shot = true;                   // Poisson photon and dark-current shot noise
  double dark_current_e_per_s = 0.0;  // mean dark electrons per pixel and second
  double read_e = 0.0;                // σ of the Normal read noise, e⁻
  double dsnu_e = 0.0;                // σ of the fixed dark-signal offset per pixel, e⁻
  double prnu = 0.0;                  // σ of the fixed relative gain per pixel (0.01 = 1 %)
  double dsnu_row_e = 0.0, dsnu_column_e = 0.0;  // σ of a fixed offset shared by a row, by a column, e⁻
  double prnu_row = 0.0, prnu_column = 0.0;      // σ of a fixed relative gain shared by a row, by a column
  std::uint64_t seed = 0;             // temporal noise: one frame
  std::uint64_t pattern_seed = 0;     // DSNU and PRNU: one sensor
};

struct FullWellConfig {
  bool enabled = false;
  double electrons = 1e5;  // saturation capacity μ_e,sat
};

// y = round(K·e + black) clipped to [0, 2^bits − 1].
struct AdcConfig {
  bool enabled = false;
  double gain_dn_per_e = 1.0;  // K
  double black_level_dn = 0.0;
  int bits = 16;

  double max_dn() const;  // 2^bits − 1
};

// Stage 6: white balance, colour matrix, response curve, clipping and 8/16-bit quantisation, on the signal
// normalised by `white_level` (default: the saturation signal, see white_level()).
enum class ResponseCurve { Linear, Gamma, Srgb };
struct RenderingConfig {
  bool enabled = false;
  std::optional<std::string> white_balance_illuminant;  // gains that make this illuminant neutral
  Eigen::Vector3d white_balance = Eigen::Vector3d::Ones();
  Eigen::Matrix3d colour_matrix = Eigen::Matrix3d::Identity();
  std::optional<double> white_level;  // signal that maps to 1 (DN above black, or e⁻ without an ADC)
  ResponseCurve curve = ResponseCurve::Linear;
  double gamma = 1.0;  // I' = k·I^γ
  double k = 1.0;
  bool clip = true;                // to [0, 1]
  std::optional<int> output_bits;  // 8 or 16: quantise the encoded value
};

// The display layer of the EXR output (display.R/G/B, docs/sensor.md): the noise-free linear signal rendered
// for people — white balance, a camera→sRGB matrix fitted to the camera's curves, exposure normalised on the
// surfaces, the sRGB curve. It changes nothing else in the output.
struct DisplayConfig {
  bool enabled = true;
  // The illuminant the picture is balanced for: none ("auto") = the brightest emitter seen in the image,
  // else D65; or a CIE illuminant's name.
  std::optional<std::string> white_balance;
  double percentile = 99.0;  // of the surfaces' brightest display channel …
  double level = 0.9;        // … put at this linear value
};

struct SensorConfig {
  std::string preset = "ideal";
  std::string description;
  OpticsConfig optics;
  ExposureConfig exposure;
  PixelConfig pixel;
  SpectralResponseConfig response;
  CfaConfig cfa;
  NoiseConfig noise;
  FullWellConfig full_well;
  AdcConfig adc;
  RenderingConfig rendering;
  DisplayConfig display;
  std::vector<std::string> notes;  // decisions taken for an image (written with the output)
};

// The signal at which the sensor saturates, in electrons: the full well and the ADC's top code, whichever
// comes first; none (an ideal sensor) when neither is on.
std::optional<double> saturation_electrons(const SensorConfig& config);
// The signal the rendering intent maps to 1, in the units it receives (DN above black with an ADC, else
// e⁻): rendering.white_level, else the saturation signal, else 1.
double white_level(const SensorConfig& config);

// ---- Presets and reading ----------------------------------------------------------------------------

const std::vector<std::string>& preset_names();
// A preset as the JSON patch it applies to the defaults (`ideal` is {}); InputError for an unknown name.
const Json& preset(std::string_view name);

// One JSON document patching the configuration, with where it came from for messages (a file name, or an
// option such as "--exposure-s").
struct ConfigPatch {
  Json patch;
  std::string source;
};

// A patch whose relative file paths (a CSV camera, a transmittance CSV) are relative to `directory`: they are
// rewritten relative to the working directory, so that patches from different places can be merged.
ConfigPatch config_patch(Json patch, std::string source, const std::filesystem::path& directory);
// Reads a config file as a patch; paths in it are relative to the file.
ConfigPatch read_config_patch(const std::filesystem::path& file);

// Applies the patches in order onto the preset (the last "preset" key given, else `ideal`), validating after
// each so that an error names the document that caused it.
SensorConfig resolve_config(const std::vector<ConfigPatch>& patches);

// Parses a whole document (defaults for absent keys); used by resolve_config and by check-scene for a
// series' sensor settings.
SensorConfig parse_config(const JsonNode& root);

// The effective configuration, every key spelled out; parse_config of it gives the same configuration.
Json config_json(const SensorConfig& config);

// "RGGB", "bilinear", "gamma", … as the JSON spells them.
std::string_view pattern_name(BayerPattern pattern);
std::string_view demosaic_name(DemosaicMethod method);
// The largest ADC resolution a demosaicing method accepts (OpenCV's, sensor_sim/cfa.h).
int demosaic_max_bits(DemosaicMethod method);

}  // namespace ct::sensor
