// SPDX-License-Identifier: Apache-2.0
// _chromatrace: the C++ half of the Python module chromatrace (python/chromatrace/__init__.py is the other half,
// docs/python.md the user's side). Each function does what its command does, through the same library calls, with
// arrays where the command has files: the analyzer (cli/cmd_analyze.cpp), the camera (cli/cmd_sensor.cpp), spectral
// EXR files (core/spectral_exr.h) and calibration (cli/cmd_calibrate.cpp).
//
// The GIL is released while the libraries work. An InputError becomes chromatrace.InputError (a ValueError) with the
// one-line message the command prints after "error: ": options are named as the command names them (--preset for
// preset=, --input-transfer for encoding=), so that a message reads the same wherever it comes from.
#include <cmath>
#include <cstdint>
#include <limits>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <OpenImageIO/imageio.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "analyzer/analysis.h"
#include "analyzer/analysis_json.h"
#include "analyzer/histogram.h"
#include "analyzer/camera_noise.h"
#include "analyzer/image_input.h"
#include "analyzer/output.h"
#include "analyzer/plots.h"
#include "analyzer/raw_input.h"
#include "analyzer/regions.h"
#include "analyzer/report.h"
#include "calibrate/calibration.h"
#include "calibrate/frames.h"
#include "calibrate/report.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/json_input.h"
#include "core/limits.h"
#include "core/parallel.h"
#include "core/spectral_exr.h"
#include "plot/png.h"
#include "sensor_sim/config.h"
#include "sensor_sim/pipeline.h"

namespace py = pybind11;

namespace ct::python {
namespace {

// ---------------------------------------------------------------------------------------------------------------
// The analyzer

// analyze's options, as cli/cmd_analyze.cpp takes them (the Python side fills them from keyword arguments).
struct AnalyzeArgs {
  std::string input_transfer = "auto", layer, camera_config;
  std::optional<std::array<double, 3>> illuminant;
  analyzer::RegionOptions regions;
  analyzer::RawOptions raw;
  std::vector<std::string> rects;
  int bins = 64, threads = 0;
  std::uint64_t seed = 1;
};

// An analysis with the image it was made of (which its report and plots draw).
struct Analysis {
  analyzer::AnalysisImage input;
  analyzer::ImageAnalysis analysis;

  std::string json() const {
    return analyzer::analysis_to_json(analysis, std::vector<bool>(analysis.results.size(), false)).dump(1, ' ', false, kReplaceInvalidUtf8);
  }
  std::string histogram_json(std::size_t region) const {
    check_region(region);
    const analyzer::RgbImage& layer = analyzer::select_layer(input, analysis.layer);
    const analyzer::RegionSamples samples = analyzer::gather_samples(layer, analysis.regions[region]);
    return analyzer::histogram_to_json(analysis.results[region].histogram, analyzer::chromaticity_histogram(samples.rgb, analysis.context.spec.bins))
        .dump(-1, ' ', false, kReplaceInvalidUtf8);
  }
  std::string plot_png(std::size_t region, const std::string& colouring) const {
    check_region(region);
    analyzer::PlotColouring c = analyzer::PlotColouring::Own;
    if (colouring == "density") c = analyzer::PlotColouring::Density;
    else if (colouring != "own") throw InputError(fmt::format("colouring: own or density, not \"{}\"", colouring));
    return plot::encode_png(analyzer::plot_region(analyzer::select_layer(input, analysis.layer), analysis, region, c, {}));
  }
  std::string report_html(std::size_t points) const {
    if (points < 1) throw InputError("--report-points: must be >= 1");
    return analyzer::report_html(input, analysis, points, false);
  }
  // As analyze -o DIR writes it, staged and moved into place.
  void write(const std::filesystem::path& dir, bool plots, bool report, std::size_t points, std::optional<std::size_t> plot_limit) const {
    if (points < 1) throw InputError("--report-points: must be >= 1");
    std::vector<std::filesystem::path> inputs;
    if (std::filesystem::is_regular_file(input.file)) inputs.push_back(input.file);
    check_output_directory(dir, inputs);
    StagedDirectory output(dir, {"analysis.json"});
    analyzer::write_analysis(output.path(), input, analysis, {plots, report, points, plot_limit});
    output.commit();
  }

