#include "cli/command.h"
namespace ct::cli {
Action add_info(CLI::App& app) {
  app.add_subcommand("info", "Describe an image");
  return [] { return 0; };
}
}  // namespace ct::cli
