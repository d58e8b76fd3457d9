// SPDX-License-Identifier: Apache-2.0
#include "core/parallel.h"

#include <algorithm>
#include <thread>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

namespace ct {

int thread_count(int requested) {
  if (requested > 0) return requested;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

void parallel_for(std::size_t count, int threads, const std::function<void(std::size_t)>& body) {
  const int n = thread_count(threads);
  if (n == 1 || count <= 1) {
    for (std::size_t i = 0; i < count; ++i) body(i);
    return;
  }
  tbb::task_arena arena(n);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 1), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) body(i);
    });
  });
}

std::size_t tile_count(int width, int height, int tile_size) {
  const std::size_t tx = static_cast<std::size_t>((width + tile_size - 1) / tile_size);
  const std::size_t ty = static_cast<std::size_t>((height + tile_size - 1) / tile_size);
  return tx * ty;
}

Tile tile_at(int width, int height, int tile_size, std::size_t index) {
  const int tx = (width + tile_size - 1) / tile_size;
  const int x = static_cast<int>(index % static_cast<std::size_t>(tx)) * tile_size;
  const int y = static_cast<int>(index / static_cast<std::size_t>(tx)) * tile_size;
  return {x, y, std::min(width, x + tile_size), std::min(height, y + tile_size)};
}

}  // namespace ct
