// SPDX-License-Identifier: Apache-2.0
// prepare-texture throughput and cache size against the I/O limit (bench/README.md, "Texture preparation").
//
// A synthetic texture (a 4096×4096 8-bit sRGB PNG reflectance by default; --hdr: a 4096×2048 float EXR
// radiance, every texel its own colour) goes through prepare_texture (core/texture_prep.h) for a band plan.
// Beside it, in the same process: the image only read with OpenImageIO and written back as float RGB EXRs (ZIP),
// as many as there are band groups (the I/O limit), and the second, cached call. Times are medians of
// alternating runs. Then the two stages that depend on the number of distinct colours, timed alone: the
// upsampling through the coefficient table (upsample_texels) and the band averages (palette_band_averages);
// and the exact per-colour fit (core/rgb_to_spectrum.h) timed on a sample of the distinct colours, which gives
// the time the upsampling would take without the table.
//
//   bench_prepare_texture [--width W] [--height H] [--bands lo:hi:w] [--runs R] [--threads T] [--noise N] [--levels L]
//                         [--hdr] [--keep DIR]
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>
#include <fmt/core.h>

#include "core/parallel.h"
#include "core/random.h"
#include "core/rgb_to_spectrum.h"
#include "core/spectral_exr.h"
#include "core/band_plan.h"
#include "core/texture_prep.h"

namespace {

namespace fs = std::filesystem;

// Smooth colour fields with per-texel noise (--noise N: ±N/2 8-bit levels, default 0; 1 % in the HDR). The number
// of distinct colours, which decides the time (each is fitted once), grows quickly with the noise. --levels L
// posterises each 8-bit channel to L levels instead (at most L³ colours).
void make_texture(const fs::path& path, int width, int height, bool hdr, double noise_levels, int levels) {
  std::vector<float> pixels(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const std::size_t t = static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
      ct::Random noise(11, t);
      const double u = double(x) / width, v = double(y) / height;
      for (int c = 0; c < 3; ++c) {
        double value = 0.5 + 0.35 * std::sin(5 * u + 1.7 * c) * std::cos(4 * v - 0.9 * c);
        if (hdr) value = value * (1.0 + 0.01 * (noise.uniform() - 0.5)) * (v < 0.1 ? 20.0 : 1.0);
        else if (levels > 0) value = std::round(value * (levels - 1)) / (levels - 1);
        else value = std::clamp(std::round(value * 255 + noise_levels * (noise.uniform() - 0.5)), 0.0, 255.0) / 255.0;
        pixels[3 * t + static_cast<std::size_t>(c)] = static_cast<float>(value);
      }
    }
  auto out = OIIO::ImageOutput::create(path.string());
  OIIO::ImageSpec spec(width, height, 3, hdr ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
  if (!out || !out->open(path.string(), spec) || !out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()))
    throw std::runtime_error("cannot write " + path.string());
  out->close();
}

// The I/O limit: read the image as float RGB, write it `files` times as float RGB EXRs (ZIP).
void io_only(const fs::path& image, const fs::path& dir, std::size_t files) {
  auto in = OIIO::ImageInput::open(image.string());
  const OIIO::ImageSpec spec = in->spec();
  std::vector<float> pixels(static_cast<std::size_t>(spec.width) * static_cast<std::size_t>(spec.height) * 3);
  in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, pixels.data());
  fs::create_directories(dir);
  for (std::size_t f = 0; f < files; ++f) {
    const fs::path path = dir / fmt::format("io-{}.exr", f);
    auto out = OIIO::ImageOutput::create(path.string());
    OIIO::ImageSpec o(spec.width, spec.height, 3, OIIO::TypeDesc::FLOAT);
    o.attribute("compression", "zip");
    out->open(path.string(), o);
    out->write_image(OIIO::TypeDesc::FLOAT, pixels.data());
    out->close();
  }
}

double seconds(const std::function<void()>& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

std::uintmax_t directory_bytes(const fs::path& dir) {
  std::uintmax_t total = 0;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file()) total += e.file_size();
  return total;
}

}  // namespace

