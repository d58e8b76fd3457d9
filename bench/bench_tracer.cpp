// SPDX-License-Identifier: Apache-2.0
// Reference tracer throughput and noise at a fixed time budget, on the paper box and the Cornell box.
//
// For each configuration, B independent renders (different seeds) each get the same time budget. Reported:
// paths per second, the standard error of the image mean (the spread of the B image means), and the
// efficiency 1 / (SE² · seconds) — all as ratios to the baseline configuration run in this same process
// (bands mode, all threads), because absolute times on a shared machine are noisy.
//
//   bench_tracer [--seconds S] [--batches B] [--resolution N]
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "core/parallel.h"
#include "core/scene.h"
#include "reference_tracer/render.h"

namespace {

struct Result {
  double paths_per_second = 0, se = 0, mean = 0, seconds = 0;
  int samples = 0;
};

Result measure(const ct::Scene& scene, ct::SpectralMode mode, int threads, double seconds, int batches) {
  std::vector<double> means;
  double paths = 0, time = 0;
  int samples = 0;
  for (int b = 0; b < batches; ++b) {
    ct::rt::RenderOptions options;
    options.samples = 1 << 20;  // the time budget decides
    options.time_limit_s = seconds;
    options.mode = mode;
    options.seed = 1000 + static_cast<std::uint64_t>(b);
    options.threads = threads;
    options.progress = false;
    options.components = {false, false, false};
    const ct::rt::RenderedImage image = ct::rt::render(scene, options);
    double sum = 0;
    for (float v : image.layers[0]) sum += v;
    means.push_back(sum / static_cast<double>(image.layers[0].size()));
    paths += static_cast<double>(image.paths);
    time += image.seconds;
    samples += image.samples;
  }
  Result r;
  double m = 0, m2 = 0;
  for (double v : means) m += v / batches;
  for (double v : means) m2 += (v - m) * (v - m) / (batches - 1);
  r.mean = m;
  r.se = std::sqrt(m2);  // the SE of one render of the budget
  r.paths_per_second = paths / time;
  r.seconds = time / batches;
  r.samples = samples / batches;
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 2.0;
  int batches = 5, resolution = 128;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--seconds") seconds = std::stod(argv[i + 1]);
    else if (a == "--batches") batches = std::stoi(argv[i + 1]);
    else if (a == "--resolution") resolution = std::stoi(argv[i + 1]);
  }
  const std::string root = CHROMATRACE_SOURCE_DIR;
  fmt::print("Reference tracer, {} s per render, {} renders per row, {}x{} pixels, {} hardware threads\n\n", seconds,
             batches, resolution, resolution, ct::thread_count(0));
  fmt::print("{:<12} {:<11} {:>7} {:>8} {:>12} {:>11} {:>10} {:>9} {:>11}\n", "scene", "mode", "threads", "spp",
             "paths/s", "image mean", "SE", "speed", "efficiency");
  for (const char* file : {"scenes/paper/box.json", "scenes/cornell_box/cornell_box.json"}) {
    ct::Scene scene = ct::load_scene(root + "/" + file);
    scene.camera.width = scene.camera.height = resolution;
    Result baseline;
    struct Config {
      ct::SpectralMode mode;
      int threads;
    };
    for (const Config c : {Config{ct::SpectralMode::Bands, 0}, Config{ct::SpectralMode::Bands, 1},
                           Config{ct::SpectralMode::Continuous, 0}}) {
      const Result r = measure(scene, c.mode, c.threads, seconds, batches);
      if (c.mode == ct::SpectralMode::Bands && c.threads == 0) baseline = r;
      const double efficiency = 1.0 / (r.se * r.se * r.seconds);
      const double base_efficiency = 1.0 / (baseline.se * baseline.se * baseline.seconds);
      fmt::print("{:<12} {:<11} {:>7} {:>8} {:>12.4g} {:>11.5g} {:>10.3g} {:>8.2f}x {:>10.2f}x\n", scene.name,
                 c.mode == ct::SpectralMode::Bands ? "bands" : "continuous", ct::thread_count(c.threads), r.samples,
                 r.paths_per_second, r.mean, r.se, r.paths_per_second / baseline.paths_per_second,
                 efficiency / base_efficiency);
    }
  }
  fmt::print("\nspeed and efficiency are relative to the scene's first row (bands mode, all threads).\n"
             "Efficiency = 1 / (SE² · seconds): how much noise a second of rendering removes.\n"
             "Note: continuous mode carries 4 wavelengths per path, bands mode all bands of the plan.\n");
  return 0;
}
