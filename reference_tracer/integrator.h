// SPDX-License-Identifier: Apache-2.0
#pragma once
// Unidirectional spectral path tracing with next-event estimation and multiple importance sampling (power
// heuristic) on area lights, and unbiased Russian roulette.
//
// The environment is a light like the others: next-event estimation samples it (∝ its texels' radiance × solid
// angle), and a path that leaves the scene sees it, MIS-weighted against that sampling; seen from the camera it
// is "emission", and its light group is the environment's.
//
// Path components (spectral-exr.md) are attributed exactly, not by sampling which lobe was chosen: at the
// first scattering event the path's throughput splits into its diffuse and glossy parts, which are carried
// on separately. A contribution after exactly one scattering event is "direct", after more "indirect"; one
// with none (the camera sees an emitter) is "emission". Each contribution also goes to its light's group
// and to bounce.<k>, k = number of scattering events. Each family of components sums to the total.

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/random.h"
#include "core/scene.h"
#include "reference_tracer/lanes.h"
#include "reference_tracer/scene_data.h"

namespace ct::rt {

struct ComponentSelection {
  bool paths = true;    // emission, diffuse_direct, diffuse_indirect, glossy_direct, glossy_indirect
  bool lights = true;   // light.<group>
  bool bounces = false; // bounce.0 .. bounce.<max_bounces>
  // Parses a comma-separated list of "paths", "lights", "bounces", "all" (spaces around items ignored), or
  // "none" alone; errors name `what`. Cases: tests/data/component_grammar.json.
  static ComponentSelection parse(const std::string& list, const std::string& what = "--components");
};

// The output layers of a render: the total first, then the components in file order.
struct LayerPlan {
  std::vector<std::string> components;
  int emission = -1, diffuse_direct = -1, diffuse_indirect = -1, glossy_direct = -1, glossy_indirect = -1;
  std::vector<int> light_group;  // per group
  std::vector<int> bounce;       // per k
  int layer_count() const { return 1 + static_cast<int>(components.size()); }
};
LayerPlan plan_layers(const ComponentSelection& selection, const std::vector<std::string>& groups, int max_bounces);

struct TracerSettings {
  int max_bounces = 8;
  SpectralMode mode = SpectralMode::Bands;
  Bands bands;
  std::uint64_t seed = 1;
  bool box_filter = true;
  int threads = 0;  // for the per-render tables (the textures' band values); 0: all cores
};

// Accumulates one pixel's layers: layer-major, layer_count × bands doubles.
class PixelAccumulator {
 public:
  PixelAccumulator(int layers, int bands) : bands_(bands), sum_(static_cast<std::size_t>(layers * bands), 0.0) {}
  double* layer(int l) { return sum_.data() + static_cast<std::ptrdiff_t>(l) * bands_; }
  const std::vector<double>& data() const { return sum_; }
  void clear() { std::fill(sum_.begin(), sum_.end(), 0.0); }

 private:
  int bands_;
  std::vector<double> sum_;
};

class PathTracer {
 public:
  PathTracer(const TracerScene& scene, TracerSettings settings, LayerPlan layers);

  // Traces one path through image point (px, py) (pixels from the top-left) and adds its contributions
  // to `pixel`. `stream` identifies the path for the random-number generator.
  void trace(double px, double py, std::uint64_t stream, PixelAccumulator& pixel) const;
  // The film position of sample `stream` ((pixel index << 32) | sample index) in pixel (x, y): the centre,
  // or stratified over the pixel (box; integrator.cpp).
  std::pair<double, double> film_position(int x, int y, std::uint64_t stream) const;
  // Object id seen through the centre of pixel (x, y); 0 for the background.
  int object_id_at(int x, int y) const;

  const LayerPlan& layers() const { return layers_; }
  const TracerSettings& settings() const { return settings_; }

 private:
  struct Chunk {
    int first_band, count;
  };
  struct Path;     // a path's lanes, throughput and next ray
  struct Shading;  // a scattering event: hit, frame, material spectra
  // One path, traced in the steps of a path tracer with next-event estimation (integrator.cpp).
  void trace_lanes(const Vec3& origin, const Vec3& direction, Random& rng, const Chunk* chunk,
                   PixelAccumulator& pixel) const;
  Path start_path(const Vec3& origin, const Vec3& direction, Random& rng, const Chunk* chunk) const;
  void add_emission(const Path& path, const SurfaceHit& s, int depth, PixelAccumulator& pixel) const;
  void add_environment(const Path& path, int depth, PixelAccumulator& pixel) const;
  std::optional<Shading> shade(SurfaceHit s, const Path& path) const;
  void sample_direct(const Path& path, const Shading& at, int depth, Random& rng, PixelAccumulator& pixel) const;
  bool sample_continuation(Path& path, const Shading& at, int depth, Random& rng) const;
  static bool survives_roulette(Path& path, int depth, Random& rng);
  void contribute(const Path& path, PixelAccumulator& pixel, int scatterings, int group, const Lanes& diffuse_part,
                  const Lanes& glossy_part) const;
  void splat(const Path& path, PixelAccumulator& pixel, int layer, const Lanes& value) const;
  Lanes lane_values(const PiecewiseLinearSpectrum& s, const Chunk* chunk, const Lanes& wavelengths) const;
  // A colour input at texture coordinates `uv`, or (texel_values) at one texel of its texture.
  Lanes lane_values(const ColourInput& in, const Vec2& uv, const Chunk* chunk, const Lanes& wavelengths) const;
  Lanes texel_values(const ColourInput& in, std::size_t texel, const Chunk* chunk, const Lanes& wavelengths) const;

  const TracerScene& scene_;
  TracerSettings settings_;
  LayerPlan layers_;
  std::vector<Chunk> chunks_;
  // Band averages of every spectrum the tracer uses, for `bands` mode.
  std::vector<std::pair<const PiecewiseLinearSpectrum*, std::vector<double>>> band_tables_;
  // Per texture, the band averages of each palette entry (palette-major), for `bands` mode, each computed the first
  // time a path meets its colour: a small render meets few of an HDRI's hundreds of thousands of colours. The values
  // are a function of the entry alone, so the image is the same whichever thread computes them.
  struct TextureBands {
    std::unique_ptr<double[]> values;                    // not initialised: pages are touched only where used
    std::unique_ptr<std::atomic<std::uint8_t>[]> state;  // per entry: 0 not computed, 1 being computed, 2 ready
  };
  std::vector<TextureBands> texture_bands_;
};

}  // namespace ct::rt
