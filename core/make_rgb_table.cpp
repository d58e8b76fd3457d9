// SPDX-License-Identifier: Apache-2.0
// Build-time generator of the RGB upsampling table compiled into the library (core/rgb_to_spectrum.h,
// RgbCoefficientTable): make_rgb_table <resolution> <output file>. The bytes do not depend on the thread count.
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>

#include "core/file_io.h"
#include "core/rgb_to_spectrum.h"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: make_rgb_table <odd resolution> <output file>\n");
    return 2;
  }
  try {
    const ct::RgbCoefficientTable table = ct::RgbCoefficientTable::compute(std::stoi(argv[1]));
    ct::write_file_atomically(argv[2], table.bytes());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_rgb_table: %s\n", e.what());
    return 1;
  }
  return 0;
}
