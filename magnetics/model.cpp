#include "magnetics/model.h"

#include <cmath>
#include <stdexcept>

#include "magnetics/kernels.h"

namespace odemag {

namespace {

// Intra-body tensors act on moments mu = M V (H = T mu). The cube-cube tensor
// maps magnetization to field (H = -N M), so T = -N / V with V the cell's own
// volume: the intra-body operator is then that of the cube tiling whatever V
// is (V differs from h^3 for shapes that are not boxes of whole cells), and
// keeps its stability. (Dividing by h^3 instead made a cylinder's cells, with
// V = 1.13 h^3, hold each other saturated: a spurious remanence.)
void build_offset_tensors(MagneticBody& body, IntraBodyTensor kind) {
  const auto& n = body.cells.lattice_extent;
  body.offset_extent = {2 * n[0] - 1, 2 * n[1] - 1, 2 * n[2] - 1};
  const double h = body.cells.spacing;
  body.offset_tensors.assign(6u * body.offset_extent[0] * body.offset_extent[1] * body.offset_extent[2],
                             0.0);
  for (int k = 0; k < body.offset_extent[2]; ++k)
    for (int j = 0; j < body.offset_extent[1]; ++j)
      for (int i = 0; i < body.offset_extent[0]; ++i) {
        const int di = i - (n[0] - 1), dj = j - (n[1] - 1), dk = k - (n[2] - 1);
        if (di == 0 && dj == 0 && dk == 0) continue;  // self term is H_endo
        const int idx = i + body.offset_extent[0] * (j + body.offset_extent[1] * k);
        double* t = &body.offset_tensors[6u * idx];
        if (kind == IntraBodyTensor::point_dipole) {
          dipole_tensor({di * h, dj * h, dk * h}, 0.0, t);
        } else {
          double n_tensor[6];
          cube_demag_tensor(di, dj, dk, h, n_tensor);
          for (int a = 0; a < 6; ++a) t[a] = -n_tensor[a] / body.cells.cell_volume;
        }
      }
}

}  // namespace

int MagneticModel::add_body(const std::string& name, const Shape& shape, const Material& material,
                            double cell_size) {
  if (std::string e = validate_shape(shape); !e.empty()) throw std::invalid_argument(e);
  if (std::string e = validate_material(material); !e.empty()) throw std::invalid_argument(e);
  if (!std::isfinite(cell_size)) throw std::invalid_argument("cell_size must be finite");

  MagneticBody body;
  body.name = name;
  body.shape = shape;
  body.material = material;
  body.first_cell = cell_count();
  if (!is_inert(material)) body.cells = make_cells(shape, cell_size);

  if (const auto* pm = std::get_if<PermanentMaterial>(&material)) {
    body.remanence = pm->magnetization;
    body.recoil = pm->recoil_susceptibility;
    body.kind = pm->recoil_susceptibility > 0.0 ? CellKind::recoil_permanent : CellKind::fixed_permanent;
  } else if (const auto* sm = std::get_if<SoftMaterial>(&material)) {
    body.kind = CellKind::soft;
    body.soft.Ms = sm->saturation;
    body.soft.gamma_D = sm->demag_factor();
    body.soft.H_K = sm->anisotropy_field;
    body.soft.easy_axis = normalized(sm->easy_axis);
    body.soft.alpha = sm->damping;
    body.soft.n = sm->moments_per_cell;
    body.coil_field = sm->coil_field;
  }
  if (body.responsive() && body.cell_count() > 1) build_offset_tensors(body, intra_tensor_);

  for (int c = 0; c < body.cell_count(); ++c) {
    cell_body_.push_back(body_count());
    if (body.kind == CellKind::soft) {
      moment_offset_.push_back(moment_count_);
      moment_count_ += body.soft.n;
      ++soft_cells_;
    } else {
      moment_offset_.push_back(-1);
    }
    if (body.responsive()) ++responsive_cells_;
  }
  bodies_.push_back(std::move(body));
  return body_count() - 1;
}

int MagneticModel::find_body(const std::string& name) const {
  for (int b = 0; b < body_count(); ++b)
    if (bodies_[b].name == name) return b;
  return -1;
}

}  // namespace odemag
