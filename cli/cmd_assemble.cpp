// SPDX-License-Identifier: Apache-2.0
// chromatrace assemble MANIFEST.json -o OUT.exr: builds a spectral EXR from band-multiplexed RGB renders (the
// Blender add-on's Cycles renders). The manifest format and the assembly are in core/assembly.h.
#include <filesystem>
#include <vector>

#include <fmt/core.h>

#include "cli/app.h"
#include "cli/command.h"
#include "core/assembly.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/parallel.h"
#include "core/spectral_exr.h"

namespace ct::cli {

Action add_assemble(CLI::App& app) {
  auto* cmd = add_command(app, "assemble");
  struct Options {
    std::string manifest, output;
    int threads = 0;
    bool quiet = false;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("manifest", o->manifest, "Manifest JSON")->required();
  cmd->add_option("-o,--output", o->output, "Output spectral EXR, written atomically")->required();
  cmd->add_option("--threads", o->threads, "OpenEXR threads (0: all cores)")->check(CLI::NonNegativeNumber);
  cmd->add_flag("-q,--quiet", o->quiet, "No progress output");

  return [o] {
    const AssemblyManifest manifest = read_assembly_manifest(o->manifest);
    if (o->output.empty()) throw InputError("--output: no file name");
    std::vector<std::filesystem::path> inputs = {o->manifest};
    for (const AssemblyInput& input : manifest.inputs) inputs.push_back(input.path);
    check_output_file(o->output, inputs);
    set_exr_threads(thread_count(o->threads));
    assemble(manifest, o->output, !o->quiet);
    return 0;
  };
}

}  // namespace ct::cli
