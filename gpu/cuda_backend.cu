// The CUDA backend: MagneticBackend on an NVIDIA GPU in double precision
// (docs/gpu.md). This file is the host side: it gathers the model and state
// into flat arrays, keeps them in device memory, launches the kernels (one per
// .cu file) and scatters the results back into the state.
//
// Coherence of host and device state (docs/gpu.md "Host and device state"):
// - Geometry (positions, radii, bodies, rotations, lattice keys, moment
//   offsets) is uploaded by begin_step, once per rigid step; the offset tensor
//   tables once per model contents (MagneticModel::generation: a copy, a new
//   model at the same address or an added body uploads them again).
// - Magnetizations belong to the host: responsive_field and forces upload
//   state.magnetization of the cells they read at every call (the relaxation
//   driver and place_cells write it on the host).
// - Moments, Hc history, history flags and noise counters of soft cells are
//   uploaded by begin_step and live on the device during the step;
//   relax_cells updates them there and copies them, with the magnetizations,
//   back to the host state before it returns. So the host state is complete
//   after every call, and host edits of moments (reset_moments, a new state)
//   take effect at the next begin_step, as a new rigid step begins.
#include "gpu/cuda_backend.h"

#include <cuda_runtime.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "gpu/cuda_check.cuh"
#include "gpu/device_buffer.cuh"
#include "gpu/device_data.cuh"
#include "magnetics/model/cell_layout.h"
#include "magnetics/relax/field_probe.h"
#include "magnetics/near_field/near_field.h"
#include "magnetics/model/state.h"

namespace odemag {

namespace {

using gpu::CellPoint;
using gpu::DeviceBody;
using gpu::DeviceBuffer;
using gpu::PinnedBuffer;

static_assert(std::is_trivially_copyable_v<Vec3> && sizeof(Vec3) == 3 * sizeof(double));
static_assert(std::is_trivially_copyable_v<ProbeCell>);
static_assert(std::is_trivially_copyable_v<DeviceBody>);

// Owning handles, so that a constructor that throws half way leaks nothing.
class Stream {
 public:
  Stream() { ODEMAG_CUDA_CHECK(cudaStreamCreateWithFlags(&stream_, cudaStreamNonBlocking)); }
  ~Stream() { (void)cudaStreamDestroy(stream_); }
  Stream(const Stream&) = delete;
  Stream& operator=(const Stream&) = delete;
  cudaStream_t get() const { return stream_; }

 private:
  cudaStream_t stream_ = nullptr;
};

class Event {
 public:
  Event() { ODEMAG_CUDA_CHECK(cudaEventCreate(&event_)); }
  ~Event() { (void)cudaEventDestroy(event_); }
  Event(const Event&) = delete;
  Event& operator=(const Event&) = delete;
  cudaEvent_t get() const { return event_; }

 private:
  cudaEvent_t event_ = nullptr;
};

// Times one interface call with four events on the stream: start, uploads
// done, kernels done, downloads done.
class CallTimer {
 public:
  CallTimer(const std::array<Event, 4>& events, cudaStream_t stream, CudaCallStats& stats)
      : events_(events), stream_(stream), stats_(stats), start_(std::chrono::steady_clock::now()) {
    advance_to(0);
  }
  void uploads_done() { advance_to(1); }
  void kernels_done() { advance_to(2); }
  // Waits for everything queued on the stream (errors of the kernels surface
  // here) and adds the phase times and bytes.
  void synchronize(double upload_bytes, double download_bytes) {
    advance_to(3);
    ODEMAG_CUDA_CHECK(cudaStreamSynchronize(stream_));
    float up = 0, kernels = 0, down = 0;
    ODEMAG_CUDA_CHECK(cudaEventElapsedTime(&up, events_[0].get(), events_[1].get()));
    ODEMAG_CUDA_CHECK(cudaEventElapsedTime(&kernels, events_[1].get(), events_[2].get()));
    ODEMAG_CUDA_CHECK(cudaEventElapsedTime(&down, events_[2].get(), events_[3].get()));
    stats_.upload_ms += up;
    stats_.kernel_ms += kernels;
    stats_.download_ms += down;
    stats_.upload_bytes += upload_bytes;
    stats_.download_bytes += download_bytes;
  }
  void stop() {
    ++stats_.calls;
    stats_.wall_ms +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  void advance_to(int k) {
    for (; recorded_ <= k; ++recorded_) ODEMAG_CUDA_CHECK(cudaEventRecord(events_[recorded_].get(), stream_));
  }
  const std::array<Event, 4>& events_;
  cudaStream_t stream_;
  CudaCallStats& stats_;
  std::chrono::steady_clock::time_point start_;
  int recorded_ = 0;
};

// The one line the CUDA backend writes when asked for the far-field
// approximation (RelaxOptions::far_field_theta > 0), which it does not have.
void print_far_field_notice(double theta) {
  std::fprintf(stderr,
               "odemag: the CUDA backend ignores solver.far_field_theta (%g: the far-field approximation is "
               "CPU-only); every pair is summed exactly\n",
               theta);
  std::fflush(stderr);
}

template <class T>
double bytes_of(size_t n) {
  return static_cast<double>(n * sizeof(T));
}

class CudaBackend final : public MagneticBackend {
 public:
  explicit CudaBackend(int device) : device_(select(device)) { totals_.resize(1); }

