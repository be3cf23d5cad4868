// `odemag sweep SPEC --out DIR`: the variants of a sweep spec
// (engine/scene/sweep.h), each run as `odemag run` would into
// DIR/variants/NNNN, and one table DIR/results.csv (docs/sweeps.md).
//
// Every runner goes through the same steps: --expand (the variant scenes and
// DIR/variants.json), --variant I (run one, in this process), --gather (the
// table). The local runner starts `odemag sweep SPEC --out DIR --variant I`
// child processes, --jobs at a time: a variant that crashes or runs out of
// memory takes only itself down, and Dask and Slurm run exactly what it runs.
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "cli/cli.h"
#include "engine/scene/sweep.h"

#ifndef ODEMAG_PYTHON_DIR
#error "ODEMAG_PYTHON_DIR (the folder of the odemag Python package) is set by cli/CMakeLists.txt"
#endif

namespace odemag::cli {

namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

// The step flags take no value (`--expand`), unlike every other option.
bool take_flag(std::vector<std::string>& args, const std::string& flag) {
  for (size_t i = 0; i < args.size() && args[i] != "--"; ++i)
    if (args[i] == flag) {
      args.erase(args.begin() + static_cast<long>(i));
      return true;
    }
  return false;
}

}  // namespace

SweepCommandLine parse_sweep_command(std::vector<std::string> args) {
  SweepCommandLine c;
  std::vector<SweepCommandLine::Mode> modes;
  for (const auto& [flag, mode] : {std::pair{"--expand", SweepCommandLine::Mode::expand},
                                   {"--gather", SweepCommandLine::Mode::gather},
                                   {"--slurm", SweepCommandLine::Mode::slurm}})
    if (take_flag(args, flag)) modes.push_back(mode);
  const Arguments a = parse_arguments("sweep", args, {"out", "jobs", "variant", "dask", "quiet"});
  if (a.positional.size() != 1) throw UsageError("'sweep' needs one spec file: odemag sweep SPEC --out DIR (see odemag --help)");
  c.spec = a.positional[0];
  const auto out = a.option("out");
  if (!out || out->empty()) throw UsageError("'sweep' needs --out DIR (see odemag --help)");
  c.out = *out;
  auto whole = [](const std::string& name, const std::string& v, long lo, long hi) {
    char* end = nullptr;
    errno = 0;
    const long n = std::strtol(v.c_str(), &end, 10);
    if (v.empty() || *end != '\0' || errno != 0 || n < lo || n > hi)
      throw UsageError("--" + name + ": expected an integer from " + std::to_string(lo) + " to " +
                       std::to_string(hi) + ", got '" + v + "'");
    return n;
  };
  if (const auto v = a.option("variant")) {
    modes.push_back(SweepCommandLine::Mode::variant);
    c.variant = static_cast<size_t>(whole("variant", *v, 0, 999999));
  }
  if (const auto d = a.option("dask")) {
    if (d->empty()) throw UsageError("--dask: expected local, local:N or a scheduler address");
    if (d->rfind("local:", 0) == 0) whole("dask local:N", d->substr(6), 1, 1024);
    modes.push_back(SweepCommandLine::Mode::dask);
    c.dask = *d;
  }
  if (modes.size() > 1) throw UsageError("'sweep': give at most one of --expand, --variant, --gather, --dask, --slurm");
  if (!modes.empty()) c.mode = modes[0];
  const unsigned cores = std::thread::hardware_concurrency();
  c.jobs = static_cast<int>(cores ? cores : 1);
  if (const auto j = a.option("jobs")) {
    if (c.mode != SweepCommandLine::Mode::local) throw UsageError("--jobs is for the local runner only");
    c.jobs = static_cast<int>(whole("jobs", *j, 1, 1024));
  }
  if (const auto q = a.option("quiet")) {
    if (*q != "yes" && *q != "no") throw UsageError("--quiet: expected yes or no, got '" + *q + "'");
    c.quiet = *q == "yes";
  }
  return c;
}

