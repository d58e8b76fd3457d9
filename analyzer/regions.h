// SPDX-License-Identifier: Apache-2.0
#pragma once
// Image regions whose colours are analysed together: the whole image, the parts of a label image or
// channel (object_id), masks, rectangles, and automatic segments (analyzer/segmentation.h).

#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "analyzer/image_input.h"

namespace ct::analyzer {

struct Region {
  std::string name;    // "image", "object 2 (sphere)", "rect 10,20 40x30", "mask hand.png", "segment 3"
  std::string source;  // "image", "labels", "mask", "rect", "segment"
  std::int64_t label = -1;  // the label value for "labels" and "segment" regions
  std::vector<std::uint32_t> pixels;  // indices y·width + x, increasing
};

struct Rect {
  int x = 0, y = 0, width = 0, height = 0;
};

Region whole_image_region(int width, int height);
// One region per distinct label, in increasing label order; labels in `skip` (e.g. 0 = background) are
// left out. Names come from `names` when present ("object 2 (sphere)").
std::vector<Region> label_regions(const std::vector<std::int32_t>& labels, const std::string& what,
                                  const std::map<std::int32_t, std::string>& names, const std::vector<std::int32_t>& skip);
// Non-zero pixels of a mask image the size of the analysed image.
Region mask_region(const LabelImage& mask, const std::string& name);
// The part of the rectangle inside the image (possibly empty).
Region rect_region(const Rect& rect, int width, int height);
// "x,y,w,h"; an InputError naming `option` otherwise.
Rect parse_rect(const std::string& text, const std::string& option);

// A region's colours: the RGB of its pixels whose three values are finite, packed [i][channel], and
// those pixels' indices. NaN and infinite pixels are counted, not analysed.
// The finite samples of a region, [i][channel], and the pixel each came from. When the region is a run of
// consecutive pixels that are all finite (the whole image, typically) they are views of the image and of the
// region themselves, else copies held here: a 24-megapixel image is not copied again.
struct RegionSamples {
  std::span<const float> rgb;
  std::span<const std::uint32_t> pixels;
  std::size_t non_finite = 0;

  RegionSamples() = default;
  RegionSamples(RegionSamples&&) = default;  // the views keep pointing at the moved buffers
  RegionSamples& operator=(RegionSamples&&) = default;
  RegionSamples(const RegionSamples&) = delete;
  RegionSamples& operator=(const RegionSamples&) = delete;

  std::size_t size() const { return pixels.size(); }

 private:
  friend RegionSamples gather_samples(const RgbImage& image, const Region& region);
  std::vector<float> own_rgb_;
  std::vector<std::uint32_t> own_pixels_;
};
RegionSamples gather_samples(const RgbImage& image, const Region& region);

}  // namespace ct::analyzer