  std::string name() const override { return "cuda"; }

  // No far-field tree on the device: every pair is summed exactly. Said once
  // per backend on stderr, the first time theta > 0 is asked for (the
  // relaxation driver sets it at every step).
  void set_far_field(double theta) override {
    if (theta > 0.0 && !far_field_noticed_) {
      far_field_noticed_ = true;
      print_far_field_notice(theta);
    }
  }

  CudaBackendStats stats() const { return stats_; }
  void reset_stats() { stats_ = {}; }

  void begin_step(const MagneticModel& model, const MagneticState& state) override {
    select(device_);
    CallTimer timer(events_, stream(), stats_.begin_step);
    // Bodies of graded cells or refined zones carry per-pair tensors
    // (MagneticBody::pair_tensors) that this backend does not sum: refuse them
    // rather than give their cells no intra-body field (docs/model.md "Graded
    // cells", "Refined contact zones").
    for (const MagneticBody& body : model.bodies()) {
      if (body.cells.graded && body.responsive())
        throw std::invalid_argument("CUDA backend: body \"" + body.name +
                                    "\" has graded cells, which only the CPU backend supports "
                                    "(MagneticModel::set_graded_cells(false) gives it a uniform lattice)");
      if (body.cells.refined && body.responsive())
        throw std::invalid_argument("CUDA backend: body \"" + body.name +
                                    "\" has refined zones, which only the CPU backend supports");
    }
    for (const MagneticBody& body : model.bodies())
      if (!body.bh_curve.empty())
        throw std::invalid_argument("CUDA backend: body \"" + body.name +
                                    "\" has a B-H curve, which only the CPU backend supports");
    double up = upload_tables(model);

    // Bodies at this step (all of the model's, indexed by body).
    h_bodies_.assign(model.body_count(), DeviceBody{});
    for (int b = 0; b < model.body_count(); ++b) {
      const MagneticBody& body = model.body(b);
      DeviceBody& d = h_bodies_[b];
      d.rotation = state.pose[b].rotation;
      d.soft = body.soft;
      d.remanent = d.rotation * (state.magnetization_scale[b] * body.remanence);
      d.recoil = body.recoil;
      d.table = table_offset_[b];
      const auto& n = body.cells.lattice_extent;
      d.key_centre = gpu::lattice_key(n[0] - 1, n[1] - 1, n[2] - 1, body.offset_extent[0],
                                      body.offset_extent[1]);
      d.cell_count = body.cell_count();
      d.kind = static_cast<int>(body.kind);
    }

    // Cell lists in the order of the shared layout (magnetics/model/cell_layout.h),
    // the CPU backend's order.
    layout_.build(model, state);
    resp_soft_.clear(), all_positions_.clear(), moment_runs_.clear();
    h_resp_point_.clear(), h_fixed_point_.clear(), h_all_point_.clear();
    h_resp_body_.clear(), h_resp_key_.clear(), h_resp_moment_.clear();
    h_resp_volume_.clear(), h_all_volume_.clear();
    h_fixed_mu_.clear(), h_history_.clear(), h_counter_.clear();
    moment_total_ = 0;
    for (const CellRun& run : layout_.all.runs) {
      const int b = run.body;
      const MagneticBody& body = model.body(b);
      const bool soft = body.kind == CellKind::soft;
      const int n = body.soft.n;
      size_t run_device = 0, run_host = 0;
      if (soft) {
        run_device = moment_total_;
        run_host = static_cast<size_t>(model.moment_offset(body.first_cell));
        const size_t count = static_cast<size_t>(body.cell_count()) * n;
        moment_runs_.push_back({run_host, run_device, count});
        moment_total_ += count;
      }
      for (int k = run.begin; k < run.end; ++k) {
        const int c = layout_.all.cell[k], i = c - body.first_cell;
        const Vec3& x = state.cell_position[c];
        const CellPoint point{x.x, x.y, x.z, body.cells.contact_radii[i]};
        const double volume = body.cells.volumes[i];
        all_positions_.push_back(x);
        h_all_point_.push_back(point);
        h_all_volume_.push_back(volume);
        if (!body.responsive()) {
          h_fixed_point_.push_back(point);
          h_fixed_mu_.push_back(volume * state.magnetization[c]);
          continue;
        }
        h_resp_volume_.push_back(volume);
        resp_soft_.push_back(soft ? 1 : 0);
        h_resp_point_.push_back(point);
        h_resp_body_.push_back(b);
        const auto& l = body.cells.lattice_index[i];
        h_resp_key_.push_back(
            gpu::lattice_key(l[0], l[1], l[2], body.offset_extent[0], body.offset_extent[1]));
        if (soft) {
          // A body's moments are contiguous in the state (model.cpp), so one
          // run per body carries them.
          if (static_cast<size_t>(model.moment_offset(c)) != run_host + static_cast<size_t>(i) * n)
            throw std::logic_error("CUDA backend: moments of body \"" + body.name + "\" are not contiguous");
          h_resp_moment_.push_back(static_cast<int>(run_device + static_cast<size_t>(i) * n));
          h_history_.push_back(state.llg_history[c]);
          h_counter_.push_back(state.noise_counter[c]);
        } else {
          h_resp_moment_.push_back(-1);
          h_history_.push_back(0);
          h_counter_.push_back(0);
        }
      }
    }
    h_moments_.resize(moment_total_);
    h_hc_prev_.resize(moment_total_);
    for (const MomentRun& run : moment_runs_) {
      std::copy_n(state.moments.begin() + run.host, run.count, h_moments_.begin() + run.device);
      std::copy_n(state.moment_hc_prev.begin() + run.host, run.count, h_hc_prev_.begin() + run.device);
    }

    // Pageable sources: cudaMemcpyAsync returns once it has staged them.
    const cudaStream_t s = stream();
    bodies_.upload(h_bodies_.data(), h_bodies_.size(), s);
    resp_point_.upload(h_resp_point_.data(), h_resp_point_.size(), s);
    resp_body_.upload(h_resp_body_.data(), h_resp_body_.size(), s);
    resp_key_.upload(h_resp_key_.data(), h_resp_key_.size(), s);
    resp_cell_.upload(layout_.responsive.cell.data(), layout_.responsive.cell.size(), s);
    resp_moment_.upload(h_resp_moment_.data(), h_resp_moment_.size(), s);
    resp_volume_.upload(h_resp_volume_.data(), h_resp_volume_.size(), s);
    all_volume_.upload(h_all_volume_.data(), h_all_volume_.size(), s);
    history_.upload(h_history_.data(), h_history_.size(), s);
    counter_.upload(h_counter_.data(), h_counter_.size(), s);
    fixed_point_.upload(h_fixed_point_.data(), h_fixed_point_.size(), s);
    fixed_mu_.upload(h_fixed_mu_.data(), h_fixed_mu_.size(), s);
    all_point_.upload(h_all_point_.data(), h_all_point_.size(), s);
    all_body_.upload(layout_.all.body.data(), layout_.all.body.size(), s);
    moments_.upload(h_moments_.data(), h_moments_.size(), s);
    hc_prev_.upload(h_hc_prev_.data(), h_hc_prev_.size(), s);
    up += bodies_.bytes() + resp_point_.bytes() + resp_body_.bytes() + resp_key_.bytes() +
          resp_cell_.bytes() + resp_moment_.bytes() + resp_volume_.bytes() + all_volume_.bytes() +
          history_.bytes() + counter_.bytes() +
          fixed_point_.bytes() + fixed_mu_.bytes() + all_point_.bytes() + all_body_.bytes() +
          moments_.bytes() + hc_prev_.bytes();
    timer.uploads_done();
    timer.synchronize(up, 0.0);
    timer.stop();
    // Near-field corrections: short pair lists, evaluated on the host with
    // the same code as the CPU backend (magnetics/near_field/near_field.h).
    near_.build(model, state, near_field_, near_mutual_induction_);
  }

