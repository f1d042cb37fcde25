// python/bench/bench_predict.cpp -- the C++ side of the Python module's overhead (docs/python.md): the
// library calls that vrelab.predict_total_g and vrelab.predict make, on a case read once.
// Usage: build/vrelab_bench_python [CASE]  (default cases/paper-predict.toml)
#include <benchmark/benchmark.h>

#include <string>

#include "io/formats/case_file.hpp"
#include "io/services/results_json.hpp"
#include "io/services/studies.hpp"

namespace {

std::string g_case = "cases/paper-predict.toml";

void BM_predict_terms(benchmark::State& state) {
  const vrelab::io::Case c = vrelab::io::read_case(g_case);
  for (auto _ : state) benchmark::DoNotOptimize(vrelab::io::predict_terms(c).total_g());
}
BENCHMARK(BM_predict_terms);

void BM_predict_study(benchmark::State& state) {
  const vrelab::io::Case c = vrelab::io::read_case(g_case);
  for (auto _ : state) {
    vrelab::io::PredictStudy s = vrelab::io::predict(c, false);
    benchmark::DoNotOptimize(s);
  }
}
BENCHMARK(BM_predict_study);

// What to_dict() adds on the C++ side: the CLI's JSON of the result.
void BM_predict_json(benchmark::State& state) {
  const vrelab::io::Case c = vrelab::io::read_case(g_case);
  const vrelab::io::PredictStudy s = vrelab::io::predict(c, false);
  for (auto _ : state) benchmark::DoNotOptimize(vrelab::io::predict_json(c, s));
}
BENCHMARK(BM_predict_json);

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (argc > 1) g_case = argv[1];
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
