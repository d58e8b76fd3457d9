// SPDX-License-Identifier: Apache-2.0
#include "core/ply.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <fmt/core.h>

#include "core/error.h"
#include "core/file_io.h"

namespace ct {
namespace {

enum class ScalarType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

std::optional<ScalarType> scalar_type(std::string_view name) {
  struct Alias {
    std::string_view name;
    ScalarType type;
  };
  static constexpr Alias aliases[] = {
      {"char", ScalarType::Int8},      {"int8", ScalarType::Int8},       {"uchar", ScalarType::UInt8},
      {"uint8", ScalarType::UInt8},    {"short", ScalarType::Int16},     {"int16", ScalarType::Int16},
      {"ushort", ScalarType::UInt16},  {"uint16", ScalarType::UInt16},   {"int", ScalarType::Int32},
      {"int32", ScalarType::Int32},    {"uint", ScalarType::UInt32},     {"uint32", ScalarType::UInt32},
      {"float", ScalarType::Float32},  {"float32", ScalarType::Float32}, {"double", ScalarType::Float64},
      {"float64", ScalarType::Float64}};
  for (const Alias& a : aliases)
    if (a.name == name) return a.type;
  return std::nullopt;
}

// Bytes one value takes at the least: its size in binary, a character and a separator in ASCII.
std::size_t min_bytes(ScalarType type, PlyFormat format) {
  if (format == PlyFormat::Ascii) return 2;
  switch (type) {
    case ScalarType::Int8:
    case ScalarType::UInt8: return 1;
    case ScalarType::Int16:
    case ScalarType::UInt16: return 2;
    case ScalarType::Int32:
    case ScalarType::UInt32:
    case ScalarType::Float32: return 4;
    case ScalarType::Float64: return 8;
  }
  return 1;
}

struct Property {
  std::string name;
  ScalarType type;                       // the item type for a list
  std::optional<ScalarType> list_count;  // set for list properties
};

struct Element {
  std::string name;
  std::size_t count = 0;
  std::vector<Property> properties;

