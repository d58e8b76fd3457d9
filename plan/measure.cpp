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
    const auto q = sensor::photon_response(r.info().bands, curves, sensor::ResponseBasis::Energy, 1.0,
                                           PiecewiseLinearSpectrum::constant(1.0));
    const std::vector<float> v = r.read_layer(r.info().total());
    const std::size_t nb = r.info().bands.size(), N = static_cast<std::size_t>(r.info().width) * r.info().height;
    std::vector<Vec3d> out(N);
    for (std::size_t p = 0; p < N; ++p)
      for (int c = 0; c < 3; ++c) {
        double s = 0;
        for (std::size_t b = 0; b < nb; ++b) s += q[c][b] * v[p * nb + b];
        out[p][c] = s;
      }
    return out;
  };
  const std::vector<Vec3d> xa = tristimuli(ra), xb = tristimuli(rb);
  const std::vector<Vec3d> xw = rw ? tristimuli(*rw) : xb;
  const std::size_t N = xa.size();
  std::vector<std::int32_t> ids(N, 0);
  if (iw.has_object_ids) white_reader.read_object_ids(0, iw.height, ids);
  const auto first_light = static_cast<std::int32_t>(scene.objects.size()) + 1;
  std::vector<double> ys;
  for (std::size_t p = 0; p < N; ++p)
    if (!near_light(ids, iw.width, iw.height, p, first_light)) ys.push_back(xw[p][1]);
  double yw = percentile(ys, 0.99);
  if (!(yw > 0)) yw = 1;
  // The white: the light through the observer over the white reference's band range.
  const PiecewiseLinearSpectrum light = scene_light_spectrum(scene);
  Vec3d white{};
  const double lo = iw.bands.min_wavelength(), hi = iw.bands.max_wavelength();
  for (int c = 0; c < 3; ++c) white[c] = integral_of_product(light, curves.curves[c], lo, hi);
  const double ws = white[1] > 0 ? yw / white[1] : 1.0;
  for (double& v : white) v = std::max(v * ws, 1e-300);
  std::vector<double> de(N);
  for (std::size_t p = 0; p < N; ++p) de[p] = delta_e_2000(xyz_to_lab(xa[p], white), xyz_to_lab(xb[p], white));
  Measurement m;
  m.pixels = N;
  m.mean = std::accumulate(de.begin(), de.end(), 0.0) / static_cast<double>(std::max<std::size_t>(N, 1));
  m.max = de.empty() ? 0 : *std::max_element(de.begin(), de.end());
  m.rms = std::sqrt(std::inner_product(de.begin(), de.end(), de.begin(), 0.0) / static_cast<double>(std::max<std::size_t>(N, 1)));
  m.p95 = percentile(de, 0.95);
  m.per_pixel = std::move(de);
  return m;
}

}  // namespace ct::plan
