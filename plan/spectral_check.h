// SPDX-License-Identifier: Apache-2.0
#pragma once
// Where a band plan cannot hold a scene's colours, found before rendering (check-scene, render, the study's
// stability table; docs/stability.md). A band-mode render multiplies band averages: light E and reflectance R give
// ⟨R⟩⟨E⟩ in each band where the truth is ⟨R·E⟩, which is exact only where one of them is flat within the band. A
// light with narrow peaks (fluorescent lamps such as CIE F11, narrow-band LEDs) or a narrow-band reflectance makes
// the two differ. For every light and every material's diffuse reflectance this computes, at 1 nm through the CIE
// 1931 observer, the colour of the material lit directly by the light with the plan's bands against the exact
// one, as ΔE00 in CIELAB under the light's white (the material at its own luminance); a surface lit by that
// light alone shows at least this error (interreflection multiplies more band averages and adds to it). The
// continuous spectral mode evaluates spectra at exact wavelengths and has no such error.

#include <string>
#include <vector>

#include "core/scene.h"

namespace ct::plan {

struct SpectralWarning {
  std::string light;     // the light's name ("environment" for the environment)
  std::string material;  // the material's name; empty: the light seen directly
  double de00 = 0;       // banded against exact
  bool light_is_cause = true;  // the light's spectrum (else the reflectance) is what the bands cannot follow
  std::string message;   // one line: the cause, how large, the fix
};

// Pairs whose ΔE00 exceeds `threshold`, worst first; none in the continuous mode. Textured reflectances and
// lights are left out (their spectra differ from texel to texel). The default, 2, is a difference seen at a glance
// (1 needs a close side-by-side look): one surface's colour, where plans aim at a mean of 1 over the image. The
// fix names the continuous mode only where the renderer has it (`continuous_available`: the tracer, not Cycles).
std::vector<SpectralWarning> check_band_plan(const Scene& scene, const Bands& bands, SpectralMode mode,
                                             double threshold = 2.0, bool continuous_available = true);

}  // namespace ct::plan
