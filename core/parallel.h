// SPDX-License-Identifier: Apache-2.0
#pragma once
// Parallel loops whose results do not depend on the thread count.
//
// Work is cut into fixed pieces (tiles of an image, blocks of scanlines) before any thread starts, and each
// piece writes only its own outputs; randomness is derived from the piece's coordinates and the seed
// (see core/random.h), never from which thread ran it. So the same inputs and seed give the same bytes
// with 1 or N threads.

#include <cstddef>
#include <functional>

namespace ct {

// Number of worker threads to use: `requested` if > 0, else all hardware threads.
int thread_count(int requested);

// Runs body(i) for i in [0, count) on up to `threads` threads (0 = all). Exceptions thrown by body are
// rethrown on the calling thread.
void parallel_for(std::size_t count, int threads, const std::function<void(std::size_t)>& body);

struct Tile {
  int x0, y0, x1, y1;  // pixels [x0, x1) × [y0, y1)
};

// Splits a width × height image into tiles of at most tile_size² pixels, in row-major tile order.
std::size_t tile_count(int width, int height, int tile_size);
Tile tile_at(int width, int height, int tile_size, std::size_t index);

}  // namespace ct
