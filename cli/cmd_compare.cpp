// SPDX-License-Identifier: Apache-2.0
// chromatrace compare A.exr B.exr -o DIR: cross-validation of two spectral renders of one scene.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "cli/app.h"
#include "cli/command.h"
#include "compare/compare.h"
#include "core/error.h"
#include "core/file_io.h"

namespace ct::cli {

namespace {

// "A1.exr,A2.exr" → its files.
std::vector<std::string> split_files(const std::string& text, const std::string& what) {
  std::vector<std::string> files;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    const std::string file = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (file.empty()) throw InputError(fmt::format("{}: empty file name in \"{}\"", what, text));
    files.push_back(file);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return files;
}

// "1%", "0.5 %" or "0.01" → a fraction.
double parse_tolerance(const std::string& text) {
  std::string t = text;
  bool percent = false;
  while (!t.empty() && (t.back() == ' ' || t.back() == '%')) {
    percent |= t.back() == '%';
    t.pop_back();
  }
  char* end = nullptr;
  const double v = std::strtod(t.c_str(), &end);
  if (t.empty() || end != t.c_str() + t.size() || !std::isfinite(v) || v < 0)
    throw InputError(fmt::format("--tolerance: expected a percentage like 1% (or a fraction), got \"{}\"", text));
  return percent ? v / 100.0 : v;
}

}  // namespace

Action add_compare(CLI::App& app) {
  auto* cmd = add_command(app, "compare");
  struct Options {
    std::string a, b, output, tolerance, pixels = "matched", camera = "cie1931", colour = "common",
                white = "scene";
    double sigmas = 4.0;
    bool quiet = false;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("a", o->a, "Render A (or several with independent seeds: A1.exr,A2.exr)")->required();
  cmd->add_option("b", o->b, "Render B (or B1.exr,B2.exr)")->required();
  cmd->add_option("-o,--output", o->output, "Output directory: compare.json, compare.png, compare.html")->required();
  cmd->add_option("--tolerance", o->tolerance,
                  "Relative tolerance for every cell, e.g. 1% (default: Lambert and emitters 1%, glossy 2%)");
  cmd->add_option("--sigmas", o->sigmas, "Standard errors allowed beyond the tolerance")->capture_default_str();
  cmd->add_option("--pixels", o->pixels,
                  "An object's pixels: matched (same id in both) or interior (and all 8 neighbours)")
      ->capture_default_str();
  cmd->add_option("--camera", o->camera, "Camera for ΔE00: cie1931 or a shipped camera")->capture_default_str();
  cmd->add_option("--colour", o->colour,
                  "Image-level colours: common (both on the coarser band plan: what the renderers do differently) or "
                  "own (each over its own bands: a coarser plan's colour error counts too)")
      ->capture_default_str();
  cmd->add_option("--white", o->white,
                  "The white of the image level's CIELAB: scene (the scene's light, from A's header; D65 where it "
                  "holds none) or d65")
      ->capture_default_str();
  cmd->add_flag("-q,--quiet", o->quiet, "No verdict on stderr");

  return [o] {
    cmp::CompareOptions options;
    options.a = split_files(o->a, "A");
    options.b = split_files(o->b, "B");
    if (!o->tolerance.empty()) options.tolerance = parse_tolerance(o->tolerance);
    options.sigmas = o->sigmas;
    options.pixels = o->pixels;
    options.camera = o->camera;
    options.colour = o->colour;
    options.white = o->white;
    if (o->output.empty()) throw InputError("--output: no directory name");
    std::vector<std::filesystem::path> inputs(options.a.begin(), options.a.end());
    inputs.insert(inputs.end(), options.b.begin(), options.b.end());
    check_output_directory(o->output, inputs);  // before the comparison, which reads every pixel
    const cmp::Comparison c = cmp::compare(options);
    cmp::write_outputs(c, o->output);
    if (!o->quiet) fmt::print(stderr, "{}", cmp::verdict(c));
    return 0;  // agreement or not, the comparison was made; compare.json says which
  };
}

}  // namespace ct::cli
