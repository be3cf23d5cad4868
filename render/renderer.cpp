#include "render/renderer.h"

// OSMesa must come before gl.h so that it sees the GL types it needs.
#include <GL/osmesa.h>
#include <GL/gl.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iterator>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "render/font5x7.h"
#include "render/text.h"

namespace odemag {

// ---------------------------------------------------------------- primitives

RenderPrimitive RenderPrimitive::sphere(const Vec3& centre, double radius, const RenderColor& color) {
  RenderPrimitive p;
  p.kind = Kind::sphere;
  p.size = {radius, radius, radius};
  p.position = centre;
  p.color = color;
  return p;
}

RenderPrimitive RenderPrimitive::box(const Vec3& centre, const Vec3& edges, const Mat3& rotation,
                                     const RenderColor& color) {
  RenderPrimitive p;
  p.kind = Kind::box;
  p.size = edges;
  p.rotation = rotation;
  p.position = centre;
  p.color = color;
  return p;
}

RenderPrimitive RenderPrimitive::cylinder(const Vec3& centre, double radius, double length,
                                          const Mat3& rotation, const RenderColor& color) {
  RenderPrimitive p;
  p.kind = Kind::cylinder;
  p.size = {radius, radius, length};
  p.rotation = rotation;
  p.position = centre;
  p.color = color;
  return p;
}

RenderPrimitive RenderPrimitive::of_surface(const Vec3& centre, std::shared_ptr<const RenderSurface> surface,
                                            const Mat3& rotation, const RenderColor& color) {
  RenderPrimitive p;
  p.kind = Kind::surface;
  p.size = {1.0, 1.0, 1.0};
  p.surface = std::move(surface);
  p.rotation = rotation;
  p.position = centre;
  p.color = color;
  return p;
}

namespace {

// ---------------------------------------------------------------- matrices

// 4x4 matrices are stored column-major, as OpenGL takes them.
using Mat4 = std::array<double, 16>;

Mat4 identity4() {
  Mat4 m{};
  m[0] = m[5] = m[10] = m[15] = 1.0;
  return m;
}

Mat4 perspective(double fovy_degrees, double aspect, double near_plane, double far_plane) {
  const double f = 1.0 / std::tan(0.5 * fovy_degrees * std::numbers::pi / 180.0);
  Mat4 m{};
  m[0] = f / aspect;
  m[5] = f;
  m[10] = (far_plane + near_plane) / (near_plane - far_plane);
  m[11] = -1.0;
  m[14] = 2.0 * far_plane * near_plane / (near_plane - far_plane);
  return m;
}

struct CameraFrame {
  Vec3 eye, forward, right, up;  // orthonormal; right = forward x up
};

CameraFrame camera_frame(const RenderCamera& cam) {
  CameraFrame c;
  c.eye = cam.position;
  c.forward = normalized(cam.target - cam.position);
  if (squared_norm(c.forward) == 0.0 || !is_finite(c.forward)) c.forward = {0.0, 1.0, 0.0};
  Vec3 up = normalized(cam.up);
  if (squared_norm(up) == 0.0 || !is_finite(up)) up = {0.0, 0.0, 1.0};
  // An up vector (nearly) parallel to the view direction: pick another.
  if (norm(cross(c.forward, up)) < 1e-6) {
    up = std::fabs(c.forward.z) < 0.9 ? Vec3{0.0, 0.0, 1.0} : Vec3{0.0, 1.0, 0.0};
  }
  c.right = normalized(cross(c.forward, up));
  c.up = cross(c.right, c.forward);
  return c;
}

Mat4 look_at(const CameraFrame& c) {
  Mat4 m = identity4();
  const Vec3 rows[3] = {c.right, c.up, -c.forward};
  for (int i = 0; i < 3; ++i) {
    m[0 * 4 + i] = rows[i].x;
    m[1 * 4 + i] = rows[i].y;
    m[2 * 4 + i] = rows[i].z;
    m[3 * 4 + i] = -dot(rows[i], c.eye);
  }
  return m;
}

// Translation times rotation (body -> world), no scale.
Mat4 rigid_transform(const Mat3& r, const Vec3& t) {
  Mat4 m = identity4();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m[j * 4 + i] = r.m[i][j];
  m[12] = t.x;
  m[13] = t.y;
  m[14] = t.z;
  return m;
}

double determinant(const Mat3& r) {
  return r.m[0][0] * (r.m[1][1] * r.m[2][2] - r.m[1][2] * r.m[2][1]) -
         r.m[0][1] * (r.m[1][0] * r.m[2][2] - r.m[1][2] * r.m[2][0]) +
         r.m[0][2] * (r.m[1][0] * r.m[2][1] - r.m[1][1] * r.m[2][0]);
}

// Projection along the (towards-the-light) direction l onto the plane z = h.
Mat4 planar_shadow(const Vec3& l, double h) {
  Mat4 m = identity4();
  const double ax = l.x / l.z, ay = l.y / l.z;
  m[8] = -ax;
  m[9] = -ay;
  m[10] = 0.0;
  m[12] = ax * h;
  m[13] = ay * h;
  m[14] = h;
  return m;
}

// ---------------------------------------------------------------- meshes

// Unit shapes: sphere of radius 1, cylinder of radius 1 along z from -0.5 to
// 0.5, cube of edge 1; all centred on the origin, triangles counter-clockwise
// seen from outside.
struct Mesh {
  std::vector<GLfloat> positions;  // xyz
  std::vector<GLfloat> normals;    // xyz
  std::vector<GLuint> indices;     // triangles

