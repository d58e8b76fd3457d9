#include "cli/command.h"
namespace ct::cli {
Action add_check_scene(CLI::App& app) {
  app.add_subcommand("check-scene", "Validate a scene");
  return [] { return 0; };
}
}  // namespace ct::cli
