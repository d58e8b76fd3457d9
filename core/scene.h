// SPDX-License-Identifier: Apache-2.0
#pragma once
// Scenes (`chromatrace-scene/1`): reading, validation and the resolved data model that the reference tracer and the exporters use. The format, every key, its
// units and each material's BRDF are documented in docs/scene-format.md.
//
// Loading validates everything a renderer relies on (types, ranges, references by name, that files exist
// and parse, that meshes load), so that code using a Scene needs no checks of its own. Every problem is a
// ct::InputError of one line naming the file and the JSON path, e.g.
//   "box.json: objects[3].material: unknown material \"plstic\" (materials: wall, plastic)".

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "core/camera.h"
#include "core/geometry.h"
#include "core/json_input.h"
#include "core/spectrum.h"
#include "core/texture.h"

namespace ct {

inline constexpr std::string_view kSceneFormat = "chromatrace-scene/1";
inline constexpr std::string_view kSpectraFormat = "chromatrace-spectra/1";

// ---- Spectra and materials --------------------------------------------------------------------------

struct NamedSpectrum {
  std::string name;
  PiecewiseLinearSpectrum spectrum;
  // The colour of an {"rgb"} source: where a radiance names this spectrum it is that colour relative to D65
  // (rgb_to_emission_spectrum), not `spectrum`, the colour's reflectance.
  std::optional<std::array<double, 3>> rgb;
};

// A spectrum as a material or light uses it: resolved, and named when it came from `spectra`. A colour input
// may instead be an image texture (docs/scene-format.md, "Textures"): then `texture` is set, `spectrum` is
// empty and the spectrum varies over the surface's (u, v), or over directions for the environment.
struct SpectrumRef {
  std::string name;  // key in the scene's `spectra`; empty when given inline
  PiecewiseLinearSpectrum spectrum;
  std::shared_ptr<const ImageTexture> texture;  // shared by every input that names the same file
};

// f = R(λ) / π
struct LambertMaterial {
  SpectrumRef reflectance;
};

// f = ρ_d(λ) / π + k_s · f_lobe: a Lambertian body term plus a spectrally flat interface lobe (the
// reference tracer's reference_tracer/bsdf.h evaluates the lobes). Validation guarantees max ρ_d + k_s <= 1.
struct DichromaticMaterial {
  // GGX microfacet lobe, alpha = roughness² (Blender's convention), no Fresnel factor; roughness 0 is a
  // perfect mirror lobe. The Smith masking-shadowing term as Cycles has it: separable G1(wo)·G1(wi) up to
  // Blender 3.x (the default, the Debian 12 Blender the add-on runs), height-correlated
  // 1 / (1 + Λ(wo) + Λ(wi)) from Blender 4.0.
  enum class Masking { Separable, HeightCorrelated };
  struct Ggx {
    double roughness;
    Masking masking;  // no default here: a nested aggregate's initialiser would leave the variant unconstructible
    double alpha() const { return roughness * roughness; }
  };
  // Normalised modified Phong lobe (n + 2) / (2π) · cos^n of the angle to the mirror direction.
  struct Phong {
    double exponent;
  };

  SpectrumRef diffuse;
  double specular = 0.0;  // k_s
  std::variant<Ggx, Phong> lobe;
};

// Perfect specular reflection scaled by R(λ).
struct MirrorMaterial {
  SpectrumRef reflectance;
};

// Blender's Principled BSDF as Cycles evaluates it, for an opaque dielectric (no metal, transmission, coat, sheen,
// subsurface or emission; white specular tint): a GGX interface with the dielectric Fresnel over a diffuse base
// (docs/scene-format.md, "principled"). Version 2 (Blender 4.0 on): Lambert base attenuated by the interface's
// albedo at the view angle, height-correlated masking, Fresnel of `ior` (scaled by specular_ior_level), Multiscatter
// GGX's energy compensation unless distribution is plain GGX. Version 1 (Blender 3.x): Burley's diffuse with
// retro-reflection added to single-scatter GGX with separable masking and F0 = 0.08 · specular.
struct PrincipledMaterial {
  SpectrumRef base_color;
  double roughness = 0.5;
  int version = 2;
  double ior = 1.5;                 // version 2
  double specular_ior_level = 0.5;  // version 2
  double specular = 0.5;            // version 1
  bool multiscatter = true;         // version 2 only: Multiscatter GGX (Blender's default) or plain GGX
  // The interface's IOR after the Specular IOR Level (v2) or from F0 = 0.08 · specular (v1); 1 when it reflects
  // nothing (no specular lobe).
  double effective_ior() const;
};

struct Material {
  std::string name;
  std::variant<LambertMaterial, DichromaticMaterial, MirrorMaterial, PrincipledMaterial> model;

  // The one spectrum that colours what the material reflects: a Lambert or mirror material's reflectance, a
  // dichromatic material's diffuse (body) reflectance (its specular lobe is flat). reflectance_key() names its
  // field in the scene file ("reflectance" or "diffuse").
  const SpectrumRef& reflectance_spectrum() const;
  const char* reflectance_key() const;
};

// "lambert", "dichromatic", "mirror" or "principled".
const char* material_type_name(const Material& material);

// ---- Lights and objects ------------------------------------------------------------------------------

using LightShape = std::variant<QuadShape, SphereShape>;

// What both renderers can represent (docs/scene-format.md, "Ranges the renderers represent"). They trace in
// 32-bit floats: at 10^6 m from the origin a float coordinate steps by 6 cm, and Embree refuses rays from
// beyond about 1.8e18; a radiance of 10^20 W m⁻² sr⁻¹ nm⁻¹ (10^16 times the Sun's) still leaves a factor of
// 10^18 before a sum of samples overflows a float.
inline constexpr double kMaxCoordinateM = 1e6;
inline constexpr double kMaxRadiance = 1e20;

struct Light {
  std::string name;
  int id = 0;  // object id: the lights follow the objects (see Object::id)
  LightShape shape;
  SpectrumRef radiance;  // relative spectrum; radiance · scale is in W m⁻² sr⁻¹ nm⁻¹
  double scale = 1.0;
  std::string group;                    // names the light's output component `light.<group>`; defaults to the name
  bool two_sided = false;               // a one-sided quad emits on the side of edge1 × edge2; a sphere emits outward
  std::optional<std::size_t> material;  // index into Scene::materials: the emitter also reflects with it