  GLuint add_vertex(double px, double py, double pz, double nx, double ny, double nz) {
    const auto index = static_cast<GLuint>(positions.size() / 3);
    positions.insert(positions.end(), {static_cast<GLfloat>(px), static_cast<GLfloat>(py),
                                       static_cast<GLfloat>(pz)});
    normals.insert(normals.end(), {static_cast<GLfloat>(nx), static_cast<GLfloat>(ny),
                                   static_cast<GLfloat>(nz)});
    return index;
  }
  void add_triangle(GLuint a, GLuint b, GLuint c) { indices.insert(indices.end(), {a, b, c}); }
};

Mesh make_sphere(int slices, int stacks) {
  Mesh mesh;
  const double pi = std::numbers::pi;
  for (int i = 0; i <= stacks; ++i) {
    const double theta = pi * i / stacks;
    for (int j = 0; j <= slices; ++j) {
      const double phi = 2.0 * pi * j / slices;
      const double x = std::sin(theta) * std::cos(phi), y = std::sin(theta) * std::sin(phi),
                   z = std::cos(theta);
      mesh.add_vertex(x, y, z, x, y, z);
    }
  }
  const auto row = static_cast<GLuint>(slices + 1);
  for (int i = 0; i < stacks; ++i) {
    for (int j = 0; j < slices; ++j) {
      const GLuint a = static_cast<GLuint>(i) * row + static_cast<GLuint>(j), b = a + row;
      if (i != 0) mesh.add_triangle(a, b, a + 1);
      if (i != stacks - 1) mesh.add_triangle(a + 1, b, b + 1);
    }
  }
  return mesh;
}

Mesh make_cylinder(int segments) {
  Mesh mesh;
  const double pi = std::numbers::pi;
  for (int j = 0; j <= segments; ++j) {  // side: smooth normals
    const double phi = 2.0 * pi * j / segments, c = std::cos(phi), s = std::sin(phi);
    mesh.add_vertex(c, s, -0.5, c, s, 0.0);
    mesh.add_vertex(c, s, 0.5, c, s, 0.0);
  }
  for (int j = 0; j < segments; ++j) {
    const auto a = static_cast<GLuint>(2 * j);
    mesh.add_triangle(a, a + 2, a + 1);
    mesh.add_triangle(a + 1, a + 2, a + 3);
  }
  for (int cap = 0; cap < 2; ++cap) {  // flat caps
    const double z = cap == 0 ? 0.5 : -0.5, nz = cap == 0 ? 1.0 : -1.0;
    const GLuint centre = mesh.add_vertex(0.0, 0.0, z, 0.0, 0.0, nz);
    for (int j = 0; j <= segments; ++j) {
      const double phi = 2.0 * pi * j / segments;
      mesh.add_vertex(std::cos(phi), std::sin(phi), z, 0.0, 0.0, nz);
    }
    for (int j = 0; j < segments; ++j) {
      const GLuint a = centre + 1 + static_cast<GLuint>(j);
      if (cap == 0)
        mesh.add_triangle(centre, a, a + 1);
      else
        mesh.add_triangle(centre, a + 1, a);
    }
  }
  return mesh;
}

Mesh make_cube() {
  Mesh mesh;
  // Outward normal n and tangents u, v with u x v = n.
  const Vec3 faces[6][3] = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}},  {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}},
                            {{0, 1, 0}, {0, 0, 1}, {1, 0, 0}},  {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},
                            {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}},  {{0, 0, -1}, {0, 1, 0}, {1, 0, 0}}};
  for (const auto& f : faces) {
    const Vec3 n = f[0], u = f[1], v = f[2];
    GLuint first = 0;
    const double corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    for (int k = 0; k < 4; ++k) {
      const Vec3 p = 0.5 * n + (0.5 * corners[k][0]) * u + (0.5 * corners[k][1]) * v;
      const GLuint index = mesh.add_vertex(p.x, p.y, p.z, n.x, n.y, n.z);
      if (k == 0) first = index;
    }
    mesh.add_triangle(first, first + 1, first + 2);
    mesh.add_triangle(first, first + 2, first + 3);
  }
  return mesh;
}

// Compiles the mesh into a display list (Mesa keeps it as a vertex buffer),
// so it is not re-submitted from client memory at every draw.
GLuint compile_mesh(const Mesh& mesh) {
  const GLuint list = glGenLists(1);
  if (list == 0) throw std::runtime_error("OffscreenRenderer: glGenLists failed");
  glEnableClientState(GL_VERTEX_ARRAY);
  glEnableClientState(GL_NORMAL_ARRAY);
  glVertexPointer(3, GL_FLOAT, 0, mesh.positions.data());
  glNormalPointer(GL_FLOAT, 0, mesh.normals.data());
  glNewList(list, GL_COMPILE);
  glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(mesh.indices.size()), GL_UNSIGNED_INT,
                 mesh.indices.data());
  glEndList();
  glDisableClientState(GL_NORMAL_ARRAY);
  glDisableClientState(GL_VERTEX_ARRAY);
  return list;
}

// Radius of a sphere around the centre that contains the primitive.
double bounding_radius(const RenderPrimitive& p) {
  const Vec3 s{std::fabs(p.size.x), std::fabs(p.size.y), std::fabs(p.size.z)};
  switch (p.kind) {
    case RenderPrimitive::Kind::sphere: return std::max({s.x, s.y, s.z});
    case RenderPrimitive::Kind::box: return 0.5 * norm(s);
    case RenderPrimitive::Kind::cylinder: return std::hypot(std::max(s.x, s.y), 0.5 * s.z);
    case RenderPrimitive::Kind::surface: return p.surface ? p.surface->radius : 0.0;
  }
  return norm(s);
}

// The view transform with what level-of-detail choices need.
struct ViewInfo {
  Mat4 matrix;
  Vec3 eye;
  double near_plane = 1e-3;
  double pixel_scale = 1.0;  // pixels per unit of (size / distance)

