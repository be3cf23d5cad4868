// `odemag run SCENE --out DIR`: simulate with ODE and write per-frame state,
// frames (when a renderer is available), a video of them (--video) and a
// summary (docs/hard-cases.md "Output safety").
#include <fcntl.h>
#include <spawn.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <numeric>

#include <nlohmann/json.hpp>

#include "cli/cli.h"
#include "odemag/simulation.h"
#include "engine/simulation/rigid_world.h"

extern char** environ;

namespace odemag::cli {

namespace {

using json = nlohmann::ordered_json;

json vec(const Vec3& v) { return json::array({v.x, v.y, v.z}); }

// Median, 90th percentile (nearest rank), mean, max and total of a sample.
json statistics(std::vector<double> x) {
  if (x.empty()) return json::object();
  std::sort(x.begin(), x.end());
  const double n = static_cast<double>(x.size());
  auto rank = [&](double p) { return x[std::min(x.size(), static_cast<size_t>(std::ceil(p * n))) - 1]; };
  const double total = std::accumulate(x.begin(), x.end(), 0.0);
  return {{"median", rank(0.5)}, {"p90", rank(0.9)}, {"mean", total / n}, {"max", x.back()},
          {"total", total}};
}

// One state line: the step count, the frame number when the line is a frame
// (frame < 0: a step between frames, --state-every-step), the time, per body
// its pose, velocities, moment, force and torque.
json state_line(const Simulation& sim, int frame) {
  json bodies = json::array();
  const SceneDescription& scene = sim.scene();
  for (int b = 0; b < sim.world().body_count(); ++b) {
    const dReal* q = dBodyGetQuaternion(sim.world().body(b));
    bodies.push_back({{"name", scene.bodies[b].name},
                      {"present", sim.world().enabled(b)},
                      {"position", vec(sim.world().pose(b).position)},
                      {"orientation", json::array({q[0], q[1], q[2], q[3]})},
                      {"velocity", vec(sim.world().velocity(b))},
                      {"angular_velocity", vec(sim.world().angular_velocity(b))},
                      {"moment", vec(sim.magnetics().moment(b))},
                      {"force", vec(sim.magnetics().force(b))},
                      {"torque", vec(sim.magnetics().torque(b))}});
  }
  json line = {{"step", sim.steps()}};
  if (frame >= 0) line["frame"] = frame;
  line["time"] = sim.time();
  line["bodies"] = bodies;
  return line;
}

// Stops the run when a body's state is NaN or infinite; nothing of that step
// is written.
void check_finite(const Simulation& sim) {
  if (std::string message = sim.non_finite_message(); !message.empty()) throw std::runtime_error(message);
}

class Progress {
 public:
  Progress(double duration, bool quiet) : duration_(duration), quiet_(quiet), tty_(isatty(STDERR_FILENO)) {}
  void update(const Simulation& sim, bool last = false) {
    if (quiet_) return;
    const auto now = std::chrono::steady_clock::now();
    if (!last && now - shown_ < std::chrono::seconds(tty_ ? 1 : 10)) return;
    shown_ = now;
    const auto& r = sim.records();
    double tm = 0, tr = 0;
    const size_t window = std::min<size_t>(r.size(), 100);
    for (size_t i = r.size() - window; i < r.size(); ++i) tm += r[i].magnetic_ms, tr += r[i].rigid_ms;
    if (window) tm /= static_cast<double>(window), tr /= static_cast<double>(window);
    // Time left at the pace so far.
    const double elapsed = std::chrono::duration<double>(now - started_).count();
    const double left = sim.time() > 0.0 ? elapsed * std::max(0.0, duration_ / sim.time() - 1.0) : 0.0;
    std::fprintf(stderr,
                 "%sodemag run: t = %.3f / %.3f s (%3.0f%%), %ld steps, T_m %.2f ms, T_r %.2f ms per step, "
                 "%.0f s left%s",
                 tty_ ? "\r" : "", sim.time(), duration_, duration_ > 0 ? 100.0 * sim.time() / duration_ : 100.0,
                 sim.steps(), tm, tr, left, tty_ && !last ? "" : "\n");
    std::fflush(stderr);
  }