 private:
  void check_region(std::size_t region) const {
    if (region >= analysis.results.size())
      throw py::index_error(fmt::format("region {}: the analysis has {} regions", region, analysis.results.size()));
  }
};

// The options checked before the image is read, in the command's order, so that a bad option is named first as the
// command names it; the rectangles parsed into the regions.
AnalyzeArgs checked(AnalyzeArgs args) {
  if (args.bins < 2 || args.bins > 1024) throw InputError(fmt::format("--bins: must be in [2, 1024], got {}", args.bins));
  if (args.threads < 0) throw InputError(fmt::format("--threads: must be >= 0, got {}", args.threads));
  if (args.regions.segment) analyzer::check_segmentation_options(args.regions.segmentation);
  if (args.illuminant) {
    const analyzer::Vec3 known((*args.illuminant)[0], (*args.illuminant)[1], (*args.illuminant)[2]);
    if (!known.allFinite() || known.minCoeff() < 0 || known.sum() <= 0)
      throw InputError("--illuminant: expected R,G,B with non-negative numbers, not all 0");
  }
  for (const std::string& r : args.rects) args.regions.rects.push_back(analyzer::parse_rect(r, "--rect"));
  args.rects.clear();
  return args;
}

// analyze's steps after reading (cli/cmd_analyze.cpp), on `args` as checked() leaves them.
Analysis analyse(analyzer::AnalysisImage input, const AnalyzeArgs& args, bool camera_numbers_checked) {
  std::optional<analyzer::Vec3> known;
  if (args.illuminant) known = analyzer::Vec3((*args.illuminant)[0], (*args.illuminant)[1], (*args.illuminant)[2]);
  Analysis out;
  out.input = std::move(input);
  const analyzer::RgbImage& layer = analyzer::select_layer(out.input, args.layer);
  analyzer::Segmentation segmentation;
  std::vector<analyzer::Region> regions = analyzer::select_regions(out.input, layer, args.regions, &segmentation, false);
  analyzer::AnalyzeOptions options;
  if (!args.camera_config.empty()) {
    options.camera_noise = analyzer::camera_noise_from_settings(args.camera_config);
    if (!camera_numbers_checked) analyzer::check_camera_numbers(out.input.file, args.layer);
  }
  options.bins = args.bins;
  options.threads = args.threads;
  options.seed = args.seed;
  out.analysis = analyzer::analyse_image(out.input, args.layer, std::move(regions), options, known, false);
  if (args.regions.segment) out.analysis.segmentation = std::move(segmentation);
  return out;
}

Analysis analyze_file(const std::string& path, const AnalyzeArgs& options) {
  py::gil_scoped_release release;
  const AnalyzeArgs args = checked(options);
  return analyse(analyzer::read_analysis_image(path, args.input_transfer, args.raw), args, false);
}

// The camera's noise is in its digital numbers, which an array holds only as linear values.
bool camera_config_allowed_for_array(const AnalyzeArgs& args) { return args.camera_config.empty() || args.input_transfer == "linear"; }

// An H × W × 3 (R, G, B) or × 4 (R, G, B, A) array of uint8, uint16, uint32 (their stored integers) or
// float32/float64, as the image named `name`.
// One copy, into the analyzer's own float image (which it sets aside pixels in), whatever the array's strides.
Analysis analyze_array(const py::array& array, const std::string& name, const AnalyzeArgs& options) {
  const AnalyzeArgs args = checked(options);
  if (array.ndim() != 3 || (array.shape(2) != 3 && array.shape(2) != 4))
    throw InputError(fmt::format("{}: an image array is height × width × 3 (R, G, B) or × 4 (R, G, B, A), got shape ({})", name,
                                 fmt::join(std::vector<py::ssize_t>(array.shape(), array.shape() + array.ndim()), ", ")));
  const py::dtype type = array.dtype();
  const std::string type_name = type.attr("name").cast<std::string>();
  int bits = 0;
  const char kind = type.kind();
  if (kind == 'u') bits = static_cast<int>(type.itemsize()) * 8;
  else if (kind != 'f' || (type.itemsize() != 4 && type.itemsize() != 8))
    throw InputError(fmt::format("{}: samples of type {}; uint8, uint16, uint32, float32 or float64", name, type_name));
  if (bits == 64) throw InputError(fmt::format("{}: samples of type uint64; uint8, uint16, uint32, float32 or float64", name));
  if (!camera_config_allowed_for_array(args))
    throw InputError(fmt::format("--camera-config: the camera's noise is in its digital numbers: give them as {} with --input-transfer linear (encoding=\"linear\")", name));
  // The file readers' limits, before any memory is taken: a broadcast view costs NumPy nothing at any size.
  check_image_size(name, array.shape(1), array.shape(0), static_cast<int>(array.shape(2)));
  const auto height = static_cast<int>(array.shape(0)), width = static_cast<int>(array.shape(1));
  const int channels = static_cast<int>(array.shape(2));
  const std::array<py::ssize_t, 3> strides = {array.strides(0), array.strides(1), array.strides(2)};
  const auto* base = static_cast<const std::uint8_t*>(array.data());
  py::gil_scoped_release release;
  std::vector<float> values(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * static_cast<std::size_t>(channels));
  const auto copy = [&]<typename T>(T) {
    std::size_t i = 0;
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x)
        for (int c = 0; c < channels; ++c) {
          T v;
          std::memcpy(&v, base + y * strides[0] + x * strides[1] + c * strides[2], sizeof(T));
          values[i++] = static_cast<float>(v);
        }
  };
  if (kind == 'u' && bits == 8) copy(std::uint8_t{});
  else if (kind == 'u' && bits == 16) copy(std::uint16_t{});
  else if (kind == 'u') copy(std::uint32_t{});
  else if (type.itemsize() == 4) copy(float{});
  else copy(double{});
  return analyse(analyzer::read_analysis_pixels(name, width, height, std::move(values), bits, args.input_transfer, channels == 4), args,
                 true);
}

// A height × width array of whole numbers (bool, integers, or floats holding whole numbers) as a label image.
analyzer::LabelImage label_image(const py::object& array, const std::string& what) {
  if (const py::array given = py::array::ensure(array); given && given.ndim() == 2)
    check_image_size(what, given.shape(1), given.shape(0), 1);
  auto a = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(array);
  if (!a || a.ndim() != 2) throw InputError(fmt::format("{}: expected a height × width array", what));
  const py::array original = py::array::ensure(array);
  if (original && original.dtype().kind() == 'f') {
    const auto f = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(array);
    for (py::ssize_t i = 0; i < f.size(); ++i)
      if (f.data()[i] != std::floor(f.data()[i]))
        throw InputError(fmt::format("{}: holds {}, not a whole number", what, f.data()[i]));
  }
  analyzer::LabelImage out;
  out.height = static_cast<int>(a.shape(0));
  out.width = static_cast<int>(a.shape(1));
  out.labels.resize(static_cast<std::size_t>(a.size()));
  for (py::ssize_t i = 0; i < a.size(); ++i) {
    const std::int64_t v = a.data()[i];
    if (v < 0 || v > std::numeric_limits<std::int32_t>::max())
      throw InputError(fmt::format("{}: holds {}, not a label in [0, {}]", what, v, std::numeric_limits<std::int32_t>::max()));
    out.labels[static_cast<std::size_t>(i)] = static_cast<std::int32_t>(v);
  }
  return out;
}

py::object segment_labels(const Analysis& a) {
  if (!a.analysis.segmentation) return py::none();
  const analyzer::Segmentation& s = *a.analysis.segmentation;
  py::array_t<std::uint16_t> out({s.height, s.width});
  std::memcpy(out.mutable_data(), s.labels.data(), s.labels.size() * sizeof(std::uint16_t));
  return out;
}

// ---------------------------------------------------------------------------------------------------------------
// Spectral EXR files and the camera

// A C-contiguous float32 view of `array` with `dims` dimensions (a copy only where NumPy needs one).
py::array_t<float, py::array::c_style | py::array::forcecast> float_array(const py::object& array, int dims, const std::string& what) {
  auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(array);
  if (!a || a.ndim() != dims) throw InputError(fmt::format("{}: expected an array of {} dimensions", what, dims));
  return a;
}

// Each layer is read straight into the NumPy array returned (no copy).
py::dict read_spectral_exr(const std::filesystem::path& path) {
  std::optional<SpectralExrReader> reader;
  {
    py::gil_scoped_release release;
    reader.emplace(path);
  }
  const SpectralExrInfo& info = reader->info();
  if (!info.spectral()) throw InputError(fmt::format("{}: no spectral channels (an RGB EXR)", path.string()));
  const auto height = static_cast<py::ssize_t>(info.height), width = static_cast<py::ssize_t>(info.width);
  const auto bands = static_cast<py::ssize_t>(info.centres_nm.size());
  py::dict out, components;
  for (const SpectralLayer& l : info.layers) {
    py::array_t<float> cube({height, width, bands});
    const std::span<float> values(cube.mutable_data(), static_cast<std::size_t>(cube.size()));
    {
      py::gil_scoped_release release;
      reader->read_rows(l, 0, info.height, values);
    }
    std::string quantity = l.name();
    if (l.component.empty()) {
      out[py::str(quantity)] = cube;
    } else {
      quantity = quantity.substr(l.component.size() + 1);
      if (!components.contains(l.component)) components[py::str(l.component)] = py::dict();
      components[py::str(l.component)][py::str(quantity)] = cube;
    }
  }
  out["components"] = components;
  out["wavelengths_nm"] = info.centres_nm;
  out["band_edges_nm"] = info.bands.edges();
  out["kind"] = info.kind();
  if (info.has_object_ids) {
    py::array_t<std::int32_t> ids({height, width});
    const std::span<std::int32_t> values(ids.mutable_data(), static_cast<std::size_t>(ids.size()));
    {
      py::gil_scoped_release release;
      reader->read_object_ids(0, info.height, values);
    }
    out["object_ids"] = ids;
  } else {
    out["object_ids"] = py::none();
  }
  out["object_names"] = info.object_names;
  out["emissive_units"] = info.emissive_units ? py::cast(*info.emissive_units) : py::none();
  out["metadata"] = info.metadata;
  out["notes"] = info.notes;
  return out;
}

// Bands by their edges, or by their centres (core's Bands::from_centres: each reaches halfway to its neighbours).
void write_spectral_exr(const std::filesystem::path& path, const py::object& total, const std::vector<double>& band_edges_nm,
                        const std::vector<double>& wavelengths_nm, bool reflective, const std::vector<std::pair<std::string, py::object>>& components,
                        const py::object& object_ids, const std::map<std::int32_t, std::string>& object_names,
                        const std::map<std::string, std::string>& attributes) {
  const auto cube = float_array(total, 3, "spectral");
  SpectralExrLayout layout;
  layout.height = static_cast<int>(cube.shape(0));
  layout.width = static_cast<int>(cube.shape(1));
  if (!band_edges_nm.empty()) {
    layout.bands = Bands::from_edges(band_edges_nm, "band_edges_nm");
  } else if (wavelengths_nm.empty()) {
    throw InputError("wavelengths_nm: give the bands' centres (or band_edges_nm)");
  } else {
    if (wavelengths_nm.size() != static_cast<std::size_t>(cube.shape(2)))
      throw InputError(fmt::format("wavelengths_nm: {} centres for {} bands in the array", wavelengths_nm.size(), cube.shape(2)));
    layout.bands = Bands::from_centres(wavelengths_nm, "wavelengths_nm");
  }
  if (static_cast<std::size_t>(cube.shape(2)) != layout.bands.size())
    throw InputError(fmt::format("spectral: {} bands in the array, {} in band_edges_nm", cube.shape(2), layout.bands.size()));
  layout.reflective = reflective;
  std::vector<py::array_t<float, py::array::c_style | py::array::forcecast>> layers;
  for (const auto& [name, array] : components) {
    layers.push_back(float_array(array, 3, "components." + name));
    if (layers.back().shape(0) != cube.shape(0) || layers.back().shape(1) != cube.shape(1) || layers.back().shape(2) != cube.shape(2))
      throw InputError(fmt::format("components.{}: its shape differs from the total's", name));
    layout.components.push_back(name);
  }
  std::optional<py::array_t<std::int32_t, py::array::c_style | py::array::forcecast>> ids;
  if (!object_ids.is_none()) {
    ids = py::array_t<std::int32_t, py::array::c_style | py::array::forcecast>::ensure(object_ids);
    if (!*ids || ids->ndim() != 2 || ids->shape(0) != cube.shape(0) || ids->shape(1) != cube.shape(1))
      throw InputError("object_ids: expected a height × width integer array of the spectral array's size");
    layout.object_ids = true;
  }
  layout.object_names = object_names;
  layout.attributes = attributes;
  py::gil_scoped_release release;
  SpectralExrWriter writer(path, layout);
  SpectralRowBlock block;
  block.rows = layout.height;
  block.total = {cube.data(), static_cast<std::size_t>(cube.size())};
  for (const auto& l : layers) block.components.emplace_back(l.data(), static_cast<std::size_t>(l.size()));
  if (ids) block.object_ids = {ids->data(), static_cast<std::size_t>(ids->size())};
  writer.write_rows(block);
  writer.finish();
}

// Every channel of an image file as float32 (height × width × channels), its channel names and its attributes (numbers
// as numbers, others as text):
// the camera simulator's EXR output as the Python side reads it back.
py::tuple read_image_channels(const std::filesystem::path& path) {
  std::unique_ptr<OIIO::ImageInput> in;
  {
    py::gil_scoped_release release;
    in = OIIO::ImageInput::open(path.string());
  }
  if (!in) throw InputError(fmt::format("{}: {}", path.string(), one_line(OIIO::geterror())));
  const OIIO::ImageSpec spec = in->spec();
  // Read straight into the NumPy array returned.
  py::array_t<float> a({static_cast<py::ssize_t>(spec.height), static_cast<py::ssize_t>(spec.width), static_cast<py::ssize_t>(spec.nchannels)});
  bool read = false;
  {
    py::gil_scoped_release release;
    read = in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, a.mutable_data());
  }
  if (!read) throw InputError(fmt::format("{}: {}", path.string(), one_line(in->geterror())));
  py::dict attributes;
  for (const OIIO::ParamValue& p : spec.extra_attribs) {
    const OIIO::TypeDesc t = p.type();
    const py::str key(p.name().string());
    const bool scalar = t.aggregate == OIIO::TypeDesc::SCALAR && t.arraylen == 0;
    if (t == OIIO::TypeDesc::STRING) attributes[key] = p.get_string();
    else if (scalar && (t.basetype == OIIO::TypeDesc::FLOAT || t.basetype == OIIO::TypeDesc::DOUBLE || t.basetype == OIIO::TypeDesc::HALF))
      attributes[key] = p.get_float();
    else if (scalar && (t.basetype == OIIO::TypeDesc::INT || t.basetype == OIIO::TypeDesc::UINT)) attributes[key] = p.get_int();
    else attributes[key] = spec.metadata_val(p);
  }
  return py::make_tuple(a, spec.channelnames, attributes);
}