  // Approximate on-screen radius in pixels of the primitive's bounding sphere.
  double pixel_radius(const RenderPrimitive& p) const {
    const double r = bounding_radius(p);
    return r * pixel_scale / std::max(norm(p.position - eye) - r, near_plane);
  }
};

void set_color(const RenderColor& c, float alpha = 1.0f) { glColor4f(c[0], c[1], c[2], alpha); }

bool translucent(const RenderPrimitive& p) { return p.opacity < 1.0f; }

std::uint8_t to_byte(float v) {
  return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
}

}  // namespace

// ---------------------------------------------------------------- renderer

struct OffscreenRenderer::Impl {
  int width = 0, height = 0, supersample = 1;
  int render_width = 0, render_height = 0;
  OSMesaContext context = nullptr;
  std::vector<std::uint8_t> framebuffer;  // RGBA8 at render size, bottom row first
  // Display lists of the unit shapes, each at three levels of detail
  // (finest first); the cube needs only one.
  std::array<GLuint, 3> sphere_lists{}, cylinder_lists{};
  GLuint cube_list = 0;
  std::unique_ptr<TextFont> font;  // captions and legend

  ~Impl() {
    if (context != nullptr) OSMesaDestroyContext(context);  // frees its display lists
  }

  void compile_meshes() {
    const int segments[3] = {48, 24, 12};
    for (std::size_t i = 0; i < 3; ++i) {
      sphere_lists[i] = compile_mesh(make_sphere(segments[i], segments[i] / 2));
      cylinder_lists[i] = compile_mesh(make_cylinder(segments[i]));
    }
    cube_list = compile_mesh(make_cube());
  }

  void make_current() {
    if (!OSMesaMakeCurrent(context, framebuffer.data(), GL_UNSIGNED_BYTE, render_width, render_height))
      throw std::runtime_error("OffscreenRenderer: OSMesaMakeCurrent failed");
  }

  // The display list for a primitive whose bounding sphere spans about
  // pixel_radius pixels of the supersampled frame.
  GLuint list_for(RenderPrimitive::Kind kind, double pixel_radius) const {
    const std::size_t level = pixel_radius > 48.0 ? 0 : (pixel_radius > 14.0 ? 1 : 2);
    switch (kind) {
      case RenderPrimitive::Kind::sphere: return sphere_lists[level];
      case RenderPrimitive::Kind::box: return cube_list;
      case RenderPrimitive::Kind::cylinder: return cylinder_lists[level];
      case RenderPrimitive::Kind::surface: return 0;
    }
    return cube_list;
  }

  // The primitive's triangles: its display list, or its surface from client
  // memory.
  void draw_shape(const RenderPrimitive& p, double pixel_radius) const {
    if (p.kind != RenderPrimitive::Kind::surface) {
      glCallList(list_for(p.kind, pixel_radius));
      return;
    }
    if (!p.surface || p.surface->positions.empty()) return;
    glEnableClientState(GL_VERTEX_ARRAY);
    glEnableClientState(GL_NORMAL_ARRAY);
    glVertexPointer(3, GL_FLOAT, 0, p.surface->positions.data());
    glNormalPointer(GL_FLOAT, 0, p.surface->normals.data());
    glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(p.surface->positions.size() / 3));
    glDisableClientState(GL_NORMAL_ARRAY);
  }

  void draw_ground(const RenderFrame& scene);
  void draw_shadows(const RenderFrame& scene, const ViewInfo& view, const Vec3& light);
  void draw_primitive(const RenderPrimitive& p, const ViewInfo& view, float alpha = 1.0f);
  void draw_translucent(const RenderFrame& scene, const ViewInfo& view);
  void draw_lines(const RenderFrame& scene);
  void downsample(std::vector<std::uint8_t>& rgb) const;
  void shade_band(const RenderFrame& scene, std::vector<std::uint8_t>& rgb, int y0, int y1) const;
  void draw_caption(const RenderFrame& scene, std::vector<std::uint8_t>& rgb) const;
  void draw_legend(const RenderFrame& scene, std::vector<std::uint8_t>& rgb) const;
};

OffscreenRenderer::OffscreenRenderer(int width, int height, int supersample)
    : impl_(std::make_unique<Impl>()) {
  if (width <= 0 || height <= 0 || supersample < 1 || supersample > 8)
    throw std::invalid_argument("OffscreenRenderer: bad size " + std::to_string(width) + "x" +
                                std::to_string(height) + " or supersample " +
                                std::to_string(supersample));
  Impl& m = *impl_;
  m.width = width;
  m.height = height;
  m.supersample = supersample;
  m.render_width = width * supersample;
  m.render_height = height * supersample;
  if (m.render_width > 16384 || m.render_height > 16384)
    throw std::invalid_argument("OffscreenRenderer: " + std::to_string(m.render_width) + "x" +
                                std::to_string(m.render_height) +
                                " supersampled frame exceeds 16384 pixels per side");
  m.framebuffer.assign(static_cast<std::size_t>(m.render_width) * static_cast<std::size_t>(m.render_height) * 4, 0);

  // Legacy (compatibility profile) context with a 24-bit depth buffer and a
  // stencil buffer for the ground shadows.
  const int attribs[] = {OSMESA_FORMAT,       OSMESA_RGBA,
                         OSMESA_DEPTH_BITS,   24,
                         OSMESA_STENCIL_BITS, 8,
                         OSMESA_ACCUM_BITS,   0,
                         OSMESA_PROFILE,      OSMESA_COMPAT_PROFILE,
                         0};
  m.context = OSMesaCreateContextAttribs(attribs, nullptr);
  if (m.context == nullptr) m.context = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, nullptr);
  if (m.context == nullptr) throw std::runtime_error("OffscreenRenderer: cannot create an OSMesa context");
  m.make_current();
  GLint depth_bits = 0;
  glGetIntegerv(GL_DEPTH_BITS, &depth_bits);
  if (depth_bits < 16)
    throw std::runtime_error("OffscreenRenderer: OSMesa context has " + std::to_string(depth_bits) +
                             " depth bits (need at least 16)");
  m.compile_meshes();
  m.font = std::make_unique<TextFont>(caption_pixel_size(height));
}

