// SPDX-License-Identifier: Apache-2.0
#include "sensor_sim/output.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include <fmt/core.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <half.h>
#include <ImfChannelList.h>
#include <ImfDoubleAttribute.h>
#include <ImfIntAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <ImfStdIO.h>
#include <ImfStringAttribute.h>
#include <ImfThreading.h>
#include <OpenImageIO/imageio.h>

#include "core/error.h"
#include "core/exr_output.h"
#include "core/exr_vocabulary.h"
#include "core/file_io.h"
#include "core/json_input.h"

namespace ct::sensor {
namespace {

namespace fs = std::filesystem;

const char* const kRgb[] = {"R", "G", "B"};

std::string lower_extension(const fs::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

std::string layer_channel(const std::string& layer, int c) {
  return layer.empty() ? kRgb[c] : fmt::format("{}.{}", layer, kRgb[c]);
}

// Slices for one [row][x][3] block of the layer (R, G, B of `layer`), for rows [y0, y0 + rows).
void insert_rgb(Imf::FrameBuffer& frame, const std::string& layer, const float* block, int width, int y0, int rows) {
  const Imath::Box2i window({0, y0}, {width - 1, y0 + rows - 1});
  for (int c = 0; c < 3; ++c)
    frame.insert(layer_channel(layer, c), Imf::Slice::Make(Imf::FLOAT, block + c, window, 3 * sizeof(float),
                                                           3 * sizeof(float) * static_cast<std::size_t>(width)));
}

// OpenImageIO writes TIFF and PNG through its own buffered file and does not report a write that failed for
// want of space (its close() returns true over a truncated file), so the finished file is checked before it
// gets its name. A PNG must run chunk by chunk to its IEND chunk at the end of the file (read without decoding,
// whose errors libpng would print); a TIFF must decode row by row.
void check_complete_png(const fs::path& file, const fs::path& target) {
  std::ifstream in(file, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto byte = [&](std::size_t i) { return static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i])); };
  std::size_t at = 8;  // the signature
  while (at + 12 <= bytes.size()) {
    const std::uint64_t length = byte(at) << 24 | byte(at + 1) << 16 | byte(at + 2) << 8 | byte(at + 3);
    const bool end = bytes.compare(at + 4, 4, "IEND") == 0;
    at += 12 + length;  // length, type, data, CRC
    if (end && at == bytes.size()) return;
  }
  throw std::runtime_error(
      fmt::format("{}: cannot complete the file: the PNG written is cut short at {} bytes", target.string(), bytes.size()));
}

void check_complete_tiff(const fs::path& file, const fs::path& target, int width, int height) {
  const auto fail = [&](std::string why) {
    std::replace(why.begin(), why.end(), '\n', ' ');
    return std::runtime_error(fmt::format("{}: cannot complete the file: the TIFF written does not read back ({})",
                                          target.string(), why));
  };
  auto input = OIIO::ImageInput::create("tiff");
  OIIO::ImageSpec spec;
  if (!input || !input->open(file.string(), spec)) throw fail(input ? input->geterror() : OIIO::geterror());
  if (spec.width != width || spec.height != height) throw fail("wrong size");
  std::vector<std::uint16_t> row(static_cast<std::size_t>(width) * static_cast<std::size_t>(spec.nchannels));
  for (int y = 0; y < height; ++y)
    if (!input->read_scanline(y, 0, OIIO::TypeDesc::UINT16, row.data())) throw fail(input->geterror());
}

}  // namespace

OutputFormat output_format(const fs::path& file) {
  const std::string ext = lower_extension(file);
  if (ext == ".exr") return OutputFormat::Exr;
  if (ext == ".tif" || ext == ".tiff") return OutputFormat::Tiff;
  if (ext == ".png") return OutputFormat::Png;
  if (ext == ".dng") return OutputFormat::Dng;
  throw InputError(fmt::format("{}: unknown output format \"{}\" (the name must end in .exr, .tif, .tiff, .png or .dng)",
                               file.string(), ext));
}