  void set_near_field(bool on, bool mutual_induction) override {
    near_field_ = on;
    near_mutual_induction_ = mutual_induction;
  }

  void fixed_field(const MagneticModel& model, const MagneticState& state, std::vector<Vec3>& H) override {
    const int n = responsive_count();
    if (n == 0) return;
    select(device_);
    CallTimer timer(events_, stream(), stats_.fixed_field);
    timer.uploads_done();
    resp_H_.resize(n);
    gpu::launch_fixed_field({n, resp_point_.data(), layout_.fixed.size(),
                             fixed_point_.data(), fixed_mu_.data(), state.external_field,
                             resp_H_.data()},
                            stream());
    timer.kernels_done();
    pin_out_.resize(n);
    resp_H_.download(pin_out_.data(), n, stream());
    timer.synchronize(0.0, bytes_of<Vec3>(n));
    for (int i = 0; i < n; ++i) H[layout_.responsive.cell[i]] = pin_out_[i];
    near_.add_field(model, state, NearFieldSources::fixed, H);
    timer.stop();
  }

  void responsive_field(const MagneticModel& model, const MagneticState& state,
                        std::vector<Vec3>& H) override {
    const int n = responsive_count();
    if (n == 0) return;
    select(device_);
    CallTimer timer(events_, stream(), stats_.responsive_field);
    const cudaStream_t s = stream();
    pin_in_.resize(n);
    for (int i = 0; i < n; ++i) pin_in_[i] = state.magnetization[layout_.responsive.cell[i]];
    resp_M_.upload(pin_in_.data(), n, s);
    timer.uploads_done();
    resp_mu_.resize(n);
    resp_mu_body_.resize(n);
    resp_H_.resize(n);
    gpu::launch_cell_moments({n, resp_body_.data(), bodies_.data(), resp_volume_.data(), resp_M_.data(),
                              resp_mu_.data(), resp_mu_body_.data()},
                             s);
    gpu::launch_responsive_field({n, resp_point_.data(), resp_body_.data(), resp_key_.data(),
                                  resp_mu_.data(), resp_mu_body_.data(), bodies_.data(),
                                  tables_.data(), resp_H_.data()},
                                 s);
    timer.kernels_done();
    pin_out_.resize(n);
    resp_H_.download(pin_out_.data(), n, s);
    timer.synchronize(bytes_of<Vec3>(n), bytes_of<Vec3>(n));
    for (int i = 0; i < n; ++i) H[layout_.responsive.cell[i]] = pin_out_[i];
    add_boundary_field(model, state, H);
    near_.add_field(model, state, NearFieldSources::responsive, H);
    timer.stop();
  }