OffscreenRenderer::~OffscreenRenderer() = default;
OffscreenRenderer::OffscreenRenderer(OffscreenRenderer&&) noexcept = default;
OffscreenRenderer& OffscreenRenderer::operator=(OffscreenRenderer&&) noexcept = default;

int OffscreenRenderer::width() const { return impl_->width; }
int OffscreenRenderer::height() const { return impl_->height; }
int OffscreenRenderer::supersample() const { return impl_->supersample; }

namespace {

// Ground tile colours: light greys a little darker than the default background.
constexpr RenderColor kTileLight{0.86f, 0.865f, 0.875f};
constexpr RenderColor kTileDark{0.76f, 0.765f, 0.78f};
constexpr float kShadowAlpha = 0.30f;

}  // namespace

void OffscreenRenderer::Impl::draw_ground(const RenderFrame& scene) {
  const double extent = std::fabs(scene.ground_extent);
  double tile = scene.ground_tile > 0.0 ? scene.ground_tile : extent / 8.0;
  const int max_tiles = 400;  // per side
  if (2.0 * extent / tile > max_tiles) tile = 2.0 * extent / max_tiles;
  const int n = std::max(1, static_cast<int>(std::ceil(2.0 * extent / tile - 1e-9)));
  const double z = scene.ground_height;
  glBegin(GL_QUADS);
  glNormal3d(0.0, 0.0, 1.0);
  for (int i = 0; i < n; ++i) {
    const double x0 = -extent + i * tile, x1 = std::min(extent, x0 + tile);
    for (int j = 0; j < n; ++j) {
      const double y0 = -extent + j * tile, y1 = std::min(extent, y0 + tile);
      set_color(((i + j) & 1) == 0 ? kTileLight : kTileDark);
      glVertex3d(x0, y0, z);
      glVertex3d(x1, y0, z);
      glVertex3d(x1, y1, z);
      glVertex3d(x0, y1, z);
    }
  }
  glEnd();
}

void OffscreenRenderer::Impl::draw_shadows(const RenderFrame& scene, const ViewInfo& view, const Vec3& light) {
  // Darken ground pixels (stencil 1) once each, wherever a primitive's
  // projection along the light onto the ground plane lands.
  glEnable(GL_STENCIL_TEST);
  glStencilFunc(GL_EQUAL, 1, 0xff);
  glStencilOp(GL_KEEP, GL_KEEP, GL_ZERO);
  glDisable(GL_DEPTH_TEST);
  glDepthMask(GL_FALSE);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glColor4f(0.0f, 0.0f, 0.05f, kShadowAlpha);
  glMatrixMode(GL_MODELVIEW);
  const Mat4 shadow = planar_shadow(light, scene.ground_height);
  for (const RenderPrimitive& p : scene.primitives) {
    if (!p.cast_shadow || translucent(p) || !is_finite(p.position) || !is_finite(p.size)) continue;
    // Bodies wholly below the ground cast nothing. (GL clip planes act after
    // the projection, where every vertex lies in the ground plane, so parts
    // of a body sunk into the ground are not cut off; they are rare.)
    if (p.position.z + bounding_radius(p) <= scene.ground_height) continue;
    glLoadMatrixd(view.matrix.data());
    glMultMatrixd(shadow.data());
    glMultMatrixd(rigid_transform(p.rotation, p.position).data());
    glScaled(p.size.x, p.size.y, p.size.z);
    draw_shape(p, 0.5 * view.pixel_radius(p));  // shadows can be coarser
  }
  glDisable(GL_BLEND);
  glDepthMask(GL_TRUE);
  glEnable(GL_DEPTH_TEST);
  glDisable(GL_STENCIL_TEST);
}

void OffscreenRenderer::Impl::draw_primitive(const RenderPrimitive& p, const ViewInfo& view, float alpha) {
  if (!is_finite(p.position) || !is_finite(p.size)) return;
  const double sx = p.size.x, sy = p.size.y, sz = p.size.z;
  glMatrixMode(GL_MODELVIEW);
  glLoadMatrixd(view.matrix.data());
  glMultMatrixd(rigid_transform(p.rotation, p.position).data());
  const double handedness = determinant(p.rotation) * sx * sy * sz;
  glFrontFace(handedness < 0.0 ? GL_CW : GL_CCW);
  const double pixels = view.pixel_radius(p);
  const Vec3 axis = normalized(p.pole_axis);
  if (squared_norm(axis) == 0.0 || !is_finite(axis)) {
    glScaled(sx, sy, sz);
    set_color(p.color, alpha);
    draw_shape(p, pixels);
    return;
  }
  // A magnet: two halves cut by the body plane through the centre normal to
  // the pole axis. The clip plane is given in body coordinates (before the
  // scale), where GL transforms it by the current modelview.
  const GLdouble north[4] = {axis.x, axis.y, axis.z, 0.0};
  const GLdouble south[4] = {-axis.x, -axis.y, -axis.z, 0.0};
  glEnable(GL_CLIP_PLANE0);
  glClipPlane(GL_CLIP_PLANE0, north);
  glPushMatrix();
  glScaled(sx, sy, sz);
  set_color(p.north_color, alpha);
  draw_shape(p, pixels);
  glPopMatrix();
  glClipPlane(GL_CLIP_PLANE0, south);
  glScaled(sx, sy, sz);
  set_color(p.south_color, alpha);
  draw_shape(p, pixels);
  glDisable(GL_CLIP_PLANE0);
}

