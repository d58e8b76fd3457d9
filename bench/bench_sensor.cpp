// SPDX-License-Identifier: Apache-2.0
// Sensor simulator throughput and memory against the I/O limit (bench/README.md, "Sensor simulator").
//
// A 1024×1024, 31-band spectral EXR (130 MB of floats) goes through the sensor; beside it, in the same process,
// the same file is only read (the layers the sensor reads, in the same blocks) and the sensor's own output
// written again with the same writer (its pixels loaded beforehand, as compression time depends on them): the
// I/O limit. Times are medians of alternating runs, to be fair on a shared machine. Peak memory is measured
// in child processes, one per task, as the peak resident set (ru_maxrss) and as its rise during the task
// above what the process held before it (the shared libraries alone take over 100 MB of resident pages).
//
//   bench_sensor [--size N] [--runs R] [--preset NAME] [--threads T] [--keep DIR]
//   bench_sensor --child make|io|sensor IN OUT PRESET THREADS      (used by the parent)
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "core/parallel.h"
#include "core/random.h"
#include "core/spectral_exr.h"
#include "sensor_sim/config.h"
#include "sensor_sim/output.h"
#include "sensor_sim/pipeline.h"

namespace {

namespace fs = std::filesystem;

constexpr int kBands = 31;  // 400–710 nm, 10 nm wide
constexpr int kRowsPerWrite = 64;

// A smooth scene with per-pixel noise like a Monte Carlo render's, so that compression is as hard as on real
// renders (pure gradients would compress unrealistically well).
void make_input(const fs::path& path, int size) {
  ct::SpectralExrLayout layout;
  layout.width = layout.height = size;
  layout.bands = ct::Bands::uniform(400, 400 + 10 * kBands, 10);
  layout.attributes["chromatrace.camera"] =
      fmt::format(R"({{"horizontal_fov_deg": 40, "vertical_fov_deg": 40, "resolution": [{}, {}]}})", size, size);
  ct::SpectralExrWriter writer(path, layout);
  std::vector<float> rows(static_cast<std::size_t>(kRowsPerWrite) * static_cast<std::size_t>(size) * kBands);
  for (int y0 = 0; y0 < size; y0 += kRowsPerWrite) {
    const int n = std::min(kRowsPerWrite, size - y0);
    for (int r = 0; r < n; ++r)
      for (int x = 0; x < size; ++x) {
        ct::Random noise(
            7, static_cast<std::uint64_t>(y0 + r) * static_cast<std::uint64_t>(size) + static_cast<std::uint64_t>(x));
        const double u = double(x) / size, v = double(y0 + r) / size;
        for (int b = 0; b < kBands; ++b) {
          const double smooth = 0.5 + 0.4 * std::sin(6 * u + 0.2 * b) * std::cos(5 * v - 0.1 * b);
          rows[(static_cast<std::size_t>(r) * static_cast<std::size_t>(size) + static_cast<std::size_t>(x)) * kBands +
               static_cast<std::size_t>(b)] = static_cast<float>(smooth * (0.8 + 0.4 * noise.uniform()));
        }
      }
    ct::SpectralRowBlock block;
    block.rows = n;
    block.total =
        std::span<const float>(rows).first(static_cast<std::size_t>(n) * static_cast<std::size_t>(size) * kBands);
    writer.write_rows(block);
  }
  writer.finish();
}

// The sensor's output image, held in memory: R, G, B and linear.R/G/B, [y][x][channel].
struct OutputPixels {
  std::vector<float> image, linear;
};

OutputPixels load_output(const fs::path& file) {
  ct::SpectralExrReader reader(file);
  const ct::SpectralExrInfo& info = reader.info();
  OutputPixels pixels;
  const std::size_t n = static_cast<std::size_t>(info.width) * static_cast<std::size_t>(info.height) * 3;
  pixels.image.resize(n);
  pixels.linear.resize(n);
  reader.read_channels({"R", "G", "B"}, 0, info.height, pixels.image);
  reader.read_channels({"linear.R", "linear.G", "linear.B"}, 0, info.height, pixels.linear);
  return pixels;
}

// The I/O alone: the total read in the sensor's blocks, and `pixels` written in an output of the sensor's layout.
void io_only(const fs::path& input, const fs::path& output, const OutputPixels& pixels) {
  ct::SpectralExrReader reader(input);
  const ct::SpectralExrInfo& info = reader.info();
  const ct::SpectralLayer& total = info.total();
  ct::sensor::OutputLayout layout;
  layout.width = info.width;
  layout.height = info.height;
  ct::sensor::SensorImageWriter writer(output, layout);
  const std::size_t row_bytes = static_cast<std::size_t>(info.width) * info.bands.size() * sizeof(float);
  const int rows = std::max(16, static_cast<int>((std::size_t{8} << 20) / row_bytes) / 16 * 16);
  std::vector<float> spectral;
  for (int y0 = 0; y0 < info.height; y0 += rows) {
    const int y1 = std::min(info.height, y0 + rows);
    const std::size_t first = static_cast<std::size_t>(y0) * static_cast<std::size_t>(info.width) * 3;
    const std::size_t count = static_cast<std::size_t>(y1 - y0) * static_cast<std::size_t>(info.width) * 3;
    spectral.resize(count / 3 * info.bands.size());
    reader.read_rows(total, y0, y1, spectral);
    ct::sensor::OutputRows block;
    block.rows = y1 - y0;
    block.image = std::span<const float>(pixels.image).subspan(first, count);
    block.linear = std::span<const float>(pixels.linear).subspan(first, count);
    writer.write_rows(block);
  }
  writer.finish();
}

void sensor(const fs::path& input, const fs::path& output, const std::string& preset, int threads) {
  const ct::sensor::SensorConfig config =
      ct::sensor::resolve_config({{{{"preset", preset}, {"exposure", {{"time_s", 2e-3}}}}, "bench"}});
  ct::sensor::RunOptions options;
  options.threads = threads;
  ct::sensor::simulate_sensor(input, output, config, options);
}

// The resident set now, from /proc/self/status (kB).
long resident_kb() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.starts_with("VmRSS:")) return std::stol(line.substr(6));
  return 0;
}