  LocalStats relax_cells(const MagneticModel&, MagneticState& state, const std::vector<Vec3>& H_A,
                         const LocalRelaxOptions& options) override {
    const int n = responsive_count();
    if (n == 0) return {};
    select(device_);
    CallTimer timer(events_, stream(), stats_.relax_cells);
    const cudaStream_t s = stream();
    pin_in_.resize(n);
    for (int i = 0; i < n; ++i) pin_in_[i] = H_A[layout_.responsive.cell[i]];
    resp_applied_.upload(pin_in_.data(), n, s);
    ODEMAG_CUDA_CHECK(cudaMemsetAsync(totals_.data(), 0, sizeof(gpu::RelaxTotals), s));
    timer.uploads_done();
    resp_M_.resize(n);
    gpu::launch_relax_cells({n, resp_body_.data(), resp_cell_.data(), resp_moment_.data(),
                             bodies_.data(), resp_applied_.data(), resp_M_.data(), moments_.data(),
                             hc_prev_.data(), history_.data(), counter_.data(), state.seed, options,
                             totals_.data()},
                            s);
    timer.kernels_done();
    // Everything the CPU backend would have changed in the host state.
    pin_out_.resize(n);
    pin_moments_.resize(moment_total_);
    pin_hc_prev_.resize(moment_total_);
    pin_history_.resize(n);
    pin_counter_.resize(n);
    pin_totals_.resize(1);
    resp_M_.download(pin_out_.data(), n, s);
    moments_.download(pin_moments_.data(), moment_total_, s);
    hc_prev_.download(pin_hc_prev_.data(), moment_total_, s);
    history_.download(pin_history_.data(), n, s);
    counter_.download(pin_counter_.data(), n, s);
    totals_.download(pin_totals_.data(), 1, s);
    timer.synchronize(bytes_of<Vec3>(n) + sizeof(gpu::RelaxTotals),
                      bytes_of<Vec3>(n) + 2 * bytes_of<Vec3>(moment_total_) + bytes_of<uint8_t>(n) +
                          bytes_of<uint64_t>(n) + sizeof(gpu::RelaxTotals));
    for (int i = 0; i < n; ++i) {
      const int c = layout_.responsive.cell[i];
      state.magnetization[c] = pin_out_[i];
      if (!resp_soft_[i]) continue;  // recoil magnets have no moments
      state.llg_history[c] = pin_history_[i];
      state.noise_counter[c] = pin_counter_[i];
    }
    for (const MomentRun& run : moment_runs_) {
      std::copy_n(pin_moments_.data() + run.device, run.count, state.moments.begin() + run.host);
      std::copy_n(pin_hc_prev_.data() + run.device, run.count, state.moment_hc_prev.begin() + run.host);
    }
    const gpu::RelaxTotals totals = pin_totals_[0];
    double worst = 0.0;
    static_assert(sizeof(worst) == sizeof(totals.max_residual_bits));
    std::memcpy(&worst, &totals.max_residual_bits, sizeof(worst));
    timer.stop();
    return {static_cast<long>(totals.llg_steps), static_cast<long>(totals.newton_steps), worst};
  }

