// chromatrace: explains colour-histogram structure by simulating image formation.
#include <cstdio>
#include <exception>
#include <string>
#include <utility>
#include <vector>

#include <fmt/core.h>

#include "cli/command.h"
#include "core/error.h"

int main(int argc, char** argv) {
  CLI::App app{"chromatrace: simulate how an image was made and explain its colour histogram"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "chromatrace 0.1.0");

  std::vector<std::pair<CLI::App*, ct::cli::Action>> commands;
  // Each add_* creates one subcommand; pair it with its action (the filter lists all, not just parsed ones).
  auto add = [&](ct::cli::Action action) {
    commands.emplace_back(app.get_subcommands([](CLI::App*) { return true; }).back(), std::move(action));
  };
  add(ct::cli::add_info(app));
  add(ct::cli::add_check_scene(app));
  add(ct::cli::add_render(app));
  add(ct::cli::add_analyze(app));
  add(ct::cli::add_sensor(app));
  add(ct::cli::add_series(app));
  add(ct::cli::add_paper(app));
  add(ct::cli::add_plan(app));
  add(ct::cli::add_study(app));
  add(ct::cli::add_scene_bands(app));
  add(ct::cli::add_export_meshes(app));
  add(ct::cli::add_assemble(app));
  add(ct::cli::add_combine(app));
  add(ct::cli::add_farm(app));
  add(ct::cli::add_compare(app));
  add(ct::cli::add_prepare_texture(app));

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    fmt::print(stderr, "chromatrace: error: {}\n", e.what());
    return 2;
  }

  for (auto& [sub, action] : commands) {
    if (!sub->parsed()) continue;
    try {
      return action();
    } catch (const ct::InputError& e) {
      fmt::print(stderr, "chromatrace {}: error: {}\n", sub->get_name(), e.what());
      return 2;
    } catch (const std::exception& e) {
      fmt::print(stderr, "chromatrace {}: failed: {}\n", sub->get_name(), e.what());
      return 1;
    }
  }
  return 2;
}
