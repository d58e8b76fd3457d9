// SPDX-License-Identifier: Apache-2.0
// chromatrace combine PART.exr... -o OUT.exr: the parts of a reference-tracer render split by seed (render
// --seeds K --part I, or chromatrace farm render) combined sample-weighted (reference_tracer/seed_split.h).
#include <filesystem>
#include <vector>

#include "cli/app.h"
#include "cli/command.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/parallel.h"
#include "core/spectral_exr.h"
#include "reference_tracer/seed_split.h"

namespace ct::cli {

Action add_combine(CLI::App& app) {
  auto* cmd = add_command(app, "combine");
  struct Options {
    std::vector<std::string> parts;
    std::string output;
    int threads = 0;
    bool quiet = false;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("parts", o->parts, "Part renders (spectral EXRs from chromatrace render)")->required();
  cmd->add_option("-o,--output", o->output, "Combined spectral EXR, written atomically")->required();
  cmd->add_option("--threads", o->threads, "OpenEXR threads (0: all cores)")->check(CLI::NonNegativeNumber);
  cmd->add_flag("-q,--quiet", o->quiet, "No progress output");

  return [o] {
    if (o->output.empty()) throw InputError("--output: no file name");
    const std::vector<std::filesystem::path> parts(o->parts.begin(), o->parts.end());
    check_output_file(o->output, parts);
    set_exr_threads(thread_count(o->threads));
    rt::combine_parts(parts, o->output, !o->quiet);
    return 0;
  };
}

}  // namespace ct::cli
