#include "magnetics/relax/threads.h"

#include <sched.h>
#include <unistd.h>

#include <omp.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace odemag {

namespace {

std::string file_text(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The cgroup v2 path of this process ("0::/PATH" in /proc/self/cgroup).
std::string cgroup_v2_path() {
  std::istringstream lines(file_text("/proc/self/cgroup"));
  for (std::string line; std::getline(lines, line);)
    if (line.rfind("0::", 0) == 0) return line.substr(3);
  return "";
}

// The cgroup's quota as a cpu.max line: v2's own, or v1's two files.
std::string cpu_max_text() {
  const std::string v2 = file_text("/sys/fs/cgroup" + cgroup_v2_path() + "/cpu.max");
  if (!v2.empty()) return v2;
  const std::string quota = file_text("/sys/fs/cgroup/cpu,cpuacct/cpu.cfs_quota_us");
  const std::string period = file_text("/sys/fs/cgroup/cpu,cpuacct/cpu.cfs_period_us");
  if (quota.empty() || period.empty() || quota.rfind("-1", 0) == 0) return "";
  return quota.substr(0, quota.find('\n')) + " " + period;
}

int affinity_cores() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof set, &set) != 0) return omp_get_num_procs();
  const int n = CPU_COUNT(&set);
  return n > 0 ? n : 1;
}

}  // namespace

int thread_count_within_quota(int cores, const std::string& cpu_max) {
  cores = cores > 0 ? cores : 1;
  std::istringstream in(cpu_max);
  std::string quota;
  double period = 0.0;
  if (!(in >> quota >> period) || quota == "max" || !(period > 0.0)) return cores;
  char* end = nullptr;
  const double q = std::strtod(quota.c_str(), &end);
  if (end == quota.c_str() || !(q > 0.0)) return cores;
  const double allowed = std::ceil(q / period);
  return allowed < cores ? static_cast<int>(allowed) : cores;
}

int default_thread_count() {
  if (const char* set = std::getenv("OMP_NUM_THREADS"); set && *set) {
    char* end = nullptr;
    const long n = std::strtol(set, &end, 10);
    if (end != set && n > 0) return static_cast<int>(n < 65536 ? n : 65536);
  }
  return thread_count_within_quota(affinity_cores(), cpu_max_text());
}

void restart_with_passive_omp_wait(char** argv) {
  if (std::getenv("OMP_WAIT_POLICY")) return;
  if (setenv("OMP_WAIT_POLICY", "passive", 1) != 0) return;
  execv("/proc/self/exe", argv);
  // The program runs on with spinning threads when it cannot be run again.
}

}  // namespace odemag
