// The CPU backend's threads on a shared machine (magnetics/relax/threads.h):
// the default count from the cores allowed and the cgroup quota, and
// OMP_NUM_THREADS over both.
#include "magnetics/relax/threads.h"

#include <gtest/gtest.h>
#include <sched.h>

#include <cstdlib>

namespace odemag {
namespace {

TEST(Threads, CgroupQuotaCapsTheCoresAllowed) {
  EXPECT_EQ(thread_count_within_quota(16, ""), 16);               // no cgroup quota file
  EXPECT_EQ(thread_count_within_quota(16, "max 100000\n"), 16);   // no quota
  EXPECT_EQ(thread_count_within_quota(16, "200000 100000\n"), 2);  // two cores' worth
  EXPECT_EQ(thread_count_within_quota(16, "150000 100000"), 2);   // rounded up
  EXPECT_EQ(thread_count_within_quota(16, "50000 100000"), 1);
  EXPECT_EQ(thread_count_within_quota(2, "800000 100000"), 2);    // the affinity mask is smaller
  EXPECT_EQ(thread_count_within_quota(0, "garbage"), 1);
}

TEST(Threads, DefaultCountIsTheAffinityOrOmpNumThreads) {
  const char* saved = std::getenv("OMP_NUM_THREADS");
  const std::string before = saved ? saved : "";
  unsetenv("OMP_NUM_THREADS");
  cpu_set_t set;
  CPU_ZERO(&set);
  ASSERT_EQ(sched_getaffinity(0, sizeof set, &set), 0);
  EXPECT_GE(default_thread_count(), 1);
  EXPECT_LE(default_thread_count(), CPU_COUNT(&set));
  setenv("OMP_NUM_THREADS", "3", 1);
  EXPECT_EQ(default_thread_count(), 3);
  setenv("OMP_NUM_THREADS", "5,2", 1);  // nested levels: the first
  EXPECT_EQ(default_thread_count(), 5);
  if (saved)
    setenv("OMP_NUM_THREADS", before.c_str(), 1);
  else
    unsetenv("OMP_NUM_THREADS");
}

}  // namespace
}  // namespace odemag
