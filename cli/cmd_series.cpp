// SPDX-License-Identifier: Apache-2.0
// chromatrace series SERIES.json -o DIR and chromatrace paper -o DIR: experiment series end to end
// (docs/series.md).
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include <fmt/core.h>
#include <fmt/format.h>

#include "cli/app.h"
#include "cli/command.h"
#include "cli/options.h"
#include "cli/series_options.h"
#include "core/band_plan.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/series_format.h"
#include "series/figure.h"
#include "series/runner.h"

namespace ct::cli {
namespace {
namespace fs = std::filesystem;

struct SeriesOptions {
  std::string series, output;
  SeriesRenderOptions render;
  int threads = 0;
  bool quiet = false, renders_only = false;
};

void add_common(CLI::App* cmd, SeriesOptions& o) {
  cmd->add_option("-o,--output", o.output, "Output directory (created; its parent must exist)")->required();
  add_series_render_options(cmd, o.render);
  cmd->add_option("--threads", o.threads, "Worker threads (0: all cores)")->check(CLI::NonNegativeNumber);
  cmd->add_flag("-q,--quiet", o.quiet, "No progress output (the summary table is still printed)");
  cmd->add_flag("--renders-only", o.renders_only,
                "Only the renders, into the cache DIR/renders (no camera, analysis, series.json or page): one task of "
                "a series split over a cluster (chromatrace farm series)");
}

// One row per expectation: variant, target, expected, found (per object where a group differs), ✔/✗.
void print_summary(const series::SeriesResult& result, const fs::path& dir) {
  int met = 0, total = 0;
  fmt::print("{:<24} {:<7} {:<10} {:<16} {}\n", "variant", "figure", "target", "expected", "found");
  for (const series::VariantResult& v : result.variants) {
    const std::string figure = v.figure.empty() ? "" : fmt::format("{}", fmt::join(v.figure, ","));
    if (!v.ok) {
      fmt::print("{:<24} {:<7} failed: {}\n", v.name, figure, v.error);
      continue;
    }
    bool first = true;
    for (const series::ExpectationResult& e : v.expectations) {
      std::vector<std::string> found;
      for (const series::Finding& f : e.findings)
        found.push_back(e.findings.size() == 1 ? f.found : fmt::format("{} {}", f.object, f.found));
      fmt::print("{:<24} {:<7} {:<10} {:<16} {} {}\n", first ? v.name : "", first ? figure : "", e.expected.target,
                 expectation_phrase(e.expected.any_of, "|", e.expected.bent_by, e.expected.thickened_by),
                 e.ok ? "✔" : "✗",
                 fmt::join(found, ", "));
      first = false;
      met += e.ok ? 1 : 0;
      ++total;
    }
  }
  fmt::print("{} of {} expectations met; {}\n", met, total, (dir / "index.html").string());
}

// The series file and the scene files it reads must not be among what the run writes: series.json and
// index.html at the top of the output directory, and everything under renders/ and each variant's directory.
void check_inputs_outside(const fs::path& dir, const Series& series, const fs::path& series_file) {
  std::vector<fs::path> inputs = series.base_scene.files;
  inputs.push_back(series_file);
  check_output_directory(dir, inputs);
  for (const char* top : {"series.json", "index.html"}) check_not_an_input(dir / top, inputs);
  std::vector<fs::path> written = {dir / "renders"};
  for (const SeriesVariant& v : series.variants) written.push_back(dir / v.name);
  for (const fs::path& input : inputs)
    for (fs::path up = fs::absolute(input).parent_path(); up.has_relative_path(); up = up.parent_path())
      for (const fs::path& w : written)
        if (same_file(up, w))
          throw InputError(fmt::format("{}: the input {} is in {}, which the series writes", dir.string(),
                                       input.string(), w.string()));
}

int run(const SeriesOptions& o, const fs::path& series_file) {
  series::RunOptions options = series_run_options(o.render, o.threads, o.quiet);
  options.renders_only = o.renders_only;
  if (o.output.empty()) throw InputError("--output: no directory given");
  const fs::path parent = fs::absolute(o.output).parent_path();
  if (!fs::is_directory(parent))
    throw InputError(fmt::format("{}: directory {} does not exist", o.output, parent.string()));
  if (fs::exists(o.output) && !fs::is_directory(o.output))
    throw InputError(fmt::format("{}: exists and is not a directory", o.output));
  series::check_renderer(options);
  const Series series = load_series(series_file, o.threads);
  check_inputs_outside(o.output, series, series_file);
  // run_series checks the variants and their sensor settings before it writes anything.
  const series::SeriesResult result = series::run_series(series, o.output, options);
  if (o.renders_only) {
    for (const series::VariantResult& v : result.variants) {
      if (!v.ok) fmt::print(stderr, "chromatrace series: {}: failed: {}\n", v.name, v.error);
      else fmt::print("{}: {}\n", v.name, (fs::path(o.output) / "renders" / (v.render_key + ".exr")).string());
    }
    for (const series::VariantResult& v : result.variants)
      if (!v.ok) return 1;
    return 0;
  }
  series::write_figure_page(o.output, series::result_json(result));
  print_summary(result, o.output);
  for (const series::VariantResult& v : result.variants)
    if (!v.ok) return 1;
  return 0;
}

}  // namespace

Action add_series(CLI::App& app) {
  auto* cmd = add_command(app, "series");
  auto o = std::make_shared<SeriesOptions>();
  cmd->add_option("series", o->series, "Series file (chromatrace-series/1)")->required();
  add_common(cmd, *o);
  return [o] { return run(*o, o->series); };
}

Action add_paper(CLI::App& app) {
  auto* cmd = add_command(app, "paper");
  auto o = std::make_shared<SeriesOptions>();
  add_common(cmd, *o);
  return [o] {
    SeriesOptions options = *o;
    if (options.render.resolution.empty()) options.render.resolution = "128x128";
    return run(options, shipped_file("scenes/paper/series.json"));
  };
}

}  // namespace ct::cli
