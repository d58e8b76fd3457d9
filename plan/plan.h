// SPDX-License-Identifier: Apache-2.0
#pragma once
// `chromatrace plan`: the fewest bands and bounces that keep a scene's image within a colour-error target,
// with the error they are predicted to cause (docs/plan.md).
//
// The prediction. A low-resolution preview render (bands mode, every component) says, for each pixel, which
// object it shows and how much luminance arrives after each number k of scattering events (bounce.k; k = 1
// split into its diffuse and glossy parts). Each object's spectrum after k events comes from radiosity with one
// patch per object, at 1 nm: transfer factors F_oj (cosine-weighted rays from the object's surface) give the
// irradiance I_1,o = Σ_l F_ol·E_l from the lights and I_k,o = Σ_j F_oj·ρ_j·I_k−1,j after more events, and the
// camera sees R_o·I_k,o (a dichromatic lobe: flat; a mirror: its reflectance); k = 0 is an emitter's own
// spectrum. A pixel's spectrum is Σ_k Y_p,k · (that spectrum scaled to unit luminance). A band plan computes the
// same recursion on band averages, as the tracer's bands mode and Cycles do, and drops k > K for a bounce limit
// K. Both go through the observer (the CIE 1931 curves or a shipped camera's) to tristimulus values, to CIELAB
// under the light's white at the level of the exact preview (core/render_delta_e.h, the white policy every
// render comparison uses), and the predicted error is the mean over pixels of their ΔE00. measure_delta_e()
// computes the same statistic between two renders. The model itself is plan/radiosity.h. docs/plan.md has the details and the measured accuracy.
//
// Band edges for a band count are fitted to that prediction by coordinate descent over a grid of edge
// positions (whole nm by default), coarse to fine, from the uniform plan and from the previous count's plan with
// its widest bands split.

#include <array>
#include <map>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/json_input.h"
#include "core/render_delta_e.h"
#include "core/scene.h"
#include "core/spectrum.h"