  void forces(const MagneticModel& model, MagneticState& state) override {
    std::fill(state.force.begin(), state.force.end(), Vec3{});
    std::fill(state.torque.begin(), state.torque.end(), Vec3{});
    const int n = layout_.all.size();
    if (n == 0) return;
    select(device_);
    CallTimer timer(events_, stream(), stats_.forces);
    const cudaStream_t s = stream();
    pin_in_.resize(n);
    for (int i = 0; i < n; ++i) pin_in_[i] = state.magnetization[layout_.all.cell[i]];
    all_M_.upload(pin_in_.data(), n, s);
    timer.uploads_done();
    all_mu_.resize(n);
    all_force_.resize(n);
    all_field_.resize(n);
    gpu::launch_cell_moments(
        {n, all_body_.data(), bodies_.data(), all_volume_.data(), all_M_.data(), all_mu_.data(), nullptr}, s);
    gpu::launch_cell_forces(
        {n, all_point_.data(), all_body_.data(), all_mu_.data(), all_force_.data(), all_field_.data()}, s);
    timer.kernels_done();
    pin_out_.resize(n);
    pin_out2_.resize(n);
    all_force_.download(pin_out_.data(), n, s);
    all_field_.download(pin_out2_.data(), n, s);
    timer.synchronize(bytes_of<Vec3>(n), 2 * bytes_of<Vec3>(n));
    if (near_.pair_count() > 0) {
      near_force_.assign(model.cell_count(), {});
      near_field_at_.assign(model.cell_count(), {});
      near_.add_forces(model, state, near_force_, near_field_at_);
      for (int i = 0; i < n; ++i) {
        pin_out_[i] += near_force_[layout_.all.cell[i]];
        pin_out2_[i] += near_field_at_[layout_.all.cell[i]];
      }
    }
    // Per-body sums in cell order, as the CPU backend.
    for (int i = 0; i < n; ++i) {
      const int b = layout_.all.body[i];
      const Vec3& xi = all_positions_[i];
      const Vec3 mi = h_all_volume_[i] * state.magnetization[layout_.all.cell[i]];
      const Vec3& f = pin_out_[i];
      state.force[b] += f;
      state.torque[b] += cell_torque(xi - state.pose[b].position, f, mi, pin_out2_[i] + state.external_field);
    }
    timer.stop();
  }

