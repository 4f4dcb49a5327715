#pragma once
// How every benchmark here is timed, and the thread count of those that run on every thread.
#include <benchmark/benchmark.h>
#include <omp.h>

namespace iesrgs {

// Wall-clock milliseconds, with the process's CPU time over all threads beside them.
inline void timed_in_wall_milliseconds(benchmark::internal::Benchmark* b) {
  b->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime();
}

// The argument "threads" (OMP_NUM_THREADS, or every core), timed as above. Each run sets the count
// itself, since an earlier benchmark may have left OpenMP and LibTorch at another.
inline void on_machine_threads(benchmark::internal::Benchmark* b) {
  b->ArgName("threads")->Arg(omp_get_max_threads());
  timed_in_wall_milliseconds(b);
}

}  // namespace iesrgs