namespace ct::plan {

enum class Renderer { Cycles, Tracer };

struct PlanOptions {
  double target_de00 = 1.0;
  std::string camera = "cie1931";  // the observer: cie1931 or a shipped camera
  Renderer renderer = Renderer::Cycles;
  double edge_step_nm = 1.0;  // band edges lie on multiples of this (and on the range's ends)
  int preview_size = 32;      // longer side of the preview render, pixels
  int preview_samples = 16;   // paths per pixel of the preview renders (two, for the noise)
  int threads = 0;            // 0: all cores
  // Cycles: also render the bounce components separately (each bounce order is a Cycles render of its own).
  bool bounce_components = false;
  // Fit a reconstruction of the bands' values (core/spectrum.h: BandReconstruction) to the scene's spectra and
  // plan with it; not when the scene has image textures, whose spectra the model does not hold.
  bool reconstruction = true;
  // Cycles: its Monte Carlo noise against the tracer's at equal samples per pixel (the ratio of one render's mean
  // ΔE00 of noise), the range the prediction is stated over and where the ratio comes from. 0: kCyclesNoiseRatio,
  // the median over the test scenes, stated over their range.
  double cycles_noise_ratio = 0;
  std::array<double, 2> cycles_noise_ratio_range{0, 0};
  std::string cycles_noise_ratio_from;
  // How Cycles' noise is shared between band groups and pairs of them as measured (NoiseRatio::group_shares), for
  // the bands it was measured with (edges in nm); other bands take the shares of plan's model (no pairs).
  std::vector<double> cycles_group_shares, cycles_group_shares_edges_nm;
  // No band group below this many samples: those Cycles' noise was measured at (the pilots'; 0: kCyclesMinSamples).
  int cycles_min_samples = 0;
  // The tracer's noise (one render's mean ΔE00) at one path per pixel as measured beside the pilots, at their size and
  // samples (NoiseRatio::tracer_at_one): the scale Cycles' predicted noise is the ratio times. 0: the preview's
  // (Model's noise at its 16 paths, scaled by 1/√paths), which a scene with rare bright paths (an HDRI's sun)
  // overstates at so few paths (docs/plan.md).
  double cycles_pilot_tracer_noise_at_one = 0;
  // Each object's Cycles-to-tracer noise ratio over the image's as the pilots measured it (NoiseRatio::object_ratio):
  // an object's predicted noise is the preview's share of it times this where it is above 1. Absent: 1.
  std::map<std::int32_t, double> cycles_object_noise_ratio;
  // Each band group's ΔE00 as a guide as the pilots measured it (NoiseRatio::group_guided_delta_e), for the bands of
  // cycles_group_shares_edges_nm: the plan names the group of the least the guide of a guided render.
  std::vector<double> cycles_group_guided_delta_e;
  // Where Cycles' noise is on the pilots (NoiseRatio::pixel_noise), which are of the preview's size: the plan adds
  // the noise to the bands' error pixel by pixel where it is (Model::joint_error). Empty, or of another size: where
  // the tracer's preview has its noise.
  std::vector<double> cycles_pixel_noise;
  int cycles_pixel_noise_width = 0, cycles_pixel_noise_height = 0;
  // Also predict the mean ΔE00 that comparing the Cycles render with a tracer reference of this many paths per
  // pixel measures (its noise counts too); 0: not.
  int reference_samples = 0;
  // Cycles: the target is that prediction, the reference's noise counted with the render's, where it is otherwise the
  // render's own error: for a render to be validated against such a reference (bench_plan_cycles.py).
  bool target_against_reference = false;
  // Cycles: the mean ΔE00 no object of the preview may be predicted above (its bands, bounces and noise); the samples
  // grow until none is. 0: twice target_de00.
  double object_target_de00 = 0;
};

// Cycles' Monte Carlo noise against the tracer's at equal samples per pixel: the mean ΔE00 between two renders with
// different seeds, Cycles over the tracer, 64 pixels on the longer side, 64 samples, 6 bands of 50 nm, Blender 3.4
// (bench/bench_cycles_noise_ratio.py): the paper box 0.77, the Cornell box 0.83, the textured scene under an HDRI
// 0.64, the glossy lights 1.05 (docs/plan.md).
constexpr double kCyclesNoiseRatio = 0.80;
constexpr double kCyclesNoiseRatioLow = 0.64, kCyclesNoiseRatioHigh = 1.05;
// How far the predicted noise of a Cycles render may be off with its ratio known, as a factor (1 + this) either way.
// Cycles renders of the paper box and the Cornell box at the samples a plan with pilots gave them (Blender 3.4 and
// 5.3, two seeds each, 48 × 48 pixels) had noise from 22 % under (the Cornell box: its pilots, at 64 samples, put
// Cycles at 0.85 of the tracer, its renders at 500 samples nearer 0.67) to 14 % over their prediction
// (docs/plan.md).
constexpr double kCyclesNoiseModelAccuracy = 0.4;
// The fewest samples a Cycles band group is given: the samples Cycles' noise was measured at (the pilots', and the
// test scenes' behind kCyclesNoiseRatio). Below them its noise is not the measured ratio's: at 8 samples a group, a
// glossy ball's highlight under an F11 panel measured 4.1 to 5.6 where 2.0 was predicted (bench/README.md).
constexpr int kCyclesMinSamples = 64;

struct BandTrial {
  int bands = 0;
  double predicted_mean = 0;
  std::vector<double> edges_nm;
  // Why a count that met the target was not taken: the first warning check_band_plan (check-scene, render) gives
  // for those bands, e.g. one material lit by one light off by more than 2 (the mean hides one surface).
  std::string refused;
  std::vector<int> cycles_samples;  // Cycles, a count taken: its samples per band group (empty: none meet the target)
};

struct Plan {
  // Settings.
  Bands bands;
  int max_bounces = 0;
  // Tracer paths per pixel at which Monte Carlo noise alone gives a mean ΔE00 at the target: from two preview
  // renders with different seeds (the noise of one is their ΔE00 / √2, falling as 1/√samples).
  int samples = 0;
  double noise_at_samples = 0, noise_at_scene_samples = 0;  // predicted mean ΔE00 of the noise
  bool target_met = false;
  // Predictions (ΔE00 against the scene's own bounce limit with exact spectra).
  double predicted_mean = 0, predicted_p95 = 0;
  double predicted_band_only = 0;    // the plan's bands at the scene's bounce limit
  double predicted_bounce_only = 0;  // exact spectra, the plan's bounce limit
  double scene_bands_predicted_mean = 0;  // the scene's own band plan, for comparison
  std::vector<BandTrial> trials;          // every band count tried, fewest first
  std::vector<double> energy_after;       // luminance fraction beyond k bounces, k = 0 .. scene max - 1
  // Cycles: samples per pixel of each band group (three bands a render), chosen with the bands: the fewest in all
  // for which the bands, the bounce limit and Monte Carlo noise together are predicted at the target, shared
  // between the groups by their part in the noise's colour error (docs/plan.md).
  std::vector<int> cycles_samples;
  double cycles_noise_ratio = 0;                  // the ratio the prediction used
  double tracer_noise_at_one = 0;                 // the tracer's noise (mean ΔE00) at one path per pixel
  bool tracer_noise_from_pilots = false;          // measured beside Cycles' pilots, else from the preview
  std::vector<double> cycles_noise_shares;        // each band group's share of the noise's variance (diagonal)
  bool cycles_noise_shares_measured = false;      // on Cycles' pilots, else by plan's model
  // The band group to guide a guided render (core/guided.h): the one whose noise, carried into every band, makes the
  // least ΔE00 over the image and its objects, as the pilots measured it (PlanOptions::cycles_group_guided_delta_e);
  // -1 where they did not.
  int cycles_guide_group = -1;
  std::vector<double> cycles_group_guided_delta_e;
  std::vector<double> cycles_noise_pair_shares;   // measured: G × G with the pairs' terms (NoiseRatio)
  double cycles_predicted_mean = 0;               // mean ΔE00 of bands, bounces and noise at cycles_samples
  double cycles_predicted_low = 0, cycles_predicted_high = 0;  // the same over the ratio's range
  double cycles_noise_only = 0;                   // the noise alone at cycles_samples (exact spectra)
  // The bands' error and the noise's in quadrature of their means: what cycles_predicted_mean, which adds them pixel
  // by pixel, would be if the noise were as strong wherever the bands miss.
  double cycles_predicted_in_quadrature = 0;
  // Each object the preview sees enough of (limit_objects in plan.cpp): its predicted mean ΔE00 at cycles_samples,
  // and the factor by which the samples grew so that none exceeds object_target_de00 (1: the mean's samples did).
  struct ObjectPrediction {
    std::string name;
    int id = 0;
    std::size_t preview_pixels = 0;
    double bands_only = 0, predicted_mean = 0;
    double noise_scale = 1;  // its pixels' noise over the image's, in the preview
    double cycles_ratio = 1;  // PlanOptions::cycles_object_noise_ratio's for it, at least 1 (1: none measured)
  };
  std::vector<ObjectPrediction> objects;
  double object_target_de00 = 0, object_samples_factor = 1;
  // With PlanOptions::reference_samples: what compare measures against such a reference, and its range.
  double cycles_predicted_against_reference = 0, cycles_against_reference_low = 0, cycles_against_reference_high = 0;
  // Cost.
  int cycles_band_groups = 0;    // ceil(bands / 3)
  int cycles_bounce_variants = 1;
  int cycles_renders = 0;        // groups × variants + 1 (the object-id render)
  int scene_cycles_renders = 0;  // the same for the scene's own settings
  double tracer_relative_time = 0;  // the plan's tracer time / the scene's settings' (model, see docs/plan.md)
  std::vector<std::string> notes;
};

Plan make_plan(const Scene& scene, const PlanOptions& options);

// A render's bounce limit and samples judged by the same model (check-scene and render warn with it,
// plan/render_check.h). The truth is exact spectra at a reference depth: at least `max_bounces` events, and as many
// as it takes for the light left beyond to fall below 1 % of what went before (the powers of the mean albedo).
struct SettingsPrediction {
  int max_bounces = 0, samples = 0;  // the settings judged
  int reference_bounces = 0;         // the model's depth
  double share_beyond = 0;           // luminance fraction that arrives after more than max_bounces events, over the
                                     // pixels not on or next to a light (as the white is taken: the lit surfaces)
  double bounce_de00 = 0;            // predicted mean ΔE00 of leaving it out (exact spectra)
  int bounces_for_target = 0;        // what plan chooses: the fewest whose truncation costs ≤ a quarter of the target
  double noise_de00 = 0;             // predicted mean ΔE00 of the tracer's Monte Carlo noise at `samples`
  int samples_for_target = 0;        // what plan chooses: paths per pixel for noise at the target
};
SettingsPrediction predict_settings(const Scene& scene, int max_bounces, int samples, const PlanOptions& options);

// The chromatrace-bands/1 document of the plan's bands, and the full report (settings, predictions, cost).
Json bands_document(const Plan& plan);
Json report_document(const Plan& plan, const Scene& scene, const PlanOptions& options);

// The light spectrum the plan adapts to: the scene's lights weighted by mean radiance × area (and the
// environment's mean radiance by 4π·R², R the scene's bounding radius; a textured light or environment as its
// texels' mean spectrum, plan/radiosity.h), as a 1 nm table.
PiecewiseLinearSpectrum scene_light_spectrum(const Scene& scene);

// Cycles' Monte Carlo noise against the tracer's, measured on the scene itself: two Cycles renders of it (pilots,
// e.g. at the plan's preview size) with different seeds and the same samples, bands and size; the tracer renders it
// twice alike (its seeds 1 and 2, the scene's bounce limit) and the ratio is that of the mean ΔE00 between the two
// of each (measure_delta_e's statistic, under the white of the first of each pair), its standard error from their
// pixels'.
// The mean ΔE00 over `pixel_count` pixels (those past bands.size() without error) of a render's error when its
// bands' error (`bands`, ΔE00 per pixel), its noise and a reference's add in quadrature pixel by pixel:
// Σ √(b² + (c·n)² + (t·r)²) / pixel_count, with c and t such that c·n and t·r have the means `noise_mean` and
// `reference_mean` over the pixels (n and r give where each noise is, in any units). At least the quadrature of the
// three means, and equal to it where the three are in the same proportion at every pixel (Minkowski's inequality);
// at most their sum.
double pixel_by_pixel_mean(const std::vector<double>& bands, const std::vector<double>& noise, double noise_mean,
                           const std::vector<double>& reference, double reference_mean, std::size_t pixel_count);

struct NoiseRatio {
  double ratio = 0, se = 0;
  double cycles = 0, tracer = 0;  // mean ΔE00 between the two renders of each
  int samples = 0;
  double tracer_at_one = 0;  // one tracer render's noise at one path per pixel: tracer / √2 × √samples
  // How Cycles' noise is shared between the band groups (three bands a render) and between pairs of them, whose
  // noise is correlated where they share paths (the same seed): G × G, row by row, summing to 1. Diagonal: e_g², e_g
  // the mean ΔE00 between the first pilot and the first with group g's bands from the second; off the diagonal,
  // (e_gh² − e_g² − e_h²) / 2 with both groups' bands from the second.
  std::vector<double> group_shares;
  std::vector<double> edges_nm;  // the pilots' band edges, which the shares are of
  // Each object's own ratio (Cycles' noise over the tracer's on its pixels) over the image's, for the objects of
  // which both pilots and both tracer renders hold at least kPilotObjectPixels: Cycles samples a glossy highlight
  // otherwise than the tracer, so an object's share of the noise may differ between them.
  std::map<std::int32_t, double> object_ratio;
  // Each group as the guide of a guided render (core/guided.h), whose every band takes the guide's noise relative to
  // its signal as a common factor: the ΔE00 that factor makes, at the pilots' size and samples, averaged over the
  // image and over each object the first pilot holds at least kPilotObjectPixels of, each once. It ranks the groups
  // as guides; it is not the guided render's error, to which its few-sample pixels (objects' edges, highlights) add.
  std::vector<double> group_guided_delta_e;
  // Where Cycles' noise is: each pixel's ΔE00 between the pilots (linearised, as `cycles` averages it), row by row at
  // their width × height.
  std::vector<double> pixel_noise;
  int width = 0, height = 0;
};
constexpr std::size_t kPilotObjectPixels = 16;
NoiseRatio measure_cycles_noise(const Scene& scene, const std::filesystem::path& a, const std::filesystem::path& b,
                                const std::string& camera = "cie1931", int threads = 0);

using Measurement = RenderDeltaE;
// ΔE00 (core/render_delta_e.h) between the totals of two spectral EXR renders of `scene` (same size; any band
// plans), each turned into tristimulus values through `camera`'s curves over its own bands, under the white of
// scene_light_spectrum() at the level of `reference` (lights: the scene's). With `white_from`, the level is that
// render's instead (so that two noisy renders compare on the scale of a third, converged one).
Measurement measure_delta_e(const std::filesystem::path& test, const std::filesystem::path& reference,
                            const Scene& scene, const std::string& camera = "cie1931",
                            const std::filesystem::path& white_from = {});

}  // namespace ct::plan
