// A MagneticBackend that forwards to another and adds up the wall time of
// each kind of call (benchmarks: where the time of a relaxation goes).
#pragma once

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "magnetics/model/backend.h"

namespace odemag {

// Forwards every call to `inner`; begin_s .. forces_s add up the seconds spent
// in each kind of call (probe_field is not timed).
class TimedBackend final : public MagneticBackend {
 public:
  explicit TimedBackend(std::unique_ptr<MagneticBackend> inner) : inner_(std::move(inner)) {}
  std::string name() const override { return inner_->name(); }
  void set_far_field(double theta) override { inner_->set_far_field(theta); }
  void set_near_field(bool on, bool mutual_induction) override { inner_->set_near_field(on, mutual_induction); }
  void begin_step(const MagneticModel& m, const MagneticState& s) override {
    timed(begin_s, [&] { inner_->begin_step(m, s); });
  }
  void fixed_field(const MagneticModel& m, const MagneticState& s, std::vector<Vec3>& H) override {
    timed(fixed_s, [&] { inner_->fixed_field(m, s, H); });
  }
  void responsive_field(const MagneticModel& m, const MagneticState& s, std::vector<Vec3>& H) override {
    timed(field_s, [&] { inner_->responsive_field(m, s, H); });
  }
  LocalStats relax_cells(const MagneticModel& m, MagneticState& s, const std::vector<Vec3>& H_A,
                         const LocalRelaxOptions& o) override {
    LocalStats r;
    timed(local_s, [&] { r = inner_->relax_cells(m, s, H_A, o); });
    return r;
  }
  void forces(const MagneticModel& m, MagneticState& s) override {
    timed(forces_s, [&] { inner_->forces(m, s); });
  }
  void probe_field(const MagneticModel& m, const MagneticState& s, const std::vector<Vec3>& p,
                   std::vector<Vec3>& H) override {
    inner_->probe_field(m, s, p, H);
  }
  void reset() { begin_s = fixed_s = field_s = local_s = forces_s = 0.0; }
  double begin_s = 0, fixed_s = 0, field_s = 0, local_s = 0, forces_s = 0;

 private:
  template <class F>
  void timed(double& total, F&& f) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    total += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  std::unique_ptr<MagneticBackend> inner_;
};

}  // namespace odemag
