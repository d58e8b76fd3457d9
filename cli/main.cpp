// SPDX-License-Identifier: Apache-2.0
// The full chromatrace program: every subcommand. Installed as libexec/chromatrace/chromatrace-full and started by
// the `chromatrace` front (cli/front.cpp) with the user's command line unchanged; cli/app.h says why there are two.
#include <map>
#include <string_view>
#include <utility>
#include <vector>

#include <OpenImageIO/imageio.h>
#include <tiffio.h>

#include "cli/app.h"
#include "cli/command.h"

int main(int argc, char** argv) {
  using namespace ct::cli;
  // Errors reach the user as one line each, through the commands' own messages: the image libraries print
  // nothing themselves (OpenImageIO would print the errors of a reader it tried and dropped, libtiff its warnings).
  OIIO::attribute("oiio:print_uncaught_errors", 0);
  TIFFSetWarningHandler(nullptr);
  TIFFSetErrorHandler(nullptr);
  const std::map<std::string_view, Action (*)(CLI::App&)> add = {
      {"info", add_info},         {"check-scene", add_check_scene},
      {"render", add_render},     {"analyze", add_analyze},
      {"sensor", add_sensor},     {"series", add_series},
      {"paper", add_paper},       {"plan", add_plan},
      {"study", add_study},       {"scene-bands", add_scene_bands},
      {"export-meshes", add_export_meshes}, {"assemble", add_assemble},
      {"combine", add_combine},   {"farm", add_farm},
      {"compare", add_compare},   {"calibrate", add_calibrate},   {"prepare-texture", add_prepare_texture},
  };
  CLI::App app{kAppDescription};
  setup_app(app);
  std::vector<std::pair<CLI::App*, Action>> commands;
  // Each add_* creates one subcommand (the last one of the app); pair it with its action.
  for (const CommandInfo& c : command_list()) {
    Action action = add.at(c.name)(app);
    commands.emplace_back(app.get_subcommands([](CLI::App*) { return true; }).back(), std::move(action));
  }
  if (const auto code = parse_command_line(app, argc, argv)) return *code;
  return run_parsed(commands);
}
