// The benchmarks' entry point: LibTorch's operations get as many threads as OpenMP's kernels, as
// in the iesrgs binary (LibTorch's own default is one thread with Debian's build, and its first
// operation on a thread would set OpenMP's count to that too). OMP_NUM_THREADS limits both.
#include <benchmark/benchmark.h>
#include <omp.h>
#include <torch/torch.h>

int main(int argc, char** argv) {
  torch::set_num_threads(omp_get_max_threads());
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