// The camera simulator on a spectral EXR file, written to `output` as `chromatrace sensor` writes it. `patches`: the
// settings as the command builds them (a preset, a file, options), each a JSON text and the option it came from.
py::dict sensor_file(const std::filesystem::path& input, const std::filesystem::path& output,
                     const std::vector<std::pair<std::string, std::string>>& patches, const std::string& config_file,
                     const std::string& illuminant, int threads, int block_rows) {
  sensor::RunReport report;
  {
    py::gil_scoped_release release;
    std::vector<sensor::ConfigPatch> p;
    if (!config_file.empty()) p.push_back(sensor::read_config_patch(config_file));
    for (const auto& [json, source] : patches) {
      Json patch = Json::parse(json, nullptr, false);
      if (patch.is_discarded() || !patch.is_object()) throw InputError(fmt::format("{}: not a JSON object of settings", source));
      p.push_back({std::move(patch), source});
    }
    const sensor::SensorConfig config = sensor::resolve_config(p);
    if (threads < 0) throw InputError(fmt::format("--threads: must be >= 0, got {}", threads));
    if (block_rows < 0) throw InputError(fmt::format("--block-rows: must be >= 0, got {}", block_rows));
    std::vector<std::filesystem::path> inputs = {input};
    if (!config_file.empty()) inputs.push_back(config_file);
    sensor::check_output_path(output, inputs);
    set_exr_threads(thread_count(threads));
    sensor::RunOptions options;
    options.threads = threads;
    options.block_rows = block_rows;
    options.illuminant = illuminant;
    report = sensor::simulate_sensor(input, output, config, options);
  }
  py::dict out;
  out["width"] = report.width;
  out["height"] = report.height;
  out["exposure_s"] = report.exposure_s;
  out["notes"] = report.notes;
  out["settings"] = report.effective_config.dump(-1, ' ', false, kReplaceInvalidUtf8);
  return out;
}

