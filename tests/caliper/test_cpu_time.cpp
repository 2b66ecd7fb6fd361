// caliper::thread_cpu_seconds(): the calling thread's CPU time, which grows while it works and
// not while it sleeps.
#include <chrono>
#include <cmath>
#include <thread>

#include <gtest/gtest.h>

#include "caliper/cpu_time.hpp"

namespace {

// Sleeping costs (almost) no CPU; the bound allows the wake-up's bookkeeping on a loaded machine.
constexpr double kSleepCpuAllowance = 0.05;  // s

TEST(CpuTime, GrowsWhileWorkingNotWhileSleeping) {
  const double t0 = caliper::thread_cpu_seconds();
  volatile double sink = 0.0;
  while (caliper::thread_cpu_seconds() - t0 < 0.02) sink = sink + std::sqrt(sink + 1.0);
  const double t1 = caliper::thread_cpu_seconds();
  EXPECT_GE(t1 - t0, 0.02);
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  const double t2 = caliper::thread_cpu_seconds();
  EXPECT_GE(t2, t1);
  EXPECT_LT(t2 - t1, kSleepCpuAllowance);
}

}  // namespace