 private:
  double duration_;
  bool quiet_, tty_;
  std::chrono::steady_clock::time_point started_ = std::chrono::steady_clock::now(), shown_{};
};

std::string frame_name(int frame) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%05d.png", frame);
  return name;
}

// A file name that frame_name gives.
bool is_frame_name(const std::string& name) {
  if (name.size() < 15 || name.rfind("frame_", 0) != 0 || name.compare(name.size() - 4, 4, ".png") != 0)
    return false;
  for (size_t i = 6; i + 4 < name.size(); ++i)
    if (name[i] < '0' || name[i] > '9') return false;
  return true;
}

// Refuses a run of more rigid steps than the limit (`--time-step 1e-12` ran
// for ever): the scene's or the flag's time step is named.
void check_step_count(const SceneDescription& scene, const RunCommandLine& c) {
  const SimulationSettings& s = scene.simulation;
  const double steps = std::ceil(s.duration / s.time_step - 0.5);
  if (!(steps > c.max_steps)) return;
  char text[320];
  std::snprintf(text, sizeof text,
                "%.3g s over a duration of %.3g s is %.3g rigid steps, more than the limit %.3g; use a longer "
                "time step or a shorter duration, or raise the limit with --max-steps N",
                s.time_step, s.duration, steps, c.max_steps);
  if (c.time_step) throw UsageError(std::string("--time-step: ") + text);
  throw SceneError(scene.file, "simulation.time_step", text);
}

// The output directory, checked before anything is written: --out must be a
// writable directory or not exist, and the run's file names in it must be
// free for files (check_output_directory). Then, once the scene is built,
// it is created (prepare_output_directory) and a previous run's frames, state.jsonl and summary.json are removed,
// so that the directory never mixes two runs (`ffmpeg -i frame_%05d.png`
// would read the stale frames of a longer earlier run).
constexpr const char* kRunFiles[] = {"state.jsonl", "state.jsonl.partial", "summary.json"};

void check_output_directory(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(dir, ec))) return;  // created by prepare_output_directory
  if (!fs::is_directory(dir, ec)) throw UsageError("--out " + dir.string() + ": exists and is not a directory");
  for (const char* name : kRunFiles) {
    const fs::path p = dir / name;
    if (fs::exists(fs::symlink_status(p, ec)) && !fs::is_regular_file(fs::symlink_status(p, ec)))
      throw UsageError("--out " + dir.string() + ": " + p.string() + " exists and is not a file");
  }
  if (::access(dir.c_str(), W_OK) != 0) throw UsageError("--out " + dir.string() + ": the directory is not writable");
}

// The temporary files a run writes in --out and renames when complete
// (render/png_writer.cpp: frame_NNNNN.png.tmp-XXXXXX from mkstemp;
// write_file_atomically: summary.json.tmp-PID). A run killed while writing
// one leaves it; the next run into the folder removes it.
bool is_temporary_name(const std::string& name) {
  const size_t at = name.find(".tmp-");
  if (at == std::string::npos || at + 5 >= name.size()) return false;
  const std::string final_name = name.substr(0, at), suffix = name.substr(at + 5);
  if (is_frame_name(final_name))  // mkstemp's six characters
    return suffix.size() == 6 && std::all_of(suffix.begin(), suffix.end(), [](char ch) {
             return std::isalnum(static_cast<unsigned char>(ch)) != 0;
           });
  if (final_name == "summary.json")  // the writer's pid
    return std::all_of(suffix.begin(), suffix.end(), [](char ch) { return ch >= '0' && ch <= '9'; });
  return false;
}

// The lock of an --out folder: DIR/.odemag.lock, held with flock(2) for the
// whole run and holding the run's pid, so that a second run into a folder in
// use is refused (exit 2) naming the first. The kernel releases the lock when
// the run ends, however it ends (kill -9 too); the file stays.
class OutputLock {
 public:
  explicit OutputLock(const std::filesystem::path& dir) {
    const std::string path = (dir / kLockFile).string();
    fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) throw UsageError("--out " + dir.string() + ": cannot create " + path + ": " + std::strerror(errno));
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      const int err = errno;
      char holder[32] = {};
      const ssize_t n = ::pread(fd_, holder, sizeof holder - 1, 0);
      ::close(fd_);
      if (err != EWOULDBLOCK)
        throw UsageError("--out " + dir.string() + ": cannot lock " + path + ": " + std::strerror(err));
      std::string pid = n > 0 ? std::string(holder, static_cast<size_t>(n)) : "";
      while (!pid.empty() && (pid.back() == '\n' || pid.back() == ' ')) pid.pop_back();
      throw UsageError("--out " + dir.string() + ": another odemag run (pid " + (pid.empty() ? "unknown" : pid) +
                       ") is writing into this folder; wait for it to end or choose another --out");
    }
    const std::string pid = std::to_string(::getpid()) + "\n";
    if (::ftruncate(fd_, 0) != 0 || ::pwrite(fd_, pid.data(), pid.size(), 0) != static_cast<ssize_t>(pid.size()))
      throw std::runtime_error("--out " + dir.string() + ": cannot write " + path + ": " + std::strerror(errno));
  }
  ~OutputLock() {
    if (fd_ >= 0) ::close(fd_);  // releases the lock
  }
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;

  static constexpr const char* kLockFile = ".odemag.lock";

 private:
  int fd_ = -1;
};