  std::optional<std::size_t> find(std::string_view property) const {
    for (std::size_t i = 0; i < properties.size(); ++i)
      if (properties[i].name == property) return i;
    return std::nullopt;
  }
};

struct Header {
  PlyFormat format = PlyFormat::Ascii;
  std::vector<Element> elements;
  std::size_t body_offset = 0;  // first byte after "end_header\n"
};

std::vector<std::string_view> split_words(std::string_view line) {
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

Header parse_header(std::string_view bytes, const std::string& source) {
  Header header;
  std::size_t pos = 0;
  bool format_seen = false;
  for (int line_no = 1;; ++line_no) {
    const std::size_t end = bytes.find('\n', pos);
    if (end == std::string_view::npos) throw InputError(fmt::format("{}: header has no end_header line", source));
    std::string_view line = bytes.substr(pos, end - pos);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos = end + 1;
    auto fail = [&](std::string_view message) {
      throw InputError(fmt::format("{}: header line {}: {}", source, line_no, message));
    };
    const std::vector<std::string_view> w = split_words(line);
    if (line_no == 1) {
      if (line != "ply") throw InputError(fmt::format("{}: not a PLY file (first line is not \"ply\")", source));
      continue;
    }
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") break;
    if (w[0] == "format") {
      if (w.size() != 3) fail("expected \"format <type> 1.0\"");
      if (w[1] == "ascii")
        header.format = PlyFormat::Ascii;
      else if (w[1] == "binary_little_endian")
        header.format = PlyFormat::BinaryLittleEndian;
      else
        fail(fmt::format("format \"{}\" is not supported (use ascii or binary_little_endian)", w[1]));
      format_seen = true;
    } else if (w[0] == "element") {
      std::size_t count = 0;
      if (w.size() != 3 || std::from_chars(w[2].data(), w[2].data() + w[2].size(), count).ec != std::errc())
        fail("expected \"element <name> <count>\"");
      header.elements.push_back({std::string(w[1]), count, {}});
    } else if (w[0] == "property") {
      if (header.elements.empty()) fail("property before any element");
      const bool list = w.size() == 5 && w[1] == "list";
      if (!list && w.size() != 3) fail("expected \"property <type> <name>\" or \"property list <type> <type> <name>\"");
      const std::string_view type_name = list ? w[3] : w[1];
      const std::optional<ScalarType> type = scalar_type(type_name);
      if (!type) fail(fmt::format("unknown property type \"{}\"", type_name));
      std::optional<ScalarType> count_type;
      if (list) {
        count_type = scalar_type(w[2]);
        if (!count_type || *count_type == ScalarType::Float32 || *count_type == ScalarType::Float64)
          fail(fmt::format("list count type \"{}\" must be an integer type", w[2]));
      }
      header.elements.back().properties.push_back({std::string(w.back()), *type, count_type});
    } else {
      fail(fmt::format("unexpected \"{}\"", w[0]));
    }
  }
  if (!format_seen) throw InputError(fmt::format("{}: header has no format line", source));
  header.body_offset = pos;
  return header;
}

// Reads scalars from the body, as text tokens or as little-endian binary.
class BodyReader {
 public:
  BodyReader(std::string_view body, PlyFormat format, const std::string& source)
      : body_(body), format_(format), source_(source) {}

  // `where` names the element being read ("vertex 12") for the message on truncated or bad data.
  double read(ScalarType type, const std::string& where) {
    return format_ == PlyFormat::Ascii ? read_text(where) : read_binary(type, where);
  }
  std::size_t remaining() const { return body_.size() - pos_; }
  // At most how many values of `type` the rest of the file can hold (the last ASCII value needs no separator).
  std::size_t capacity(ScalarType type) const {
    return (body_.size() - pos_ + (format_ == PlyFormat::Ascii ? 1 : 0)) / min_bytes(type, format_);
  }

 private:
  double read_text(const std::string& where) {
    while (pos_ < body_.size() && std::isspace(static_cast<unsigned char>(body_[pos_]))) ++pos_;
    const std::size_t start = pos_;
    while (pos_ < body_.size() && !std::isspace(static_cast<unsigned char>(body_[pos_]))) ++pos_;
    if (start == pos_) throw InputError(fmt::format("{}: {}: unexpected end of file", source_, where));
    double value = 0.0;
    const auto [end, ec] = std::from_chars(body_.data() + start, body_.data() + pos_, value);
    if (ec != std::errc() || end != body_.data() + pos_)
      throw InputError(
          fmt::format("{}: {}: \"{}\" is not a number", source_, where, body_.substr(start, pos_ - start)));
    return value;
  }

  template <typename T>
  double load(const std::string& where) {
    if (body_.size() - pos_ < sizeof(T))
      throw InputError(fmt::format("{}: {}: unexpected end of file", source_, where));
    unsigned char raw[sizeof(T)];
    std::memcpy(raw, body_.data() + pos_, sizeof(T));
    if constexpr (std::endian::native == std::endian::big) std::reverse(std::begin(raw), std::end(raw));
    T value;
    std::memcpy(&value, raw, sizeof(T));
    pos_ += sizeof(T);
    return static_cast<double>(value);
  }

  double read_binary(ScalarType type, const std::string& where) {
    switch (type) {
      case ScalarType::Int8: return load<std::int8_t>(where);
      case ScalarType::UInt8: return load<std::uint8_t>(where);
      case ScalarType::Int16: return load<std::int16_t>(where);
      case ScalarType::UInt16: return load<std::uint16_t>(where);
      case ScalarType::Int32: return load<std::int32_t>(where);
      case ScalarType::UInt32: return load<std::uint32_t>(where);
      case ScalarType::Float32: return load<float>(where);
      case ScalarType::Float64: return load<double>(where);
    }
    return 0.0;
  }

  std::string_view body_;
  PlyFormat format_;
  const std::string& source_;
  std::size_t pos_ = 0;
};

// One element instance: the scalar properties' values, and the items of the list property named `list`.
struct Record {
  std::vector<double> scalars;  // indexed like the element's properties (lists leave a 0)
  std::vector<double> list;
};

Record read_record(BodyReader& reader, const Element& element, std::optional<std::size_t> list,
                   const std::string& source, const std::string& where) {
  Record record;
  record.scalars.assign(element.properties.size(), 0.0);
  for (std::size_t p = 0; p < element.properties.size(); ++p) {
    const Property& property = element.properties[p];
    if (!property.list_count) {
      record.scalars[p] = reader.read(property.type, where);
      continue;
    }
    const double n = reader.read(*property.list_count, where);
    if (n < 0 || n != std::floor(n))
      throw InputError(fmt::format("{}: {}: list length {} is not a count", source, where, n));
    // Before allocating the items: a length the rest of the file cannot hold is a lie (or a cut file).
    if (n > static_cast<double>(reader.capacity(property.type)))
      throw InputError(fmt::format("{}: {}: list length {} is more than the rest of the file holds", source, where, n));
    std::vector<double> items(static_cast<std::size_t>(n));
    for (double& item : items) item = reader.read(property.type, where);
    if (list && p == *list) record.list = std::move(items);
  }
  return record;
}

}  // namespace

TriangleMesh parse_ply(std::string_view bytes, const std::string& source) {
  const Header header = parse_header(bytes, source);
  BodyReader reader(bytes.substr(header.body_offset), header.format, source);
  TriangleMesh mesh;
  std::vector<std::vector<double>> faces;
  bool vertices_seen = false, faces_seen = false;

  for (const Element& element : header.elements) {
    std::optional<std::size_t> xyz[3], nxyz[3], uv[2], face_list;
    if (element.name == "vertex") {
      vertices_seen = true;
      const char* names[] = {"x", "y", "z", "nx", "ny", "nz"};
      for (int k = 0; k < 3; ++k) {
        xyz[k] = element.find(names[k]);
        nxyz[k] = element.find(names[3 + k]);
        if (!xyz[k]) throw InputError(fmt::format("{}: vertex element has no property {}", source, names[k]));
      }
      if (nxyz[0].has_value() != nxyz[1].has_value() || nxyz[0].has_value() != nxyz[2].has_value())
        throw InputError(fmt::format("{}: vertex normals need all of nx, ny, nz", source));
      // Texture coordinates under the names exporters use (Blender writes s, t).
      for (const auto& [u, v] : {std::pair{"u", "v"}, {"s", "t"}, {"texture_u", "texture_v"}, {"texture_s", "texture_t"}}) {
        if (uv[0]) break;
        uv[0] = element.find(u);
        uv[1] = element.find(v);
        if (uv[0].has_value() != uv[1].has_value())
          throw InputError(fmt::format("{}: texture coordinates need both {} and {}", source, u, v));
      }
    } else if (element.name == "face") {
      faces_seen = true;
      face_list = element.find("vertex_indices");
      if (!face_list) face_list = element.find("vertex_index");
      if (!face_list || !element.properties[*face_list].list_count)
        throw InputError(fmt::format("{}: face element has no list property vertex_indices", source));
    }

    // Before reading: a count the rest of the file cannot hold (4e9 elements in 200 bytes) is refused at
    // once instead of read value by value; an element with no properties holds nothing to read.
    if (element.properties.empty()) continue;
    std::size_t record_bytes = 0;
    for (const Property& property : element.properties)
      record_bytes += min_bytes(property.list_count ? *property.list_count : property.type, header.format);
    const std::size_t room = (reader.remaining() + (header.format == PlyFormat::Ascii ? 1 : 0)) / record_bytes;
    if (element.count > room)
      throw InputError(fmt::format("{}: element {} declares {} entries, more than the {} that the rest of the file can hold",
                                   source, element.name, element.count, room));
    for (std::size_t i = 0; i < element.count; ++i) {
      const std::string where = fmt::format("{} {}", element.name, i);
      Record record = read_record(reader, element, face_list, source, where);
      if (element.name == "vertex") {
        const Vec3 p(record.scalars[*xyz[0]], record.scalars[*xyz[1]], record.scalars[*xyz[2]]);
        if (!p.allFinite()) throw InputError(fmt::format("{}: {}: position is not finite", source, where));
        mesh.positions.push_back(p);
        if (nxyz[0]) {
          const Vec3 n(record.scalars[*nxyz[0]], record.scalars[*nxyz[1]], record.scalars[*nxyz[2]]);
          const double length = n.norm();
          if (!(length > 0.0) || !std::isfinite(length))
            throw InputError(
                fmt::format("{}: {}: normal ({}, {}, {}) has no direction", source, where, n.x(), n.y(), n.z()));
          mesh.normals.push_back(n / length);
        }
        if (uv[0]) {
          const Vec2 t(record.scalars[*uv[0]], record.scalars[*uv[1]]);
          if (!t.allFinite()) throw InputError(fmt::format("{}: {}: texture coordinate is not finite", source, where));
          mesh.uvs.push_back(t);
        }
      } else if (element.name == "face") {
        faces.push_back(std::move(record.list));
      }
    }
  }
  if (!vertices_seen) throw InputError(fmt::format("{}: no vertex element", source));
  if (!faces_seen) throw InputError(fmt::format("{}: no face element", source));

  const std::size_t vertex_count = mesh.positions.size();
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const std::vector<double>& face = faces[f];
    if (face.size() < 3)
      throw InputError(fmt::format("{}: face {}: has {} vertices, needs at least 3", source, f, face.size()));
    for (double index : face)
      if (!(index >= 0 && index < static_cast<double>(vertex_count)) || index != std::floor(index))
        throw InputError(
            fmt::format("{}: face {}: vertex index {} out of range ({} vertices)", source, f, index, vertex_count));
    for (std::size_t k = 1; k + 1 < face.size(); ++k)
      mesh.triangles.push_back({static_cast<std::uint32_t>(face[0]), static_cast<std::uint32_t>(face[k]),
                                static_cast<std::uint32_t>(face[k + 1])});
  }
  return mesh;
}

TriangleMesh read_ply(const std::filesystem::path& file) { return parse_ply(read_file(file), file.string()); }

namespace {

template <typename T>
void append_binary(std::string& out, T value) {
  unsigned char raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(std::begin(raw), std::end(raw));
  out.append(reinterpret_cast<const char*>(raw), sizeof(T));
}

}  // namespace

std::string format_ply(const TriangleMesh& mesh, PlyFormat format) {
  if (mesh.positions.size() > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    throw std::runtime_error("PLY: too many vertices for int indices");
  const bool normals = !mesh.normals.empty();
  const bool uvs = !mesh.uvs.empty();
  const bool ascii = format == PlyFormat::Ascii;
  std::string out = fmt::format("ply\nformat {} 1.0\ncomment written by chromatrace\nelement vertex {}\n",
                                ascii ? "ascii" : "binary_little_endian", mesh.positions.size());
  for (const char* name : {"x", "y", "z"}) out += fmt::format("property double {}\n", name);
  if (normals)
    for (const char* name : {"nx", "ny", "nz"}) out += fmt::format("property double {}\n", name);
  if (uvs)
    for (const char* name : {"u", "v"}) out += fmt::format("property double {}\n", name);
  out += fmt::format("element face {}\nproperty list uchar int vertex_indices\nend_header\n", mesh.triangles.size());

  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    std::vector<double> values(mesh.positions[i].data(), mesh.positions[i].data() + 3);
    if (normals) values.insert(values.end(), mesh.normals[i].data(), mesh.normals[i].data() + 3);
    if (uvs) values.insert(values.end(), mesh.uvs[i].data(), mesh.uvs[i].data() + 2);
    if (ascii) {
      // fmt's shortest round-trip form, so reading back gives the same doubles.
      for (std::size_t k = 0; k < values.size(); ++k) out += fmt::format("{}{}", k ? " " : "", values[k]);
      out += '\n';
    } else {
      for (double v : values) append_binary(out, v);
    }
  }
  for (const auto& [a, b, c] : mesh.triangles) {
    if (ascii) {
      out += fmt::format("3 {} {} {}\n", a, b, c);
    } else {
      append_binary<std::uint8_t>(out, 3);
      for (std::uint32_t index : {a, b, c}) append_binary(out, static_cast<std::int32_t>(index));
    }
  }
  return out;
}

void write_ply(const std::filesystem::path& file, const TriangleMesh& mesh, PlyFormat format) {
  write_file_atomically(file, format_ply(mesh, format));
}

}  // namespace ct
