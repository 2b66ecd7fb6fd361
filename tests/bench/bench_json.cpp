// parse_json on one object of N keys against the same-sized array of N numbers (the baseline,
// which has no keys to look up). Linear parsing keeps the ratio flat as N grows; a quadratic
// key insertion makes it grow with N (issue 10: 80,000 keys took 67 s).
#include <benchmark/benchmark.h>

#include <string>

#include "caliper/json.hpp"

namespace {

std::string object_text(int n) {
  std::string s = "{";
  for (int i = 0; i < n; ++i)
    s += (i ? ",\"k" : "\"k") + std::to_string(i) + "\":" + std::to_string(i);
  return s + "}";
}

std::string array_text(int n) {
  std::string s = "[";
  for (int i = 0; i < n; ++i)
    s += (i ? ",\"k" : "\"k") + std::to_string(i) + "\"," + std::to_string(i);
  return s + "]";
}

void BM_ParseObjectKeys(benchmark::State& state) {
  const std::string text = object_text(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(caliper::parse_json(text));
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

void BM_ParseArrayBaseline(benchmark::State& state) {
  const std::string text = array_text(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(caliper::parse_json(text));
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

// Looking every key up once: linear overall when find() is O(1).
void BM_FindEveryKey(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const caliper::Json j = caliper::parse_json(object_text(n));
  for (auto _ : state)
    for (int i = 0; i < n; ++i) benchmark::DoNotOptimize(j.find("k" + std::to_string(i)));
  state.SetItemsProcessed(state.iterations() * n);
}

}  // namespace

BENCHMARK(BM_ParseObjectKeys)->Arg(1000)->Arg(10000)->Arg(80000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ParseArrayBaseline)->Arg(1000)->Arg(10000)->Arg(80000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FindEveryKey)->Arg(1000)->Arg(10000)->Arg(80000)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