// Creates --out, takes its lock and removes a previous run's files and the
// temporary files of an interrupted one (nothing else).
std::unique_ptr<OutputLock> prepare_output_directory(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw UsageError("--out " + dir.string() + ": cannot create the directory: " + ec.message());
  auto lock = std::make_unique<OutputLock>(dir);
  std::vector<fs::path> previous;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if ((is_frame_name(name) || is_temporary_name(name)) && e.is_regular_file(ec)) previous.push_back(e.path());
  }
  for (const char* name : kRunFiles)
    if (fs::exists(dir / name, ec)) previous.push_back(dir / name);
  for (const fs::path& p : previous)
    if (!fs::remove(p, ec) || ec)
      throw std::runtime_error("cannot remove the previous run's " + p.string() + ": " + ec.message());
  return lock;
}

// --video: the frames encoded by the ffmpeg program.

// The file that posix_spawnp would run for `name`: the first executable
// PATH/name (PATH unset: execvp's default /bin:/usr/bin); "" when none.
std::string find_program(const std::string& name) {
  const char* env = std::getenv("PATH");
  const std::string path = env ? env : "/bin:/usr/bin";
  for (size_t start = 0;;) {
    const size_t end = path.find(':', start);
    const std::string dir = path.substr(start, end == std::string::npos ? std::string::npos : end - start);
    const std::string file = (dir.empty() ? "." : dir) + "/" + name;
    struct stat st {};
    if (::stat(file.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(file.c_str(), X_OK) == 0) return file;
    if (end == std::string::npos) return "";
    start = end + 1;
  }
}

// p absolute, normalized, without a trailing '/'.
std::filesystem::path normal(const std::filesystem::path& p) {
  std::filesystem::path n = std::filesystem::absolute(p).lexically_normal();
  return n.has_filename() ? n : n.parent_path();
}

// Checks --video before anything is written (exit 2) and returns the ffmpeg
// to run: ffmpeg on PATH, a build with the renderer, and the video's
// directory writable or --out (which the run creates).
std::string check_video(const RunCommandLine& c, bool renderer) {
  namespace fs = std::filesystem;
  const std::string& video = *c.video;
  const std::string ffmpeg = find_program("ffmpeg");
  if (ffmpeg.empty())
    throw UsageError("--video " + video + ": needs the ffmpeg program, which is not on PATH; install ffmpeg "
                     "(apt-get install ffmpeg) or leave out --video");
  if (!renderer) throw UsageError("--video " + video + ": this build has no renderer, so there are no frames to encode");
  std::error_code ec;
  const fs::path file = normal(video), parent = file.parent_path();
  if (fs::is_directory(file, ec)) throw UsageError("--video " + video + ": is a directory");
  if (parent != normal(c.out) && (!fs::is_directory(parent, ec) || ::access(parent.c_str(), W_OK) != 0))
    throw UsageError("--video " + video + ": " + parent.string() + " is not a writable directory");
  return ffmpeg;
}

int run_program(const std::string& program, const std::vector<std::string>& args) {
  return wait_program(start_program(program, args));
}

// Encodes DIR/frame_NNNNN.png at `rate` frames per second: MP4 as H.264
// yuv420p (padded to even dimensions, which yuv420p needs), GIF through a
// palette made from the frames. ffmpeg writes VIDEO.tmp-PID, renamed over
// VIDEO only when it succeeded (docs/hard-cases.md "Output safety").
void encode_video(const std::string& ffmpeg, const std::filesystem::path& dir, const std::string& video,
                  double rate) {
  // Absolute paths: a name starting with '-' is no option and one with ':'
  // no protocol to ffmpeg; '%' in DIR is escaped for the image2 pattern.
  std::string pattern;
  for (char ch : normal(dir).string()) pattern += ch == '%' ? std::string("%%") : std::string(1, ch);
  pattern += "/frame_%05d.png";
  const std::string path = normal(video).string(), temporary = path + ".tmp-" + std::to_string(getpid());
  char fps[32];
  std::snprintf(fps, sizeof fps, "%.10g", rate);
  std::vector<std::string> args = {ffmpeg, "-nostdin", "-hide_banner", "-loglevel", "error", "-y",
                                   "-framerate", fps, "-i", pattern};
  const std::vector<std::string> format =
      std::filesystem::path(video).extension() == ".gif"
          ? std::vector<std::string>{"-vf", "split[a][b];[a]palettegen[p];[b][p]paletteuse", "-f", "gif"}
          : std::vector<std::string>{"-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", "libx264", "-pix_fmt",
                                     "yuv420p", "-f", "mp4"};
  args.insert(args.end(), format.begin(), format.end());
  args.push_back(temporary);
  const int status = run_program(ffmpeg, args);
  const int fd = status == 0 ? ::open(temporary.c_str(), O_RDONLY | O_CLOEXEC) : -1;
  const bool synced = fd >= 0 && ::fsync(fd) == 0;
  if (fd >= 0) ::close(fd);
  if (!synced || std::rename(temporary.c_str(), path.c_str()) != 0) {
    const std::string why = status != 0 ? "ffmpeg failed (exit status " + std::to_string(status) + ")"
                                        : "cannot write " + temporary + ": " + std::strerror(errno);
    ::unlink(temporary.c_str());
    throw std::runtime_error("--video " + video + ": " + why + "; the frames are in " + dir.string());
  }
}

}  // namespace

