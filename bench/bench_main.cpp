// Runs the benchmarks, then prints the ratios the foundation issue states as goals:
//   picard_overhead = t(Picard solve) / (iterations × t(one G evaluation))   goal ≤ 1.2
//   speedup         = t(KINSOL strategy) / t(our engine)                        goal ≥ 3
// Measured, not asserted: the numbers are reported, whatever they are.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <map>
#include <string>
#include <vector>

namespace {

struct Collector : benchmark::ConsoleReporter {
  struct Entry {
    double ns = 0.0, iterations = 0.0, evaluations = 0.0;
  };
  std::map<std::string, Entry> results;

  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& r : runs) {
      if (r.run_type != Run::RT_Iteration || r.error_occurred) continue;
      Entry e;
      e.ns = r.GetAdjustedRealTime();  // default time unit: ns
      auto it = r.counters.find("iterations");
      if (it != r.counters.end()) e.iterations = it->second.value;
      it = r.counters.find("evaluations");
      if (it != r.counters.end()) e.evaluations = it->second.value;
      results[r.benchmark_name()] = e;
    }
  }
};

void ratio(const Collector& c, const char* ours, const char* theirs) {
  auto a = c.results.find(ours), b = c.results.find(theirs);
  if (a == c.results.end() || b == c.results.end()) return;
  std::printf("  %-22s vs %-14s %7.0f ns vs %8.0f ns  speedup %5.2fx  (iterations %g vs %g)\n",
              ours, theirs, a->second.ns, b->second.ns, b->second.ns / a->second.ns,
              a->second.iterations, b->second.iterations);
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  Collector collector;
  benchmark::RunSpecifiedBenchmarks(&collector);
  benchmark::Shutdown();

  const auto g_free = collector.results.find("BM_ChuaG");
  const auto chain = collector.results.find("BM_ChuaGChain");
  const auto picard = collector.results.find("BM_Picard");
  if (chain == collector.results.end() || g_free == collector.results.end() ||
      picard == collector.results.end()) {
    return 0;
  }
  std::printf("\nmodified-Chua window, tol 1e-5\n");
  const double g_chained = chain->second.ns / chain->second.evaluations;
  std::printf("  one G evaluation: %.1f ns in a dependent chain w <- G(w), %.1f ns independent\n",
              g_chained, g_free->second.ns);
  std::printf("  Picard: %.0f ns for %g iterations (%g evaluations)\n", picard->second.ns,
              picard->second.iterations, picard->second.evaluations);
  std::printf("  picard_overhead = t(solve) / (iterations x t(G chained)) = %.3f   (goal <= 1.2)\n",
              picard->second.ns / (picard->second.iterations * g_chained));
  std::printf(
      "  against independent G evaluations (throughput, unreachable for an iteration): %.3f\n",
      picard->second.ns / (picard->second.iterations * g_free->second.ns));
  std::printf("speedup over the KINSOL strategy doing the same iterations (goal >= 3):\n");
  ratio(collector, "BM_Picard", "BM_Kinsol/0");
  ratio(collector, "BM_Aitken", "BM_Kinsol/0");
  ratio(collector, "BM_Steffensen", "BM_Kinsol/0");
  ratio(collector, "BM_Anderson/2", "BM_Kinsol/1");
  ratio(collector, "BM_Anderson/3", "BM_Kinsol/1");
  ratio(collector, "BM_Newton/0", "BM_Kinsol/2");
  ratio(collector, "BM_Newton/1", "BM_Kinsol/2");

  auto ns = [&](const char* name) {
    const auto it = collector.results.find(name);
    return it == collector.results.end() ? 0.0 : it->second.ns;
  };
  if (ns("BM_CeresTinySolver") > 0 && ns("BM_CeresPreparedProblem") > 0) {
    std::printf("\nCeres on the 6-output Chua window (m = 6, n = 3):\n");
    std::printf(
        "  TinySolver %.0f ns, prepared ceres::Problem %.0f ns, Problem per solve %.0f ns\n",
        ns("BM_CeresTinySolver"), ns("BM_CeresPreparedProblem"), ns("BM_CeresProblemPerSolve"));
  }
  if (ns("BM_NloptKeptOpt") > 0) {
    std::printf(
        "NLopt LD_SLSQP, 3-D bounded quadratic: opt kept %.0f ns, rebuilt per solve %.0f ns\n",
        ns("BM_NloptKeptOpt"), ns("BM_NloptOptPerSolve"));
  }
  return 0;
}
