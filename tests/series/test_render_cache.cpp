// SPDX-License-Identifier: Apache-2.0
// The render cache's key (series/render_cache.h): the same inputs give the same key; the renderer, a render
// setting and, for Cycles, another Blender or one changed in place give another.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>

#include "core/scene.h"
#include "series/render_cache.h"
#include "tests/core/spectral_exr_fixtures.h"

namespace ct::series {
namespace {

namespace fs = std::filesystem;

const fs::path kMinimal = fs::path(CHROMATRACE_TEST_DATA) / "scenes" / "minimal.json";

std::string key(const Scene& scene, const RunOptions& options) { return render_key(render_inputs(scene, options)); }

TEST(RenderCache, TheKeyFollowsTheRendererTheSettingsAndTheBlender) {
  const Scene scene = load_scene(kMinimal);
  test::TempDir dir;
  const fs::path a = dir.file("blender-a"), b = dir.file("blender-b");
  std::ofstream(a) << "#!/bin/sh\n";
  std::ofstream(b) << "#!/bin/sh\n";
  RunOptions tracer;
  RunOptions cycles;
  cycles.renderer = Renderer::Cycles;
  cycles.blender = a;
  EXPECT_EQ(key(scene, tracer), key(scene, tracer));
  EXPECT_EQ(key(scene, cycles), key(scene, cycles));
  EXPECT_NE(key(scene, tracer), key(scene, cycles));
  RunOptions more = tracer;
  more.spp = 7;
  EXPECT_NE(key(scene, tracer), key(scene, more));
  // Another Blender, and the same one rewritten (another size and time), render anew.
  RunOptions other = cycles;
  other.blender = b;
  EXPECT_NE(key(scene, cycles), key(scene, other));
  const std::string before = key(scene, cycles);
  std::ofstream(a, std::ios::app) << "# upgraded\n";
  fs::last_write_time(a, fs::last_write_time(a) + std::chrono::seconds(10));
  EXPECT_NE(key(scene, cycles), before);
  // Each band group's samples, and which groups are guided with what threshold, render anew.
  RunOptions planned = cycles;
  planned.cycles_samples = {256, 32};
  RunOptions guided = planned;
  guided.cycles_guided_groups = {1};
  RunOptions adaptive = guided;
  adaptive.cycles_guided_threshold = 0.01;
  EXPECT_NE(key(scene, planned), key(scene, cycles));
  EXPECT_NE(key(scene, guided), key(scene, planned));
  EXPECT_NE(key(scene, adaptive), key(scene, guided));
  // The tracer's key does not depend on any Blender.
  RunOptions tracer_with_blender = tracer;
  tracer_with_blender.blender = b;
  EXPECT_EQ(key(scene, tracer), key(scene, tracer_with_blender));
}

}  // namespace
}  // namespace ct::series
