// SPDX-License-Identifier: Apache-2.0
#pragma once
// The words chromatrace's EXR files share, spectral (the renderers') and RGB (the camera's): the object-id
// channel and its names, the component list, and the camera's numbers. Every part that reads or writes them
// uses these, so a file one part writes is the file the next part reads (docs/spectral-exr.md,
// docs/sensor.md "Output").

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace ct::exr {

// Per pixel, the id of the object seen at the pixel's centre; 0 is "no object".
inline constexpr const char* kObjectIdChannel = "object_id";
// A FLOAT channel holds every whole number up to 2^24 exactly: the largest object id.
inline constexpr std::int32_t kMaxObjectId = 1 << 24;
// JSON object from object id (a decimal string) to name, e.g. {"1": "floor"}.
inline constexpr const char* kObjectsAttribute = "chromatrace.objects";
// The light-path component layers, comma-separated, in order.
inline constexpr const char* kComponentsAttribute = "chromatrace.components";

// Whether a stored object_id sample is an id: a whole number in [0, kMaxObjectId].
bool is_object_id(double value);
// Throws InputError "<file>: channel object_id: value <v> at pixel (x, y) is not an object id (…)" unless
// is_object_id(value).
void check_object_id(double value, const std::string& file, std::size_t x, std::size_t y);

// kObjectsAttribute's text from names, and back. InputError "<where>: …" for text that is not a JSON object
// from whole numbers in [0, kMaxObjectId] to strings.
std::string object_names_text(const std::map<std::int32_t, std::string>& names);
std::map<std::int32_t, std::string> parse_object_names(std::string_view text, const std::string& where);

// kComponentsAttribute's text from names, and back (items trimmed of spaces, empty items dropped).
std::string component_list_text(const std::vector<std::string>& names);
std::vector<std::string> parse_component_list(std::string_view text);

}  // namespace ct::exr
