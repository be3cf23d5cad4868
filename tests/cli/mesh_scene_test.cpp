// Mesh and compound bodies in scene files (docs/scene-format.md "Meshes",
// "Compounds"): STL (ASCII and binary), OBJ and PLY files and inline arrays
// give the same body; every bad input is refused with one message naming the
// file and the key, and `odemag solve` exits 2 with one line.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "odemag/scene.h"
#include "tests/support/program_run.h"

namespace odemag {
namespace {

namespace fs = std::filesystem;
using Tri = std::array<int, 3>;

// The unit cube [0, 1]^3 (mm in the files below), outward.
const std::vector<Vec3> kCubeVertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0},
                                         {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
const std::vector<Tri> kCubeTriangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                                         {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};

class MeshScene : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("odemag_mesh_scene_" + std::to_string(::getpid()) + "_" +
                                         ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path write(const std::string& name, const std::string& content) const {
    std::ofstream(dir_ / name, std::ios::binary) << content;
    return dir_ / name;
  }
  // A scene of one magnet whose shape is `shape`, written to scene.json.
  fs::path scene(const std::string& shape) const {
    return write("scene.json", R"({"cell_size": 0.0002,
      "materials": {"m": {"type": "permanent", "magnetization": [0, 0, 1e6]}},
      "bodies": [{"name": "part", "shape": )" + shape + R"(, "material": "m", "density": 1000}]})");
  }
  SceneDescription load(const std::string& shape) const { return load_scene(scene(shape).string()); }
  SceneError refusal(const std::string& shape) const {
    try {
      load(shape);
    } catch (const SceneError& e) {
      return e;
    }
    ADD_FAILURE() << "accepted: " << shape;
    return SceneError("", "", "");
  }
  fs::path dir_;
};

std::string ascii_stl(const std::vector<Vec3>& v, const std::vector<Tri>& t) {
  std::string s = "solid cube\n";
  for (const Tri& f : t) {
    s += " facet normal 0 0 0\n  outer loop\n";
    for (int k : f)
      s += "   vertex " + std::to_string(v[k].x) + " " + std::to_string(v[k].y) + " " + std::to_string(v[k].z) + "\n";
    s += "  endloop\n endfacet\n";
  }
  return s + "endsolid cube\n";
}

std::string binary_stl(const std::vector<Vec3>& v, const std::vector<Tri>& t, uint32_t count_in_header = 0) {
  std::string s(80, ' ');
  const uint32_t n = count_in_header ? count_in_header : static_cast<uint32_t>(t.size());
  s.append(reinterpret_cast<const char*>(&n), 4);
  for (const Tri& f : t) {
    float data[12] = {0, 0, 0};
    for (int k = 0; k < 3; ++k) {
      data[3 + 3 * k] = static_cast<float>(v[f[k]].x);
      data[4 + 3 * k] = static_cast<float>(v[f[k]].y);
      data[5 + 3 * k] = static_cast<float>(v[f[k]].z);
    }
    s.append(reinterpret_cast<const char*>(data), sizeof data);
    s.append(2, '\0');
  }
  return s;
}

std::string obj(const std::vector<Vec3>& v, const std::vector<Tri>& t) {
  std::string s;
  for (const Vec3& x : v) s += "v " + std::to_string(x.x) + " " + std::to_string(x.y) + " " + std::to_string(x.z) + "\n";
  for (const Tri& f : t) s += "f " + std::to_string(f[0] + 1) + " " + std::to_string(f[1] + 1) + " " + std::to_string(f[2] + 1) + "\n";
  return s;
}

std::string ply(const std::vector<Vec3>& v, const std::vector<Tri>& t) {
  std::string s = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(v.size()) +
                  "\nproperty float x\nproperty float y\nproperty float z\nelement face " + std::to_string(t.size()) +
                  "\nproperty list uchar int vertex_indices\nend_header\n";
  for (const Vec3& x : v) s += std::to_string(x.x) + " " + std::to_string(x.y) + " " + std::to_string(x.z) + "\n";
  for (const Tri& f : t) s += "3 " + std::to_string(f[0]) + " " + std::to_string(f[1]) + " " + std::to_string(f[2]) + "\n";
  return s;
}

// The unit cube in mm, scale 0.001: a 1 mm cube, 1e-9 m^3, its centre of
// mass moved to the body origin; the same from every format and inline.
TEST_F(MeshScene, EveryFormatGivesTheCube) {
  write("cube_ascii.stl", ascii_stl(kCubeVertices, kCubeTriangles));
  write("cube_binary.stl", binary_stl(kCubeVertices, kCubeTriangles));
  write("cube.obj", obj(kCubeVertices, kCubeTriangles));
  write("cube.ply", ply(kCubeVertices, kCubeTriangles));
  std::vector<std::string> shapes;
  for (const char* f : {"cube_ascii.stl", "cube_binary.stl", "cube.obj", "cube.ply"})
    shapes.push_back(std::string(R"({"mesh": {"file": ")") + f + R"(", "scale": 0.001}})");
  shapes.push_back(R"({"mesh": {"vertices": [[0,0,0],[0.001,0,0],[0,0.001,0],[0.001,0.001,0],[0,0,0.001],
    [0.001,0,0.001],[0,0.001,0.001],[0.001,0.001,0.001]], "triangles": [[0,2,1],[1,2,3],[4,5,6],[5,7,6],[0,1,4],
    [1,5,4],[2,6,3],[3,6,7],[0,4,2],[2,4,6],[1,3,5],[3,7,5]]}})");
  for (const std::string& s : shapes) {
    const SceneDescription d = load(s);
    const Mesh* m = std::get_if<Mesh>(&d.bodies[0].shape);
    ASSERT_NE(m, nullptr) << s;
    EXPECT_EQ(m->vertices().size(), 8u) << s;  // identical vertices joined
    EXPECT_EQ(m->triangles().size(), 12u) << s;
    EXPECT_NEAR(shape_volume(*m), 1e-9, 1e-15) << s;
    const Vec3 h = shape_half_extents(*m);
    EXPECT_NEAR(h.x, 0.0005, 1e-9) << s;  // centred
    EXPECT_TRUE(d.notices.empty()) << s;
  }
}