int main(int argc, char** argv) {
  int width = 4096, height = 0, runs = 3, threads = 0;
  std::string bands_text = "400:700:10";
  bool hdr = false, keep = false;
  double noise_levels = 0.0;
  int levels = 0;
  fs::path dir = fs::temp_directory_path() / fmt::format("ct-bench-prep-{}", ::getpid());
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--width" && has_value) width = std::stoi(argv[++i]);
    else if (a == "--height" && has_value) height = std::stoi(argv[++i]);
    else if (a == "--bands" && has_value) bands_text = argv[++i];
    else if (a == "--runs" && has_value) runs = std::stoi(argv[++i]);
    else if (a == "--threads" && has_value) threads = std::stoi(argv[++i]);
    else if (a == "--keep" && has_value) dir = argv[++i], keep = true;
    else if (a == "--noise" && has_value) noise_levels = std::stod(argv[++i]);
    else if (a == "--levels" && has_value) levels = std::stoi(argv[++i]);
    else if (a == "--hdr") hdr = true;
    else {
      fmt::print(stderr, "usage: bench_prepare_texture [--width W] [--height H] [--bands lo:hi:w] [--runs R] "
                         "[--threads T] [--noise N] [--levels L] [--hdr] [--keep DIR]\n");
      return 2;
    }
  }
  if (height == 0) height = hdr ? 2048 : 4096;
  threads = ct::thread_count(threads);
  ct::set_exr_threads(threads);
  OIIO::attribute("threads", threads);
  fs::create_directories(dir);
  const fs::path image = dir / (hdr ? "texture.exr" : "texture.png");
  make_texture(image, width, height, hdr, noise_levels, levels);

  ct::TexturePrepRequest request;
  request.image = image;
  request.use = hdr ? ct::TextureUse::Radiance : ct::TextureUse::Reflectance;
  request.bands = ct::Bands::parse(bands_text);
  request.threads = threads;
  const std::size_t groups = ct::cycles_band_groups(request.bands.size());

  std::vector<double> io, cold, cached;
  ct::TexturePrepResult result;
  for (int r = 0; r < runs; ++r) {
    fs::remove_all(dir / "io");
    io.push_back(seconds([&] { io_only(image, dir / "io", groups); }));
    fs::remove_all(dir / "cache");
    cold.push_back(seconds([&] { result = ct::prepare_texture(request, dir / "cache"); }));
    cached.push_back(seconds([&] { ct::prepare_texture(request, dir / "cache"); }));
  }
  const double mb = 1e-6;
  fmt::print("{}x{} {} {} ({} texels, {} distinct colours, {:.1f} MB file), bands {} ({} bands, {} groups), "
             "{} threads, median of {}\n\n",
             width, height, hdr ? "float EXR" : "8-bit sRGB PNG", hdr ? "radiance" : "reflectance", result.texels,
             result.distinct_colours, static_cast<double>(fs::file_size(image)) * mb, bands_text,
             request.bands.size(), groups, threads, runs);
  fmt::print("| run                                   | time     | on disk   | vs I/O |\n");
  fmt::print("| read + write {:2} EXRs only (I/O limit) | {:6.2f} s | {:6.0f} MB | 1.00x  |\n", groups, median(io),
             static_cast<double>(directory_bytes(dir / "io")) * mb, 1.0);
  fmt::print("| prepare-texture, first call           | {:6.2f} s | {:6.0f} MB | {:.2f}x  |\n", median(cold),
             static_cast<double>(directory_bytes(dir / "cache")) * mb, median(cold) / median(io));
  fmt::print("| prepare-texture, cached               | {:6.3f} s |           | {:.3f}x |\n", median(cached),
             median(cached) / median(io));

  // The stages that scale with the distinct colours, alone, and the exact fit on a sample of those colours.
  const ct::ImageTexture texture = ct::read_image_texture(image, image.string(), std::nullopt, request.use, 1.0);
  ct::TexelSpectra spectra;
  const double upsample = seconds([&] { spectra = ct::upsample_texels(texture, threads); });
  const double averages = seconds([&] { ct::palette_band_averages(spectra, request.bands, threads); });
  std::vector<std::array<double, 3>> sample;
  const std::size_t distinct = spectra.palette.size(), wanted = std::min<std::size_t>(distinct, 1000);
  {
    std::vector<bool> taken(distinct, false);
    for (std::size_t t = 0; t < texture.texel_count() && sample.size() < wanted; t += texture.texel_count() / wanted + 1)
      if (!taken[spectra.palette_of[t]]) {
        taken[spectra.palette_of[t]] = true;
        sample.push_back(texture.texel(t));
      }
  }
  std::vector<ct::ScaledSigmoid> fitted(sample.size());
  const double fit = seconds([&] {
    ct::parallel_for(sample.size(), threads, [&](std::size_t i) {
      fitted[i] = request.use == ct::TextureUse::Reflectance ? ct::ScaledSigmoid{1.0, ct::fit_rgb_reflectance(sample[i])}
                                                             : ct::fit_rgb_unbounded(sample[i]);
    });
  });
  // The table lookups alone, over every distinct colour (upsample_texels also finds the distinct colours).
  std::vector<std::array<double, 3>> colours(distinct);
  for (std::size_t t = 0; t < texture.texel_count(); ++t) colours[spectra.palette_of[t]] = texture.texel(t);
  std::vector<ct::ScaledSigmoid> looked_up(distinct);
  const double lookups = seconds([&] {
    ct::parallel_for(distinct, threads, [&](std::size_t i) { looked_up[i] = ct::texel_spectrum(colours[i], request.use); });
  });
  const double fit_all = fit / static_cast<double>(sample.size()) * static_cast<double>(distinct);
  fmt::print("\n| stage ({} distinct colours, {} threads)          | time     |\n", distinct, threads);
  fmt::print("| upsampling through the table (upsample_texels)   | {:6.2f} s |\n", upsample);
  fmt::print("|   the table lookups alone                        | {:6.2f} s |\n", lookups);
  fmt::print("| band averages of the palette                     | {:6.2f} s |\n", averages);
  fmt::print("| exact fit of {:4} of the colours                 | {:6.2f} s |\n", sample.size(), fit);
  fmt::print("| exact fit of all, extrapolated (no table)        | {:6.0f} s | {:.0f}x the table's lookups, {:.0f}x upsample_texels\n",
             fit_all, fit_all / lookups, fit_all / upsample);
  if (!keep) fs::remove_all(dir);
  return 0;
}
