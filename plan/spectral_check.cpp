// SPDX-License-Identifier: Apache-2.0
#include "plan/spectral_check.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include <fmt/core.h>

#include "core/cie.h"
#include "core/colour.h"
#include "plan/spectral_grid.h"

namespace ct::plan {
namespace {

// A spectrum on the 1 nm grid [lo, hi].
using Samples = std::vector<double>;

Samples sample(const PiecewiseLinearSpectrum& s, const Grid& grid) {
  return grid.sample([&](double nm) { return s(nm); }).v;
}

// The samples band b holds: [a, e) of `count` samples starting at `lo` nm (the last band also holds the last).
std::pair<int, int> band_span(const Bands& bands, std::size_t b, int lo, std::size_t count) {
  const int last = static_cast<int>(count) - 1;
  const int a = std::clamp(static_cast<int>(std::lround(bands.lo(b))) - lo, 0, last);
  const int e = b + 1 == bands.size() ? last + 1 : std::clamp(static_cast<int>(std::lround(bands.hi(b))) - lo, 0, last + 1);
  return {a, e};
}

// The band values themselves: each band's average over its samples (0 for a band that holds none).
std::vector<double> band_values(const Samples& s, const Bands& bands, int lo) {
  std::vector<double> out(bands.size(), 0.0);
  for (std::size_t b = 0; b < bands.size(); ++b) {
    const auto [a, e] = band_span(bands, b, lo, s.size());
    if (e <= a) continue;
    double sum = 0;
    for (int i = a; i < e; ++i) sum += s[i];
    out[b] = sum / (e - a);
  }
  return out;
}

// The spectrum as the band plan holds it: each band's average, flat over the band. Sample i stands for
// [i − ½, i + ½] nm (as tristimulus() sums, the two ends halved), so a band [lo, hi) holds the samples lo … hi − 1 (the last also hi), and bands
// of 1 nm hold every sample as it is.
Samples banded(const Samples& s, const Bands& bands, int lo) {
  Samples out(s.size(), 0.0);
  const std::vector<double> values = band_values(s, bands, lo);
  for (std::size_t b = 0; b < bands.size(); ++b) {
    const auto [a, e] = band_span(bands, b, lo, s.size());
    for (int i = a; i < e; ++i) out[i] = values[b];
  }
  return out;
}

Samples product(const Samples& a, const Samples& b) {
  Samples out(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) out[i] = a[i] * b[i];
  return out;
}

std::string describe(const Bands& bands) {
  bool uniform = true;
  for (std::size_t b = 1; b < bands.size(); ++b) uniform = uniform && std::abs(bands.width(b) - bands.width(0)) < 1e-6;
  return uniform ? fmt::format("{} bands of {:.3g} nm", bands.size(), bands.width(0)) : fmt::format("{} bands", bands.size());
}

}  // namespace

std::vector<SpectralWarning> check_band_plan(const Scene& scene, const Bands& bands, SpectralMode mode, double threshold,
                                             bool continuous_available) {
  const char* continuous = continuous_available ? ", or --spectral-mode continuous" : "";
  std::vector<SpectralWarning> out;
  if (mode == SpectralMode::Continuous || bands.size() == 0) return out;
  const int lo = static_cast<int>(std::ceil(bands.min_wavelength() - 1e-9));
  const int hi = static_cast<int>(std::floor(bands.max_wavelength() + 1e-9));
  if (hi - lo < 2) return out;
  const Grid grid{lo, hi};
  const std::array<const PiecewiseLinearSpectrum*, 3> curves = {&cie::x_bar(), &cie::y_bar(), &cie::z_bar()};
  Observer cmf;
  for (int c = 0; c < 3; ++c) cmf[c] = grid.sample([&](double nm) { return (*curves[c])(nm); });
  const Samples flat = grid.constant(1.0).v;

  std::vector<std::pair<std::string, Samples>> lights;
  for (const Light& l : scene.lights)
    if (!l.radiance.texture) lights.emplace_back(l.name, sample(l.radiance.spectrum, grid));
  if (scene.environment && !scene.environment->radiance.texture)
    lights.emplace_back("environment", sample(scene.environment->radiance.spectrum, grid));

  // ΔE00 of reflectance `r` lit by `e`: banded against exact, under the white of `e`.
  auto error = [&](const Samples& r, const Samples& e) {
    Vec3d white = tristimulus(e, cmf);
    if (!(white[1] > 0)) return 0.0;
    const Vec3d exact = tristimulus(product(r, e), cmf);
    Vec3d approx;
    if (bands.reconstruction()) {
      // The render's band values ⟨R⟩⟨E⟩, turned into a colour through the bands' reconstruction.
      std::vector<double> v = band_values(r, bands, lo);
      const std::vector<double> ve = band_values(e, bands, lo);
      for (std::size_t b = 0; b < v.size(); ++b) v[b] *= ve[b];
      approx = bands_to_xyz(v, bands);
    } else {
      approx = tristimulus(product(banded(r, bands, lo), banded(e, bands, lo)), cmf);
    }
    return delta_e_2000(xyz_to_lab(approx, white), xyz_to_lab(exact, white));
  };
  for (const auto& [light, e] : lights) {
    // The light seen directly (a white surface): its own colour through the bands.
    const double direct = error(flat, e);
    if (direct > threshold)
      out.push_back({light, "", direct, true,
                     fmt::format("light \"{}\": {} give its own colour a ΔE00 of {:.1f} (its spectrum has narrow peaks "
                                 "the bands average away); use bands fitted to it (chromatrace plan) or narrower ones "
                                 "where it peaks{}",
                                 light, describe(bands), direct, continuous)});
    for (const Material& m : scene.materials) {
      const SpectrumRef& ref = m.reflectance_spectrum();
      if (ref.texture) continue;
      const Samples r = sample(ref.spectrum, grid);
      const double de = error(r, e);
      if (!(de > threshold) || !(de > direct)) continue;
      // Whose spectrum the bands cannot follow: the reflectance, if it is off under flat light too.
      const bool reflectance_cause = error(r, flat) > 0.5 * de;
      out.push_back({light, m.name, de, !reflectance_cause,
                     fmt::format("material \"{}\" lit by \"{}\": {} give its colour a ΔE00 of {:.1f} ({}); use bands "
                                 "fitted to the scene (chromatrace plan) or narrower ones{}",
                                 m.name, light, describe(bands), de,
                                 reflectance_cause ? "its reflectance changes faster than the bands"
                                                   : "the light's spectrum has narrow peaks the bands average away",
                                 continuous)});
    }
  }
  std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.de00 > b.de00; });
  return out;
}

}  // namespace ct::plan