struct SensorImageWriter::File {
  // EXR
  std::unique_ptr<AtomicExrOutput> exr;
  std::vector<float> ids;  // object ids as floats, for the current block
  std::vector<Imath::half> display;  // the display layer as half, for the current block
  // TIFF / PNG
  std::unique_ptr<AtomicFile> output;  // declared before the image writer: destroyed after it lets go of the file
  std::unique_ptr<OIIO::ImageOutput> image;
  // DNG
  std::unique_ptr<DngWriter> dng;
};

SensorImageWriter::SensorImageWriter(const fs::path& path, OutputLayout layout)
    : path_(path), layout_(std::move(layout)) {
  const std::string name = path_.string();
  if (layout_.width < 1 || layout_.height < 1)
    throw InputError(
        fmt::format("{}: image size must be at least 1 x 1, got {} x {}", name, layout_.width, layout_.height));
  auto file = std::make_unique<File>();

  if (layout_.format == OutputFormat::Exr) {
    Imf::Header header(layout_.width, layout_.height);
    header.compression() = Imf::ZIP_COMPRESSION;
    for (const std::string& layer : [&] {
           std::vector<std::string> layers = {"", "linear"};
           layers.insert(layers.end(), layout_.components.begin(), layout_.components.end());
           if (layout_.display) layers.push_back("display");
           return layers;
         }())
      for (int c = 0; c < 3; ++c)
        header.channels().insert(layer_channel(layer, c), Imf::Channel(layer == "display" ? Imf::HALF : Imf::FLOAT));
    if (layout_.object_ids) {
      header.channels().insert(exr::kObjectIdChannel, Imf::Channel(Imf::FLOAT));
      header.insert(exr::kObjectsAttribute, Imf::StringAttribute(exr::object_names_text(layout_.object_names)));
    }
    for (const auto& [key, value] : layout_.attributes) header.insert(key, Imf::StringAttribute(value));
    for (const auto& [key, value] : layout_.number_attributes) header.insert(key, Imf::DoubleAttribute(value));
    for (const auto& [key, value] : layout_.integer_attributes) header.insert(key, Imf::IntAttribute(value));
    file->exr = std::make_unique<AtomicExrOutput>(path_, header);
  } else if (layout_.format == OutputFormat::Dng) {
    file->dng = std::make_unique<DngWriter>(path_, layout_.width, layout_.height, layout_.dng);
  } else {
    file->output = std::make_unique<AtomicFile>(path_);
    const std::string temporary = file->output->temporary().string();
    const char* format = layout_.format == OutputFormat::Tiff ? "tiff" : "png";
    file->image = OIIO::ImageOutput::create(format);
    if (!file->image) throw std::runtime_error(fmt::format("{}: OpenImageIO cannot write {}", name, format));
    OIIO::ImageSpec spec(layout_.width, layout_.height, 3,
                         layout_.bits == 8 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::UINT16);
    if (layout_.format == OutputFormat::Tiff) spec.attribute("compression", "zip");
    if (!layout_.colour_space.empty()) spec.attribute("oiio:ColorSpace", layout_.colour_space);
    nlohmann::json description = nlohmann::json::object();
    for (const auto& [key, value] : layout_.number_attributes) {
      spec.attribute(key, OIIO::TypeDesc::DOUBLE, &value);
      description[key] = value;
    }
    for (const auto& [key, value] : layout_.integer_attributes) {
      spec.attribute(key, value);
      description[key] = value;
    }
    if (!description.empty()) spec.attribute("ImageDescription", description.dump(-1, ' ', false, kReplaceInvalidUtf8));
    if (!file->image->open(temporary, spec))
      throw std::runtime_error(fmt::format("{}: cannot start writing: {}", name, file->image->geterror()));
  }
  file_ = std::move(file);
}

SensorImageWriter::~SensorImageWriter() = default;