void OffscreenRenderer::Impl::draw_translucent(const RenderFrame& scene, const ViewInfo& view) {
  std::vector<std::pair<double, const RenderPrimitive*>> order;
  for (const RenderPrimitive& p : scene.primitives)
    if (translucent(p) && p.opacity > 0.0f && is_finite(p.position))
      order.emplace_back(norm(p.position - view.eye), &p);
  if (order.empty()) return;
  // Farthest first; each body's far side, then its near side. Depth is tested
  // (opaque solids and lines hide them) but not written.
  std::stable_sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glDepthMask(GL_FALSE);
  glEnable(GL_CULL_FACE);
  for (const auto& entry : order) {
    const RenderPrimitive* p = entry.second;
    // Two surfaces per body: each gets alpha a with (1 - a)^2 = 1 - opacity,
    // so that looking through the body dims what is behind by its opacity.
    const float alpha = 1.0f - std::sqrt(1.0f - std::clamp(p->opacity, 0.0f, 1.0f));
    glCullFace(GL_FRONT);
    draw_primitive(*p, view, alpha);
    glCullFace(GL_BACK);
    draw_primitive(*p, view, alpha);
  }
  glFrontFace(GL_CCW);
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);
}

void OffscreenRenderer::Impl::draw_lines(const RenderFrame& scene) {
  glDisable(GL_LIGHTING);
  glDisable(GL_CULL_FACE);
  glDisableClientState(GL_NORMAL_ARRAY);
  std::vector<GLdouble> xyz;
  for (const RenderLine& line : scene.lines) {
    if (line.points.size() < 2) continue;
    xyz.clear();
    for (const Vec3& p : line.points) xyz.insert(xyz.end(), {p.x, p.y, p.z});
    glLineWidth(std::clamp(line.width * static_cast<float>(supersample), 1.0f, 255.0f));
    set_color(line.color);
    glVertexPointer(3, GL_DOUBLE, 0, xyz.data());
    glDrawArrays(GL_LINE_STRIP, 0, static_cast<GLsizei>(line.points.size()));
  }
}

void OffscreenRenderer::Impl::downsample(std::vector<std::uint8_t>& rgb) const {
  const int s = supersample;
  const unsigned divisor = static_cast<unsigned>(s * s), half = divisor / 2;
  rgb.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3);
  const std::size_t src_stride = static_cast<std::size_t>(render_width) * 4;
  std::vector<unsigned> sums(static_cast<std::size_t>(width) * 3);
  for (int y = 0; y < height; ++y) {
    std::fill(sums.begin(), sums.end(), 0u);
    // Output row y (top first) covers GL rows (height - 1 - y) * s ... + s - 1.
    const int gl_row0 = (height - 1 - y) * s;
    for (int dy = 0; dy < s; ++dy) {
      const std::uint8_t* src = framebuffer.data() + static_cast<std::size_t>(gl_row0 + dy) * src_stride;
      unsigned* sum = sums.data();
      for (int x = 0; x < width; ++x, sum += 3) {
        for (int dx = 0; dx < s; ++dx, src += 4) {
          sum[0] += src[0];
          sum[1] += src[1];
          sum[2] += src[2];
        }
      }
    }
    std::uint8_t* dst = rgb.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(width) * 3;
    for (std::size_t i = 0; i < sums.size(); ++i)
      dst[i] = static_cast<std::uint8_t>((sums[i] + half) / divisor);
  }
}

void OffscreenRenderer::Impl::shade_band(const RenderFrame& scene, std::vector<std::uint8_t>& rgb, int y0,
                                         int y1) const {
  // A translucent panel in the background colour keeps text readable over
  // the scene.
  for (int y = std::max(0, y0); y < std::min(height, y1); ++y) {
    std::uint8_t* px = rgb.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(width) * 3;
    for (int x = 0; x < width; ++x, px += 3)
      for (int c = 0; c < 3; ++c)
        px[c] = to_byte(0.25f * static_cast<float>(px[c]) / 255.0f + 0.75f * scene.background[static_cast<std::size_t>(c)]);
  }
}

namespace {

// Margins of the caption and legend bands for a font.
int band_margin(const TextFont& f) { return std::max(3, f.pixel_size() / 2); }
int band_pad(const TextFont& f) { return std::max(2, f.pixel_size() / 4); }

void fill_rect(std::vector<std::uint8_t>& rgb, int width, int height, int x0, int y0, int x1, int y1,
               const RenderColor& color) {
  const std::uint8_t c[3] = {to_byte(color[0]), to_byte(color[1]), to_byte(color[2])};
  for (int y = std::max(0, y0); y < std::min(height, y1); ++y)
    for (int x = std::max(0, x0); x < std::min(width, x1); ++x) {
      std::uint8_t* px = rgb.data() + (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) * 3;
      px[0] = c[0], px[1] = c[1], px[2] = c[2];
    }
}

// A value with an SI prefix and the unit, three significant digits: "12.5 mN".
std::string si_value(double v, const std::string& unit, bool micro_sign) {
  if (v == 0.0 || !std::isfinite(v)) return (std::isfinite(v) ? "0 " : "? ") + unit;
  struct Prefix {
    double factor;
    const char* name;
  };
  const Prefix prefixes[] = {{1e9, "G"}, {1e6, "M"}, {1e3, "k"}, {1.0, ""}, {1e-3, "m"},
                             {1e-6, micro_sign ? "\xc2\xb5" : "u"}, {1e-9, "n"}, {1e-12, "p"}};
  const double a = std::fabs(v);
  const Prefix* chosen = &prefixes[std::size(prefixes) - 1];
  for (const Prefix& p : prefixes)
    if (a >= p.factor * 0.9995) {
      chosen = &p;
      break;
    }
  char text[64];
  std::snprintf(text, sizeof text, "%.3g %s", v / chosen->factor, chosen->name);
  return text + unit;
}

}  // namespace

