// SPDX-License-Identifier: Apache-2.0
#pragma once
// The radiosity model behind plan's predictions (plan/plan.h): one patch per object and light, transfer factors
// between them from cosine-weighted rays, and the colour each surface shows after k scattering events.
//
// Transfer factors: for every surface id o (0 the background, then the objects, then the lights, as in an
// object-id image), cosine-weighted rays from points spread uniformly over its area, on the side of its surface
// that receives the most light (else: that sees the most of the scene). hits[o][j] is the fraction reaching
// surface id j (j = 0: none, the ray escapes), which for a Lambertian patch is its form factor F_oj; lit[o][l]
// the fraction reaching the emitting side of light l. The irradiance on o after k events is Σ_j F_oj·B_k−1,j
// (radiance units, a Lambertian sender) and the direct irradiance Σ_l lit_ol·E_l.
//
// Templates: per surface id, bounce order k and lobe (diffuse, glossy), the tristimulus values of what the camera
// sees: k = 0 the surface's own emission; k ≥ 1 its reflectance times the irradiance after k events. Computed in a
// basis: 1 nm samples (the exact spectra) or band averages (a band plan, as the renderers' bands mode).

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "core/colour.h"
#include "core/geometry.h"
#include "core/scene.h"
#include "core/spectrum.h"
#include "core/texture.h"
#include "plan/spectral_grid.h"

namespace ct::plan {

struct Transfer {
  std::vector<std::vector<double>> hits, lit;  // [id][id], [id][light]
};

// Transfer factors of the scene's surfaces (`meshes`: scene_meshes(scene)) from `samples` rays per surface and
// side. Deterministic: each surface's rays come from its own seeded stream.
Transfer transfer_factors(const Scene& scene, const std::vector<TriangleMesh>& meshes, int samples);

// What a surface of the scene contributes to the model, on the 1 nm grid.
struct Surface {
  Sampled emission;  // zero unless a light
  Sampled diffuse;   // R_o
  Sampled glossy;    // what a glossy bounce multiplies by
  Sampled albedo;    // what the surface sends on (diffuse + specular)
  bool emitter = false;
  // An image texture's colours (texture_colours: their shares sum to 1, the shares times the spectra to `diffuse`),
  // what a camera sees of the surface; empty for a surface of one spectrum.
  std::vector<std::pair<double, Sampled>> colours;
};

// The mean spectrum of an image texture where it is seen, its texels upsampled as the renderers upsample them
// (core/texture.h), the texture's scale included: `weight` per texel (its share of a surface's area or of the
// sphere of directions). Texels are pooled by colour first (reflectances on a grid of 1/64 per channel; radiances
// by chromaticity, rgb / max, on that grid, their magnitudes summed), each pool's mean colour upsampled once: within
// a pool the spectra differ by less than the sigmoid's change over 1/64 of a channel. 1 nm samples over 360–830 nm.
PiecewiseLinearSpectrum mean_texture_spectrum(const ImageTexture& texture, const std::vector<double>& weight);
// A texture's colours: its texels (by `weight`, as for mean_texture_spectrum) in at most `count` clusters of similar
// colour (weighted k-means in linear RGB), each with its share of the weight and its texels' mean spectrum (the
// texture's scale included). The shares times the spectra sum to mean_texture_spectrum; empty for a texture that
// is black wherever it is seen.
struct TextureColour {
  double share;
  PiecewiseLinearSpectrum spectrum;
};
std::vector<TextureColour> texture_colours(const ImageTexture& texture, const std::vector<double>& weight,
                                           std::size_t count);

// Each texel's share of the area of `mesh`, whose triangles' corners have the (u, v) `uvs` (core/geometry.h,
// corner_uvs): area-uniform points from a seeded stream, each looked up at its (u, v). Even shares when there are
// no (u, v).
std::vector<double> surface_texel_weights(const TriangleMesh& mesh, const std::vector<std::array<Vec2, 3>>& uvs,
                                          const ImageTexture& texture);
// corner_uvs of a light's shape.
std::vector<std::array<Vec2, 3>> light_corner_uvs(const Light& light);
// Each texel's share of the sphere of directions, for an equirectangular environment: a row's texels at polar angle
// θ cover solid angle ∝ sin θ.
std::vector<double> environment_texel_weights(const ImageTexture& texture);

// A light's emitted radiance (× its scale), a textured one's as its texels' mean over `mesh`, the light's shape.
PiecewiseLinearSpectrum emitted_mean_radiance(const Light& light, const TriangleMesh& mesh);
// The environment's radiance (× its scale), a textured one's as its texels' mean over the sphere of directions.
PiecewiseLinearSpectrum mean_environment_radiance(const Environment& environment);

// The scene's surfaces by id (0: the background, which sends the environment's or the scene's light and
// reflects the mean albedo), with the scene's light spectrum (`light`: scene_light_spectrum on the grid), the
// area-weighted mean albedo, and the environment (empty when the scene has none). An image texture is modelled
// as its texels' mean spectrum over the surface, or over the sphere of directions for the environment
// (mean_texture_spectrum), with a note: the spread of its colours about that mean is not modelled. `textured` is
// set when a material is an image texture (whose texels' spectra no reconstruction is fitted to: with
// `reconstruction`, a note says so).
struct SceneSurfaces {
  std::vector<Surface> surfaces;
  Sampled mean_albedo, environment;
  bool has_environment = false, textured = false;
};
SceneSurfaces scene_surfaces(const Scene& scene, const std::vector<TriangleMesh>& meshes, const Grid& grid,
                             const Sampled& light, bool reconstruction, std::vector<std::string>& notes);

// The model's spectra in one basis: 1 nm samples (exact) or band averages (a plan), with each basis element's
// weight in each observer channel.
struct Basis {
  std::array<std::vector<double>, 3> weight;
  std::vector<std::vector<double>> emission, diffuse, glossy, albedo;  // per surface id
  std::vector<double> light, mean_albedo, environment;
  std::size_t size() const { return light.size(); }
};

// The spectra behind the templates (in the basis), [id][k][lobe].
using TemplateSpectra = std::vector<std::vector<std::array<std::vector<double>, 2>>>;
using Templates = std::vector<std::vector<std::array<Vec3d, 2>>>;  // [id][k][lobe]

// Tristimulus values of every (id, k, lobe) template for k = 0 .. kmax, by radiosity over the transfer factors;
// where that gives no light (a surface no sampled ray lit), the mean-albedo model E·R·ρ̄^(k−1). With `spectra`,
// also the spectrum behind each.
Templates bounce_templates(const Basis& basis, const Transfer& transfer, int kmax, TemplateSpectra* spectra = nullptr);

}  // namespace ct::plan