namespace {

std::string file_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

bool has_option(const std::vector<std::string>& args, const std::string& name) {
  for (const std::string& a : args)
    if (a == "--" + name || a.rfind("--" + name + "=", 0) == 0) return true;
  return false;
}

// A spec checked beyond what the scene layer knows: the figures to collect
// and the `odemag run` arguments of every variant.
struct CheckedSweep {
  Sweep sweep;
  std::vector<std::string> run_args;  // after SCENE --out DIR
};

CheckedSweep load_sweep(const std::string& spec) {
  CheckedSweep c{Sweep::load(spec), {}};
  const Sweep& s = c.sweep;
  for (size_t i = 0; i < s.collect().size(); ++i) {
    const std::string& name = s.collect()[i];
    bool known = false;
    for (const OutcomeDescription& o : s.base().outcomes) known = known || o.name == name;
    for (const std::string& f : summary_figures()) known = known || f == name;
    if (!known) {
      std::string outcomes;
      for (const OutcomeDescription& o : s.base().outcomes) outcomes += (outcomes.empty() ? "" : ", ") + o.name;
      throw SceneError(spec, "collect[" + std::to_string(i) + "]",
                       "unknown figure '" + name + "': neither an outcome of " + s.scene_file() + " (" +
                           (outcomes.empty() ? "none" : outcomes) +
                           ") nor a summary figure (steps, duration, wall_seconds, magnetic_ms.mean, ...; "
                           "docs/sweeps.md)");
    }
  }
  c.run_args = s.run_arguments();
  for (const char* forbidden : {"out", "video"})
    if (has_option(c.run_args, forbidden))
      throw SceneError(spec, "run", std::string("--") + forbidden + " is set by the sweep, not in run");
  if (!has_option(c.run_args, "frames")) c.run_args.insert(c.run_args.end(), {"--frames", "no"});
  if (!has_option(c.run_args, "quiet")) c.run_args.insert(c.run_args.end(), {"--quiet", "yes"});
  if (!has_option(c.run_args, "threads")) c.run_args.insert(c.run_args.end(), {"--threads", "1"});
  std::vector<std::string> probe = {"scene.json", "--out", "DIR"};
  probe.insert(probe.end(), c.run_args.begin(), c.run_args.end());
  try {
    parse_run_command(probe);
  } catch (const UsageError& e) {
    throw SceneError(spec, "run", e.what());
  }
  return c;
}

std::string variant_name(size_t i, size_t count) {
  std::string digits = std::to_string(i);
  const size_t width = std::max<size_t>(4, std::to_string(count ? count - 1 : 0).size());
  return std::string(width - std::min(width, digits.size()), '0') + digits;
}

fs::path variant_dir(const SweepCommandLine& c, size_t i, size_t count) {
  return fs::path(c.out) / "variants" / variant_name(i, count);
}

// What a finished variant's summary must carry to be reused: FNV-1a (64 bit)
// of the variant scene and its run arguments.
std::string variant_hash(const SweepVariant& v, const std::vector<std::string>& run_args) {
  std::string text = v.scene_json;
  for (const std::string& a : run_args) text += '\0' + a;
  uint64_t h = 14695981039346656037ull;
  for (unsigned char ch : text) h = (h ^ ch) * 1099511628211ull;
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

// The variant's summary.json when it is there, parses, and was written for
// this scene and these arguments.
std::optional<json> finished_summary(const fs::path& dir, const std::string& hash) {
  std::error_code ec;
  if (!fs::is_regular_file(dir / "summary.json", ec)) return std::nullopt;
  const json s = json::parse(file_text(dir / "summary.json"), nullptr, false);
  if (!s.is_object() || !s.contains("sweep") || !s["sweep"].is_object() || s["sweep"].value("hash", "") != hash)
    return std::nullopt;
  return s;
}

// Writes the variant's scene.json unless it already holds this text (a
// resumed sweep leaves finished variants untouched).
void write_variant_scene(const fs::path& dir, const SweepVariant& v) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw std::runtime_error("cannot create " + dir.string() + ": " + ec.message());
  if (fs::is_regular_file(dir / "scene.json", ec) && file_text(dir / "scene.json") == v.scene_json) return;
  write_file_atomically((dir / "scene.json").string(), v.scene_json);
}

std::string csv_cell(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string q = "\"";
  for (char ch : s) q += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return q + "\"";
}

std::string csv_line(const std::vector<std::string>& cells) {
  std::string line;
  for (size_t i = 0; i < cells.size(); ++i) {
    if (i) line += ',';
    line += csv_cell(cells[i]);
  }
  return line + "\n";
}

std::vector<std::string> csv_header(const Sweep& s) {
  std::vector<std::string> h = {"variant"};
  h.insert(h.end(), s.columns().begin(), s.columns().end());
  h.insert(h.end(), s.collect().begin(), s.collect().end());
  h.push_back("status");
  return h;
}

// One row: the index, the overrides (empty where a variant keeps the base
// value), the collected figures (an outcome of that name first, else the
// summary's key path), and ok / failed / missing.
std::vector<std::string> csv_row(const Sweep& s, const SweepVariant& v, const std::optional<json>& summary,
                                 const std::string& status) {
  std::vector<std::string> row = {std::to_string(v.index)};
  for (const std::string& column : s.columns()) {
    std::string cell;
    for (const auto& [path, value] : v.overrides)
      if (path == column) cell = value;
    if (cell.size() >= 2 && cell.front() == '"') cell = json::parse(cell).get<std::string>();
    row.push_back(cell);
  }
  for (const std::string& name : s.collect()) {
    const json* x = nullptr;
    if (summary) {
      if ((*summary)["outcomes"].contains(name)) {
        x = &(*summary)["outcomes"][name];
      } else {
        std::string pointer = "/" + name;
        for (char& ch : pointer) ch = ch == '.' ? '/' : ch;
        if (summary->contains(json::json_pointer(pointer))) x = &summary->at(json::json_pointer(pointer));
      }
    }
    row.push_back(!x ? "" : x->is_string() ? x->get<std::string>() : x->dump());
  }
  row.push_back(status);
  return row;
}

int run_variant(const SweepCommandLine& c, const CheckedSweep& cs, const FrameWriterFactory& frames) {
  const Sweep& s = cs.sweep;
  if (c.variant >= s.size())
    throw UsageError("--variant " + std::to_string(c.variant) + ": the sweep has " + std::to_string(s.size()) +
                     " variants (0 to " + std::to_string(s.size() - 1) + ")");
  const SweepVariant v = s.variant(c.variant);
  const fs::path dir = variant_dir(c, c.variant, s.size());
  write_variant_scene(dir, v);
  const std::string hash = variant_hash(v, cs.run_args);
  std::optional<json> summary = finished_summary(dir, hash);
  if (!summary) {
    // Run into a folder of its own, then move the results in: summary.json
    // (with the hash) last, so a variant is either finished or not there.
    char host[256] = "host";
    ::gethostname(host, sizeof host - 1);
    const fs::path run = dir / (".run-" + std::string(host) + "-" + std::to_string(::getpid()));
    std::error_code ec;
    fs::remove_all(run, ec);
    std::vector<std::string> args = {(dir / "scene.json").string(), "--out", run.string()};
    args.insert(args.end(), cs.run_args.begin(), cs.run_args.end());
    try {
      run_simulation(args, frames);
      json result = json::parse(file_text(run / "summary.json"));
      json overrides = json::object();
      for (const auto& [path, value] : v.overrides) overrides[path] = json::parse(value);
      result["sweep"] = {{"spec", s.spec_file()}, {"variant", v.index}, {"hash", hash}, {"overrides", overrides}};
      for (const fs::directory_entry& e : fs::directory_iterator(run))  // state.jsonl, frames with --frames yes
        if (e.path().filename() != "summary.json") fs::rename(e.path(), dir / e.path().filename());
      write_file_atomically((dir / "summary.json").string(), result.dump(2) + "\n");
      summary = result;
    } catch (const std::exception& e) {
      write_file_atomically((dir / "error.txt").string(), one_line(e.what()) + "\n");
      fs::remove_all(run, ec);
      throw;
    }
    fs::remove(dir / "error.txt", ec);
    fs::remove_all(run, ec);
  }
  write_stdout(csv_line(csv_row(s, v, summary, "ok")));
  return 0;
}

// DIR/variants/NNNN/scene.json for every variant and DIR/variants.json, the
// list the Dask runner reads.
void expand(const SweepCommandLine& c, const CheckedSweep& cs) {
  const Sweep& s = cs.sweep;
  for (size_t i = 0; i < s.size(); ++i) s.variant(i);  // every variant valid before anything is written
  json list = json::array();
  for (size_t i = 0; i < s.size(); ++i) {
    const SweepVariant v = s.variant(i);
    write_variant_scene(variant_dir(c, i, s.size()), v);
    json overrides = json::object();
    for (const auto& [path, value] : v.overrides) overrides[path] = json::parse(value);
    list.push_back({{"index", i},
                    {"dir", "variants/" + variant_name(i, s.size())},
                    {"hash", variant_hash(v, cs.run_args)},
                    {"overrides", overrides}});
  }
  const json doc = {{"spec", s.spec_file()},   {"scene", s.scene_file()}, {"count", s.size()},
                    {"columns", s.columns()},  {"collect", s.collect()},  {"run", cs.run_args},
                    {"header", csv_header(s)}, {"variants", list}};
  write_file_atomically((fs::path(c.out) / "variants.json").string(), doc.dump(2) + "\n");
}

// DIR/results.csv from the variants' summaries, written at once. Returns the
// indices of the variants not finished (failed: DIR/variants/NNNN/error.txt).
std::vector<size_t> gather(const SweepCommandLine& c, const CheckedSweep& cs) {
  const Sweep& s = cs.sweep;
  std::string table = csv_line(csv_header(s));
  std::vector<size_t> unfinished;
  for (size_t i = 0; i < s.size(); ++i) {
    const SweepVariant v = s.variant(i);
    const fs::path dir = variant_dir(c, i, s.size());
    const std::optional<json> summary = finished_summary(dir, variant_hash(v, cs.run_args));
    std::error_code ec;
    const std::string status = summary ? "ok" : fs::exists(dir / "error.txt", ec) ? "failed" : "missing";
    if (!summary) unfinished.push_back(i);
    table += csv_line(csv_row(s, v, summary, status));
  }
  write_file_atomically((fs::path(c.out) / "results.csv").string(), table);
  return unfinished;
}

int report(const SweepCommandLine& c, const CheckedSweep& cs, const std::vector<size_t>& unfinished) {
  const fs::path table = fs::path(c.out) / "results.csv";
  if (unfinished.empty()) {
    if (!c.quiet)
      std::fprintf(stderr, "odemag sweep: %zu variants, table %s\n", cs.sweep.size(), table.string().c_str());
    return 0;
  }
  std::string which;
  for (size_t i : unfinished) which += (which.empty() ? "" : ", ") + variant_name(i, cs.sweep.size());
  std::fprintf(stderr, "odemag sweep: %zu of %zu variants did not finish (%s; see error.txt in their folders); table %s\n",
               unfinished.size(), cs.sweep.size(), which.c_str(), table.string().c_str());
  return 1;
}

std::string self_program() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw std::runtime_error("cannot find the odemag program (/proc/self/exe): " + ec.message());
  return self.string();
}

