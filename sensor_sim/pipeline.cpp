#include "sensor_sim/pipeline.h"

#include <algorithm>
#include <cmath>
#include <future>
#include <map>
#include <optional>

#include <fmt/core.h>
#include <fmt/format.h>

#include "core/cie.h"
#include "core/error.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "core/spectral_exr.h"
#include "sensor_sim/adc.h"
#include "sensor_sim/cfa.h"
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
  int width() const { return model.width(); }
  int height() const { return model.height(); }
};

// Rows [y0, y1) of a layer read for sensor rows: the rendered rows [k·y0, k·y1). A NaN or infinite radiance
// has no photon count: it is bad input, named by channel and pixel.
std::vector<float> read_sensor_rows(SpectralExrReader& reader, const SpectralLayer& layer, int k, int y0, int y1) {
  const SpectralExrInfo& info = reader.info();
  std::vector<float> values(to_size(k * (y1 - y0)) * to_size(info.width) * layer.channels.size());
  reader.read_rows(layer, k * y0, k * y1, values);
  const auto bad = std::find_if(values.begin(), values.end(), [](float v) { return !std::isfinite(v); });
  if (bad != values.end()) {
    const std::size_t i = static_cast<std::size_t>(bad - values.begin()), bands = layer.channels.size();
    const std::size_t pixel = i / bands;
    throw InputError(fmt::format("{}: channel {}: value {} at pixel ({}, {}) is not finite", info.file,
                                 layer.channels[i % bands], *bad, pixel % to_size(info.width),
                                 to_size(k * y0) + pixel / to_size(info.width)));
  }
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
// per pixel — with a CFA, one per pixel demosaiced into three.
std::vector<float> read_out_rows(const Run& run, std::span<const float> linear, int y0, int y1) {
  const SensorConfig& c = run.config;
  const std::size_t width = to_size(run.width());
  const std::size_t rows = to_size(y1 - y0);
  const auto value = [&](std::size_t r, std::size_t x, int channel) {
    const std::uint64_t pixel = (to_size(y0) + r) * width + x;
    const double e = read_out_electrons(c.noise, c.full_well, run.exposure_s,
                                        linear[(r * width + x) * 3 + to_size(channel)], pixel, channel);
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
  if (const auto it = info.metadata.find("chromatrace.components"); it != info.metadata.end())
    for (std::size_t start = 0; start <= it->second.size();) {
      const std::size_t comma = std::min(it->second.find(',', start), it->second.size());
      order.push_back(it->second.substr(start, comma - start));
      start = comma + 1;
    }
  std::vector<const SpectralLayer*> layers;
  for (const std::string& name : order)
    if (const SpectralLayer* layer = info.find_layer(name, SpectralQuantity::S0); layer && !name.empty())
      layers.push_back(layer);
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

// Exposure time that puts the `percentile` of the brightest channel's noise-free signal at `level` of the
// saturation signal (1 e⁻ for an ideal sensor): one pass over the total with T = 1 s.
double auto_exposure(SpectralExrReader& reader, const Run& unit_run, const SpectralLayer& total, int rows_per_block,
                     Progress& progress) {
  const ExposureConfig& e = unit_run.config.exposure;
  const int height = unit_run.height(), k = unit_run.model.supersample;
  std::vector<float> brightest;
  brightest.reserve(to_size(unit_run.width()) * to_size(height));
  for (int y0 = 0; y0 < height; y0 += rows_per_block) {
    const int y1 = std::min(height, y0 + rows_per_block);
    const std::vector<float> linear = linear_rows(unit_run, read_sensor_rows(reader, total, k, y0, y1), y0, y1);
    for (std::size_t p = 0; p < linear.size(); p += 3)
      brightest.push_back(std::max({linear[p], linear[p + 1], linear[p + 2]}));
    progress.advance();
  }
  const std::size_t rank =
      static_cast<std::size_t>(std::floor(e.auto_percentile / 100.0 * static_cast<double>(brightest.size() - 1)));
  std::nth_element(brightest.begin(), brightest.begin() + static_cast<std::ptrdiff_t>(rank), brightest.end());
  const double per_second = brightest[rank];
  if (!(per_second > 0))
    throw InputError(fmt::format("{}: exposure.time_s \"auto\": the image is black (its {}th percentile is {})",
                                 reader.info().file, e.auto_percentile, per_second));
  return e.auto_level * saturation_electrons(unit_run.config).value_or(1.0) / per_second;
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

// The file's layout: TIFF/PNG need integer codes, which the final image has only with the rendering intent
// (values in [0, 1]) or as digital numbers that fit the file.
OutputLayout output_layout(const fs::path& output, const SensorConfig& c, int width, int height) {
  OutputLayout layout;
  layout.width = width;
  layout.height = height;
  layout.format = output_format(output);
  if (layout.format == OutputFormat::Exr) return layout;
  const std::string file = output.string();
  if (c.rendering.enabled) {
    layout.bits = c.rendering.output_bits.value_or(layout.format == OutputFormat::Png ? 8 : 16);
    layout.code_scale = std::ldexp(1.0, layout.bits) - 1.0;
    if (c.rendering.curve == ResponseCurve::Srgb) layout.colour_space = "sRGB";
    return layout;
  }
  if (!c.adc.enabled)
    throw InputError(
        fmt::format("{}: a TIFF or PNG holds integer codes, but the image is in electrons; enable "
                    "rendering (rendering.enabled) or the ADC (adc.enabled), or write an EXR",
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

}  // namespace

void check_output_path(const fs::path& output) {
  output_format(output);
  if (output.filename().empty()) throw InputError(fmt::format("{}: no file name", output.string()));
  const fs::path parent = fs::absolute(output).parent_path();
  if (!fs::is_directory(parent))
    throw InputError(fmt::format("{}: directory {} does not exist", output.string(), parent.string()));
}

RunReport simulate_sensor(const fs::path& input, const fs::path& output, SensorConfig config,
                          const RunOptions& options) {
  check_output_path(output);
  SpectralExrReader reader(input);
  const SpectralExrInfo& info = reader.info();
  const SpectralLayer* total = info.find_layer("", SpectralQuantity::S0);
  if (total == nullptr) {
    if (!info.spectral()) info.total();  // the reader's "no spectral channels" message
    throw InputError(
        fmt::format("{}: channels S0.<λ>nm: missing; the sensor needs emitted radiance, and this "
                    "file is {}",
                    info.file, info.kind()));
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

  std::optional<FieldOfView> fov;
  if (config.optics.enabled && config.optics.cos4) {
    fov = field_of_view(info, config.optics.fov_deg);
    if (!fov) {
      config.optics.cos4 = false;
      config.notes.push_back(
          "cos4 fall-off off: the image has no chromatrace.camera and no optics.fov_deg (--fov-deg) was given");
    } else {
      config.notes.push_back(fmt::format("cos4 fall-off over a {:.6g} x {:.6g} degree field of view (from {})",
                                         fov->horizontal_deg, fov->vertical_deg, fov->source));
    }
  }

  const auto component_list = component_layers_of(info);
  const std::vector<std::string>& components = component_list.first;
  const std::vector<const SpectralLayer*>& component_layers = component_list.second;

  Run run;
  run.threads = options.threads;
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
  Progress progress("sensor", blocks * (config.exposure.time_s ? 1 : 2), options.progress);

  if (!config.exposure.time_s) {
    run.config = config;
    config.exposure.time_s = auto_exposure(reader, run, *total, rows_per_block, progress);
    config.notes.push_back(fmt::format(
        "exposure.time_s \"auto\": {:.6g} s puts the {:g}th percentile of the brightest channel at {:g} of {}",
        *config.exposure.time_s, config.exposure.auto_percentile, config.exposure.auto_level,
        saturation_electrons(config) ? fmt::format("saturation ({:.6g} e-)", *saturation_electrons(config))
                                     : std::string("1 e- (the ideal sensor does not saturate)")));
  }
  run.exposure_s = *config.exposure.time_s * config.exposure.scale;
  run.model = linear_model(config, run.exposure_s, info.bands, fov, info.width, info.height);

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
  if (layout.format == OutputFormat::Exr) {
    layout.components = components;
    layout.object_ids = info.has_object_ids;
    layout.object_names = info.object_names;
    // The renderer's description of the scene and camera travels on with the image.
    for (const auto& [key, value] : info.metadata)
      if (key.starts_with("chromatrace.") && key != "chromatrace.components") layout.attributes[key] = value;
    layout.attributes["chromatrace.sensor"] = report.effective_config.dump();
    layout.attributes["chromatrace.units"] = units_json(config, run.intent).dump();
    if (!components.empty())
      layout.attributes["chromatrace.components"] = fmt::format("{}", fmt::join(components, ","));
  }
  SensorImageWriter writer(output, layout);

  const bool exr = layout.format == OutputFormat::Exr;
  const auto read_block = [&](int y0) {
    BlockInput in;
    in.y0 = y0;
    in.y1 = std::min(height, y0 + rows_per_block);
    in.context = config.cfa.enabled ? demosaic_context(in.y0, in.y1, height) : RowRange{in.y0, in.y1};
    in.total = read_sensor_rows(reader, *total, k, in.context.first, in.context.last);
    if (exr) {
      for (const SpectralLayer* layer : component_layers)
        in.components.push_back(read_sensor_rows(reader, *layer, k, in.y0, in.y1));
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
    const std::vector<float> linear_ext = linear_rows(run, in.total, e0, e1);
    std::vector<float> image = read_out_rows(run, linear_ext, e0, e1);
    const std::size_t own = to_size(y0 - e0) * row_values, own_size = to_size(y1 - y0) * row_values;
    image.erase(image.begin() + static_cast<std::ptrdiff_t>(own + own_size), image.end());
    image.erase(image.begin(), image.begin() + static_cast<std::ptrdiff_t>(own));
    if (config.rendering.enabled) render_rows(run, image);

    OutputRows rows;
    rows.rows = y1 - y0;
    rows.image = image;
    std::vector<std::vector<float>> component_rows;
    std::vector<std::int32_t> ids;
    if (exr) {
      rows.linear = std::span<const float>(linear_ext).subspan(own, own_size);
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
