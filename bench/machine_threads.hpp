#pragma once
// For benchmarks that run on every thread: names the count, and sets it for each run, since an
// earlier benchmark may have left OpenMP and LibTorch at another.
#include <benchmark/benchmark.h>
#include <omp.h>

namespace iesrgs {

// The argument "threads" (OMP_NUM_THREADS, or every core), timed in wall-clock milliseconds with
// the process's CPU time over all threads.
inline void on_machine_threads(benchmark::internal::Benchmark* b) {
  b->ArgName("threads")
      ->Arg(omp_get_max_threads())
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime()
      ->MeasureProcessCPUTime();
}

}  // namespace iesrgs