// A camera raw's (or the simulator's DNG's) Bayer mosaic as stored.
py::dict read_raw_mosaic(const std::filesystem::path& path) {
  analyzer::CameraMosaic m;
  {
    py::gil_scoped_release release;
    m = analyzer::read_camera_mosaic(path);
  }
  py::array_t<std::uint16_t> values({static_cast<py::ssize_t>(m.height), static_cast<py::ssize_t>(m.width)});
  std::memcpy(values.mutable_data(), m.values.data(), m.values.size() * sizeof(std::uint16_t));
  py::dict out;
  out["mosaic"] = values;
  out["pattern"] = m.pattern;
  out["black_level"] = m.black_level;
  out["white_level"] = m.white_level;
  return out;
}

// ---------------------------------------------------------------------------------------------------------------
// Calibration

// (name, exposure time, array) as the calibration's frame: a height × width array is one channel (monochrome), height ×
// width × 3 is R, G, B.
using ArrayFrame = std::tuple<std::string, double, py::object>;
calibrate::Frame frame_of(const ArrayFrame& item) {
  const auto& [name, exposure_s, array] = item;
  if (const py::array given = py::array::ensure(array); given && given.ndim() >= 2)
    check_image_size(name, given.shape(1), given.shape(0), given.ndim() == 3 ? static_cast<int>(given.shape(2)) : 1);
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(array);
  if (!a || (a.ndim() != 2 && !(a.ndim() == 3 && a.shape(2) == 3)))
    throw InputError(fmt::format("{}: a frame is a height × width array (one channel) or height × width × 3 (R, G, B)", name));
  const auto height = static_cast<int>(a.shape(0)), width = static_cast<int>(a.shape(1));
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  const std::size_t channels = a.ndim() == 2 ? 1 : 3;
  std::vector<std::vector<double>> planes(channels, std::vector<double>(n));
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t c = 0; c < channels; ++c) planes[c][i] = a.data()[i * channels + c];
  return calibrate::frame_in_memory(name, exposure_s, width, height, planes);
}