void expect_refusal(const SceneError& e, const std::string& key, const std::string& words) {
  EXPECT_EQ(e.key(), key) << e.what();
  EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
  EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
}

TEST_F(MeshScene, BadFilesAreRefusedNamingTheFileAndTheKey) {
  const std::string key = "bodies[0].shape.mesh.file";
  expect_refusal(refusal(R"({"mesh": {"file": "missing.stl"}})"), key, "missing.stl\" does not exist");
  write("cube.xyz", "1 2 3\n");
  expect_refusal(refusal(R"({"mesh": {"file": "cube.xyz"}})"), key, "unknown format \".xyz\"");
  std::string truncated = binary_stl(kCubeVertices, kCubeTriangles);
  truncated.resize(truncated.size() - 120);
  write("truncated.stl", truncated);
  expect_refusal(refusal(R"({"mesh": {"file": "truncated.stl"}})"), key, "truncated.stl\" cannot be read as stl");
  std::vector<Tri> open = kCubeTriangles;
  open.pop_back();
  write("open.stl", binary_stl(kCubeVertices, open));
  expect_refusal(refusal(R"({"mesh": {"file": "open.stl"}})"), key, "not closed: 3 boundary edges");
  std::vector<Tri> flipped = kCubeTriangles;
  std::swap(flipped[4][1], flipped[4][2]);
  std::swap(flipped[5][1], flipped[5][2]);
  write("flipped.obj", obj(kCubeVertices, flipped));
  expect_refusal(refusal(R"({"mesh": {"file": "flipped.obj"}})"), key, "not consistently oriented");
  // Two cubes in one file, the second crossing the first.
  std::vector<Vec3> v = kCubeVertices;
  std::vector<Tri> t = kCubeTriangles;
  for (const Vec3& x : kCubeVertices) v.push_back(x + Vec3{0.5, 0.25, 0.125});
  for (const Tri& f : kCubeTriangles) t.push_back({f[0] + 8, f[1] + 8, f[2] + 8});
  write("crossing.ply", ply(v, t));
  expect_refusal(refusal(R"({"mesh": {"file": "crossing.ply"}})"), key, "intersects itself");
  // A huge binary STL: refused from its header, with the cost it would have.
  write("huge.stl", binary_stl(kCubeVertices, kCubeTriangles, 50'000'000));
  expect_refusal(refusal(R"({"mesh": {"file": "huge.stl"}})"), key, "50000000 triangles, more than the 2000000 accepted");
  fs::create_directories(dir_ / "folder.stl");
  expect_refusal(refusal(R"({"mesh": {"file": "folder.stl"}})"), key, "is a folder");
}

