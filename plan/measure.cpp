// SPDX-License-Identifier: Apache-2.0
// measure_delta_e: ΔE00 between two spectral EXR renders. Apart from plan.cpp so that plan's model, which
// `chromatrace check-scene` runs, is linked without OpenEXR (chromatrace_plan_model).
#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>

#include <fmt/core.h>

#include "core/colour.h"
#include "core/error.h"
#include "core/spectral_exr.h"
#include "core/render_delta_e.h"
#include "plan/plan.h"
#include "sensor_sim/spectral_response.h"

namespace ct::plan {

Measurement measure_delta_e(const std::filesystem::path& test, const std::filesystem::path& reference,
                            const Scene& scene, const std::string& camera, const std::filesystem::path& white_from) {
  const sensor::CameraCurves curves = sensor::camera_curves(camera, {"r", "g", "b"}, "--camera");
  SpectralExrReader ra(test), rb(reference);
  std::optional<SpectralExrReader> rw;
  if (!white_from.empty()) rw.emplace(white_from);
  SpectralExrReader& white_reader = rw ? *rw : rb;
  const SpectralExrInfo &ia = ra.info(), &ib = rb.info(), &iw = white_reader.info();
  for (const auto& [info, file] : {std::pair{&ia, &test}, std::pair{&iw, &white_from}})
    if (info->width != ib.width || info->height != ib.height)
      throw InputError(fmt::format("{}: {}x{} pixels but {} has {}x{}", file->string(), info->width, info->height,
                                   reference.string(), ib.width, ib.height));
  auto tristimuli = [&](SpectralExrReader& r) {
    const std::vector<float> v = r.read_layer(r.info().total());
    return sensor::camera_tristimulus(v, r.info().bands, curves,
                                      static_cast<std::size_t>(r.info().width) * r.info().height);
  };
  const std::vector<Vec3d> xa = tristimuli(ra), xb = tristimuli(rb);
  const std::vector<Vec3d> xw = rw ? tristimuli(*rw) : xb;
  std::vector<std::int32_t> ids(xa.size(), 0);
  if (iw.has_object_ids) white_reader.read_object_ids(0, iw.height, ids);
  const auto first_light = static_cast<std::int32_t>(scene.objects.size()) + 1;
  // The white: the scene's light through the observer over the white reference's band range.
  const PiecewiseLinearSpectrum light = scene_light_spectrum(scene);
  WhitePolicy policy;
  const double lo = iw.bands.min_wavelength(), hi = iw.bands.max_wavelength();
  for (int c = 0; c < 3; ++c) policy.light[c] = integral_of_product(light, curves.curves[c], lo, hi);
  const Vec3d white = white_point(
      xw, near_emitters(ids, iw.width, iw.height, [&](std::int32_t id) { return id >= first_light; }), policy);
  return delta_e_between(xa, xb, white);
}

}  // namespace ct::plan