pid_t start_program(const std::string& program, std::vector<std::string> args, bool quiet_stdout) {
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  if (quiet_stdout) posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  const int err = posix_spawn(&pid, program.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (err != 0) throw std::runtime_error("cannot run " + program + ": " + std::strerror(err));
  return pid;
}

int wait_program(pid_t pid) {
  int raw = 0;
  while (waitpid(pid, &raw, 0) < 0)
    if (errno != EINTR) throw std::runtime_error("waiting for process " + std::to_string(pid) + ": " + std::strerror(errno));
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
}

const std::vector<std::string>& summary_figures() {
  static const std::vector<std::string> figures = [] {
    std::vector<std::string> f = {"bodies", "cells", "responsive_cells", "time_step", "duration", "steps",
                                  "frames", "wall_seconds", "steps_not_converged", "magnetic_steps_skipped",
                                  "exact_solver_failures"};
    for (const char* group : {"magnetic_ms", "rigid_ms", "iterations", "substeps", "held", "rezoned"})
      for (const char* s : {"median", "p90", "mean", "max", "total"}) f.push_back(std::string(group) + "." + s);
    return f;
  }();
  return figures;
}

int run_simulation(const std::vector<std::string>& args, const FrameWriterFactory& frames) {
  const RunCommandLine c = parse_run_command(args);
  const std::string& out = c.out;
  const SolveOptions& options = c.solve;

  SceneDescription scene = load_scene(c.scene);
  for (const std::string& n : scene.notices) std::fprintf(stderr, "odemag run: %s\n", n.c_str());
  SimulationSettings& settings = scene.simulation;
  settings.duration = c.duration.value_or(settings.duration);
  settings.frame_rate = c.frame_rate.value_or(settings.frame_rate);
  settings.time_step = c.time_step.value_or(settings.time_step);
  scene.camera.width = c.width.value_or(scene.camera.width);
  scene.camera.height = c.height.value_or(scene.camera.height);
  const bool want_frames = c.frames;
  const bool quiet = c.quiet;

  check_step_count(scene, c);
  check_cell_pairs(scene, options);
  const std::filesystem::path dir(out);
  check_output_directory(dir);
  const std::string ffmpeg = c.video ? check_video(c, static_cast<bool>(frames)) : "";

  std::unique_ptr<MagneticBackend> backend = scene_backend(scene, options);
  const std::string backend_name = backend->name();
  Simulation sim(scene, std::move(backend));

  const std::unique_ptr<OutputLock> lock = prepare_output_directory(dir);
  std::unique_ptr<FrameWriter> frame_writer;
  if (want_frames && frames) frame_writer = frames(scene);
  if (want_frames && !frame_writer)
    std::fprintf(stderr, "odemag run: this build has no renderer; writing state without frames\n");

  StreamedFile state_file((dir / "state.jsonl").string());
  Progress progress(settings.duration, quiet);
  const auto started = std::chrono::steady_clock::now();
  int frame = 0;
  double next_frame_time = 0.0;
  auto emit_frame = [&] {
    state_file.append(state_line(sim, frame).dump() + "\n");
    if (frame_writer) frame_writer->write(sim, (dir / frame_name(frame)).string());
    ++frame;
    next_frame_time = frame / settings.frame_rate;
  };
  sim.magnetics().compute();  // frame 0 shows the relaxed initial magnetization
  emit_frame();
  size_t notices_shown = 0;
  while (sim.time() + 0.5 * settings.time_step < settings.duration) {
    sim.step();
    check_finite(sim);
    for (; notices_shown < sim.notices().size(); ++notices_shown)
      std::fprintf(stderr, "odemag run: %s\n", sim.notices()[notices_shown].c_str());
    if (sim.time() + 0.5 * settings.time_step >= next_frame_time) {
      emit_frame();
    } else if (c.state_every_step) {
      state_file.append(state_line(sim, -1).dump() + "\n");
    }
    progress.update(sim);
  }
  sim.finish();
  state_file.finish();
  progress.update(sim, true);
  if (c.video) encode_video(ffmpeg, dir, *c.video, settings.frame_rate);  // before summary.json: a finished run

  // summary.json: the cost of every rigid step and the scene's outcomes
  // (summary_figures() lists its numbers for sweeps: keep the two together).
  std::vector<double> tm, tr, iterations, substeps, held, rezoned;
  long not_converged = 0, skipped = 0;
  for (const StepReport& r : sim.records()) {
    tm.push_back(r.magnetic_ms);
    tr.push_back(r.rigid_ms);
    iterations.push_back(r.iterations);
    substeps.push_back(r.substeps);
    held.push_back(r.held);
    rezoned.push_back(r.rezoned);
    if (!r.converged) ++not_converged;
    skipped += r.skipped;
  }
  const MagneticModel& model = sim.magnetics().model();
  json outcomes = json::object();
  for (const auto& [name, value] : sim.outcomes()) outcomes[name] = value;
  json summary = {
      {"scene", scene.file},
      {"title", scene.title},
      {"backend", backend_name},
      {"bodies", model.body_count()},
      {"cells", model.cell_count()},
      {"responsive_cells", model.responsive_cell_count()},
      {"time_step", settings.time_step},
      {"duration", sim.time()},
      {"steps", sim.steps()},
      {"frames", frame},
      {"frames_written", frame_writer != nullptr},
      {"wall_seconds",
       std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count()},
      {"magnetic_ms", statistics(tm)},
      {"rigid_ms", statistics(tr)},
      {"iterations", statistics(iterations)},
      {"substeps", statistics(substeps)},  // one relaxation per substep
      // bodies held over a step's later substeps (magnetic_solve "moving")
      {"held", statistics(held)},
      // bodies whose refined contact zones moved to their contacts (solver.contact_refinement)
      {"rezoned", statistics(rezoned)},
      {"steps_not_converged", not_converged},
      {"magnetic_steps_skipped", skipped},  // substeps, with solver.skip_unchanged
      // substeps QuickStep took instead
      {"exact_solver_failures", sim.world().exact_solver_failures()},
      {"outcomes", outcomes},
      {"notices", sim.notices()},  // as printed while running (Simulation::notices)
  };
  if (const long failures = sim.world().exact_solver_failures(); failures > 0)
    std::fprintf(stderr,
                 "odemag: ODE's exact contact solver failed in %ld substep%s (last: %s); QuickStep took %s "
                 "(docs/simulation.md \"Contacts\")\n",
                 failures, failures == 1 ? "" : "s", sim.world().last_exact_solver_failure().c_str(),
                 failures == 1 ? "it" : "them");
  if (c.video) summary["video"] = *c.video;
  write_file_atomically((dir / "summary.json").string(), summary.dump(2) + "\n");
  return 0;
}

}  // namespace odemag::cli
