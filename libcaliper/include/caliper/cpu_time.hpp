/// \file cpu_time.hpp
/// CPU time of the calling thread, for per-frame and benchmark timings: the machines that run the
/// programs and their benchmarks are shared, so wall time would measure the neighbours as much as
/// the code (docs/performance.md).
#pragma once

namespace caliper {

/// Seconds of CPU time used so far by the calling thread (POSIX CLOCK_THREAD_CPUTIME_ID). Only
/// differences between two calls on the same thread mean anything.
double thread_cpu_seconds();

}  // namespace caliper