void SensorImageWriter::write_rows(const OutputRows& block) {
  if (!file_) throw std::logic_error(fmt::format("{}: write_rows after finish", path_.string()));
  const std::size_t width = static_cast<std::size_t>(layout_.width);
  const std::size_t values = static_cast<std::size_t>(block.rows) * width * (layout_.format == OutputFormat::Dng ? 1 : 3);
  if (block.rows < 0 || rows_written_ + block.rows > layout_.height || block.image.size() != values)
    throw std::invalid_argument(fmt::format("{}: row block does not fit the layout", path_.string()));
  if (block.rows == 0) return;
  const int y0 = rows_written_;

  if (layout_.format == OutputFormat::Exr) {
    const bool sizes_match =
        block.linear.size() == values && block.components.size() == layout_.components.size() &&
        std::all_of(block.components.begin(), block.components.end(), [&](auto c) { return c.size() == values; }) &&
        block.object_ids.size() == (layout_.object_ids ? values / 3 : 0) &&
        block.display.size() == (layout_.display ? values : 0);
    if (!sizes_match) throw std::invalid_argument(fmt::format("{}: row block layers do not match", path_.string()));
    Imf::FrameBuffer frame;
    insert_rgb(frame, "", block.image.data(), layout_.width, y0, block.rows);
    insert_rgb(frame, "linear", block.linear.data(), layout_.width, y0, block.rows);
    for (std::size_t c = 0; c < layout_.components.size(); ++c)
      insert_rgb(frame, layout_.components[c], block.components[c].data(), layout_.width, y0, block.rows);
    if (layout_.display) {  // stored as half: 11 bits of an sRGB-encoded value in [0, 1] are 3 more than 8-bit
      file_->display.assign(block.display.begin(), block.display.end());
      const Imath::Box2i window({0, y0}, {layout_.width - 1, y0 + block.rows - 1});
      for (int c = 0; c < 3; ++c)
        frame.insert(layer_channel("display", c),
                     Imf::Slice::Make(Imf::HALF, file_->display.data() + c, window, 3 * sizeof(Imath::half),
                                      3 * sizeof(Imath::half) * width));
    }
    if (layout_.object_ids) {
      file_->ids.assign(block.object_ids.begin(), block.object_ids.end());
      const Imath::Box2i window({0, y0}, {layout_.width - 1, y0 + block.rows - 1});
      frame.insert(exr::kObjectIdChannel,
                   Imf::Slice::Make(Imf::FLOAT, file_->ids.data(), window, sizeof(float), sizeof(float) * width));
    }
    file_->exr->write_rows(frame, y0, block.rows);
  } else if (file_->dng) {
    file_->dng->write_rows(y0, block.rows, block.image);
  } else {
    const double top = std::ldexp(1.0, layout_.bits) - 1.0;
    const auto code = [&](float v) { return std::clamp(std::round(v * layout_.code_scale), 0.0, top); };
    bool written = false;
    if (layout_.bits == 8) {
      std::vector<std::uint8_t> codes(values);
      for (std::size_t i = 0; i < values; ++i) codes[i] = static_cast<std::uint8_t>(code(block.image[i]));
      written = file_->image->write_scanlines(y0, y0 + block.rows, 0, OIIO::TypeDesc::UINT8, codes.data());
    } else {
      std::vector<std::uint16_t> codes(values);
      for (std::size_t i = 0; i < values; ++i) codes[i] = static_cast<std::uint16_t>(code(block.image[i]));
      written = file_->image->write_scanlines(y0, y0 + block.rows, 0, OIIO::TypeDesc::UINT16, codes.data());
    }
    if (!written)
      throw std::runtime_error(fmt::format("{}: cannot write rows {}-{}: {}", path_.string(), y0, y0 + block.rows - 1,
                                           file_->image->geterror()));
  }
  rows_written_ += block.rows;
}

void SensorImageWriter::finish() {
  if (!file_) throw std::logic_error(fmt::format("{}: finish called twice", path_.string()));
  if (rows_written_ != layout_.height)
    throw std::logic_error(
        fmt::format("{}: finish after {} of {} rows", path_.string(), rows_written_, layout_.height));
  if (file_->exr) {
    file_->exr->finish();
  } else if (file_->dng) {
    file_->dng->finish();
  } else {
    if (!file_->image->close())
      throw std::runtime_error(fmt::format("{}: cannot complete the file: {}", path_.string(), file_->image->geterror()));
    if (layout_.format == OutputFormat::Png)
      check_complete_png(file_->output->temporary(), path_);
    else
      check_complete_tiff(file_->output->temporary(), path_, layout_.width, layout_.height);
    file_->output->commit();
  }
  file_.reset();
}

}  // namespace ct::sensor