int run_local(const SweepCommandLine& c, const CheckedSweep& cs) {
  const Sweep& s = cs.sweep;
  expand(c, cs);
  std::vector<size_t> pending;
  for (size_t i = 0; i < s.size(); ++i) {
    const fs::path dir = variant_dir(c, i, s.size());
    if (finished_summary(dir, variant_hash(s.variant(i), cs.run_args))) continue;
    pending.push_back(i);
    std::error_code ec;  // the run folders a crashed or killed sweep left behind
    for (const fs::directory_entry& e : fs::directory_iterator(dir, ec))
      if (e.path().filename().string().rfind(".run-", 0) == 0) fs::remove_all(e.path(), ec);
  }
  if (!c.quiet)
    std::fprintf(stderr, "odemag sweep: %zu variants, %zu to run (%zu finished before), %d at a time\n", s.size(),
                 pending.size(), s.size() - pending.size(), c.jobs);
  const std::string self = self_program();
  std::map<pid_t, size_t> running;
  size_t next = 0, done = 0;
  while (next < pending.size() || !running.empty()) {
    while (next < pending.size() && running.size() < static_cast<size_t>(c.jobs)) {
      const size_t i = pending[next++];
      running[start_program(self, {self, "sweep", c.spec, "--out", c.out, "--variant", std::to_string(i)}, true)] = i;
    }
    int raw = 0;
    const pid_t pid = ::waitpid(-1, &raw, 0);
    if (pid < 0) {
      if (errno == EINTR) continue;
      throw std::runtime_error(std::string("waiting for the variants: ") + std::strerror(errno));
    }
    const auto it = running.find(pid);
    if (it == running.end()) continue;
    ++done;
    const bool ok = WIFEXITED(raw) && WEXITSTATUS(raw) == 0;
    if (!c.quiet || !ok)
      std::fprintf(stderr, "odemag sweep: variant %s %s (%zu/%zu)\n", variant_name(it->second, s.size()).c_str(),
                   ok ? "done" : "failed", done, pending.size());
    running.erase(it);
  }
  return report(c, cs, gather(c, cs));
}