py::tuple calibrate_files(const std::vector<std::string>& flats, const std::vector<std::string>& darks, const std::vector<ArrayFrame>& flat_arrays,
                          const std::vector<ArrayFrame>& dark_arrays, std::optional<double> photons_per_s,
                          const std::vector<double>& photons_per_pixel, const std::string& input_transfer, std::optional<double> wavelength_nm,
                          const std::string& camera, const std::string& basis, std::optional<double> pixel_um, std::optional<double> temperature_c,
                          const std::string& report_dir) {
  std::string sensor_json, report_json;
  calibrate::CalibrationInput input;
  for (const ArrayFrame& f : flat_arrays) input.flat_frames.push_back(frame_of(f));
  for (const ArrayFrame& f : dark_arrays) input.dark_frames.push_back(frame_of(f));
  {
    py::gil_scoped_release release;
    for (const std::string& f : flats) input.flats.emplace_back(f);
    for (const std::string& f : darks) input.darks.emplace_back(f);
    input.photons_per_s = photons_per_s;
    input.photons_per_pixel = photons_per_pixel;
    analyzer::parse_input_transfer(input_transfer);
    input.input_transfer = input_transfer;
    input.wavelength_nm = wavelength_nm;
    input.pixel_pitch_um = pixel_um;
    input.temperature_c = temperature_c;
    input.camera = camera;
    input.basis = basis;
    std::optional<StagedDirectory> report;
    if (!report_dir.empty()) {
      std::vector<std::filesystem::path> inputs = input.flats;
      inputs.insert(inputs.end(), input.darks.begin(), input.darks.end());
      check_output_directory(report_dir, inputs, calibrate::report_files());
    }
    const calibrate::Calibration c = calibrate::calibrate(input);
    if (!report_dir.empty()) {
      report.emplace(report_dir, std::vector<std::string>{"index.html"});
      calibrate::write_report(c, report->path());
      report->commit();
    }
    sensor_json = c.sensor.dump(-1, ' ', false, kReplaceInvalidUtf8);
    report_json = c.report.dump(-1, ' ', false, kReplaceInvalidUtf8);
  }
  return py::make_tuple(sensor_json, report_json);
}

}  // namespace
}  // namespace ct::python