void OffscreenRenderer::Impl::draw_caption(const RenderFrame& scene, std::vector<std::uint8_t>& rgb) const {
  if (scene.text.empty()) return;
  const TextFont& f = *font;
  const int margin = band_margin(f), pad = band_pad(f);
  std::vector<std::string> lines;
  for (const std::string& paragraph : scene.text)
    for (std::string& line : f.wrap(paragraph, width - 2 * margin)) lines.push_back(std::move(line));
  if (lines.empty()) return;
  const int band = 2 * pad + static_cast<int>(lines.size()) * f.line_height();
  shade_band(scene, rgb, 0, band);
  int baseline = pad + f.ascent();
  for (const std::string& line : lines) {
    f.draw(rgb, width, height, margin, baseline, line, scene.text_color);
    baseline += f.line_height();
  }
}

void OffscreenRenderer::Impl::draw_legend(const RenderFrame& scene, std::vector<std::uint8_t>& rgb) const {
  const RenderLegend& legend = scene.legend;
  if (!legend.any()) return;
  const TextFont& f = *font;
  const int margin = band_margin(f), pad = band_pad(f), em = f.pixel_size();
  const int swatch = std::max(4, f.ascent() * 3 / 4);
  const int line = std::max(1, em / 9);  // stroke of the scale bar
  const RenderColor ink = scene.text_color;

  // The items, each a width and a painter taking (x, baseline).
  struct Item {
    int width;
    std::function<void(int, int)> paint;
  };
  std::vector<Item> items;
  auto swatch_item = [&](const std::string& name, const RenderColor& color) {
    const int text_x = swatch + em / 3;
    return Item{text_x + f.width_of(name), [&, name, color, text_x](int x, int baseline) {
                  fill_rect(rgb, width, height, x, baseline - swatch, x + swatch, baseline, color);
                  f.draw(rgb, width, height, x + text_x, baseline, name, ink);
                }};
  };
  if (legend.poles) {
    items.push_back(swatch_item("north", legend.north));
    items.push_back(swatch_item("south", legend.south));
  }
  if (!legend.colorbar.empty()) {
    const bool micro = f.freetype();
    const std::string low = si_value(legend.colorbar_low, legend.colorbar_unit, micro);
    const std::string high = si_value(legend.colorbar_high, legend.colorbar_unit, micro);
    const std::string head = legend.colorbar_label + " " + (legend.colorbar_low == 0.0 ? "0" : low);
    const int bar = 5 * em, gap = em / 3;
    const int w_head = f.width_of(head), w_high = f.width_of(high);
    items.push_back(Item{w_head + gap + bar + gap + w_high, [&, head, high, bar, gap, w_head](int x, int baseline) {
                           f.draw(rgb, width, height, x, baseline, head, ink);
                           const int x0 = x + w_head + gap;
                           const std::size_t n = legend.colorbar.size();
                           for (int i = 0; i < bar; ++i) {
                             // Sample i of the bar, linear between the given colours.
                             const double u = n == 1 ? 0.0 : (i + 0.5) / bar * static_cast<double>(n - 1);
                             const std::size_t k = std::min(n - 1, static_cast<std::size_t>(u));
                             const std::size_t k1 = std::min(n - 1, k + 1);
                             const auto t = static_cast<float>(u - static_cast<double>(k));
                             RenderColor c{};
                             for (std::size_t j = 0; j < 3; ++j)
                               c[j] = legend.colorbar[k][j] + t * (legend.colorbar[k1][j] - legend.colorbar[k][j]);
                             fill_rect(rgb, width, height, x0 + i, baseline - swatch, x0 + i + 1, baseline, c);
                           }
                           f.draw(rgb, width, height, x0 + bar + gap, baseline, high, ink);
                         }});
  }
  if (legend.scale_bar) {
    const ScaleBar sb = scale_bar_for(scene.camera, height, std::max(0.2 * width, 3.0 * em));
    const int n = static_cast<int>(std::lround(sb.pixels));
    if (n >= 2) {
      const int gap = em / 3;
      items.push_back(Item{n + gap + f.width_of(sb.label), [&, sb, n, gap](int x, int baseline) {
                             // A bar of n pixels with end ticks, centred on the x-height.
                             const int mid = baseline - f.ascent() / 3;
                             const int tick = std::max(2, f.ascent() / 3);
                             fill_rect(rgb, width, height, x, mid - line / 2, x + n, mid - line / 2 + line, ink);
                             fill_rect(rgb, width, height, x, mid - tick, x + line, mid + tick, ink);
                             fill_rect(rgb, width, height, x + n - line, mid - tick, x + n, mid + tick, ink);
                             f.draw(rgb, width, height, x + n + gap, baseline, sb.label, ink);
                           }});
    }
  }
  if (items.empty()) return;
  // Rows, filled left to right.
  const int spacing = em, room = width - 2 * margin;
  std::vector<std::vector<std::size_t>> rows(1);
  int used = 0;
  for (std::size_t i = 0; i < items.size(); ++i) {
    const int need = (rows.back().empty() ? 0 : spacing) + items[i].width;
    if (!rows.back().empty() && used + need > room) {
      rows.emplace_back();
      used = 0;
    }
    used += rows.back().empty() ? items[i].width : spacing + items[i].width;
    rows.back().push_back(i);
  }
  const int band = 2 * pad + static_cast<int>(rows.size()) * f.line_height();
  shade_band(scene, rgb, height - band, height);
  int baseline = height - band + pad + f.ascent();
  for (const auto& row : rows) {
    int x = margin;
    for (std::size_t i : row) {
      items[i].paint(x, baseline);
      x += items[i].width + spacing;
    }
    baseline += f.line_height();
  }
}