// --dask: the Python runner (python/odemag/sweeps.py) with this program.
int run_dask(const SweepCommandLine& c) {
  const char* python_env = std::getenv("ODEMAG_PYTHON");
  const std::string python = python_env && *python_env ? python_env : "/usr/bin/python3";
  const char* old = std::getenv("PYTHONPATH");
  const std::string path = std::string(ODEMAG_PYTHON_DIR) + (old && *old ? ":" + std::string(old) : "");
  ::setenv("PYTHONPATH", path.c_str(), 1);
  std::vector<std::string> args = {python, "-m", "odemag.sweeps", c.spec, "--out", c.out, "--dask", c.dask,
                                   "--odemag", self_program()};
  if (c.quiet) args.push_back("--quiet");
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::fflush(nullptr);
  ::execv(python.c_str(), argv.data());
  throw std::runtime_error("cannot run " + python + " for --dask: " + std::strerror(errno) +
                           " (set ODEMAG_PYTHON to a Python with python3-distributed)");
}

// --slurm: a job-array script (one task per variant) and a gather script.
int write_slurm(const SweepCommandLine& c, const CheckedSweep& cs) {
  const std::string out = fs::absolute(c.out).lexically_normal().string();
  const std::string spec = fs::absolute(c.spec).lexically_normal().string();
  for (const std::string& p : {out, spec})
    if (p.find_first_of("% \t\n'") != std::string::npos)
      throw UsageError("--slurm: the path " + p + " has a space, a quote or '%', which #SBATCH lines cannot hold");
  expand(c, cs);
  const std::string self = self_program(), logs = out + "/slurm";
  std::error_code ec;
  fs::create_directories(logs, ec);
  const std::string command = "'" + self + "' sweep '" + spec + "' --out '" + out + "'";
  const std::string head = "#!/bin/bash\n# Written by odemag sweep --slurm (docs/sweeps.md \"Slurm\").\n";
  write_file_atomically(out + "/sweep.sbatch",
                        head + "#SBATCH --job-name=odemag-sweep\n#SBATCH --array=0-" + std::to_string(cs.sweep.size() - 1) +
                            "\n#SBATCH --ntasks=1\n#SBATCH --cpus-per-task=1\n#SBATCH --output=" + logs +
                            "/variant-%a.log\nexec " + command + " --variant \"$SLURM_ARRAY_TASK_ID\"\n");
  write_file_atomically(out + "/gather.sbatch", head + "#SBATCH --job-name=odemag-gather\n#SBATCH --ntasks=1\n"
                                                       "#SBATCH --output=" + logs + "/gather.log\nexec " + command +
                                                       " --gather\n");
  write_stdout("jobid=$(sbatch --parsable " + out + "/sweep.sbatch) && sbatch --dependency=afterok:${jobid%%;*} " +
               out + "/gather.sbatch\n");
  return 0;
}