PYBIND11_MODULE(_chromatrace, m) {
  using namespace ct::python;
  m.doc() = "The C++ half of chromatrace's Python module; use the package chromatrace (docs/python.md).";

  static py::exception<ct::InputError> input_error(m, "InputError", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const ct::InputError& e) {
      PyErr_SetString(input_error.ptr(), ct::one_line(e.what()).c_str());
    }
  });

  py::class_<AnalyzeArgs>(m, "AnalyzeArgs")
      .def(py::init<>())
      .def_readwrite("input_transfer", &AnalyzeArgs::input_transfer)
      .def_readwrite("layer", &AnalyzeArgs::layer)
      .def_readwrite("camera_config", &AnalyzeArgs::camera_config)
      .def_readwrite("illuminant", &AnalyzeArgs::illuminant)
      .def_readwrite("rects", &AnalyzeArgs::rects)
      .def_readwrite("bins", &AnalyzeArgs::bins)
      .def_readwrite("threads", &AnalyzeArgs::threads)
      .def_readwrite("seed", &AnalyzeArgs::seed)
      .def_property("labels", [](const AnalyzeArgs& a) { return a.regions.labels; }, [](AnalyzeArgs& a, const std::string& v) { a.regions.labels = v; })
      .def_property("no_labels", [](const AnalyzeArgs& a) { return a.regions.no_labels; }, [](AnalyzeArgs& a, bool v) { a.regions.no_labels = v; })
      .def_property("masks", [](const AnalyzeArgs& a) { return a.regions.masks; },
                    [](AnalyzeArgs& a, const std::vector<std::string>& v) { a.regions.masks = v; })
      .def_property("segment", [](const AnalyzeArgs& a) { return a.regions.segment; }, [](AnalyzeArgs& a, bool v) { a.regions.segment = v; })
      .def_property("segment_size", [](const AnalyzeArgs& a) { return a.regions.segmentation.working_megapixels; },
                    [](AnalyzeArgs& a, double v) { a.regions.segmentation.working_megapixels = v; })
      .def_property("segment_min_area", [](const AnalyzeArgs& a) { return a.regions.segmentation.min_area; },
                    [](AnalyzeArgs& a, double v) { a.regions.segmentation.min_area = v; })
      .def_property("segment_tolerance", [](const AnalyzeArgs& a) { return a.regions.segmentation.tolerance; },
                    [](AnalyzeArgs& a, double v) { a.regions.segmentation.tolerance = v; })
      .def_property("segment_angle", [](const AnalyzeArgs& a) { return a.regions.segmentation.angle_deg; },
                    [](AnalyzeArgs& a, double v) { a.regions.segmentation.angle_deg = v; })
      .def_property("segment_dark", [](const AnalyzeArgs& a) { return a.regions.segmentation.dark; },
                    [](AnalyzeArgs& a, double v) { a.regions.segmentation.dark = v; })
      .def_property("raw_demosaic", [](const AnalyzeArgs& a) { return a.raw.demosaic; },
                    [](AnalyzeArgs& a, const std::string& v) { a.raw.demosaic = v; })
      .def("set_label_array", [](AnalyzeArgs& a, const py::object& array) { a.regions.label_image = label_image(array, "labels"); })
      .def("add_mask_array", [](AnalyzeArgs& a, const std::string& name, const py::object& array) {
             a.regions.mask_images.emplace_back(name, label_image(array, "mask " + name));
           })
      .def_property("raw_half_size", [](const AnalyzeArgs& a) { return a.raw.half_size; }, [](AnalyzeArgs& a, bool v) { a.raw.half_size = v; });

  py::class_<Analysis>(m, "Analysis")
      .def("json", &Analysis::json, "The content of analysis.json")
      .def("labels", &segment_labels, "The segmentation's labels (height × width uint16; 0 unassigned), or None")
      .def("histogram_json", &Analysis::histogram_json, py::arg("region"), py::call_guard<py::gil_scoped_release>())
      .def("plot_png", [](const Analysis& a, std::size_t region, const std::string& colouring) {
             std::string png;
             {
               py::gil_scoped_release release;
               png = a.plot_png(region, colouring);
             }
             return py::bytes(png);
           }, py::arg("region"), py::arg("colouring") = "own")
      .def("report_html", &Analysis::report_html, py::arg("points") = 20000, py::call_guard<py::gil_scoped_release>())
      .def("write", &Analysis::write, py::arg("directory"), py::arg("plots") = true, py::arg("report") = true, py::arg("points") = 20000,
           py::arg("plot_limit") = std::optional<std::size_t>(12), py::call_guard<py::gil_scoped_release>());

  m.def("analyze_file", &analyze_file, py::arg("path"), py::arg("args"));
  m.def("analyze_array", &analyze_array, py::arg("array"), py::arg("name"), py::arg("args"));
  m.def("read_spectral_exr", &read_spectral_exr, py::arg("path"));
  m.def("write_spectral_exr", &write_spectral_exr, py::arg("path"), py::arg("spectral"), py::arg("band_edges_nm"),
        py::arg("wavelengths_nm"), py::arg("reflective"),
        py::arg("components"), py::arg("object_ids"), py::arg("object_names"), py::arg("attributes"));
  m.def("read_image_channels", &read_image_channels, py::arg("path"));
  m.def("read_raw_mosaic", &read_raw_mosaic, py::arg("path"));
  m.def("sensor_file", &sensor_file, py::arg("input"), py::arg("output"), py::arg("patches"), py::arg("config_file"),
        py::arg("illuminant"), py::arg("threads"), py::arg("block_rows"));
  m.def("calibrate_files", &calibrate_files, py::arg("flats"), py::arg("darks"), py::arg("flat_arrays"), py::arg("dark_arrays"),
        py::arg("photons_per_s"), py::arg("photons_per_pixel"),
        py::arg("input_transfer"), py::arg("wavelength_nm"), py::arg("camera"), py::arg("basis"), py::arg("pixel_um"),
        py::arg("temperature_c"), py::arg("report_dir"));
}
