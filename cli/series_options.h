// SPDX-License-Identifier: Apache-2.0
#pragma once
// The render options of an experiment series (chromatrace series, paper and farm series), parsed one way.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "series/runner.h"

namespace ct::cli {

struct SeriesRenderOptions {
  std::string renderer = "tracer", resolution, components = "paths,lights", plan;
  std::optional<int> max_bounces, spp;
  std::vector<std::string> variants;
  std::optional<std::uint64_t> seed;
};

// --variant, --renderer, --resolution, --spp, --seed, --plan, --max-bounces, --components.
void add_series_render_options(CLI::App* cmd, SeriesRenderOptions& o);
// The runner's options; InputError naming the option for a bad value.
series::RunOptions series_run_options(const SeriesRenderOptions& o, int threads, bool quiet);
// The same options as arguments of a chromatrace series command line (the plan file's path made absolute).
std::vector<std::string> series_render_arguments(const SeriesRenderOptions& o);

}  // namespace ct::cli
