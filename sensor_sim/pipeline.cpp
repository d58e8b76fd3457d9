// SPDX-License-Identifier: Apache-2.0
#include "sensor_sim/pipeline.h"

#include <algorithm>
#include <cmath>
#include <future>
#include <optional>
#include <set>
#include <tuple>

#include <fmt/core.h>
#include <fmt/format.h>

#include "core/exr_vocabulary.h"
#include "core/cie.h"
#include "core/colour.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/json_input.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "core/spectral_exr.h"
#include "sensor_sim/adc.h"
#include "sensor_sim/cfa.h"
#include "sensor_sim/display.h"
#include "sensor_sim/display_rendering.h"
#include "sensor_sim/dng_writer.h"
#include "sensor_sim/exposure.h"
#include "sensor_sim/illumination.h"
#include "sensor_sim/linear_signal.h"
#include "sensor_sim/noise.h"
#include "sensor_sim/optics.h"
#include "sensor_sim/output.h"
#include "sensor_sim/rendering_intent.h"
#include "sensor_sim/sensor_rows.h"

namespace ct::sensor {
namespace {

namespace fs = std::filesystem;

// Input buffers of a block stay near this size (all layers read for it together; two blocks are in memory
// at a time, one being read while the other is processed).
constexpr std::size_t kBlockBudgetBytes = std::size_t{8} << 20;


// Stages 4–5 for sensor rows [y0, y1): what the sensor reads out (DN with the ADC, else e⁻), three channels
// per pixel — with a CFA, one per pixel demosaiced into three, or (`mosaic_only`, for a DNG) the mosaic itself.
std::vector<float> read_out_rows(const SensorRun& run, std::span<const float> linear, int y0, int y1,
                                 bool mosaic_only = false) {
  const SensorConfig& c = run.config;
  const std::size_t width = to_size(run.width());
  const std::size_t rows = to_size(y1 - y0);
  const auto value = [&](std::size_t r, std::size_t x, int channel) {
    const std::size_t y = to_size(y0) + r;
    const sensor::PixelSite site{y * width + x, static_cast<std::uint32_t>(y), static_cast<std::uint32_t>(x)};
    const double e = read_out_electrons(c.noise, c.full_well, run.exposure_s,
                                        linear[(r * width + x) * 3 + to_size(channel)], site, channel);
    return static_cast<float>(c.adc.enabled ? digitise(c.adc, e) : e);
  };
  std::vector<float> rgb(rows * width * 3);
  if (!c.cfa.enabled) {
    parallel_for(rows, run.threads, [&](std::size_t r) {
      for (std::size_t x = 0; x < width; ++x)
        for (int ch = 0; ch < 3; ++ch) rgb[(r * width + x) * 3 + to_size(ch)] = value(r, x, ch);
    });
    return rgb;
  }
  std::vector<float> mosaic(rows * width);
  parallel_for(rows, run.threads, [&](std::size_t r) {
    for (std::size_t x = 0; x < width; ++x)
      mosaic[r * width + x] = value(r, x, cfa_channel(c.cfa.pattern, static_cast<int>(x), y0 + static_cast<int>(r)));
  });
  if (mosaic_only) return mosaic;
  demosaic(mosaic, run.width(), static_cast<int>(rows), y0, c.cfa.pattern, c.cfa.demosaic, c.adc.bits, rgb);
  return rgb;
}

// A block's input as read from the file: the total for the block's rows and their demosaicing context, the
// components and the rendered object ids for its own rows.
struct BlockInput {
  int y0 = 0, y1 = 0;
  RowRange context{0, 0};
  std::vector<float> total;
  std::vector<std::vector<float>> components;
  std::vector<std::int32_t> ids;
};

// Stage 6 in place: the rendering intent on the signal above black.
void render_rows(const SensorRun& run, std::span<float> rgb) {
  const double black = run.config.adc.enabled ? run.config.adc.black_level_dn : 0.0;
  parallel_for(rgb.size() / 3, run.threads, [&](std::size_t p) {
    float* v = rgb.data() + 3 * p;
    const Eigen::Vector3d out = render(run.intent, Eigen::Vector3d(v[0] - black, v[1] - black, v[2] - black));
    for (int c = 0; c < 3; ++c) v[c] = static_cast<float>(out[c]);
  });
}

// The input's path components (S0 layers), in the order its chromatrace.components lists them (the reader
// sorts layers by name), then any it does not list.
std::pair<std::vector<std::string>, std::vector<const SpectralLayer*>> component_layers_of(
    const SpectralExrInfo& info) {
  std::vector<std::string> order;
  if (const auto it = info.metadata.find(exr::kComponentsAttribute); it != info.metadata.end())
    order = exr::parse_component_list(it->second);
  std::vector<const SpectralLayer*> layers;
  for (const std::string& name : order)
    if (const SpectralLayer* layer = info.find_layer(name, SpectralQuantity::S0)) layers.push_back(layer);
  for (const SpectralLayer& layer : info.layers)
    if (!layer.component.empty() && layer.quantity == SpectralQuantity::S0 &&
        std::find(layers.begin(), layers.end(), &layer) == layers.end())
      layers.push_back(&layer);
  std::vector<std::string> names;
  for (const SpectralLayer* layer : layers) names.push_back(layer->component);
  return {names, layers};
}

// Sensor rows per block: the input buffers near kBlockBudgetBytes, in whole ZIP chunks (at least one).
int block_rows(const SpectralExrInfo& info, std::size_t layers, int k, int requested, int height) {
  if (requested > 0) return std::min(requested, height);
  const std::size_t rendered_row = to_size(info.width) * info.bands.size() * sizeof(float) * layers;
  const std::size_t chunks = kBlockBudgetBytes / std::max<std::size_t>(1, rendered_row) / kChunkRows;
  const int rendered = static_cast<int>(std::clamp<std::size_t>(chunks, 1, to_size(height))) * kChunkRows;
  return std::clamp(rendered / k, 1, height);
}

// The object ids of the scene's lights: the names of chromatrace.scene's "lights" that chromatrace.objects
// gives an id. Metadata that is missing or not of that form names no light.
std::set<std::int32_t> light_object_ids(const SpectralExrInfo& info) {
  std::set<std::int32_t> ids;
  const auto it = info.metadata.find("chromatrace.scene");
  if (it == info.metadata.end() || info.object_names.empty()) return ids;
  const Json scene = Json::parse(it->second, nullptr, false);
  if (!scene.is_object() || !scene.contains("lights") || !scene["lights"].is_array()) return ids;
  for (const Json& light : scene["lights"])
    if (light.is_object() && light.contains("name") && light["name"].is_string())
      for (const auto& [id, name] : info.object_names)
        if (name == light["name"].get<std::string>()) ids.insert(id);
  return ids;
}

// Whether each pixel integrates light over an area (1) or samples it at a point (0): a point only when the
// scene was rendered with pixel_filter "point" (chromatrace.scene; the tracer and the add-on both honour it)
// and the sensor does not supersample. Only area pixels can mix two objects' colours at an edge
// (docs/analyze.md, mixed).
int pixel_area(const SpectralExrInfo& info, const SensorConfig& config) {
  if (config.pixel.supersample > 1) return 1;
  const auto scene = info.metadata.find("chromatrace.scene");
  if (scene == info.metadata.end()) return 1;
  const Json j = Json::parse(scene->second, nullptr, false);
  const bool point = j.is_object() && j.contains("render") && j["render"].is_object() && j["render"].contains("pixel_filter") &&
                     j["render"]["pixel_filter"] == "point";
  return point ? 0 : 1;
}

// What the camera did, as numeric attributes (docs/sensor.md, "Output"): the black level, the white level at
// which R, G, B clip, the mean dark signal and the read noise's σ, all in the units of R, G, B as the file
// stores them (TIFF/PNG codes); the ADC's bits; and whether noise and the ADC were on.
void camera_levels(const SensorConfig& c, double exposure_s, OutputLayout& layout) {
  for (const char* key : {"chromatrace.black_level", "chromatrace.white_level", "chromatrace.dark_signal",
                          "chromatrace.read_noise", "chromatrace.bits", "chromatrace.noise", "chromatrace.adc",
                          "chromatrace.pixel_area", "chromatrace.cfa", "chromatrace.curve_gamma", "chromatrace.curve_k",
                          "chromatrace.curve_srgb"})
    layout.attributes.erase(key);  // an input's own, passed through as text, would clash
  auto& number = layout.number_attributes;
  const double dark_e = c.noise.dark_current_e_per_s * exposure_s;
  const double read_e = c.noise.enabled ? c.noise.read_e : 0.0;
  if (c.rendering.enabled) {
    layout.attributes["chromatrace.signal"] = "normalised";
    number["chromatrace.black_level"] = 0.0;
    if (c.rendering.clip || c.rendering.output_bits) number["chromatrace.white_level"] = 1.0;
  } else if (c.adc.enabled) {
    const double k = c.adc.gain_dn_per_e;
    layout.attributes["chromatrace.signal"] = "DN";
    number["chromatrace.black_level"] = c.adc.black_level_dn;
    number["chromatrace.white_level"] =
        c.full_well.enabled ? std::min(c.adc.max_dn(), c.adc.black_level_dn + k * c.full_well.electrons)
                            : c.adc.max_dn();
    number["chromatrace.dark_signal"] = k * dark_e;
    number["chromatrace.read_noise"] = k * read_e;
  } else {
    layout.attributes["chromatrace.signal"] = "e-";
    number["chromatrace.black_level"] = 0.0;
    if (c.full_well.enabled) number["chromatrace.white_level"] = c.full_well.electrons;
    number["chromatrace.dark_signal"] = dark_e;
    number["chromatrace.read_noise"] = read_e;
  }
  // TIFF and PNG store R, G, B as codes round(value · code_scale): the levels are given in codes.
  if (layout.format != OutputFormat::Exr)
    for (auto& [key, value] : number) value *= layout.code_scale;
  // The response curve that encoded R, G, B from the normalised signal (1 = rendering.white_level), so that
  // the analyzer can undo it: I' = k·I^γ, or the sRGB curve. Without a rendering, R, G, B are linear.
  const bool srgb = c.rendering.enabled && c.rendering.curve == ResponseCurve::Srgb;
  const bool power = c.rendering.enabled && c.rendering.curve == ResponseCurve::Gamma;
  number["chromatrace.curve_gamma"] = power ? c.rendering.gamma : 1.0;
  number["chromatrace.curve_k"] = power ? c.rendering.k : 1.0;
  layout.integer_attributes["chromatrace.curve_srgb"] = srgb ? 1 : 0;
  layout.integer_attributes["chromatrace.bits"] = c.adc.enabled ? c.adc.bits : 0;
  layout.integer_attributes["chromatrace.noise"] = c.noise.enabled ? 1 : 0;
  layout.integer_attributes["chromatrace.adc"] = c.adc.enabled ? 1 : 0;
}

// chromatrace.units: what the numbers of R, G, B and of the linear layers are.
Json units_json(const SensorConfig& c, const RenderingIntent& intent) {
  const CameraCurves& camera = c.response.curves;
  Json rgb = {{"channels", camera.channels}};
  if (c.rendering.enabled) {
    rgb["unit"] = "normalised";
    rgb["white"] = intent.white;
    rgb["white_unit"] = c.adc.enabled ? "DN above black level" : "e-";
    rgb["curve"] = c.rendering.curve == ResponseCurve::Linear ? "linear"
                   : c.rendering.curve == ResponseCurve::Srgb
                       ? "sRGB"
                       : fmt::format("{:g} * I^{:g}", c.rendering.k, c.rendering.gamma);
    rgb["white_balance"] = {intent.gains[0], intent.gains[1], intent.gains[2]};
    rgb["quantised_bits"] = c.rendering.output_bits ? Json(*c.rendering.output_bits) : Json(nullptr);
  } else if (c.adc.enabled) {
    rgb["unit"] = "DN";
    rgb["black_level_dn"] = c.adc.black_level_dn;
    rgb["bits"] = c.adc.bits;
  } else {
    rgb["unit"] = "e-";
  }
  return {{"RGB", rgb},
          {"linear",
           {{"unit", "e-"},
            {"channels", camera.channels},
            {"what",
             "noise-free mean photo-electrons per sensor pixel: optics, exposure, pixel area and spectral "
             "response (stages 1-3); path components in the same unit"}}}};
}

// Whether the output is a PNG of the display rendering: a PNG is a picture for people, so without a rendering
// intent of the user's (rendering.enabled) it shows the display rendering, unless display.enabled is false,
// which asks for the camera's raw numbers.
bool display_png(const fs::path& output, const SensorConfig& c) {
  return output_format(output) == OutputFormat::Png && !c.rendering.enabled && c.display.enabled;
}

// The file's layout: TIFF/PNG need integer codes, which the final image has only with the rendering intent
// (values in [0, 1]), as the display rendering (PNG), or as digital numbers that fit the file.
// The smallest side of an image that raw readers take for a raw image (LibRaw's identify()).
constexpr int kMinDngSide = 22;

OutputLayout output_layout(const fs::path& output, const SensorConfig& c, int width, int height) {
  OutputLayout layout;
  layout.width = width;
  layout.height = height;
  layout.format = output_format(output);
  if (layout.format == OutputFormat::Exr) return layout;
  const std::string file = output.string();
  if (layout.format == OutputFormat::Dng) {
    if (!c.cfa.enabled || !c.adc.enabled || c.adc.bits > 16 || c.rendering.enabled)
      throw InputError(fmt::format(
          "{}: a DNG holds a Bayer mosaic of at most 16-bit digital numbers: it needs cfa.enabled and adc.enabled "
          "with adc.bits <= 16 and rendering.enabled false (are {}, {}, {}, {}); a camera preset sets them",
          file, c.cfa.enabled, c.adc.enabled, c.adc.bits, c.rendering.enabled));
    // LibRaw (and dcraw, which it follows) takes an image under 22 pixels a side for no raw image: such a DNG
    // would be one that `info` and `analyze` refuse.
    if (width < kMinDngSide || height < kMinDngSide)
      throw InputError(fmt::format("{}: a DNG of {} x {} pixels: raw readers (LibRaw, dcraw) read none under {} pixels "
                                   "a side; write a larger image, or an EXR, TIFF or PNG",
                                   file, width, height, kMinDngSide));
    layout.code_scale = 1.0;
    return layout;
  }
  if (display_png(output, c)) {
    layout.bits = 8;
    layout.code_scale = 255.0;
    layout.colour_space = "sRGB";
    return layout;
  }
  if (c.rendering.enabled) {
    layout.bits = c.rendering.output_bits.value_or(layout.format == OutputFormat::Png ? 8 : 16);
    layout.code_scale = std::ldexp(1.0, layout.bits) - 1.0;
    if (c.rendering.curve == ResponseCurve::Srgb) layout.colour_space = "sRGB";
    return layout;
  }
  if (!c.adc.enabled)
    throw InputError(
        fmt::format("{}: a TIFF or PNG holds integer codes, but the image is in electrons; enable "
                    "rendering (rendering.enabled) or the ADC (adc.enabled), write an EXR, or (PNG) leave "
                    "display.enabled on for the picture",
                    file));
  if (c.adc.bits > 16)
    throw InputError(
        fmt::format("{}: a TIFF or PNG holds at most 16-bit digital numbers, but adc.bits is {}; "
                    "enable rendering or write an EXR",
                    file, c.adc.bits));
  layout.bits = layout.format == OutputFormat::Png && c.adc.bits <= 8 ? 8 : 16;
  layout.code_scale = 1.0;  // digital numbers as they are
  return layout;
}

// The input's total radiance, checked against what the camera needs: emitted radiance (S0), bands the curves
// cover (unless told to treat them as zero), and room for the supersampling.
const SpectralLayer& total_radiance(const SpectralExrInfo& info, SensorConfig& config, bool lit) {
  const SpectralLayer* total = info.find_layer("", lit ? SpectralQuantity::T : SpectralQuantity::S0);
  if (lit && total == nullptr)
    throw InputError(fmt::format("{}: channels T.<λ>nm: missing; --illuminant lights a spectral reflectance image, and "
                                 "this file is {}",
                                 info.file, info.kind()));
  if (info.bispectral && (lit || info.find_layer("", SpectralQuantity::S0) == nullptr))
    throw InputError(fmt::format("{}: a bi-spectral (fluorescent) file: its re-radiation channels T.<λ>.<λ'>nm are not "
                                 "supported; the sensor takes emitted radiance (S0), or the plain reflectance T.<λ>nm "
                                 "lit with --illuminant, of a file without re-radiation",
                                 info.file));
  if (total == nullptr) {
    if (!info.spectral()) info.total();  // the reader's "no spectral channels" message
    throw InputError(
        fmt::format("{}: channels S0.<λ>nm: missing; the sensor needs emitted radiance, and this "
                    "file is {}{}",
                    info.file, info.kind(),
                    info.reflective ? " (light it with --illuminant NAME|FILE.csv)" : ""));
  }
  if (config.response.outside_curve == CurveOutside::Error)
    check_band_coverage(info.bands, config.response.curves, info.file);
  const int k = config.pixel.supersample;
  if (k > info.width || k > info.height)
    throw InputError(
        fmt::format("{}: pixel.supersample: {} x {} rendered pixels per sensor pixel do not fit the "
                    "{} x {} image",
                    info.file, k, k, info.width, info.height));
  if (info.width % k != 0 || info.height % k != 0)
    config.notes.push_back(fmt::format("supersample {}: the last {} column(s) and {} row(s) are dropped", k,
                                       info.width % k, info.height % k));
  return *total;
}

// Stage 1's cos⁴ needs the camera's field of view: from the renderer's chromatrace.camera or optics.fov_deg,
// else the fall-off is switched off, with a note either way.
std::optional<FieldOfView> cos4_field_of_view(const SpectralExrInfo& info, SensorConfig& config) {
  if (!config.optics.enabled || !config.optics.cos4) return std::nullopt;
  std::optional<FieldOfView> fov = field_of_view(info, config.optics.fov_deg);
  if (!fov) {
    config.optics.cos4 = false;
    config.notes.push_back(
        "cos4 fall-off off: the image has no chromatrace.camera and no optics.fov_deg (--fov-deg) was given");
  } else {
    config.notes.push_back(fmt::format("cos4 fall-off over a {:.6g} x {:.6g} degree field of view (from {})",
                                       fov->horizontal_deg, fov->vertical_deg, fov->source));
  }
  return fov;
}

// What the output says of itself: the renderer's description passed on, the sensor's configuration and units,
// the components, the display layer's making, and the camera's numbers (black, white, curve, pixel area).
void describe_output(const SpectralExrInfo& info, const SensorConfig& config, const SensorRun& run, const RunReport& report,
                     const std::vector<std::string>& components, bool want_display, bool picture,
                     Json display_description, double display_scale, OutputLayout& layout) {
  if (layout.format == OutputFormat::Exr) {
    layout.components = components;
    layout.object_ids = info.has_object_ids;
    layout.object_names = info.object_names;
    // The renderer's description of the scene and camera travels on with the image.
    for (const auto& [key, value] : info.metadata)
      if (key.starts_with("chromatrace.") && key != exr::kComponentsAttribute) layout.attributes[key] = value;
    layout.attributes["chromatrace.sensor"] = report.effective_config.dump(-1, ' ', false, kReplaceInvalidUtf8);
    layout.attributes["chromatrace.units"] = units_json(config, run.intent).dump(-1, ' ', false, kReplaceInvalidUtf8);
    if (!components.empty())
      layout.attributes[exr::kComponentsAttribute] = exr::component_list_text(components);
    if (want_display) {
      layout.display = true;
      display_description["scale"] = display_scale;
      layout.attributes["chromatrace.display"] = display_description.dump(-1, ' ', false, kReplaceInvalidUtf8);
    }
  }
  camera_levels(config, run.exposure_s, layout);
  layout.integer_attributes["chromatrace.pixel_area"] = pixel_area(info, config);
  layout.integer_attributes["chromatrace.cfa"] = config.cfa.enabled ? 1 : 0;
  if (picture) {  // the codes are the display rendering's (sRGB, 0…255), not the camera's numbers
    layout.attributes["chromatrace.signal"] = "display";
    layout.number_attributes = {{"chromatrace.black_level", 0.0}, {"chromatrace.white_level", 255.0},
                                {"chromatrace.curve_gamma", 1.0}, {"chromatrace.curve_k", 1.0}};
    layout.integer_attributes["chromatrace.curve_srgb"] = 1;
  }
}

// What a DNG says of the capture (docs/sensor.md, "DNG"): the levels as camera_levels() put them, the as-shot
// neutral (the camera's signal of a white lit by the scene illuminant, largest channel 1), the D65 colour matrix
// from the camera's curves, the exposure, the f-number and the camera's name.
DngMetadata dng_metadata(const SensorConfig& c, const SensorRun& run, const Bands& bands, const std::vector<double>& scene_light,
                         const OutputLayout& layout) {
  DngMetadata m;
  m.pattern = std::string(pattern_name(c.cfa.pattern));
  m.black_level = layout.number_attributes.at("chromatrace.black_level");
  m.white_level = layout.number_attributes.at("chromatrace.white_level");
  m.as_shot_neutral = dng_neutral(run.model.weights, scene_light);
  m.colour_matrix = dng_colour_matrix(run.model.weights, bands);
  m.colour_matrix_a = dng_colour_matrix(run.model.weights, bands, "A");
  // The temporal noise of the model (docs/sensor.md, stage 5) in values normalised to [0, 1] over D = white − black:
  // σ² = K·x/D (shot noise) + (K²(σ_read² + I_d·T) + 1/12)/D² (read noise, dark current shot noise, quantisation).
  if (c.noise.enabled && c.adc.enabled) {
    const double K = c.adc.gain_dn_per_e, D = m.white_level - m.black_level;
    const double dark_e2 = c.noise.read_e * c.noise.read_e + (c.noise.shot ? c.noise.dark_current_e_per_s * run.exposure_s : 0.0);
    m.noise_profile = std::pair{c.noise.shot ? K / D : 0.0, (K * K * dark_e2 + 1.0 / 12.0) / (D * D)};
  }
  m.camera = c.response.camera;
  m.exposure_s = run.exposure_s;
  if (c.optics.enabled) m.f_number = c.optics.f_number;
  return m;
}

// What a run reads and writes, decided from the input, the output's name and the settings before any pixel is
// read.
struct RunPlan {
  const SpectralLayer* total = nullptr;     // the radiance (or lit reflectance) the camera sees
  const SpectralLayer* emission = nullptr;  // the emitters' own layer, when the input has one
  std::vector<std::string> components;      // the path components carried through, and their layers
  std::vector<const SpectralLayer*> component_layers;
  std::set<std::int32_t> lights;  // the object ids of the scene's lights
  OutputLayout layout;
  std::optional<FieldOfView> fov;  // for stage 1's cos⁴ fall-off
  int k = 1;  // rendered pixels per sensor pixel, each way
  int rows_per_block = 1;
  std::size_t blocks = 0;
  bool exr = false, dng = false;
  bool auto_time = false;     // exposure.time_s "auto"
  bool picture = false;       // a PNG holding the display rendering
  bool want_display = false;  // a display rendering is written
  bool want_light = false;    // the scene illuminant is needed (the display's white balance, a DNG's neutral)
};

// Plans the run and sets up `run` at unit exposure (its threads, lighting and linear model). Refuses a Bayer
// mosaic on an image smaller than 2 × 2 sensor pixels.
RunPlan plan_run(const SpectralExrInfo& info, const fs::path& output, SensorConfig& config, const RunOptions& options,
                 SensorRun& run) {
  RunPlan plan;
  const bool lit = !options.illuminant.empty();
  plan.total = &total_radiance(info, config, lit);
  plan.k = config.pixel.supersample;
  plan.fov = cos4_field_of_view(info, config);
  // A lit reflectance image is one layer of light; emissive layers a file may hold beside it are not its light.
  if (!lit) std::tie(plan.components, plan.component_layers) = component_layers_of(info);

  run.threads = options.threads;
  if (lit) {
    const Illumination illumination = read_illumination(options.illuminant);
    run.lighting = band_averages(illumination.spectrum, info.bands);
    config.notes.push_back(fmt::format(
        "reflectance lit by {}: radiance = reflectance x the illuminant's band average, 1 W/m2/sr/nm at 560 nm",
        illumination.name));
  }
  run.model = linear_model(config, 1.0, info.bands, plan.fov, info.width, info.height);
  const int height = run.height();
  if (config.cfa.enabled && (run.width() < 2 || height < 2))
    throw InputError(
        fmt::format("{}: cfa.enabled: a Bayer mosaic needs at least 2 x 2 sensor pixels, the image "
                    "has {} x {}",
                    info.file, run.width(), height));
  plan.layout = output_layout(output, config, run.width(), height);
  plan.rows_per_block = block_rows(info, 1 + plan.components.size(), plan.k, options.block_rows, height);
  plan.blocks = to_size((height + plan.rows_per_block - 1) / plan.rows_per_block);
  plan.exr = plan.layout.format == OutputFormat::Exr;
  plan.dng = plan.layout.format == OutputFormat::Dng;
  plan.auto_time = !config.exposure.time_s;
  plan.picture = display_png(output, config);
  plan.want_display = (plan.exr && config.display.enabled) || plan.picture;
  plan.want_light = plan.want_display || plan.dng;  // a DNG's as-shot neutral is the scene illuminant's
  plan.emission = lit ? nullptr : info.find_layer("emission", SpectralQuantity::S0);
  plan.lights = light_object_ids(info);
  return plan;
}

// What the pass at unit exposure decided besides the exposure time.
struct Exposure {
  DisplayRendering display;  // its scale for the chosen exposure
  Json display_description;
  std::vector<double> scene_light;  // the display's white-balance illuminant, per band
  std::array<double, 3> glare{};    // veiling glare per channel at the chosen exposure
};

// One pass at unit exposure over the rows `surveyed`: the automatic exposure time (into `config`), the display's
// white balance and brightness, the veiling glare. Leaves `run` with its linear model at the chosen exposure.
Exposure expose(SpectralExrReader& reader, const RunPlan& plan, const std::vector<RowRange>& surveyed,
                const std::string& lit_by, SensorConfig& config, SensorRun& run, Progress& progress) {
  const SpectralExrInfo& info = reader.info();
  Survey survey;
  if (!surveyed.empty()) {
    run.config = config;
    const bool exclude = plan.auto_time && config.exposure.auto_exclude_emitters;
    survey = survey_image(reader, run, *plan.total, exclude || plan.want_light ? plan.emission : nullptr,
                          exclude || plan.want_light ? plan.lights : std::set<std::int32_t>{}, surveyed,
                          plan.want_light, progress);
  }
  if (plan.auto_time) config.exposure.time_s = auto_exposure(survey, config, info.file, config.notes);
  Exposure exposure;
  if (plan.want_light)
    exposure.display = display_rendering(survey, run.model, config, info, lit_by, run.lighting,
                                         exposure.display_description, config.notes, exposure.scene_light);
  // Veiling glare at unit exposure: flare × the image's mean signal, per channel.
  if (config.optics.flare > 0 && survey.pixels > 0)
    for (std::size_t c = 0; c < 3; ++c)
      exposure.glare[c] = config.optics.flare * survey.signal_sum[c] / double(survey.pixels);
  run.exposure_s = *config.exposure.time_s * config.exposure.scale;
  for (double& g : exposure.glare) g *= run.exposure_s;
  run.model = linear_model(config, run.exposure_s, info.bands, plan.fov, info.width, info.height);
  // The display's matrix and scale were found at unit exposure; the linear layer scales with the time. The
  // display is exposed like the camera's own picture: the time (chosen or automatic) is normalised away, an
  // over-exposure asked for with exposure.scale shows, clipped, as it would in the camera's JPEG.
  exposure.display.scale /= *config.exposure.time_s;
  return exposure;
}

// Reads, processes and writes the image block by block: the next block is read while this one is processed and
// written (one thread at a time uses the reader).
void write_blocks(SpectralExrReader& reader, const RunPlan& plan, const SensorRun& run, const Exposure& exposure,
                  SensorImageWriter& writer, Progress& progress) {
  const SpectralExrInfo& info = reader.info();
  const SensorConfig& config = run.config;
  const int k = plan.k, height = run.height(), rows_per_block = plan.rows_per_block;
  const bool exr = plan.exr, dng = plan.dng, picture = plan.picture;
  const OutputLayout& layout = plan.layout;
  const DisplayRendering& display = exposure.display;
  const auto read_block = [&](int y0) {
    BlockInput in;
    in.y0 = y0;
    in.y1 = std::min(height, y0 + rows_per_block);
    in.context = config.cfa.enabled ? demosaic_context(in.y0, in.y1, height) : RowRange{in.y0, in.y1};
    in.total = read_sensor_rows(reader, *plan.total, k, in.context.first, in.context.last, run.lighting);
    if (exr) {
      for (const SpectralLayer* layer : plan.component_layers)
        in.components.push_back(read_sensor_rows(reader, *layer, k, in.y0, in.y1, run.lighting));
      if (layout.object_ids) {
        in.ids.resize(to_size(k * (in.y1 - in.y0)) * to_size(info.width));
        reader.read_object_ids(k * in.y0, k * in.y1, in.ids);
      }
    }
    return in;
  };
  std::future<BlockInput> next = std::async(std::launch::async, read_block, 0);
  const std::size_t row_values = to_size(run.width()) * 3;
  for (;;) {
    const BlockInput in = next.get();
    if (in.y1 < height) next = std::async(std::launch::async, read_block, in.y1);
    const int y0 = in.y0, y1 = in.y1, e0 = in.context.first, e1 = in.context.last;
    std::vector<float> linear_ext = linear_rows(run, in.total, e0, e1);
    if (config.optics.flare > 0)  // the glare lands on every pixel: it is light, so the linear layer has it too
      for (std::size_t i = 0; i < linear_ext.size(); ++i) linear_ext[i] += static_cast<float>(exposure.glare[i % 3]);
    std::vector<float> image = read_out_rows(run, linear_ext, e0, e1, dng);
    const std::size_t own = to_size(y0 - e0) * row_values, own_size = to_size(y1 - y0) * row_values;
    const std::size_t image_values = dng ? 1 : 3;  // a DNG holds the mosaic: one value per pixel
    const std::size_t image_own = own / 3 * image_values, image_size = own_size / 3 * image_values;
    image.erase(image.begin() + static_cast<std::ptrdiff_t>(image_own + image_size), image.end());
    image.erase(image.begin(), image.begin() + static_cast<std::ptrdiff_t>(image_own));
    if (config.rendering.enabled) render_rows(run, image);
    if (picture)  // the picture for people in place of the raw numbers
      display_pixels(display, linear_ext.data() + own, image.size() / 3, run.threads, image.data());

    OutputRows rows;
    rows.rows = y1 - y0;
    rows.image = image;
    std::vector<std::vector<float>> component_rows;
    std::vector<std::int32_t> ids;
    std::vector<float> display_rows;
    if (exr) {
      rows.linear = std::span<const float>(linear_ext).subspan(own, own_size);
      if (layout.display) {
        display_rows.resize(own_size);
        display_pixels(display, linear_ext.data() + own, own_size / 3, run.threads, display_rows.data());
        rows.display = display_rows;
      }
      for (const std::vector<float>& spectral : in.components)
        component_rows.push_back(linear_rows(run, spectral, y0, y1));
      for (const auto& c : component_rows) rows.components.emplace_back(c);
      if (layout.object_ids) {
        ids = k == 1 ? in.ids : sensor_ids(in.ids, info.width, k, run.width(), y1 - y0);
        rows.object_ids = ids;
      }
    }
    writer.write_rows(rows);
    progress.advance();
    if (y1 == height) break;
  }
}

}  // namespace

void check_output_path(const fs::path& output, const std::vector<fs::path>& inputs) {
  check_output_file(output, inputs);  // first: "/dev/null: is a character device" says more than its format
  output_format(output);
}

RunReport simulate_sensor(const fs::path& input, const fs::path& output, SensorConfig config,
                          const RunOptions& options) {
  check_output_path(output, {input});
  SpectralExrReader reader(input);
  const SpectralExrInfo& info = reader.info();
  SensorRun run;
  RunPlan plan = plan_run(info, output, config, options, run);
  const std::vector<RowRange> surveyed =
      plan.auto_time || plan.want_light || config.optics.flare > 0
          ? survey_rows(plan.auto_time, plan.k, run.height(), plan.rows_per_block)
          : std::vector<RowRange>{};
  Progress progress("sensor", plan.blocks + surveyed.size(), options.progress);
  const Exposure exposure = expose(reader, plan, surveyed, options.illuminant, config, run, progress);

  Eigen::Vector3d gains = config.rendering.white_balance;
  if (config.rendering.white_balance_illuminant)
    gains =
        white_balance_gains(run.model.weights, info.bands, cie::illuminant(*config.rendering.white_balance_illuminant));
  run.intent = rendering_intent(config, gains);
  run.config = config;

  RunReport report;
  report.width = run.width();
  report.height = run.height();
  report.exposure_s = run.exposure_s;
  report.notes = config.notes;
  report.effective_config = config_json(config);
  describe_output(info, config, run, report, plan.components, plan.want_display, plan.picture,
                  exposure.display_description, exposure.display.scale, plan.layout);
  if (plan.dng) plan.layout.dng = dng_metadata(config, run, info.bands, exposure.scene_light, plan.layout);
  SensorImageWriter writer(output, plan.layout);
  write_blocks(reader, plan, run, exposure, writer, progress);
  writer.finish();
  return report;
}

}  // namespace ct::sensor
