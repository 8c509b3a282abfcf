// Event queues of the event-driven engine (src/edm/event_queue.hpp): tournament tree against binary heap with
// handles, on the access pattern of the engine: take the earliest slot, give it a new time a little later, and
// re-predict one other slot (the collision partner). Times per slot are exponential with mean 1 (the mean time
// between a particle's events), so the queue holds N times spread over ~1 time unit ahead of "now".
// Result and choice: docs/edm.md.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "core/rng.hpp"
#include "edm/event_queue.hpp"

namespace {

template <class Q>
void queueBench(benchmark::State& state) {
    const auto n = static_cast<std::uint32_t>(state.range(0));
    // Random numbers drawn beforehand, so that only the queue is timed.
    constexpr std::size_t kTable = 1u << 16;
    haet::Rng rng(1, 9001);
    std::vector<double> delays(kTable);
    std::vector<std::uint32_t> partners(kTable);
    for (std::size_t k = 0; k < kTable; ++k) {
        delays[k] = -std::log(1.0 - rng.uniform());
        partners[k] = static_cast<std::uint32_t>(rng.bits() % n);
    }
    Q q;
    q.reset(n);
    std::size_t k = 0;
    for (std::uint32_t i = 0; i < n; ++i) q.update(i, delays[k++ % kTable]);
    for (auto _ : state) {
        const std::uint32_t i = q.top();
        const double now = q.topTime();
        q.update(i, now + delays[k % kTable]);
        q.update(partners[k % kTable], now + delays[(k + 7) % kTable]);
        ++k;
        benchmark::DoNotOptimize(q.top());
    }
    state.SetItemsProcessed(state.iterations());  // one item = one event (two updates and a top)
}

void tree(benchmark::State& s) { queueBench<haet::EventTree>(s); }
void heap(benchmark::State& s) { queueBench<haet::EventHeap>(s); }
void calendar(benchmark::State& s) { queueBench<haet::EventCalendar>(s); }

BENCHMARK(tree)->Name("EdmQueue/tree")->RangeMultiplier(10)->Range(1000, 1000000);
BENCHMARK(heap)->Name("EdmQueue/heap")->RangeMultiplier(10)->Range(1000, 1000000);
BENCHMARK(calendar)->Name("EdmQueue/calendar")->RangeMultiplier(10)->Range(1000, 1000000);

}  // namespace

// haet_bench links benchmark::benchmark, not benchmark_main: this weak main gives way to a main in any other
// bench/*.cpp file.
__attribute__((weak)) int main(int argc, char** argv) {
    ::benchmark::Initialize(&argc, argv);
    if (::benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    ::benchmark::RunSpecifiedBenchmarks();
    ::benchmark::Shutdown();
    return 0;
}
