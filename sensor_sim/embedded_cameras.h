// SPDX-License-Identifier: Apache-2.0
#pragma once
// The camera curves of sensor_sim/cameras/, compiled into the library (see cmake/EmbedFiles.cmake).

#include <string_view>

namespace ct::sensor::cameras_embedded {
// The bytes of a file by its name, e.g. "nikon_d850.csv"; empty if unknown.
std::string_view file(std::string_view name);
}  // namespace ct::sensor::cameras_embedded
