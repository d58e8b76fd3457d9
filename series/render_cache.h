// SPDX-License-Identifier: Apache-2.0
#pragma once
// The render cache of a series run (series/runner.h: renders/<key>.exr): what a render depends on, and the key
// that names it. A changed spectrum or mesh file changes the key (files are named by a hash of their bytes); a
// moved folder, or the scene's name and description, do not.

#include <string>

#include "core/json_input.h"
#include "core/scene.h"
#include "series/runner.h"

namespace ct::series {

// What a render depends on: the scene with its named files hashed, the renderer (for Cycles, the Blender: its path,
// size and modification time) and the run's render settings.
Json render_inputs(const Scene& scene, const RunOptions& options);

// The cache key of those inputs: 16 hex digits of FNV-1a (64 bits; a cache key, not a cryptographic hash).
std::string render_key(const Json& inputs);

}  // namespace ct::series
