// SPDX-License-Identifier: Apache-2.0
#pragma once
// What the two executables behind `chromatrace` share, so that they parse a command line alike: the top-level
// app, the list of subcommands with their descriptions, the handling of parse errors and of an action's errors.
//
// `chromatrace` (cli/front.cpp) is small: it runs --help, --version and check-scene itself and hands every other
// command line to the full program (cli/main.cpp, installed as libexec/chromatrace/chromatrace-full), which holds
// every subcommand and the image libraries they need (README.md, "The `chromatrace` command"; bench/README.md,
// "Start-up").

#include <optional>
#include <span>
#include <string_view>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli/command.h"

namespace ct::cli {

struct CommandInfo {
  std::string_view name, description;
};

// Every subcommand, in the order `chromatrace --help` lists them.
std::span<const CommandInfo> command_list();

// The top-level app: its description, one subcommand required, --version.
void setup_app(CLI::App& app);
inline constexpr const char* kAppDescription =
    "chromatrace: simulate how an image was made and explain its colour histogram";

// Adds the subcommand `name` of command_list(), with its description.
CLI::App* add_command(CLI::App& app, std::string_view name);

// Parses the command line: nothing when a subcommand is to run, else the exit code after printing help, the
// version or the usage error (exit 2).
std::optional<int> parse_command_line(CLI::App& app, int argc, char** argv);

// Runs the action of the subcommand that was parsed: its exit code, 2 with one line for bad input
// (ct::InputError), 1 for any other failure; 2 if none was parsed.
int run_parsed(const std::vector<std::pair<CLI::App*, Action>>& commands);

}  // namespace ct::cli