std::vector<std::uint8_t> OffscreenRenderer::render(const RenderFrame& scene) {
  Impl& m = *impl_;
  m.make_current();

  const CameraFrame cam = camera_frame(scene.camera);
  const Mat4 view = look_at(cam);
  const bool ground = scene.ground && cam.eye.z > scene.ground_height && std::isfinite(scene.ground_height) &&
                      std::isfinite(scene.ground_extent) && scene.ground_extent != 0.0;

  // Near and far planes from the nearest and farthest scene content.
  double nearest = std::numeric_limits<double>::infinity(), farthest = 0.0;
  auto include = [&](const Vec3& centre, double radius) {
    if (!is_finite(centre) || !std::isfinite(radius)) return;
    const double d = norm(centre - cam.eye);
    nearest = std::min(nearest, d - radius);
    farthest = std::max(farthest, d + radius);
  };
  include(scene.camera.target, 0.0);
  for (const RenderPrimitive& p : scene.primitives) include(p.position, bounding_radius(p));
  for (const RenderLine& line : scene.lines) {
    for (std::size_t i = 0; i < line.points.size(); ++i) {
      include(line.points[i], 0.0);
      if (i == 0) continue;
      // The point of the segment nearest to the eye.
      const Vec3 a = line.points[i - 1], ab = line.points[i] - a;
      const double len2 = squared_norm(ab);
      if (len2 > 0.0) include(a + std::clamp(dot(cam.eye - a, ab) / len2, 0.0, 1.0) * ab, 0.0);
    }
  }
  if (ground) {
    const double e = std::fabs(scene.ground_extent);
    for (double sx : {-e, e})
      for (double sy : {-e, e}) include({sx, sy, scene.ground_height}, 0.0);
    // The point of the ground square nearest to the eye.
    include({std::clamp(cam.eye.x, -e, e), std::clamp(cam.eye.y, -e, e), scene.ground_height}, 0.0);
  }
  const double far_plane = std::max(farthest * 1.05, 1e-6);
  const double near_plane = std::clamp(0.9 * nearest, far_plane * 1e-4, far_plane * 0.5);
  const double fov = std::clamp(scene.camera.fov_degrees, 1.0, 170.0);
  ViewInfo view_info;
  view_info.matrix = view;
  view_info.eye = cam.eye;
  view_info.near_plane = near_plane;
  view_info.pixel_scale = 0.5 * m.render_height / std::tan(0.5 * fov * std::numbers::pi / 180.0);

  // Lights, as directions towards the light in world coordinates: a key light
  // from above, over the viewer's left shoulder (it also casts the ground
  // shadows), and a weak fill from the viewer's right.
  const Vec3 world_up{0.0, 0.0, 1.0};
  Vec3 back = -(cam.forward - dot(cam.forward, world_up) * world_up);
  back = squared_norm(back) > 1e-12 ? normalized(back) : -cam.up;
  const Vec3 right_h = normalized(cross(-back, world_up));
  const Vec3 key = normalized(1.0 * world_up + 0.35 * back - 0.6 * right_h);
  const Vec3 fill = normalized(-cam.forward + 0.9 * cam.right - 0.2 * cam.up);

  glViewport(0, 0, m.render_width, m.render_height);
  glClearColor(scene.background[0], scene.background[1], scene.background[2], 1.0f);
  glClearDepth(1.0);
  glClearStencil(0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);

  glMatrixMode(GL_PROJECTION);
  glLoadMatrixd(perspective(fov,
                            static_cast<double>(m.width) / m.height, near_plane, far_plane)
                    .data());
  glMatrixMode(GL_MODELVIEW);
  glLoadMatrixd(view.data());

  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);
  glDisable(GL_LIGHTING);
  glDisable(GL_CULL_FACE);
  glDisable(GL_DITHER);
  glShadeModel(GL_SMOOTH);
  glEnableClientState(GL_VERTEX_ARRAY);

  if (ground) {
    glEnable(GL_STENCIL_TEST);
    glStencilFunc(GL_ALWAYS, 1, 0xff);
    glStencilOp(GL_KEEP, GL_KEEP, GL_REPLACE);
    m.draw_ground(scene);
    glDisable(GL_STENCIL_TEST);
    if (scene.shadows && key.z > 0.05) m.draw_shadows(scene, view_info, key);
  }

  // Solids, lit.
  glMatrixMode(GL_MODELVIEW);
  glLoadMatrixd(view.data());  // lights are given in world coordinates
  glEnable(GL_LIGHTING);
  glEnable(GL_NORMALIZE);
  glEnable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  const GLfloat zero[4] = {0, 0, 0, 1};
  glLightModelfv(GL_LIGHT_MODEL_AMBIENT, zero);
  glLightModeli(GL_LIGHT_MODEL_TWO_SIDE, GL_FALSE);
  glLightModeli(GL_LIGHT_MODEL_LOCAL_VIEWER, GL_FALSE);
  glLightModeli(GL_LIGHT_MODEL_COLOR_CONTROL, GL_SEPARATE_SPECULAR_COLOR);
  const GLfloat key_pos[4] = {static_cast<GLfloat>(key.x), static_cast<GLfloat>(key.y),
                              static_cast<GLfloat>(key.z), 0.0f};
  const GLfloat key_ambient[4] = {0.24f, 0.24f, 0.25f, 1.0f};
  const GLfloat key_diffuse[4] = {0.78f, 0.78f, 0.76f, 1.0f};
  const GLfloat key_specular[4] = {0.45f, 0.45f, 0.45f, 1.0f};
  glEnable(GL_LIGHT0);
  glLightfv(GL_LIGHT0, GL_POSITION, key_pos);
  glLightfv(GL_LIGHT0, GL_AMBIENT, key_ambient);
  glLightfv(GL_LIGHT0, GL_DIFFUSE, key_diffuse);
  glLightfv(GL_LIGHT0, GL_SPECULAR, key_specular);
  const GLfloat fill_pos[4] = {static_cast<GLfloat>(fill.x), static_cast<GLfloat>(fill.y),
                               static_cast<GLfloat>(fill.z), 0.0f};
  const GLfloat fill_diffuse[4] = {0.30f, 0.30f, 0.32f, 1.0f};
  glEnable(GL_LIGHT1);
  glLightfv(GL_LIGHT1, GL_POSITION, fill_pos);
  glLightfv(GL_LIGHT1, GL_AMBIENT, zero);
  glLightfv(GL_LIGHT1, GL_DIFFUSE, fill_diffuse);
  glLightfv(GL_LIGHT1, GL_SPECULAR, zero);
  glEnable(GL_COLOR_MATERIAL);
  glColorMaterial(GL_FRONT_AND_BACK, GL_AMBIENT_AND_DIFFUSE);
  const GLfloat material_specular[4] = {0.35f, 0.35f, 0.35f, 1.0f};
  glMaterialfv(GL_FRONT_AND_BACK, GL_SPECULAR, material_specular);
  glMaterialf(GL_FRONT_AND_BACK, GL_SHININESS, 40.0f);
  for (const RenderPrimitive& p : scene.primitives)
    if (!translucent(p)) m.draw_primitive(p, view_info);
  glFrontFace(GL_CCW);
  glDisable(GL_COLOR_MATERIAL);
  glDisable(GL_NORMALIZE);

  // Lines, unlit, depth tested against the solids.
  glMatrixMode(GL_MODELVIEW);
  glLoadMatrixd(view.data());
  m.draw_lines(scene);

  // Translucent solids, lit, over everything behind them.
  glEnable(GL_LIGHTING);
  glEnable(GL_NORMALIZE);
  glEnable(GL_COLOR_MATERIAL);
  m.draw_translucent(scene, view_info);
  glDisable(GL_COLOR_MATERIAL);
  glDisable(GL_NORMALIZE);
  glDisable(GL_LIGHTING);
  glDisableClientState(GL_VERTEX_ARRAY);
  glFinish();

  std::vector<std::uint8_t> rgb;
  m.downsample(rgb);
  m.draw_caption(scene, rgb);
  m.draw_legend(scene, rgb);
  return rgb;
}

