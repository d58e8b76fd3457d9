// SPDX-License-Identifier: Apache-2.0
// chromatrace analyze IMAGE -o DIR: colour-histogram analysis of image regions (docs/analyze.md).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include <fmt/format.h>
#include "analyzer/analysis.h"
#include "analyzer/camera_noise.h"
#include "analyzer/output.h"
#include "analyzer/raw_input.h"
#include "cli/app.h"
#include "cli/command.h"
#include "core/error.h"
#include "core/file_io.h"

namespace ct::cli {
namespace {

analyzer::Vec3 parse_colour(const std::string& text) {
  analyzer::Vec3 v;
  char extra = 0;
  if (std::sscanf(text.c_str(), "%lf,%lf,%lf%c", &v[0], &v[1], &v[2], &extra) != 3 || !v.allFinite() || v.minCoeff() < 0 || v.sum() <= 0)
    throw InputError(fmt::format("--illuminant: expected R,G,B with non-negative numbers, not all 0, got \"{}\"", text));
  return v;
}

// Before any work: the output directory is no input, and no input is among the files written into it.
void check_output(const std::filesystem::path& dir, const std::string& image, const analyzer::RegionOptions& regions) {
  std::vector<std::filesystem::path> inputs = {image};
  if (std::filesystem::is_regular_file(regions.labels)) inputs.push_back(regions.labels);
  for (const std::string& mask : regions.masks) inputs.push_back(mask);
  check_output_directory(dir, inputs);
  for (const char* written : {"analysis.json", "report.html"}) check_not_an_input(dir / written, inputs);
  for (const std::filesystem::path& input : inputs)
    for (const char* sub : {"histograms", "plots"})
      if (same_file(input.parent_path().empty() ? std::filesystem::path(".") : input.parent_path(), dir / sub))
        throw InputError(fmt::format("{}: the input {} is in the directory {} that analyze writes", dir.string(),
                                     input.string(), (dir / sub).string()));
}

}  // namespace

Action add_analyze(CLI::App& app) {
  auto* cmd = add_command(app, "analyze");
  struct Options {
    std::string image, output, layer, illuminant, input_transfer = "auto", camera_config;
    analyzer::RegionOptions regions;
    analyzer::RawOptions raw;
    std::vector<std::string> rects;
    int bins = 64, threads = 0;
    std::size_t report_points = 20000;
    std::uint64_t seed = 1;
    bool no_plots = false, no_report = false, quiet = false;
    std::string plots = "12";
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("image", o->image,
                  "Image: PNG, TIFF, EXR, camera raw (DNG, CR2, NEF, …) (the sensor simulator's EXR adds layers and object ids)")
      ->required();
  cmd->add_option("-o,--output", o->output, "Output directory (created; its parent must exist)")->required();
  cmd->add_option("--layer", o->layer, "RGB layer to analyse: final (R,G,B), linear, or a component name")->default_str("final");
  cmd->add_option("--input-transfer", o->input_transfer,
                  "What R, G, B hold: auto (from the file's metadata and type), linear, srgb, or gamma=G (a display gamma, "
                  "e.g. 2.2)")
      ->capture_default_str();
  cmd->add_option("--raw-demosaic", o->raw.demosaic,
                  "Camera raw: LibRaw's demosaicing, linear, vng, ppg, ahd, dcb, dht or aahd")
      ->capture_default_str();
  cmd->add_flag("--raw-half-size", o->raw.half_size,
                "Camera raw: no demosaicing; each 2x2 Bayer tile gives its own red, green and blue (half size)");
  cmd->add_option("--labels", o->regions.labels, "Label regions: an id channel of the image (object_id) or a label image file");
  cmd->add_flag("--no-labels", o->regions.no_labels, "Ignore the image's object_id channel");
  cmd->add_option("--mask", o->regions.masks, "Mask image (non-zero pixels form a region); repeatable");
  cmd->add_option("--rect", o->rects, "Rectangle x,y,width,height; repeatable");
  cmd->add_flag("--segment", o->regions.segment,
                "Add automatic segments: linear colour clusters extended over dichromatic planes, so that a highlight "
                "stays with its object; writes labels.png");
  analyzer::SegmentationOptions& seg = o->regions.segmentation;
  cmd->add_option("--segment-size", seg.working_megapixels, "Working size of the segmentation in megapixels (larger images are area-averaged to it)")
      ->capture_default_str();
  cmd->add_option("--segment-min-area", seg.min_area, "Smallest segment, as a fraction of the image's valid pixels")->capture_default_str();
  cmd->add_option("--segment-tolerance", seg.tolerance, "Largest colour-angle step between neighbouring pixels of a segment, in noise σ")
      ->capture_default_str();
  cmd->add_option("--segment-angle", seg.angle_deg, "How far (degrees) the mean colours of two parts of a segment may differ beyond their noise")
      ->capture_default_str();
  cmd->add_option("--segment-dark", seg.dark, "Pixels darker than this many noise σ are left unassigned")->capture_default_str();
  cmd->add_option("--plots", o->plots, "Plots for the N largest regions, or all")->capture_default_str();
  cmd->add_option("--bins", o->bins, "Histogram bins per channel (2–1024)")->capture_default_str();
  cmd->add_option("--illuminant", o->illuminant, "Known illuminant R,G,B in the layer's units: report angular errors");
  cmd->add_option("--camera-config", o->camera_config,
                  "The camera's sensor settings (chromatrace-sensor/1, e.g. from chromatrace calibrate): judge clusters against its "
                  "noise instead of the noise measured on the image (a camera raw, or the simulator's EXR in digital numbers)");
  cmd->add_option("--report-points", o->report_points, "Points per region in report.html")->capture_default_str();
  cmd->add_option("--seed", o->seed, "Seed of the robust line fits")->capture_default_str();
  cmd->add_flag("--no-plots", o->no_plots, "Write no PNG plots");
  cmd->add_flag("--no-report", o->no_report, "Write no report.html");
  cmd->add_option("--threads", o->threads, "Worker threads (0: all cores)")->capture_default_str();
  cmd->add_flag("-q,--quiet", o->quiet, "No progress output");

  return [o] {
    if (o->bins < 2 || o->bins > 1024) throw InputError(fmt::format("--bins: must be in [2, 1024], got {}", o->bins));
    if (o->threads < 0) throw InputError(fmt::format("--threads: must be >= 0, got {}", o->threads));
    if (o->report_points < 1) throw InputError("--report-points: must be >= 1");
    std::optional<std::size_t> plot_limit;
    if (o->plots != "all") {
      std::size_t used = 0;
      long long n = -1;
      try {
        n = std::stoll(o->plots, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != o->plots.size() || n < 0) throw InputError(fmt::format("--plots: expected a number >= 0 or all, got \"{}\"", o->plots));
      plot_limit = static_cast<std::size_t>(n);
    }
    if (o->regions.segment) analyzer::check_segmentation_options(o->regions.segmentation);
    const std::optional<analyzer::Vec3> known = o->illuminant.empty() ? std::nullopt : std::optional(parse_colour(o->illuminant));
    for (const std::string& r : o->rects) o->regions.rects.push_back(analyzer::parse_rect(r, "--rect"));
    check_output(o->output, o->image, o->regions);

    const analyzer::AnalysisImage input = analyzer::read_analysis_image(o->image, o->input_transfer, o->raw);
    const analyzer::RgbImage& layer = analyzer::select_layer(input, o->layer);
    // Regions first: a bad --labels or --mask is one line, with nothing printed before it. The segmentation's
    // progress bar starts with it.
    analyzer::Segmentation segmentation;
    std::vector<analyzer::Region> regions = analyzer::select_regions(input, layer, o->regions, &segmentation, !o->quiet);
    if (!o->quiet && input.encoding.curve)
      fmt::print(stderr, "{}: R, G, B {} ({})\n", o->image,
                 input.encoding.curve->linear() ? "taken as linear light" : "encoded by " + input.encoding.curve->describe() +
                                                                               ": undone for the linear-light analysis",
                 input.encoding.curve_source);
    if (!o->quiet)
      for (const std::string& note : input.notes) fmt::print(stderr, "{}: note: {}\n", o->image, note);
    analyzer::AnalyzeOptions options;
    if (!o->camera_config.empty()) {
      options.camera_noise = analyzer::camera_noise_from_settings(o->camera_config);
      analyzer::check_camera_numbers(o->image, o->layer);
    }
    options.bins = o->bins;
    options.threads = o->threads;
    options.seed = o->seed;
    analyzer::ImageAnalysis analysis = analyzer::analyse_image(input, o->layer, std::move(regions), options, known, !o->quiet);
    if (o->regions.segment) {
      if (!o->quiet)
        fmt::print(stderr, "segmentation: {} segments, {:.1f} % of the valid pixels unassigned ({} dark, {} in parts too small), {:.1f} s\n",
                   std::count_if(analysis.regions.begin(), analysis.regions.end(), [](const analyzer::Region& r) { return r.source == "segment"; }),
                   100 * segmentation.unassigned_fraction(), segmentation.dark_pixels, segmentation.small_pixels, segmentation.seconds);
      analysis.segmentation = std::move(segmentation);
    }
    // Written aside and moved into place when complete: a full disk leaves no partial analysis behind.
    StagedDirectory output(o->output, {"analysis.json"});
    analyzer::write_analysis(output.path(), input, analysis, {!o->no_plots, !o->no_report, o->report_points, plot_limit});
    output.commit();
    if (!o->quiet) {
      for (const analyzer::RegionAnalysis& r : analysis.results)
        fmt::print(stderr, "{}: {}{} ({} px){}\n", r.name,
                   analyzer::class_name(r.linear_light ? r.linear_light->shape : r.shape.shape),
                   r.linear_light ? fmt::format(" in linear light, {} as stored", analyzer::class_name(r.shape.shape)) : "", r.pixels,
                   r.shape.shape == analyzer::ShapeClass::None ? " — " + r.shape.reason : "");
      const auto& best = analysis.illuminant.best();
      fmt::print(stderr, "illuminant ({}): ({:.4f}, {:.4f}, {:.4f}){}{}{}\n", best.method, best.rgb[0], best.rgb[1], best.rgb[2],
                 best.uncertainty_deg ? fmt::format(" ± {:.2f}°", *best.uncertainty_deg) : "",
                 best.reliable ? "" : ", unreliable: " + best.unreliable_reason,
                 best.error_deg ? fmt::format(", {:.2f}° from the known one", *best.error_deg) : "");
      std::vector<std::string> written = {"analysis.json", "histograms/"};
      if (!o->no_plots) written.push_back("plots/");
      if (analysis.segmentation) written.push_back("labels.png");
      if (!o->no_report) written.push_back("report.html");
      fmt::print(stderr, "{}: {}\n", o->output, fmt::join(written, ", "));
    }
    return 0;
  };
}

}  // namespace ct::cli
