#pragma once
// Mean wall time of one call, for the CLI tables and the suite (Google Benchmark is for the
// benchmarks proper). `call` must redo its whole work each time (restart from the same guess).
#include <chrono>
#include <limits>

namespace nlobs::reference {

// Calls `call` in doubling batches (1, 2, 4, ...) until at least `min_total_ns` have passed
// and `min_calls` calls were made, or until `max_calls` calls; returns the mean ns per call.
template <typename Call>
double mean_ns_per_call(Call&& call, double min_total_ns, long min_calls = 1,
                        long max_calls = std::numeric_limits<long>::max()) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  long calls = 0, batch = 1;
  double elapsed_ns = 0.0;
  while ((elapsed_ns < min_total_ns || calls < min_calls) && calls < max_calls) {
    for (long i = 0; i < batch && calls < max_calls; ++i, ++calls) call();
    batch *= 2;
    elapsed_ns = std::chrono::duration<double, std::nano>(Clock::now() - start).count();
  }
  return elapsed_ns / static_cast<double>(calls);
}

}  // namespace nlobs::reference