  void probe_field(const MagneticModel& model, const MagneticState& state,
                   const std::vector<Vec3>& points, std::vector<Vec3>& H) override {
    const std::vector<ProbeCell> cells = probe_cells(model, state);
    const int n = static_cast<int>(points.size());
    H.resize(n);
    if (n == 0) return;
    select(device_);
    CallTimer timer(events_, stream(), stats_.probe_field);
    const cudaStream_t s = stream();
    probe_cells_.upload(cells.data(), cells.size(), s);
    probe_points_.upload(points.data(), points.size(), s);
    timer.uploads_done();
    probe_H_.resize(n);
    gpu::launch_probe_field({n, probe_points_.data(), static_cast<int>(cells.size()), probe_cells_.data(),
                             state.external_field, probe_H_.data()},
                            s);
    timer.kernels_done();
    pin_out_.resize(n);
    probe_H_.download(pin_out_.data(), n, s);
    timer.synchronize(bytes_of<ProbeCell>(cells.size()) + bytes_of<Vec3>(n), bytes_of<Vec3>(n));
    std::copy_n(pin_out_.data(), n, H.begin());
    timer.stop();
  }

 private:
  struct MomentRun {
    size_t host, device, count;  // first moment in state.moments, first on the device, moments
  };

  static int select(int device) {
    ODEMAG_CUDA_CHECK(cudaSetDevice(device));
    return device;
  }
  cudaStream_t stream() const { return stream_.get(); }
  int responsive_count() const { return layout_.responsive.size(); }

  // The offset tensors of every body in one device array, uploaded when the
  // model's tables changed. Returns the bytes uploaded.
  double upload_tables(const MagneticModel& model) {
    if (model.generation() == table_generation_ && table_offset_.size() == static_cast<size_t>(model.body_count()))
      return 0.0;
    std::vector<double> tables;
    table_offset_.assign(model.body_count(), -1);
    for (int b = 0; b < model.body_count(); ++b) {
      const std::vector<double>& t = model.body(b).offset_tensors;
      if (t.empty()) continue;
      table_offset_[b] = static_cast<long long>(tables.size());
      tables.insert(tables.end(), t.begin(), t.end());
    }
    tables_.upload(tables.data(), tables.size(), stream());
    table_generation_ = model.generation();
    return bytes_of<double>(tables.size());
  }

  int device_;
  bool near_field_ = true, near_mutual_induction_ = true;
  bool far_field_noticed_ = false;
  NearField near_;
  std::vector<Vec3> near_force_, near_field_at_;
  Stream stream_;
  std::array<Event, 4> events_;
  CudaBackendStats stats_;

  // This step's cell lists on the host (begin_step).
  CellLayout layout_;
  std::vector<uint8_t> resp_soft_;
  std::vector<Vec3> all_positions_;
  std::vector<MomentRun> moment_runs_;
  size_t moment_total_ = 0;
  uint64_t table_generation_ = 0;  // MagneticModel::generation of the uploaded tables; 0: none (never a generation)
  std::vector<long long> table_offset_;  // per body, into tables_; -1: none

  // Host staging of begin_step (pageable; once per step).
  std::vector<DeviceBody> h_bodies_;
  std::vector<CellPoint> h_resp_point_, h_fixed_point_, h_all_point_;
  std::vector<int> h_resp_body_, h_resp_key_, h_resp_moment_;
  std::vector<double> h_resp_volume_, h_all_volume_;  // V of each cell (CellSet::volumes)
  std::vector<Vec3> h_fixed_mu_, h_moments_, h_hc_prev_;
  std::vector<uint8_t> h_history_;
  std::vector<uint64_t> h_counter_;