// --out checked before anything is written, as `odemag run` checks its own
// (exit 2): a folder, or a path that can be made one (its nearest existing
// ancestor a writable folder); --gather reads what the other steps wrote there,
// so its folder must exist.
void check_sweep_output(const SweepCommandLine& c) {
  std::error_code ec;
  const fs::path out = fs::absolute(c.out, ec).lexically_normal();
  const std::string where = "--out " + c.out + ": ";
  if (fs::exists(fs::status(out, ec))) {
    if (!fs::is_directory(out, ec)) throw UsageError(where + "exists and is not a directory");
    if (::access(out.c_str(), W_OK) != 0) throw UsageError(where + "the directory is not writable");
    return;
  }
  if (c.mode == SweepCommandLine::Mode::gather)
    throw UsageError(where + "no such directory (--gather reads the variants that --expand and --variant wrote there)");
  fs::path ancestor = out.parent_path();
  while (!ancestor.empty() && !fs::exists(fs::status(ancestor, ec)) && ancestor != ancestor.root_path())
    ancestor = ancestor.parent_path();
  if (!fs::is_directory(ancestor, ec))
    throw UsageError(where + "cannot be created: " + ancestor.string() + " is not a directory");
  if (::access(ancestor.c_str(), W_OK) != 0)
    throw UsageError(where + "cannot be created: " + ancestor.string() + " is not writable");
}

}  // namespace

int run_sweep(const std::vector<std::string>& args, const FrameWriterFactory& frames) {
  const SweepCommandLine c = parse_sweep_command(args);
  check_sweep_output(c);
  if (c.mode == SweepCommandLine::Mode::dask) {
    load_sweep(c.spec);  // a bad spec is named here, exit 2, before Python starts
    return run_dask(c);
  }
  const CheckedSweep cs = load_sweep(c.spec);
  switch (c.mode) {
    case SweepCommandLine::Mode::expand: expand(c, cs); return 0;
    case SweepCommandLine::Mode::variant: return run_variant(c, cs, frames);
    case SweepCommandLine::Mode::gather: return report(c, cs, gather(c, cs));
    case SweepCommandLine::Mode::slurm: return write_slurm(c, cs);
    default: return run_local(c, cs);
  }
}

}  // namespace odemag::cli
