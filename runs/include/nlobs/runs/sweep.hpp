#pragma once
// One sweep over any key of a scenario, below any program (`nlobs run --sweep KEY=v1,v2,…` prints
// and writes what it returns):
//   an observer key — each observer of the scenario whose type takes the key is given each
//     value (θ of the high-gain observers, the horizon or sample period of the modulating ones,
//     any key of a plugin's type) and run on the prepared data; sample_period, a mode switch,
//     only where it is on;
//   otherwise a parameter of the scenario's model, simulated again for each value (the same
//     noise draws: the seed is the scenario's).
// Every value's run counts its metrics "after" the same sample: the scenario's settle index
// (0 without one) and, for the key `horizon` (a window length in seconds), past the longest
// value's window.
#include <cstddef>
#include <string>
#include <vector>

#include "nlobs/observers/core/simulation.hpp"
#include "nlobs/runs/scenario_run.hpp"

namespace nlobs {

struct SweepSettings {
  // Run only the observers given the value (an observer key): the others' rows would repeat
  // for every value.
  bool only_swept_observers = false;
  // How the messages name the sweep ("sweep theta = 0.1: …"; `nlobs run` says "--sweep").
  std::string label = "sweep";
};

struct SweepValue {
  double value = 0.0;
  RunResult result;  // names made unique, coordinate errors added (run_metrics.hpp)
  std::vector<long> horizon_indices;  // per observer run, its window less one
  // The papers' figures of each observer run (run_metrics.hpp: the embedded and canonical
  // errors, the MVT's residual), computed once with the run: a table reads them.
  std::vector<ObserverFigures> figures;
};

struct SweepRun {
  std::string key;
  // The key is the model's — a parameter, or `substeps` of its discretisation — and every value
  // simulated again; else the observers'.
  bool model_parameter = false;
  std::vector<std::size_t> swept;  // scenario indices of the observers given the value
  std::vector<std::size_t> run;    // scenario indices of the observers run, in result order
  long settle_index = 0;           // the first sample every value's "after" metrics count
  std::vector<SweepValue> values;  // in the order given
};

// Throws std::invalid_argument naming the key (and the value, "LABEL KEY = v: …", for what one
// value's run refuses): no values, a value that is not finite, data without the truth (a sweep
// compares with it), a key that no observer takes and the model has no parameter of; and
// std::runtime_error when a re-simulation leaves the model's domain.
SweepRun run_sweep(const PreparedScenario& prepared, const std::string& key,
                   const std::vector<double>& values, const SweepSettings& settings = {});

}  // namespace nlobs