  // Device data.
  DeviceBuffer<DeviceBody> bodies_;
  DeviceBuffer<double> tables_, resp_volume_, all_volume_;
  DeviceBuffer<CellPoint> resp_point_, fixed_point_, all_point_;
  DeviceBuffer<int> resp_body_, resp_key_, resp_cell_, resp_moment_, all_body_;
  DeviceBuffer<Vec3> fixed_mu_, resp_M_, resp_mu_, resp_mu_body_, resp_H_, resp_applied_;
  DeviceBuffer<Vec3> all_M_, all_mu_, all_force_, all_field_;
  DeviceBuffer<Vec3> moments_, hc_prev_;
  DeviceBuffer<uint8_t> history_;
  DeviceBuffer<uint64_t> counter_;
  DeviceBuffer<gpu::RelaxTotals> totals_;
  DeviceBuffer<ProbeCell> probe_cells_;
  DeviceBuffer<Vec3> probe_points_, probe_H_;

  // Pinned staging for the transfers of every iteration.
  PinnedBuffer<Vec3> pin_in_, pin_out_, pin_out2_, pin_moments_, pin_hc_prev_;
  PinnedBuffer<uint8_t> pin_history_;
  PinnedBuffer<uint64_t> pin_counter_;
  PinnedBuffer<gpu::RelaxTotals> pin_totals_;
};

std::string cuda_version(int v) { return std::to_string(v / 1000) + "." + std::to_string(v % 1000 / 10); }

}  // namespace

bool cuda_backend_compiled() { return true; }

std::unique_ptr<MagneticBackend> make_cuda_backend(std::string* why) {
  auto fail = [why](const std::string& reason) -> std::unique_ptr<MagneticBackend> {
    if (why) *why = reason;
    return nullptr;
  };
  int count = 0;
  const cudaError_t status = cudaGetDeviceCount(&count);
  if (status != cudaSuccess) {
    (void)cudaGetLastError();  // clear the error for later calls
    int driver = 0;
    (void)cudaDriverGetVersion(&driver);
    std::string reason = std::string("no usable CUDA device: cudaGetDeviceCount: ") +
                         cudaGetErrorName(status) + " (" + cudaGetErrorString(status) + ")";
    if (driver == 0)
      reason += "; no NVIDIA driver is installed";
    else if (driver < CUDART_VERSION)
      reason += "; the driver supports CUDA " + cuda_version(driver) + ", this build needs CUDA " +
                cuda_version(CUDART_VERSION);
    return fail(reason);
  }
  if (count == 0) return fail("no CUDA device (cudaGetDeviceCount found none)");
  int device = 0;
  if (const cudaError_t e = cudaGetDevice(&device); e != cudaSuccess) {
    (void)cudaGetLastError();
    return fail(std::string("cudaGetDevice: ") + cudaGetErrorString(e));
  }
  if (const cudaError_t e = gpu::check_kernel_image(); e != cudaSuccess) {
    (void)cudaGetLastError();
    int major = 0, minor = 0;
    (void)cudaDeviceGetAttribute(&major, cudaDevAttrComputeCapabilityMajor, device);
    (void)cudaDeviceGetAttribute(&minor, cudaDevAttrComputeCapabilityMinor, device);
    return fail("CUDA device " + std::to_string(device) + " (compute capability " + std::to_string(major) +
                "." + std::to_string(minor) +
                ") cannot run this build's kernels (built for sm_90 and compute_90 PTX; "
                "set CMAKE_CUDA_ARCHITECTURES): " + cudaGetErrorString(e));
  }
  try {
    return std::make_unique<CudaBackend>(device);
  } catch (const std::exception& e) {
    return fail(std::string("the CUDA backend could not start: ") + e.what());
  }
}

CudaBackendStats cuda_backend_stats(const MagneticBackend& backend) {
  const auto* cuda = dynamic_cast<const CudaBackend*>(&backend);
  return cuda ? cuda->stats() : CudaBackendStats{};
}

void reset_cuda_backend_stats(MagneticBackend& backend) {
  if (auto* cuda = dynamic_cast<CudaBackend*>(&backend)) cuda->reset_stats();
}

}  // namespace odemag
