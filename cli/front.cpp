// SPDX-License-Identifier: Apache-2.0
// chromatrace, the command users run: --help, --version and check-scene run here; every other command line is
// handed, unchanged, to the full program (cli/main.cpp) by execv. This executable links no image library
// (OpenImageIO, OpenCV, OpenEXR), so help and scene checks start in milliseconds (bench/README.md, "Start-up").
//
// The front parses a command line itself only when no argument is the name of a subcommand other than
// check-scene: the other subcommands are then never entered, so CLI11 parses it exactly as the full program
// would (same app, same check-scene; cli/app.h), and help, version, usage errors and check-scene's output are the
// full program's. A scene with an image texture needs OpenImageIO to be checked (its texels are read and
// validated): scene loading then reaches read_image_texture below, which hands the whole command line over.
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string_view>

#include <unistd.h>

#include <fmt/core.h>

#include "cli/app.h"
#include "cli/command.h"
#include "core/texture.h"

namespace ct {
namespace {

// Thrown where the front would need an image library; caught in main, which hands over. Not a std::exception, so
// that no handler on the way turns it into an error message.
struct NeedsImageLibrary {};

}  // namespace

// core/texture.h's image reading, which chromatrace_texture_io defines with OpenImageIO (core/CMakeLists.txt).
ImageTexture read_image_texture(const std::filesystem::path&, const std::string&, std::optional<TextureColourSpace>,
                                TextureUse, double) {
  throw NeedsImageLibrary{};
}
TextureColourSpace default_texture_colour_space(const std::filesystem::path&) { throw NeedsImageLibrary{}; }

namespace cli {
namespace {

namespace fs = std::filesystem;

bool names_other_command(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    for (const CommandInfo& c : command_list())
      if (c.name != "check-scene" && c.name == argv[i]) return true;
  return false;
}

// Replaces this process by the full program, found relative to this executable (CHROMATRACE_FULL_PROGRAM: the same
// relative path in the build tree and installed), with the same arguments, argv[0] included. The full program
// takes CHROMATRACE_FRONT as its own name (cli/options.h, own_executable) for the commands it starts.
[[noreturn]] void hand_over(char** argv) {
  std::error_code error;
  const fs::path self = fs::read_symlink("/proc/self/exe", error);
  const fs::path full = (self.parent_path() / CHROMATRACE_FULL_PROGRAM).lexically_normal();
  if (!error) ::setenv("CHROMATRACE_FRONT", self.c_str(), 1);
  ::execv(full.c_str(), argv);
  fmt::print(stderr, "chromatrace: failed: cannot run the full program {}: {}\n", full.string(),
             error ? error.message() : std::strerror(errno));
  std::exit(1);
}

}  // namespace
}  // namespace cli
}  // namespace ct

int main(int argc, char** argv) {
  using namespace ct::cli;
  if (names_other_command(argc, argv)) hand_over(argv);
  CLI::App app{kAppDescription};
  setup_app(app);
  std::vector<std::pair<CLI::App*, Action>> commands;
  for (const CommandInfo& c : command_list()) {
    if (c.name != "check-scene") {
      add_command(app, c.name);  // named and described for --help; never entered (names_other_command)
      continue;
    }
    Action action = add_check_scene(app);
    commands.emplace_back(app.get_subcommands([](CLI::App*) { return true; }).back(), std::move(action));
  }
  if (const auto code = parse_command_line(app, argc, argv)) return *code;
  try {
    return run_parsed(commands);
  } catch (const ct::NeedsImageLibrary&) {
    hand_over(argv);
  }
}