  PiecewiseLinearSpectrum emitted_radiance() const { return radiance.spectrum.scaled(scale); }
};

// The light from every direction that leaves the scene (Blender's world): a spectrum, the same from every
// direction, or a latitude-longitude (equirectangular) texture, mapped as Blender's Environment Texture node
// maps it by default (docs/scene-format.md, "Environment"), turned about +Z by `rotation_deg`.
struct Environment {
  SpectrumRef radiance;  // relative; radiance · scale is in W m⁻² sr⁻¹ nm⁻¹
  double scale = 1.0;
  double rotation_deg = 0.0;  // counter-clockwise seen from +Z
  std::string group = "environment";
};

struct Object {
  std::string name;
  int id = 0;                // 1, 2, ... in file order; 0 is the background
  std::size_t material = 0;  // index into Scene::materials
  Shape shape;
};

// ---- Camera and render settings -----------------------------------------------------------------------

enum class PixelFilter { Box, Point };
enum class SpectralMode { Bands, Continuous };

struct Tessellation {
  int segments = kDefaultSegments;  // around spheres and cylinders
  std::optional<int> rings;         // pole to pole on spheres; unset: half the sphere's segments
};

// Defaults that command-line options override.
// The render settings a scene may leave out, as core/data/defaults.json gives them: the one source the tracer,
// check-scene and the Blender add-on (which reads the same file) share.
struct RenderDefaults {
  int samples = 0;
  int max_bounces = 0;
  std::uint64_t seed = 0;
  PixelFilter pixel_filter = PixelFilter::Box;
  SpectralMode spectral_mode = SpectralMode::Bands;
  std::string bands;  // lo:hi:width
};
const RenderDefaults& render_defaults();

struct RenderSettings {
  int samples = render_defaults().samples;          // paths per pixel
  int max_bounces = render_defaults().max_bounces;  // scattering events per path: 0 emitters only, 1 direct light, >= 2 global
  std::uint64_t seed = render_defaults().seed;
  PixelFilter pixel_filter = render_defaults().pixel_filter;  // box: integrate over the pixel area; point: its centre
  SpectralMode spectral_mode = render_defaults().spectral_mode;
  Bands bands = Bands::parse(render_defaults().bands, "defaults.json: render.bands");
  Tessellation tessellation;
};

// ---- Scene ---------------------------------------------------------------------------------------------

struct Scene {
  std::string source;               // names the scene in messages: its file, or a series variant
  std::filesystem::path directory;  // paths inside the scene are relative to it
  std::string name;                 // `name`, or the file's stem
  std::string description;
  Json json;  // the document as given (a series variant: patched), for embedding
  std::vector<NamedSpectrum> spectra;
  std::vector<Material> materials;
  std::vector<Object> objects;
  std::vector<Light> lights;
  std::optional<Environment> environment;
  Camera camera;
  RenderSettings render;
  // The files it was read from: the scene file (when loaded from one), then the CSV tables, textures and
  // meshes it reads. An output must never be one of them.
  std::vector<std::filesystem::path> files;

  const Material* find_material(std::string_view name) const;
  const NamedSpectrum* find_spectrum(std::string_view name) const;
  // Number of object ids in use: objects then lights, so ids run 1 .. id_count().
  int id_count() const { return static_cast<int>(objects.size() + lights.size()); }
};

Scene load_scene(const std::filesystem::path& file);
// Validates a scene document. `source` prefixes every message; relative paths resolve against `directory`.
Scene parse_scene(const Json& document, const std::string& source, const std::filesystem::path& directory);

// A list of named spectra on their own (`chromatrace-spectra/1`): {"format": ..., "spectra": {name: source}},
// each source as in a scene's `spectra` (docs/scene-format.md), paths relative to the file. Tools that
// need spectra outside a scene (the Blender add-on's band averages) use it.
std::vector<NamedSpectrum> load_spectra(const std::filesystem::path& file);
std::vector<NamedSpectrum> parse_spectra(const Json& document, const std::string& source,
                                         const std::filesystem::path& directory);

// World-space triangles of every object and then every light: element i has object id i + 1.
std::vector<TriangleMesh> scene_meshes(const Scene& scene);

// Calls `visit` on every file path a scene document holds (a spectrum's `csv`, a shape's `file`), wherever it
// stands, so that it can read or rewrite it.
void for_each_scene_path(Json& document, const std::function<void(Json& path)>& visit);

// A scene document whose relative paths are made relative to `to` (absolute when `to` is empty), from their
// meaning relative to `from`; so a scene can be written to another folder.
Json rebase_scene_paths(Json document, const std::filesystem::path& from, const std::filesystem::path& to);

// The "format" of a scene or series document (core/series_format.h), so tools can accept either; "" if there
// is none.
std::string document_format(const Json& document);

}  // namespace ct
