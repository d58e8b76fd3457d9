// SPDX-License-Identifier: Apache-2.0
#pragma once
// Assembly of a spectral EXR from RGB renders that each carried up to three bands in their R, G and B
// channels (the Blender add-on's band-multiplexed Cycles renders; `chromatrace assemble`, docs/blender.md).
//
// The manifest (chromatrace-assemble/1, written by blender_addon/chromatrace/manifest.py) says which file and
// channel holds each band, which render passes make the total and each component (a sum of signed products
// of passes, e.g. diffuse_direct = DiffDir × DiffCol, bounce.2 = Combined(2 bounces) − Combined(1 bounce)),
// where the object ids are, and the header's metadata:
//
//   {"format": "chromatrace-assemble/1", "edges_nm": [400, 450, 500, 550], "view_layer": "ViewLayer",
//    "reconstruction": {"lo_nm": 400, "step_nm": 1, "matrix": [...]},  (optional, as in a band-plan file)
//    "bands": [{"channel": "R", "files": {"main": "g000.exr"}}, ...],
//    "total": [{"passes": ["Combined"]}],
//    "components": [{"name": "diffuse_direct", "terms": [{"passes": ["DiffDir", "DiffCol"]}]}, ...],
//    "object_ids": {"file": "g000.exr", "channel": "ViewLayer.IndexOB.X"}, "object_names": {"1": "floor"},
//    "attributes": {"chromatrace.renderer": "..."}, "sum_tolerance": 1e-4,
//    "guided": {"bands": [3, 4, 5], "radius": 4, "false_refusal": 1e-4}}  (optional)
//
// A term's "file" names an entry of each band's "files" (default "main"); "sign" is 1 or -1 (default 1);
// file paths are relative to the manifest. Pass channel names are "<view_layer>.<pass>.<channel>".
//
// Each family of components (path types, light groups, bounces) must add up to the total: the renderer
// accumulated them separately in float, so they differ by rounding, which must stay within sum_tolerance
// relative to the pixel's magnitude (else an InputError names the family, pixel and band). That rounding
// residual is then added to the family's largest component at that pixel (reconcile_families), so the file
// satisfies the exact bound `chromatrace info --check` verifies.
//
// "guided" names the bands rendered with fewer samples than the rest: after assembly they are reconstructed
// from the others (core/guided.h), object by object and component by component, and the header's
// chromatrace.guided says which bands were, from which, and where a reconstruction was refused. The whole
// image is then held in memory (a 1920 × 1080 image of 6 bands and 8 layers takes 400 MB).

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/spectrum.h"

namespace ct {

// A render file the manifest names, with the channels to read from it (each once).
struct AssemblyInput {
  std::filesystem::path path;         // the manifest's directory / the name given, lexically normal
  std::vector<std::string> channels;  // "<view_layer>.<pass>.<channel>", the object-id channel
};

// One signed product of passes, all from one input.
struct PassProduct {
  std::size_t input = 0;              // index into AssemblyManifest::inputs
  std::vector<std::size_t> channels;  // the factors: indices into that input's channels
  double sign = 1.0;                  // 1 or -1
};

// The total or a component in one band: a sum of signed products of passes.
using PassSum = std::vector<PassProduct>;

// The channel that holds the object ids.
struct ObjectIdChannel {
  std::size_t input = 0;    // index into AssemblyManifest::inputs
  std::size_t channel = 0;  // index into that input's channels
};

// The manifest's "guided": the bands reconstructed from the others (core/guided.h: GuidedOptions).
struct GuidedAssembly {
  std::vector<std::size_t> bands;
  int radius = 4;
  double false_refusal = 1e-4;
  // The guided bands' renders used Cycles' adaptive sampling (threshold > 0): each pixel had their own samples and,
  // where its noise stayed above the threshold, up to max_samples. Recorded in the header; it changes nothing here.
  double adaptive_threshold = 0;
  int adaptive_max_samples = 0;
};

// A manifest as read: every file and channel resolved, ready to assemble.
struct AssemblyManifest {
  std::string file;  // the manifest's path as given, for messages
  Bands bands;
  std::vector<AssemblyInput> inputs;
  std::vector<PassSum> total;                        // [band]
  std::vector<std::string> components;               // names, in the manifest's order
  std::vector<std::vector<PassSum>> component_sums;  // [component][band]
  std::optional<ObjectIdChannel> object_ids;
  std::map<std::int32_t, std::string> object_names;
  std::map<std::string, std::string> attributes;  // chromatrace.<key>
  double sum_tolerance = 1e-4;
  std::optional<GuidedAssembly> guided;
};

// Reads and checks a manifest. Bad input is a one-line InputError naming the file and the JSON path of the
// field at fault, e.g. "m.json: components[0].name: \"sparkle\" is not one of …". The render files are not
// opened here.
AssemblyManifest read_assembly_manifest(const std::filesystem::path& file);

// A family of components that must sum to the total.
struct SummingFamily {
  std::string name;                  // "path types", "light groups", "bounces"
  std::vector<std::size_t> members;  // indices into the component list
};

// The summing families among `components`, in the order path types, light groups, bounces; path types only
// when they are complete (path_types_complete), since an incomplete set cannot add up to the total.
std::vector<SummingFamily> summing_families(const std::vector<std::string>& components);

// The first family that reconcile_families found to miss the total by more than rounding.
struct FamilyMismatch {
  std::size_t family = 0;  // index into the families given
  double sum = 0;          // its members' sum
};

// One pixel in one band: makes every family sum to `total` by adding the residual (total − sum) to the
// family's member of largest magnitude (the first of equals), where it changes the value least in relative
// terms. A residual above tolerance · (|total| + Σ|member|) + 1e-30 is more than rounding: the first such
// family is returned, with `components` left part-reconciled. A NaN residual passes that test and so lands
// in the largest member. Pure: no I/O, and only `components` (all the pixel's components) changes.
std::optional<FamilyMismatch> reconcile_families(double total, std::span<double> components,
                                                 std::span<const SummingFamily> families, double tolerance);

// Reads the manifest's renders block by block and writes the spectral EXR atomically to `output`, showing
// progress on stderr when asked. Missing files or channels, renders of different sizes, families off by more
// than rounding and object ids that are not whole numbers in [0, 2^24] are InputErrors naming the file.
void assemble(const AssemblyManifest& manifest, const std::filesystem::path& output, bool show_progress);

}  // namespace ct
