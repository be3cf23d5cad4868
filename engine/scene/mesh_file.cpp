#include "engine/scene/mesh_file.h"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>

namespace odemag {

std::string mesh_size_refusal(size_t triangles) {
  char text[256];
  std::snprintf(text, sizeof text,
                "%zu triangles, more than the %zu accepted: loading and checking it would take about %.0f s "
                "and %.0f MB",
                triangles, kMaxMeshTriangles, kMeshSecondsPerTriangle * static_cast<double>(triangles),
                static_cast<double>(triangles) * 150.0 / 1e6);
  return text;
}

void join_identical_vertices(MeshFileContent& mesh) {
  std::map<std::array<double, 3>, int> index;
  std::vector<int> to(mesh.vertices.size());
  std::vector<Vec3> joined;
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Vec3& v = mesh.vertices[i];
    // +0 and -0 are one position.
    const std::array<double, 3> key = {v.x + 0.0, v.y + 0.0, v.z + 0.0};
    auto [it, added] = index.try_emplace(key, static_cast<int>(joined.size()));
    if (added) joined.push_back(v);
    to[i] = it->second;
  }
  for (auto& t : mesh.triangles)
    for (int& k : t) k = to[static_cast<size_t>(k)];
  mesh.vertices = std::move(joined);
}

namespace {

// A binary STL's triangle count from its header (80 bytes, then a 32-bit
// count), so that a huge file is refused before it is read; 0 when the file
// is not a binary STL.
size_t binary_stl_count(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char head[84];
  if (!in.read(head, sizeof head)) return 0;
  if (std::string(head, 5) == "solid") return 0;  // ASCII (or a binary one whose header says solid: Assimp decides)
  const auto* b = reinterpret_cast<const unsigned char*>(head + 80);
  return static_cast<size_t>(b[0]) | static_cast<size_t>(b[1]) << 8 | static_cast<size_t>(b[2]) << 16 |
         static_cast<size_t>(b[3]) << 24;
}

}  // namespace

MeshFileContent read_mesh_file(const std::string& path) {
  namespace fs = std::filesystem;
  const std::string name = "\"" + path + "\"";
  std::error_code ec;
  if (!fs::exists(path, ec)) throw MeshFileError("mesh file " + name + " does not exist");
  if (fs::is_directory(path, ec)) throw MeshFileError("mesh file " + name + " is a folder");
  if (!std::ifstream(path, std::ios::binary)) throw MeshFileError("mesh file " + name + " cannot be read");
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  Assimp::Importer importer;
  if (ext.empty() || !importer.IsExtensionSupported(ext))
    throw MeshFileError("mesh file " + name + ": unknown format \"" + ext +
                        "\" (STL, OBJ, PLY and the other formats of Assimp are read)");
  if (ext == ".stl")
    if (const size_t n = binary_stl_count(path); n > kMaxMeshTriangles)
      throw MeshFileError("mesh file " + name + " has " + mesh_size_refusal(n));
  const aiScene* scene = importer.ReadFile(
      path, aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_ValidateDataStructure);
  if (!scene || !scene->mRootNode || (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE))
    throw MeshFileError("mesh file " + name + " cannot be read as " + ext.substr(1) + ": " +
                        std::string(importer.GetErrorString()));
  MeshFileContent out;
  size_t triangles = 0;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) triangles += scene->mMeshes[m]->mNumFaces;
  if (triangles > kMaxMeshTriangles) throw MeshFileError("mesh file " + name + " has " + mesh_size_refusal(triangles));
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    const int first = static_cast<int>(out.vertices.size());
    for (unsigned v = 0; v < mesh->mNumVertices; ++v)
      out.vertices.push_back({mesh->mVertices[v].x, mesh->mVertices[v].y, mesh->mVertices[v].z});
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines: no solid
      out.triangles.push_back({first + static_cast<int>(face.mIndices[0]), first + static_cast<int>(face.mIndices[1]),
                               first + static_cast<int>(face.mIndices[2])});
    }
  }
  if (out.triangles.empty()) throw MeshFileError("mesh file " + name + " holds no triangles");
  join_identical_vertices(out);
  return out;
}

}  // namespace odemag
