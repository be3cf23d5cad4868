#include "odemag/material.h"

#include "magnetics/materials/bh_curve.h"

#include <cmath>

namespace odemag {

double SoftMaterial::demag_factor() const {
  if (!bh_curve.empty()) return 1.0 / 3.0 + 1.0 / BhCurve(bh_curve).initial_susceptibility();
  return 1.0 / 3.0 + (std::isinf(susceptibility) ? 0.0 : 1.0 / susceptibility);
}

bool is_inert(const Material& material) {
  return std::holds_alternative<InertMaterial>(material);
}

bool has_positive_susceptibility(const Material& material) {
  if (std::holds_alternative<SoftMaterial>(material)) return true;
  const auto* permanent = std::get_if<PermanentMaterial>(&material);
  return permanent && permanent->recoil_susceptibility > 0.0;
}

namespace {

bool finite(const Vec3& v) { return is_finite(v); }

std::string validate_one(const InertMaterial&) { return {}; }

std::string validate_one(const PermanentMaterial& m) {
  if (!finite(m.magnetization)) return "magnetization must be finite";
  if (!std::isfinite(m.recoil_susceptibility) || m.recoil_susceptibility < -1.0)
    return "recoil_susceptibility must be finite and >= -1";
  if (m.recoil_susceptibility < 0.0 && (m.magnetization.x != 0.0 || m.magnetization.y != 0.0 || m.magnetization.z != 0.0))
    return "a negative recoil_susceptibility (a diamagnet) needs magnetization 0";
  return {};
}

std::string validate_one(const SoftMaterial& m) {
  if (!m.bh_curve.empty()) {
    if (const std::string e = bh_curve_error(m.bh_curve); !e.empty()) return "bh_curve: " + e;
    if (m.saturation != 0.0 || !std::isinf(m.susceptibility))
      return "bh_curve sets the saturation and the susceptibility: leave them unset";
  } else {
    if (!std::isfinite(m.saturation) || m.saturation <= 0.0) return "saturation must be finite and > 0";
    if (std::isnan(m.susceptibility) || m.susceptibility <= 0.0)
      return "susceptibility must be > 0 (or \"infinite\")";
  }
  if (!std::isfinite(m.anisotropy_field) || m.anisotropy_field < 0.0)
    return "anisotropy_field must be finite and >= 0";
  if (!finite(m.easy_axis) || norm(m.easy_axis) == 0.0)
    return "easy_axis must be a finite non-zero vector";
  if (!std::isfinite(m.damping) || m.damping <= 0.0) return "damping must be finite and > 0";
  if (!finite(m.coil_field)) return "coil_field must be finite";
  if (m.moments_per_cell < 2 || m.moments_per_cell > kMaxMomentsPerCell ||
      m.moments_per_cell % 2 != 0)
    return "moments_per_cell must be an even number from 2 to " +
           std::to_string(kMaxMomentsPerCell);
  return {};
}

}  // namespace

std::string validate_material(const Material& material) {
  return std::visit([](const auto& m) { return validate_one(m); }, material);
}

}  // namespace odemag