// ---------------------------------------------------------------- legend

int caption_pixel_size(int height) { return std::max(9, static_cast<int>(std::lround(height / 30.0))); }

ScaleBar scale_bar_for(const RenderCamera& camera, int height, double max_pixels) {
  ScaleBar sb;
  const double d = norm(camera.target - camera.position);
  const double fov = std::clamp(camera.fov_degrees, 1.0, 170.0);
  const double per_metre = height / (2.0 * d * std::tan(0.5 * fov * std::numbers::pi / 180.0));
  if (!(per_metre > 0.0) || !std::isfinite(per_metre) || !(max_pixels > 0.0)) return sb;
  const double longest = max_pixels / per_metre;
  const double decade = std::pow(10.0, std::floor(std::log10(longest)));
  const double mantissa = longest / decade * (1.0 + 1e-9);
  const double step = mantissa >= 5.0 ? 5.0 : (mantissa >= 2.0 ? 2.0 : 1.0);
  sb.metres = step * decade;
  sb.pixels = sb.metres * per_metre;
  char text[48];
  if (sb.metres >= 1000.0)
    std::snprintf(text, sizeof text, "%g km", sb.metres / 1000.0);
  else if (sb.metres >= 1.0)
    std::snprintf(text, sizeof text, "%g m", sb.metres);
  else if (sb.metres >= 0.01)
    std::snprintf(text, sizeof text, "%g cm", sb.metres * 100.0);
  else
    std::snprintf(text, sizeof text, "%g mm", sb.metres * 1000.0);
  sb.label = text;
  return sb;
}

// ---------------------------------------------------------------- text

int draw_text_rgb(std::vector<std::uint8_t>& rgb, int width, int height, int x, int y,
                  const std::string& text, const RenderColor& color, int scale) {
  scale = std::max(1, scale);
  if (width <= 0 || height <= 0 ||
      rgb.size() < static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3)
    return x;
  const std::uint8_t c[3] = {to_byte(color[0]), to_byte(color[1]), to_byte(color[2])};
  for (char ch : text) {
    const auto& rows = font5x7::glyph(ch);
    for (int r = 0; r < font5x7::kGlyphHeight; ++r) {
      for (int col = 0; col < font5x7::kGlyphWidth; ++col) {
        if (((rows[static_cast<std::size_t>(r)] >> (font5x7::kGlyphWidth - 1 - col)) & 1u) == 0) continue;
        for (int dy = 0; dy < scale; ++dy) {
          const int py = y + r * scale + dy;
          if (py < 0 || py >= height) continue;
          for (int dx = 0; dx < scale; ++dx) {
            const int px = x + col * scale + dx;
            if (px < 0 || px >= width) continue;
            std::uint8_t* dst = rgb.data() + (static_cast<std::size_t>(py) * static_cast<std::size_t>(width) + static_cast<std::size_t>(px)) * 3;
            dst[0] = c[0];
            dst[1] = c[1];
            dst[2] = c[2];
          }
        }
      }
    }
    x += font5x7::kAdvance * scale;
  }
  return x;
}

}  // namespace odemag
