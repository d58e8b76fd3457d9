// SPDX-License-Identifier: Apache-2.0
// The RGB upsampling table against the exact fit (bench/README.md, "RGB upsampling table").
//
// For each table resolution: the time to compute the table, then over a dense set of colours the error of the
// table's spectrum against the exact per-colour fit (core/rgb_to_spectrum.h) — CIEDE2000 between their colours
// under D65, and the largest difference of their 10 nm band averages over 360–830 nm relative to the spectrum's
// peak — and the round trip of each (spectrum -> XYZ under D65 -> linear sRGB against the input, as ΔE00 and as
// the largest component error). Reflectances: uniform in linear [0, 1]³, uniform in sRGB-encoded [0, 1]³ (as
// 8-bit photographs are) and the 8-bit sRGB grid of every S-th code (default 5). Radiances: random colours over 6 decades,
// compared after dividing by their scale 2·max(r, g, b) (the shape is what the table gives). Last, the time per
// colour of the exact fit and of a table lookup.
//
//   bench_rgb_table [--resolutions 17,33,65] [--samples N] [--grid-step S] [--threads T] [--embedded]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "core/colour.h"
#include "core/parallel.h"
#include "core/random.h"
#include "core/rgb_to_spectrum.h"

namespace {

using ct::Vec3d;

double seconds(const std::function<void()>& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

Vec3d lab_of(const Vec3d& linear_srgb) {
  static const Vec3d white = ct::xyY_to_xyz({0.31271, 0.32902, 1.0});
  return ct::xyz_to_lab(ct::linear_srgb_to_xyz(linear_srgb), white);
}

// Band averages over 360–830 nm in 10 nm bands of the tabulated spectrum.
std::vector<double> bands_of(const ct::SigmoidPolynomial& p) {
  static const ct::Bands bands = ct::Bands::parse("360:830:10");
  return ct::band_averages(ct::ScaledSigmoid{1.0, p}.tabulated(), bands);
}

struct Errors {
  double de_max = 0, de_sum2 = 0;          // table vs exact, ΔE00
  double band_max = 0, band_sum2 = 0;      // table vs exact, band averages / peak
  double rt_de_max = 0, rt_rgb_max = 0;    // table round trip
  double exact_rt_de_max = 0;              // exact fit round trip
  Vec3d worst{};                           // colour of de_max
  std::size_t count = 0;
  void add(const Errors& e) {
    if (e.de_max > de_max) worst = e.worst;
    de_max = std::max(de_max, e.de_max);
    de_sum2 += e.de_sum2;
    band_max = std::max(band_max, e.band_max);
    band_sum2 += e.band_sum2;
    rt_de_max = std::max(rt_de_max, e.rt_de_max);
    rt_rgb_max = std::max(rt_rgb_max, e.rt_rgb_max);
    exact_rt_de_max = std::max(exact_rt_de_max, e.exact_rt_de_max);
    count += e.count;
  }
};

// Errors of one reflectance colour (in [0, 1]³); `exact` is its exact fit.
Errors measure(const ct::RgbCoefficientTable& table, const Vec3d& rgb, const ct::SigmoidPolynomial& exact) {
  const ct::SigmoidPolynomial got = table.lookup(rgb);
  const Vec3d got_rgb = ct::reflectance_linear_srgb(got), exact_rgb = ct::reflectance_linear_srgb(exact);
  Errors e;
  e.count = 1;
  e.de_max = ct::delta_e_2000(lab_of(got_rgb), lab_of(exact_rgb));
  e.de_sum2 = e.de_max * e.de_max;
  e.worst = rgb;
  const std::vector<double> a = bands_of(got), b = bands_of(exact);
  const double peak = std::max(*std::max_element(b.begin(), b.end()), 1e-300);
  for (std::size_t i = 0; i < a.size(); ++i) e.band_max = std::max(e.band_max, std::abs(a[i] - b[i]) / peak);
  e.band_sum2 = e.band_max * e.band_max;
  e.rt_de_max = ct::delta_e_2000(lab_of(got_rgb), lab_of(rgb));
  for (int c = 0; c < 3; ++c) e.rt_rgb_max = std::max(e.rt_rgb_max, std::abs(got_rgb[c] - rgb[c]));
  e.exact_rt_de_max = ct::delta_e_2000(lab_of(exact_rgb), lab_of(rgb));
  return e;
}

struct ColourSet {
  std::string name;
  std::vector<Vec3d> colours;  // reflectances in [0, 1]³ (radiances already divided by their scale)
  std::vector<ct::SigmoidPolynomial> exact;
};

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> resolutions = {17, 33, 65};
  int samples = 20000, threads = 0, grid_step = 5;
  bool embedded = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--resolutions" && i + 1 < argc) {
      resolutions.clear();
      std::stringstream list(argv[++i]);
      for (std::string item; std::getline(list, item, ',');) resolutions.push_back(std::stoi(item));
    } else if (a == "--samples" && i + 1 < argc) samples = std::stoi(argv[++i]);
    else if (a == "--threads" && i + 1 < argc) threads = std::stoi(argv[++i]);
    else if (a == "--grid-step" && i + 1 < argc) grid_step = std::stoi(argv[++i]);
    else if (a == "--embedded") embedded = true;
    else {
      fmt::print(stderr, "usage: bench_rgb_table [--resolutions 17,33,65] [--samples N] [--grid-step S] [--threads T] [--embedded]\n");
      return 2;
    }
  }
  threads = ct::thread_count(threads);

  std::vector<ColourSet> sets(4);
  sets[0].name = "reflectance, uniform linear";
  sets[1].name = "reflectance, uniform sRGB-encoded";
  sets[2].name = fmt::format("reflectance, 8-bit grid /{}", grid_step);
  sets[3].name = "radiance, 1e-3..1e3, / scale";
  for (int s = 0; s < samples; ++s) {
    ct::Random r(7, static_cast<std::uint64_t>(s));
    sets[0].colours.push_back({r.uniform(), r.uniform(), r.uniform()});
    sets[1].colours.push_back({ct::srgb_decode(r.uniform()), ct::srgb_decode(r.uniform()), ct::srgb_decode(r.uniform())});
    const double m = std::pow(10.0, -3.0 + 6.0 * r.uniform());
    const Vec3d radiance = {m * r.uniform(), m * r.uniform(), m * r.uniform()};
    const double scale = 2.0 * std::max({radiance[0], radiance[1], radiance[2]});
    sets[3].colours.push_back({radiance[0] / scale, radiance[1] / scale, radiance[2] / scale});
  }
  for (int rr = 0; rr <= 255; rr += grid_step)
    for (int gg = 0; gg <= 255; gg += grid_step)
      for (int bb = 0; bb <= 255; bb += grid_step)
        sets[2].colours.push_back({ct::srgb_decode(rr / 255.0), ct::srgb_decode(gg / 255.0), ct::srgb_decode(bb / 255.0)});

  std::size_t total = 0;
  const double fit_seconds = seconds([&] {
    for (ColourSet& set : sets) {
      set.exact.resize(set.colours.size());
      ct::parallel_for(set.colours.size(), threads, [&](std::size_t i) { set.exact[i] = ct::fit_rgb_reflectance(set.colours[i]); });
      total += set.colours.size();
    }
  });
  fmt::print("exact fits of {} colours: {:.1f} s on {} threads ({:.0f} µs of CPU per colour)\n\n", total, fit_seconds,
             threads, 1e6 * fit_seconds * threads / static_cast<double>(total));

  std::vector<std::pair<std::string, ct::RgbCoefficientTable>> tables;
  for (const int n : resolutions) {
    ct::RgbCoefficientTable table;
    const double t = seconds([&] { table = ct::RgbCoefficientTable::compute(n, threads); });
    fmt::print("resolution {}: computed in {:.2f} s on {} threads, {:.1f} MB\n", n, t, threads,
               static_cast<double>(table.bytes().size()) * 1e-6);
    tables.emplace_back(fmt::format("table {}", n), std::move(table));
  }
  if (embedded) tables.emplace_back(fmt::format("embedded ({})", ct::rgb_table().resolution()), ct::rgb_table());

  fmt::print("\n| table | colours | ΔE00 vs exact max | rms | band avg vs exact max | rms | round trip ΔE00 max | "
             "max rgb error | exact fit round trip ΔE00 max | worst colour (linear sRGB) |\n|---|---|---|---|---|---|---|---|---|---|\n");
  for (const auto& [name, table] : tables)
    for (const ColourSet& set : sets) {
      std::vector<Errors> per(set.colours.size());
      ct::parallel_for(set.colours.size(), threads, [&](std::size_t i) { per[i] = measure(table, set.colours[i], set.exact[i]); });
      Errors e;
      for (const Errors& p : per) e.add(p);
      const double n = static_cast<double>(e.count);
      fmt::print("| {} | {}: {} | {:.2e} | {:.2e} | {:.2e} | {:.2e} | {:.2e} | {:.2e} | {:.2e} | ({:.4g}, {:.4g}, {:.4g}) |\n",
                 name, set.name, e.count, e.de_max, std::sqrt(e.de_sum2 / n), e.band_max, std::sqrt(e.band_sum2 / n),
                 e.rt_de_max, e.rt_rgb_max, e.exact_rt_de_max, e.worst[0], e.worst[1], e.worst[2]);
    }

  // Time per colour, one thread: the exact fit against a lookup of the last table.
  const ct::RgbCoefficientTable& table = tables.back().second;
  const std::vector<Vec3d>& colours = sets[0].colours;
  const std::size_t fits = std::min<std::size_t>(colours.size(), 2000);
  double sink = 0;
  const double fit_time = seconds([&] {
    for (std::size_t i = 0; i < fits; ++i) sink += ct::fit_rgb_reflectance(colours[i]).c[0];
  }) / static_cast<double>(fits);
  const int lookups = 20;
  const double lookup_time = seconds([&] {
    for (int rep = 0; rep < lookups; ++rep)
      for (const Vec3d& c : colours) sink += table.lookup(c).c[0];
  }) / (static_cast<double>(lookups) * static_cast<double>(colours.size()));
  fmt::print("\none thread: exact fit {:.1f} µs per colour, {} lookup {:.3f} µs per colour ({:.0f}x) [{}]\n", fit_time * 1e6,
             tables.back().first, lookup_time * 1e6, fit_time / lookup_time, sink != 0 ? "ok" : "-");
  return 0;
}