double seconds_of(const std::function<void()>& task) {
  const auto start = std::chrono::steady_clock::now();
  task();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

struct Memory {
  long peak_kb = 0;  // ru_maxrss of the child
  long rise_kb = 0;  // peak minus the resident set before the task
};

// Runs one task in a child process (this program with --child), which prints its memory figures.
Memory child_memory(const std::string& self, const std::string& args) {
  std::FILE* pipe = popen((self + " --child " + args).c_str(), "r");
  Memory m;
  if (pipe == nullptr || std::fscanf(pipe, "%ld %ld", &m.peak_kb, &m.rise_kb) != 2 || pclose(pipe) != 0)
    throw std::runtime_error("child failed: " + args);
  return m;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 7 && std::string(argv[1]) == "--child") {
    const std::string task = argv[2];
    ct::set_exr_threads(ct::thread_count(std::stoi(argv[6])));
    const long before = resident_kb();
    if (task == "make") make_input(argv[3], std::stoi(argv[5]));
    if (task == "io") io_only(argv[3], argv[4], load_output(argv[4]));
    if (task == "sensor") sensor(argv[3], argv[4], argv[5], std::stoi(argv[6]));
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    fmt::print("{} {}\n", usage.ru_maxrss, usage.ru_maxrss - before);
    return 0;
  }
  int size = 1024, runs = 5, threads = 0;
  std::string preset = "canon_eos_5d_mkiii";
  fs::path dir = fs::temp_directory_path() / fmt::format("chromatrace-bench-sensor-{}", ::getpid());
  bool keep = false;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--size")
      size = std::stoi(argv[i + 1]);
    else if (a == "--runs")
      runs = std::stoi(argv[i + 1]);
    else if (a == "--preset")
      preset = argv[i + 1];
    else if (a == "--threads")
      threads = std::stoi(argv[i + 1]);
    else if (a == "--keep")
      dir = argv[i + 1], keep = true;
  }
  const std::string self = fs::canonical("/proc/self/exe").string();
  fs::create_directories(dir);
  const std::string input = (dir / "input.exr").string(), out = (dir / "out.exr").string();
  const std::string t = std::to_string(threads);
  if (!fs::exists(input)) child_memory(self, fmt::format("make {} - {} {}", input, size, t));
  ct::set_exr_threads(ct::thread_count(threads));
  const double raw_mb = double(size) * size * kBands * 4 / 1e6;
  fmt::print(
      "Sensor simulator, {}x{} pixels x {} bands ({:.0f} MB of floats, {:.0f} MB on disk), preset {}, "
      "{} threads\n\n",
      size, size, kBands, raw_mb, double(fs::file_size(input)) / 1e6, preset, ct::thread_count(threads));

  sensor(input, out, preset, threads);
  const OutputPixels pixels = load_output(out);
  const std::string copy = (dir / "io.exr").string();
  std::vector<double> io_times, sensor_times;
  for (int r = 0; r < runs; ++r) {
    io_times.push_back(seconds_of([&] { io_only(input, copy, pixels); }));
    sensor_times.push_back(seconds_of([&] { sensor(input, out, preset, threads); }));
  }
  const Memory io = child_memory(self, fmt::format("io {} {} - {}", input, out, t));  // rewrites out.exr
  const Memory sim = child_memory(self, fmt::format("sensor {} {} {} {}", input, out, preset, t));
  const double io_s = median(io_times), sensor_s = median(sensor_times);
  fmt::print("| run | time (median of {}) | peak resident set | rise during the task |\n|---|---|---|---|\n", runs);
  fmt::print("| read + write only (I/O limit) | {:.2f} s | {:.0f} MB | {:.0f} MB |\n", io_s, io.peak_kb / 1024.0,
             io.rise_kb / 1024.0);
  fmt::print("| sensor ({}) | {:.2f} s | {:.0f} MB | {:.0f} MB |\n", preset, sensor_s, sim.peak_kb / 1024.0,
             sim.rise_kb / 1024.0);
  fmt::print("\nsensor / I/O time: {:.2f}x; the sensor's memory rise is {:.0f} % of the spectral image ({:.0f} MB)\n",
             sensor_s / io_s, 100.0 * sim.rise_kb * 1024.0 / (raw_mb * 1e6), raw_mb);
  if (!keep) fs::remove_all(dir);
  return 0;
}
