// SPDX-License-Identifier: Apache-2.0
// chromatrace export-meshes SCENE.json DIR: the triangles of every object and light as PLY files, made by the
// one tessellation rule (core/geometry.h), so that another renderer (Cycles through the Blender add-on) sees
// exactly the triangles the reference tracer traces.
#include <cctype>
#include <filesystem>
#include <memory>
#include <string>
#include <system_error>

#include <fmt/core.h>

#include "cli/app.h"
#include "cli/command.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/geometry.h"
#include "core/json_input.h"
#include "core/ply.h"
#include "core/scene.h"

namespace ct::cli {
namespace {

namespace fs = std::filesystem;

struct ExportMeshesOptions {
  std::string scene, directory;
  bool ascii = false, json = false, quiet = false, uvs = false;
};

// "007_left wall" -> "007_left_wall.ply": the id keeps names unique, the name keeps files readable.
std::string mesh_file_name(int id, const std::string& name) {
  std::string safe;
  for (const char c : name)
    safe += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.') ? c : '_';
  return fmt::format("{:03d}_{}.ply", id, safe);
}

int run(const ExportMeshesOptions& o) {
  const Scene scene = load_scene(o.scene);
  const fs::path dir(o.directory);
  check_output_directory(dir, scene.files);
  const std::vector<TriangleMesh> meshes = scene_meshes(scene);
  // Every file name first: a mesh the scene reads must not be replaced by its own export.
  std::vector<std::string> files;
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    const bool is_light = i >= scene.objects.size();
    const std::string& name = is_light ? scene.lights[i - scene.objects.size()].name : scene.objects[i].name;
    files.push_back(mesh_file_name(static_cast<int>(i) + 1, name));
    if (fs::is_directory(dir)) check_output_file(dir / files.back(), scene.files);
  }
  // Written aside and moved into place when complete: a full disk leaves no partial set of meshes behind.
  StagedDirectory staged(dir);

  const PlyFormat format = o.ascii ? PlyFormat::Ascii : PlyFormat::BinaryLittleEndian;
  Json objects = Json::array(), lights = Json::array();
  std::size_t triangles = 0;
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    const bool is_light = i >= scene.objects.size();
    const std::string& name = is_light ? scene.lights[i - scene.objects.size()].name : scene.objects[i].name;
    const int id = static_cast<int>(i) + 1;
    const std::string& file = files[i];
    if (o.uvs) {
      const std::vector<std::array<Vec2, 3>> uvs =
          is_light ? std::visit([](const auto& shape) { return corner_uvs(Shape(shape)); }, scene.lights[i - scene.objects.size()].shape)
                   : corner_uvs(scene.objects[i].shape);
      write_ply(staged.path() / file, with_vertex_uvs(meshes[i], uvs), format);
    } else {
      write_ply(staged.path() / file, meshes[i], format);
    }
    triangles += meshes[i].triangles.size();
    (is_light ? lights : objects)
        .push_back({{"name", name},
                    {"id", id},
                    {"file", file},
                    {"triangles", meshes[i].triangles.size()},
                    {"smooth", !meshes[i].normals.empty()}});
  }
  staged.commit();
  if (o.json)
    fmt::print("{}\n", Json({{"scene", o.scene}, {"directory", o.directory}, {"objects", objects}, {"lights", lights}}).dump(1, ' ', false, kReplaceInvalidUtf8));
  else if (!o.quiet)
    fmt::print("{}: {} meshes, {} triangles\n", o.directory, meshes.size(), triangles);
  return 0;
}

}  // namespace

Action add_export_meshes(CLI::App& app) {
  auto o = std::make_shared<ExportMeshesOptions>();
  auto* cmd = add_command(app, "export-meshes");
  cmd->add_option("scene", o->scene, "Scene file (chromatrace-scene/1)")->required();
  cmd->add_option("directory", o->directory, "Output directory (created if missing; its parent must exist)")->required();
  cmd->add_flag("--ascii", o->ascii, "Write ASCII PLY instead of binary little-endian");
  cmd->add_flag("--uvs", o->uvs,
                "Write each vertex's texture coordinates (u, v) as the tracer maps textures, a vertex on a seam once per "
                "(u, v)");
  cmd->add_flag("--json", o->json, "Print the list of files (name, object id, file, triangles, smooth) as JSON");
  cmd->add_flag("-q,--quiet", o->quiet, "Print nothing on success");
  return [o] { return run(*o); };
}

}  // namespace ct::cli
