#include "sensor_sim/pipeline.h"

#include <algorithm>
#include <cmath>
#include <future>
#include <map>
#include <optional>
#include <set>

#include <fmt/core.h>
#include <fmt/format.h>

#include "core/exr_vocabulary.h"
#include "core/cie.h"
#include "core/colour.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "core/spectral_exr.h"
#include "core/statistics.h"
#include "sensor_sim/adc.h"
#include "sensor_sim/cfa.h"
#include "sensor_sim/display.h"
#include "sensor_sim/dng_writer.h"
#include "sensor_sim/illumination.h"
#include "sensor_sim/linear_signal.h"
#include "sensor_sim/noise.h"
#include "sensor_sim/optics.h"
#include "sensor_sim/output.h"
#include "sensor_sim/rendering_intent.h"

namespace ct::sensor {
namespace {

namespace fs = std::filesystem;

// Input buffers of a block stay near this size (all layers read for it together; two blocks are in memory
// at a time, one being read while the other is processed).
constexpr std::size_t kBlockBudgetBytes = std::size_t{8} << 20;
// OpenEXR's ZIP compression packs 16 scanlines per chunk; blocks of whole chunks decompress each chunk once.
constexpr int kChunkRows = 16;

std::size_t to_size(int n) { return static_cast<std::size_t>(n); }

// What stays fixed over a run.
struct Run {
  SensorConfig config;
  LinearModel model;
  RenderingIntent intent;
  double exposure_s = 0;
  int threads = 0;
  std::vector<double> lighting;  // a reflectance image's illuminant per band (empty for radiance)
  int width() const { return model.width(); }
  int height() const { return model.height(); }
};

// Rows [y0, y1) of a layer read for sensor rows: the rendered rows [k·y0, k·y1). A NaN or infinite radiance
// has no photon count, and no surface emits or reflects a negative total radiance: both are bad input, named by
// channel and pixel. (A component may dip below zero by rounding where it was taken as a difference.) A
// reflectance image is lit: each band's value times the illuminant's band average `lighting` (illumination.h).
std::vector<float> read_sensor_rows(SpectralExrReader& reader, const SpectralLayer& layer, int k, int y0, int y1,
                                    const std::vector<double>& lighting) {
  const SpectralExrInfo& info = reader.info();
  std::vector<float> values(to_size(k * (y1 - y0)) * to_size(info.width) * layer.channels.size());
  reader.read_rows(layer, k * y0, k * y1, values);
  const bool total = layer.component.empty();
  const auto bad = std::find_if(values.begin(), values.end(),
                                [total](float v) { return !std::isfinite(v) || (total && v < 0.0f); });
  if (bad != values.end()) {
    const std::size_t i = static_cast<std::size_t>(bad - values.begin()), bands = layer.channels.size();
    const std::size_t pixel = i / bands;
    throw InputError(fmt::format("{}: channel {}: value {} at pixel ({}, {}) is {}", info.file,
                                 layer.channels[i % bands], *bad, pixel % to_size(info.width),
                                 to_size(k * y0) + pixel / to_size(info.width),
                                 std::isfinite(*bad) ? "negative: a radiance is >= 0" : "not finite"));
  }
  if (!lighting.empty())
    for (std::size_t i = 0; i < values.size(); ++i)
      values[i] = static_cast<float>(values[i] * lighting[i % lighting.size()]);
  return values;
}

// The linear signal of sensor rows [y0, y1) from their rendered rows, in parallel over rows.
std::vector<float> linear_rows(const Run& run, std::span<const float> spectral, int y0, int y1) {
  const std::size_t in_row = spectral.size() / to_size(y1 - y0);
  const std::size_t out_row = to_size(run.width()) * 3;
  std::vector<float> out(to_size(y1 - y0) * out_row);
  parallel_for(to_size(y1 - y0), run.threads, [&](std::size_t r) {
    const int y = y0 + static_cast<int>(r);
    linear_signal(run.model, spectral.subspan(r * in_row, in_row), y, y + 1,
                  std::span<float>(out).subspan(r * out_row, out_row));
  });
  return out;
}

// Stages 4–5 for sensor rows [y0, y1): what the sensor reads out (DN with the ADC, else e⁻), three channels
// per pixel — with a CFA, one per pixel demosaiced into three, or (`mosaic_only`, for a DNG) the mosaic itself.
std::vector<float> read_out_rows(const Run& run, std::span<const float> linear, int y0, int y1,
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
void render_rows(const Run& run, std::span<float> rgb) {
  const double black = run.config.adc.enabled ? run.config.adc.black_level_dn : 0.0;
  parallel_for(rgb.size() / 3, run.threads, [&](std::size_t p) {
    float* v = rgb.data() + 3 * p;
    const Eigen::Vector3d out = render(run.intent, Eigen::Vector3d(v[0] - black, v[1] - black, v[2] - black));
    for (int c = 0; c < 3; ++c) v[c] = static_cast<float>(out[c]);
  });
}

// The object id of each sensor pixel: the most frequent of its k×k rendered pixels (the smallest id on a tie).
std::vector<std::int32_t> sensor_ids(const std::vector<std::int32_t>& rendered, int in_width, int k, int width,
                                     int rows) {
  std::vector<std::int32_t> ids(to_size(width) * to_size(rows));
  std::map<std::int32_t, int> count;
  for (int r = 0; r < rows; ++r)
    for (int x = 0; x < width; ++x) {
      count.clear();
      for (int sy = 0; sy < k; ++sy)
        for (int sx = 0; sx < k; ++sx) ++count[rendered[to_size(r * k + sy) * to_size(in_width) + to_size(x * k + sx)]];
      ids[to_size(r) * to_size(width) + to_size(x)] =
          std::max_element(count.begin(), count.end(), [](auto& a, auto& b) { return a.second < b.second; })->first;
    }
  return ids;
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

// Sensor rows the display's exposure statistics sample: every row of small images; of larger ones the rows
// of every n-th group of 16 rendered rows (one ZIP chunk), n = ⌊groups / 8⌋, so that about 8 groups are read.
bool display_sample_row(int y, int k, int height) {
  const int groups = (k * height + kChunkRows - 1) / kChunkRows;
  const int stride = std::max(1, groups / 8);
  return (k * y / kChunkRows) % stride == 0;
}

// Sensor row ranges [first, last) to survey: every row in blocks when the exposure is automatic, else only the
// rows the display samples.
std::vector<RowRange> survey_rows(bool all_rows, int k, int height, int rows_per_block) {
  std::vector<RowRange> ranges;
  for (int y = 0; y < height;) {
    if (!all_rows && !display_sample_row(y, k, height)) {
      ++y;
      continue;
    }
    int end = y + 1;
    while (end < height && end - y < rows_per_block && (all_rows || display_sample_row(end, k, height))) ++end;
    ranges.push_back({y, end});
    y = end;
  }
  return ranges;
}

// What one pass over the image at unit exposure (T = 1 s) finds: the brightest channel of each pixel for the
// automatic exposure (surfaces and emitters apart), the emitters' spectra, and the camera signal of the
// surfaces in the display's sample rows.
struct Survey {
  std::vector<float> surfaces, emitters;  // brightest channel per pixel, e⁻/s
  std::map<std::int32_t, std::pair<std::vector<double>, std::size_t>> emitter_spectra;  // by id: Σ bands, pixels
  std::vector<float> display_samples;                                                  // surfaces, 3 per pixel
  std::array<double, 3> signal_sum{};  // Σ linear signal over every surveyed pixel, emitters included (veiling glare)
  std::size_t pixels = 0;
};

Survey survey_image(SpectralExrReader& reader, const Run& unit_run, const SpectralLayer& total,
                    const SpectralLayer* emission, const std::set<std::int32_t>& lights,
                    const std::vector<RowRange>& ranges, bool want_display, Progress& progress) {
  const SpectralExrInfo& info = reader.info();
  const int k = unit_run.model.supersample, width = unit_run.width(), height = unit_run.height();
  const std::size_t bands = info.bands.size();
  const bool ids_needed = info.has_object_ids && (!lights.empty() || want_display);
  Survey s;
  for (const RowRange& range : ranges) {
    const int y0 = range.first, y1 = range.last;
    const std::vector<float> total_spectra = read_sensor_rows(reader, total, k, y0, y1, unit_run.lighting);
    const std::vector<float> linear = linear_rows(unit_run, total_spectra, y0, y1);
    std::vector<float> emission_spectra, emission_linear;
    if (emission != nullptr) {
      emission_spectra = read_sensor_rows(reader, *emission, k, y0, y1, unit_run.lighting);
      emission_linear = linear_rows(unit_run, emission_spectra, y0, y1);
    }
    std::vector<std::int32_t> ids;
    if (ids_needed) {
      std::vector<std::int32_t> rendered(to_size(k * (y1 - y0)) * to_size(info.width));
      reader.read_object_ids(k * y0, k * y1, rendered);
      ids = k == 1 ? rendered : sensor_ids(rendered, info.width, k, width, y1 - y0);
    }
    for (int r = 0; r < y1 - y0; ++r) {
      const bool sampled = want_display && display_sample_row(y0 + r, k, height);
      for (int x = 0; x < width; ++x) {
        const std::size_t p = to_size(r) * to_size(width) + to_size(x);
        const float* c = linear.data() + 3 * p;
        const double sum = double(c[0]) + c[1] + c[2];
        for (int ch = 0; ch < 3; ++ch) s.signal_sum[to_size(ch)] += c[ch];
        ++s.pixels;
        bool emitter = false;
        if (!emission_linear.empty()) {
          const float* e = emission_linear.data() + 3 * p;
          emitter = sum > 0 && double(e[0]) + e[1] + e[2] > 0.5 * sum;
        }
        const std::int32_t id = ids.empty() ? -1 : ids[p];
        if (!ids.empty() && lights.contains(id)) emitter = true;
        (emitter ? s.emitters : s.surfaces).push_back(std::max({c[0], c[1], c[2]}));
        if (!want_display) continue;
        if (!emitter) {
          if (sampled) s.display_samples.insert(s.display_samples.end(), c, c + 3);
          continue;
        }
        // The emitter's spectrum as seen: its emission (or, without that layer, its total) over the k×k
        // rendered pixels.
        const std::vector<float>& spectra = emission_spectra.empty() ? total_spectra : emission_spectra;
        auto& [sum_bands, count] = s.emitter_spectra[id];
        sum_bands.resize(bands, 0.0);
        for (int sy = 0; sy < k; ++sy)
          for (int sx = 0; sx < k; ++sx) {
            const float* l = spectra.data() +
                             (to_size(r * k + sy) * to_size(info.width) + to_size(x * k + sx)) * bands;
            for (std::size_t b = 0; b < bands; ++b) sum_bands[b] += l[b] / double(k * k);
          }
        ++count;
      }
    }
    progress.advance();
  }
  return s;
}

// Exposure time that puts the `auto_percentile` of the brightest channel's noise-free signal of the surfaces
// (every pixel unless emitters are excluded, or when nothing else is in view) at `auto_level` of the
// saturation signal (1 e⁻ for an ideal sensor).
double auto_exposure(Survey& survey, const SensorConfig& config, const std::string& file,
                     std::vector<std::string>& notes) {
  const ExposureConfig& e = config.exposure;
  std::vector<float>& values = survey.surfaces;
  std::string what = "of the brightest channel";
  if (!e.auto_exclude_emitters || survey.surfaces.empty()) {
    if (e.auto_exclude_emitters && !survey.emitters.empty())
      notes.push_back("exposure.time_s \"auto\": every pixel is an emitter seen directly; the exposure is keyed on them");
    values.insert(values.end(), survey.emitters.begin(), survey.emitters.end());
  } else if (!survey.emitters.empty()) {
    what = fmt::format("of the brightest channel of the surfaces ({} emitter pixel{} left out)", survey.emitters.size(),
                       survey.emitters.size() == 1 ? "" : "s");
  }
  // The configuration says percentiles (0–100); core/statistics.h takes quantiles (0–1), by the same rule.
  const double per_second = quantile_in_place(values, e.auto_percentile / 100.0);
  if (!(per_second > 0))
    throw InputError(fmt::format("{}: exposure.time_s \"auto\": the image is black (its {}th percentile is {})", file,
                                 e.auto_percentile, per_second));
  const double time = e.auto_level * saturation_electrons(config).value_or(1.0) / per_second;
  notes.push_back(fmt::format(
      "exposure.time_s \"auto\": {:.6g} s puts the {:g}th percentile {} at {:g} of {}", time, e.auto_percentile, what,
      e.auto_level,
      saturation_electrons(config) ? fmt::format("saturation ({:.6g} e-)", *saturation_electrons(config))
                                   : std::string("1 e- (the ideal sensor does not saturate)")));
  return time;
}

// The display rendering at unit exposure: the white balance's illuminant (display.white_balance, else the
// illuminant lighting a reflectance image, else the brightest emitter the survey saw, else D65), its matrix, and
// the scale that puts the display.percentile of the surfaces' brightest linear sRGB channel at display.level.
// `description` says what was chosen, as JSON; `scene_light` is the illuminant's band values.
DisplayRendering display_rendering(const Survey& survey, const LinearModel& unit_model, const SensorConfig& config,
                                   const SpectralExrInfo& info, const std::string& lit_by, const std::vector<double>& lighting,
                                   Json& description, std::vector<std::string>& notes, std::vector<double>& scene_light) {
  const Bands& bands = info.bands;
  std::vector<double> light;
  std::string source;
  if (config.display.white_balance) {
    light = band_averages(cie::illuminant(*config.display.white_balance), bands);
    source = fmt::format("illuminant {} (display.white_balance)", *config.display.white_balance);
  } else if (!lighting.empty()) {
    light = lighting;
    source = fmt::format("illuminant {} lighting the reflectance image (--illuminant)", lit_by);
  } else {
    const std::array<std::vector<double>, 3> xyz = xyz_band_weights(bands);
    double best = 0;
    for (const auto& [id, entry] : survey.emitter_spectra) {
      double y = 0;
      for (std::size_t b = 0; b < bands.size(); ++b) y += entry.first[b] / double(entry.second) * xyz[1][b];
      if (y > best) {
        best = y;
        light = entry.first;
        for (double& v : light) v /= double(entry.second);
        const auto name = info.object_names.find(id);
        source = id < 0 ? fmt::format("the brightest emitter in view ({} pixels)", entry.second)
                        : fmt::format("the brightest emitter in view, object {}{} ({} pixels)", id,
                                      name == info.object_names.end() ? "" : " (" + name->second + ")", entry.second);
      }
    }
  }
  DisplayRendering d;
  const auto matrix_for = [&](const std::vector<double>& l) { return display_matrix(unit_model.weights, bands, l); };
  try {
    if (light.empty()) throw InputError("no emitter in view");
    d.matrix = matrix_for(light);
  } catch (const InputError& e) {
    if (!light.empty()) notes.push_back(fmt::format("display: white balance on D65: {} ({})", source, e.what()));
    light = band_averages(cie::illuminant("D65"), bands);
    source = "illuminant D65 (no emitter in view)";
    d.matrix = matrix_for(light);
  }
  std::vector<float> brightest;
  for (std::size_t i = 0; i + 2 < survey.display_samples.size(); i += 3) {
    const Eigen::Vector3d c(survey.display_samples[i], survey.display_samples[i + 1], survey.display_samples[i + 2]);
    brightest.push_back(static_cast<float>(std::max(0.0, (d.matrix * c).maxCoeff())));
  }
  const double p = brightest.empty() ? 0.0 : quantile_in_place(brightest, config.display.percentile / 100.0);
  if (p > 0) {
    d.scale = config.display.level / p;
  } else {
    d.scale = 1.0;
    notes.push_back("display: the surfaces are black; the display layer's exposure is not normalised");
  }
  Json matrix = Json::array();
  for (int r = 0; r < 3; ++r) matrix.push_back({d.matrix(r, 0), d.matrix(r, 1), d.matrix(r, 2)});
  const Eigen::Vector3d white = white_response(unit_model.weights, light);
  description = {{"channels", {"display.R", "display.G", "display.B"}},
                 {"encoding", "sRGB (IEC 61966-2-1), clamped to [0, 1]"},
                 {"white_balance", source},
                 {"white_response", {white[0], white[1], white[2]}},
                 {"percentile", config.display.percentile},
                 {"level", config.display.level},
                 {"samples", brightest.size()}};
  description["matrix"] = matrix;  // camera e⁻ → linear sRGB, before the scale
  scene_light = light;
  return d;
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
void describe_output(const SpectralExrInfo& info, const SensorConfig& config, const Run& run, const RunReport& report,
                     const std::vector<std::string>& components, bool want_display, bool picture,
                     Json display_description, double display_scale, OutputLayout& layout) {
  if (layout.format == OutputFormat::Exr) {
    layout.components = components;
    layout.object_ids = info.has_object_ids;
    layout.object_names = info.object_names;
    // The renderer's description of the scene and camera travels on with the image.
    for (const auto& [key, value] : info.metadata)
      if (key.starts_with("chromatrace.") && key != exr::kComponentsAttribute) layout.attributes[key] = value;
    layout.attributes["chromatrace.sensor"] = report.effective_config.dump();
    layout.attributes["chromatrace.units"] = units_json(config, run.intent).dump();
    if (!components.empty())
      layout.attributes[exr::kComponentsAttribute] = exr::component_list_text(components);
    if (want_display) {
      layout.display = true;
      display_description["scale"] = display_scale;
      layout.attributes["chromatrace.display"] = display_description.dump();
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
DngMetadata dng_metadata(const SensorConfig& c, const Run& run, const Bands& bands, const std::vector<double>& scene_light,
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

// The display rendering of `count` pixels of linear signal from `linear`, into `out`.
void display_pixels(const DisplayRendering& display, const float* linear, std::size_t count, int threads, float* out) {
  parallel_for(count, threads, [&](std::size_t p) {
    const float* c = linear + 3 * p;
    const Eigen::Vector3d v = display_value(display, Eigen::Vector3d(c[0], c[1], c[2]));
    for (int ch = 0; ch < 3; ++ch) out[3 * p + to_size(ch)] = static_cast<float>(v[ch]);
  });
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
  const bool lit = !options.illuminant.empty();
  const SpectralLayer* total = &total_radiance(info, config, lit);
  const int k = config.pixel.supersample;
  const std::optional<FieldOfView> fov = cos4_field_of_view(info, config);

  // A lit reflectance image is one layer of light; emissive layers a file may hold beside it are not its light.
  const auto component_list = lit ? decltype(component_layers_of(info)){} : component_layers_of(info);
  const std::vector<std::string>& components = component_list.first;
  const std::vector<const SpectralLayer*>& component_layers = component_list.second;

  Run run;
  run.threads = options.threads;
  if (lit) {
    const Illumination illumination = read_illumination(options.illuminant);
    run.lighting = band_averages(illumination.spectrum, info.bands);
    config.notes.push_back(fmt::format(
        "reflectance lit by {}: radiance = reflectance x the illuminant's band average, 1 W/m2/sr/nm at 560 nm",
        illumination.name));
  }
  run.model = linear_model(config, 1.0, info.bands, fov, info.width, info.height);
  const int height = run.height();
  if (config.cfa.enabled && (run.width() < 2 || height < 2))
    throw InputError(
        fmt::format("{}: cfa.enabled: a Bayer mosaic needs at least 2 x 2 sensor pixels, the image "
                    "has {} x {}",
                    info.file, run.width(), height));
  OutputLayout layout = output_layout(output, config, run.width(), height);
  const std::size_t layers_per_block = 1 + components.size();
  const int rows_per_block = block_rows(info, layers_per_block, k, options.block_rows, height);
  const std::size_t blocks = to_size((height + rows_per_block - 1) / rows_per_block);
  const bool exr = layout.format == OutputFormat::Exr;
  const bool dng = layout.format == OutputFormat::Dng;
  const bool auto_time = !config.exposure.time_s;
  const bool picture = display_png(output, config);  // the PNG holds the display rendering
  const bool want_display = (exr && config.display.enabled) || picture;
  const bool want_light = want_display || dng;  // a DNG's as-shot neutral is the scene illuminant's
  const SpectralLayer* emission = lit ? nullptr : info.find_layer("emission", SpectralQuantity::S0);
  const std::set<std::int32_t> lights = light_object_ids(info);
  const std::vector<RowRange> surveyed =
      auto_time || want_light || config.optics.flare > 0 ? survey_rows(auto_time, k, height, rows_per_block)
                                                            : std::vector<RowRange>{};
  Progress progress("sensor", blocks + surveyed.size(), options.progress);

  // One pass at unit exposure: the automatic exposure time, the display's white balance and brightness.
  Survey survey;
  if (!surveyed.empty()) {
    run.config = config;
    const bool exclude = auto_time && config.exposure.auto_exclude_emitters;
    survey = survey_image(reader, run, *total, exclude || want_light ? emission : nullptr,
                          exclude || want_light ? lights : std::set<std::int32_t>{}, surveyed, want_light, progress);
  }
  if (auto_time) config.exposure.time_s = auto_exposure(survey, config, info.file, config.notes);
  Json display_description;
  DisplayRendering display;
  std::vector<double> scene_light;
  if (want_light)
    display = display_rendering(survey, run.model, config, info, options.illuminant, run.lighting, display_description,
                                config.notes, scene_light);
  // Veiling glare at unit exposure: flare × the image's mean signal, per channel.
  std::array<double, 3> glare{};
  if (config.optics.flare > 0 && survey.pixels > 0)
    for (std::size_t c = 0; c < 3; ++c) glare[c] = config.optics.flare * survey.signal_sum[c] / double(survey.pixels);
  survey = Survey{};
  run.exposure_s = *config.exposure.time_s * config.exposure.scale;
  for (double& g : glare) g *= run.exposure_s;
  run.model = linear_model(config, run.exposure_s, info.bands, fov, info.width, info.height);
  // The display's matrix and scale were found at unit exposure; the linear layer scales with the time. The
  // display is exposed like the camera's own picture: the time (chosen or automatic) is normalised away, an
  // over-exposure asked for with exposure.scale shows, clipped, as it would in the camera's JPEG.
  display.scale /= *config.exposure.time_s;

  Eigen::Vector3d gains = config.rendering.white_balance;
  if (config.rendering.white_balance_illuminant)
    gains =
        white_balance_gains(run.model.weights, info.bands, cie::illuminant(*config.rendering.white_balance_illuminant));
  run.intent = rendering_intent(config, gains);
  run.config = config;

  RunReport report;
  report.width = run.width();
  report.height = height;
  report.exposure_s = run.exposure_s;
  report.notes = config.notes;
  report.effective_config = config_json(config);
  describe_output(info, config, run, report, components, want_display, picture, display_description, display.scale, layout);
  if (dng) layout.dng = dng_metadata(config, run, info.bands, scene_light, layout);
  SensorImageWriter writer(output, layout);

  const auto read_block = [&](int y0) {
    BlockInput in;
    in.y0 = y0;
    in.y1 = std::min(height, y0 + rows_per_block);
    in.context = config.cfa.enabled ? demosaic_context(in.y0, in.y1, height) : RowRange{in.y0, in.y1};
    in.total = read_sensor_rows(reader, *total, k, in.context.first, in.context.last, run.lighting);
    if (exr) {
      for (const SpectralLayer* layer : component_layers)
        in.components.push_back(read_sensor_rows(reader, *layer, k, in.y0, in.y1, run.lighting));
      if (layout.object_ids) {
        in.ids.resize(to_size(k * (in.y1 - in.y0)) * to_size(info.width));
        reader.read_object_ids(k * in.y0, k * in.y1, in.ids);
      }
    }
    return in;
  };
  // The next block is read while this one is processed and written (one thread at a time uses the reader).
  std::future<BlockInput> next = std::async(std::launch::async, read_block, 0);
  const std::size_t row_values = to_size(run.width()) * 3;
  for (;;) {
    const BlockInput in = next.get();
    if (in.y1 < height) next = std::async(std::launch::async, read_block, in.y1);
    const int y0 = in.y0, y1 = in.y1, e0 = in.context.first, e1 = in.context.last;
    std::vector<float> linear_ext = linear_rows(run, in.total, e0, e1);
    if (config.optics.flare > 0)  // the glare lands on every pixel: it is light, so the linear layer has it too
      for (std::size_t i = 0; i < linear_ext.size(); ++i) linear_ext[i] += static_cast<float>(glare[i % 3]);
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
  writer.finish();
  return report;
}

}  // namespace ct::sensor