TEST_F(MeshScene, BadInlineMeshesAreRefusedNamingTheKey) {
  const std::string cube_v = R"([[0,0,0],[1,0,0],[0,1,0],[1,1,0],[0,0,1],[1,0,1],[0,1,1],[1,1,1]])";
  expect_refusal(refusal(R"({"mesh": {"vertices": )" + cube_v +
                         R"(, "triangles": [[0,2,1],[1,2,3],[4,5,6],[5,7,6],[0,1,4],[1,5,4],[2,6,3],[3,6,7],[0,4,2],[2,4,6],[1,3,5],[3,7,9]]}})"),
                 "bodies[0].shape.mesh.triangles", "triangle 11 has vertex index 9 out of range");
  expect_refusal(refusal(R"({"mesh": {"vertices": [[0,0,0],[1,0,0],[0,1,0],[0,0,1e999]], "triangles": [[0,2,1]]}})"),
                 "bodies[0].shape.mesh.vertices[3][2]", "");
  expect_refusal(refusal(R"({"mesh": {"vertices": )" + cube_v + "}}"), "bodies[0].shape.mesh.triangles",
                 "required key is missing");
  expect_refusal(refusal(R"({"mesh": {"file": "a.stl", "vertices": [[0,0,0]]}})"), "bodies[0].shape.mesh",
                 "either file or vertices and triangles");
  // A flat closed mesh: no volume.
  expect_refusal(refusal(R"({"mesh": {"vertices": [[0,0,0],[1,0,0],[0,1,0],[0.3,0.3,0]],
                  "triangles": [[0,2,1],[0,1,3],[1,2,3],[2,0,3]]}})"),
                 "bodies[0].shape.mesh.triangles", "encloses no volume");
}

TEST_F(MeshScene, InvertedMeshesAndOddUnitsGetANotice) {
  std::vector<Tri> inverted = kCubeTriangles;
  for (Tri& f : inverted) std::swap(f[1], f[2]);
  write("inverted.stl", binary_stl(kCubeVertices, inverted));
  const SceneDescription d = load(R"({"mesh": {"file": "inverted.stl", "scale": 0.01}})");
  EXPECT_NEAR(shape_volume(d.bodies[0].shape), 1e-6, 1e-12);
  ASSERT_EQ(d.notices.size(), 1u);
  EXPECT_NE(d.notices[0].find("bodies[0].shape.mesh.file: mesh file \"inverted.stl\": the triangles run clockwise"),
            std::string::npos)
      << d.notices[0];
  write("cube.stl", binary_stl(kCubeVertices, kCubeTriangles));
  const SceneDescription tiny = load(R"({"mesh": {"file": "cube.stl", "scale": 1e-7}})");
  ASSERT_EQ(tiny.notices.size(), 1u);
  EXPECT_NE(tiny.notices[0].find("1e-07 m across: are its units right (bodies[0].shape.mesh.scale)?"), std::string::npos)
      << tiny.notices[0];
}

TEST_F(MeshScene, CompoundsPlaceTheirPartsAndRefuseMaterials) {
  write("cube.obj", obj(kCubeVertices, kCubeTriangles));
  const SceneDescription d = load(R"({"compound": [
      {"shape": {"box": [0.002, 0.001, 0.001]}, "position": [0, 0, 0]},
      {"shape": {"mesh": {"file": "cube.obj", "scale": 0.001}}, "position": [0.0015, 0, 0],
       "orientation": [0.7071067811865476, 0, 0, 0.7071067811865476]}]})");
  const Compound* c = std::get_if<Compound>(&d.bodies[0].shape);
  ASSERT_NE(c, nullptr);
  ASSERT_EQ(c->parts().size(), 2u);
  EXPECT_NEAR(shape_volume(*c), 3e-9, 1e-15);
  // The centre of mass (x = 0.5 mm) moved to the origin.
  EXPECT_NEAR(c->parts()[0].position.x, -0.0005, 1e-12);
  EXPECT_NEAR(c->parts()[1].position.x, 0.001, 1e-12);
  expect_refusal(refusal(R"({"compound": [{"shape": {"sphere": 0.001}, "material": "m"}]})"),
                 "bodies[0].shape.compound[0].material", "parts of different materials in one body are not supported");
  expect_refusal(refusal(R"({"compound": [{"shape": {"compound": [{"shape": {"sphere": 0.001}}]}}]})"),
                 "bodies[0].shape.compound[0].shape.compound", "cannot be a compound");
  expect_refusal(refusal(R"({"compound": []})"), "bodies[0].shape.compound", "non-empty array");
}

// odemag solve on a bad mesh: exit 2, one line naming the file and the key.
TEST_F(MeshScene, OdemagSolveExitsTwoWithOneLine) {
  std::vector<Tri> open = kCubeTriangles;
  open.pop_back();
  write("open.stl", binary_stl(kCubeVertices, open));
  const fs::path s = scene(R"({"mesh": {"file": "open.stl", "scale": 0.001}})");
  const test_support::ProgramRun r =
      test_support::run_program(test_support::shell_quote(ODEMAG_BINARY_DIR "/bin/odemag") + " solve " +
                                    test_support::shell_quote(s.string()),
                                dir_);
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(test_support::lines(r.err).size(), 1u) << r.err;
  EXPECT_NE(r.err.find("scene.json: bodies[0].shape.mesh.file: mesh file \"open.stl\": the mesh is not closed"),
            std::string::npos)
      << r.err;
}

}  // namespace
}  // namespace odemag
