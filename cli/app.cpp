// SPDX-License-Identifier: Apache-2.0
#include "cli/app.h"

#include <array>
#include <csignal>
#include <cstdio>
#include <exception>
#include <stdexcept>
#include <string>

#include <fmt/core.h>

#include "core/error.h"

namespace ct::cli {

std::span<const CommandInfo> command_list() {
  static constexpr std::array<CommandInfo, 17> kCommands = {{
      {"info", "Describe an image: kind, size, bands, layers, components, object ids, metadata, per-band statistics"},
      {"check-scene",
       "Validate a scene (chromatrace-scene/1) or an experiment series (chromatrace-series/1) and summarise it"},
      {"render", "Render a scene with the reference spectral path tracer"},
      {"analyze", "Analyse the colour histograms of image regions: shapes, illuminant, light paths"},
      {"sensor", "Simulate a camera: spectral radiance to the numbers a sensor records"},
      {"series",
       "Run an experiment series end to end: render, camera and analysis per variant, found vs expected structures, a "
       "figure page"},
      {"paper",
       "Reproduce the paper's Figures 3 and 4: its experiment series, shipped with chromatrace, at 128x128 pixels "
       "unless told otherwise"},
      {"plan", "Choose the fewest bands and bounces that keep a scene within a ΔE00 target"},
      {"study",
       "Measure render cost against error for band plans, samples, bounces, spectral mode and renderer, against a "
       "converged reference"},
      {"scene-bands",
       "Band averages of the spectra, materials and lights of a scene (or of a chromatrace-spectra/1 list)"},
      {"export-meshes",
       "Write every object and light of a scene as a world-space PLY mesh (with normals where shading is smooth), "
       "tessellated as the reference tracer does"},
      {"assemble",
       "Build a spectral EXR from band-multiplexed RGB renders listed in a manifest (chromatrace-assemble/1)"},
      {"combine", "Combine reference-tracer renders of one scene with different seeds, weighted by their samples"},
      {"farm", "Split work into Slurm jobs on a cluster: tasks in a job array, then an assembly"},
      {"compare", "Cross-validate two spectral renders of one scene: per object, band and component, and ΔE00"},
      {"calibrate",
       "A camera's EMVA 1288 parameters (gain, dark noise, saturation, dark current, DSNU, PRNU, linearity) from flat and "
       "dark frames, as sensor settings"},
      {"prepare-texture",
       "Per-band-group EXR textures (R, G, B = band averages of each texel's spectrum) of an image texture or HDRI, "
       "for Cycles through the Blender add-on; cached by content"},
  }};
  return kCommands;
}

void setup_app(CLI::App& app) {
  app.require_subcommand(1);
  app.set_version_flag("--version", "chromatrace 0.1.0");
}

CLI::App* add_command(CLI::App& app, std::string_view name) {
  for (const CommandInfo& c : command_list())
    if (c.name == name) return app.add_subcommand(std::string(c.name), std::string(c.description));
  throw std::logic_error(fmt::format("add_command: no subcommand {}", name));
}

namespace {

// The subcommand a command line names: its first argument when that is not an option. Checked before CLI11
// parses, which would take an unknown name for an extra argument and, with --help, print the general help and
// exit 0 (`chromatrace develop --help`).
std::optional<int> refuse_unknown_command(int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-') return std::nullopt;
  const std::string_view name = argv[1];
  std::string known;
  for (const CommandInfo& c : command_list()) {
    if (c.name == name) return std::nullopt;
    known += known.empty() ? "" : ", ";
    known += c.name;
  }
  fmt::print(stderr, "chromatrace: error: unknown command \"{}\" (the commands: {}; chromatrace --help)\n",
             one_line(name), known);
  return 2;
}

// CLI11 gives an option that takes several values (--rect, --flat, --variant, --set, --cycles-pilot) the words after
// it even when one is another option of the command: `--variant -o DIR` made -o a variant's name and then said
// "--output is required". Such a word is named as what it is: the first option of a parsed command one of whose values
// is the name of another of its options.
std::optional<std::string> swallowed_option(const CLI::App& app) {
  for (const CLI::App* command : app.get_subcommands()) {
    if (!command->parsed()) continue;
    const std::vector<const CLI::Option*> options = command->get_options();
    for (const CLI::Option* option : options) {
      if (option->get_items_expected_max() <= 1 || option->count() == 0) continue;
      for (const std::string& value : option->results())
        if (value.size() > 1 && value[0] == '-')
          for (const CLI::Option* other : options)
            if (other != option && other->check_name(value))
              return fmt::format("{}: no value given before the option {}", option->get_name(), value);
    }
  }
  return std::nullopt;
}

}  // namespace

std::optional<int> parse_command_line(CLI::App& app, int argc, char** argv) {
  if (const auto code = refuse_unknown_command(argc, argv)) return code;
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // Named by the subcommand it is an error of (refuse_unknown_command has checked the name), as its other errors
    // are; an option taken for another's value first (the error CLI11 saw follows from it).
    const bool command = argc >= 2 && argv[1][0] != '-';
    const std::optional<std::string> swallowed = swallowed_option(app);
    fmt::print(stderr, "chromatrace{}{}: error: {}\n", command ? " " : "", command ? one_line(argv[1]) : "",
               one_line(swallowed ? *swallowed : std::string(e.what())));
    return 2;
  }
  if (const std::optional<std::string> swallowed = swallowed_option(app)) {
    fmt::print(stderr, "chromatrace {}: error: {}\n", one_line(argv[1]), one_line(*swallowed));
    return 2;
  }
  return std::nullopt;
}

int run_parsed(const std::vector<std::pair<CLI::App*, Action>>& commands) {
  // A file-size limit (ulimit -f) then fails the write with EFBIG, which the writers report (exit 1, the temporary
  // file removed), instead of killing the process with the temporary file left behind.
  std::signal(SIGXFSZ, SIG_IGN);
  for (const auto& [sub, action] : commands) {
    if (!sub->parsed()) continue;
    // Every message one line: a file or object name with a line break in it, or a library's own lines, escaped.
    try {
      return action();
    } catch (const ct::InputError& e) {
      fmt::print(stderr, "chromatrace {}: error: {}\n", sub->get_name(), one_line(e.what()));
      return 2;
    } catch (const std::exception& e) {
      fmt::print(stderr, "chromatrace {}: failed: {}\n", sub->get_name(), one_line(e.what()));
      return 1;
    }
  }
  return 2;
}

}  // namespace ct::cli
