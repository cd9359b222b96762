#pragma once
// What a run is judged by beyond the per-state MSE, iterations and failures that run_observers
// measures (observers/core/simulation.hpp): the error in an observer's own coordinates with the
// truth known, and the figures the papers' observers are read by — the embedded high-gain
// observer's peaking ([HG-EMB23]), the modulating-function observer's canonical-state error
// ([MF-LTV]), the MVT's solve residual. Computed from what the observers publish (their
// signals), for any observer that publishes them.
#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "nlobs/observers/core/observer.hpp"
#include "nlobs/observers/core/simulation.hpp"

namespace nlobs {

// Two observers of one name (two `ekf` entries) become "ekf" and "ekf #2" in every report, CSV
// column and plot: otherwise their columns, rows and keys would be indistinguishable.
void make_names_unique(RunResult& r);

// Observers in other coordinates publish their estimate there as signals of kind
// kEmbeddedEstimate (ẑ, high gain) or kCanonicalEstimate (η̂, modulating functions): with the
// truth known, the error in those coordinates (through Observer::coordinates_at) becomes the
// signal "z_error" (kEmbeddedError) or "eta_error" (kCanonicalError, with the true norm
// "eta_norm", kCanonicalNorm). A second call adds nothing.
void add_coordinate_errors(const Measurements& data,
                           const std::vector<std::unique_ptr<Observer>>& observers, RunResult& r);

// run_observers (simulation.hpp) and what the run layer adds to its result, for a run and for
// each value of a sweep alike: names made unique, the coordinate errors above, and into
// `horizon_indices` each observer's window less one (its first sample with a full window).
RunResult measure_observers(const Measurements& data,
                            std::vector<std::unique_ptr<Observer>>& observers, long settle_index,
                            std::vector<long>& horizon_indices,
                            const std::function<void(long done, long total)>& progress = {});

// Per observer with an embedded error signal (kEmbeddedError, add_coordinate_errors): what
// [HG-EMB23]'s figures show.
struct EmbeddedMetrics {
  double max_zhat_norm = 0.0;  // the peaking: max_k ‖ẑ_k‖ over the kEmbeddedEstimate signals
  double final_z_error = NAN;
  double z_rms_after = NAN;
  double max_residual_after = NAN;  // of the kProjectionResidual signal (NaN without one)
  long time_index_below = -1;       // ‖z − ẑ‖ < 1e-6 from here to the end
  double jumps = 0.0;               // the kJumpCount signal's last value (0 without one)
};
std::optional<EmbeddedMetrics> embedded_metrics(const RunResult& r, std::size_t i);

// Per observer with a canonical error signal (kCanonicalError and kCanonicalNorm, added by
// add_coordinate_errors).
struct ModulatingMetrics {
  double rel_after_horizon = NAN;  // max ‖η − η̂‖ / max ‖η‖ over samples from one horizon on
  double abs_after_horizon = NAN;  // the same, absolute (summary: max_eta_error_after_horizon)
  double final_rel = NAN;          // the same over the last 10 % of the run
  double eta_rms_after = NAN;      // RMS of ‖η − η̂‖ from the settle index on
  double max_bound = NAN;          // largest Theorem 1 bound (the kCanonicalBound signal), if any
};
std::optional<ModulatingMetrics> modulating_metrics(const RunResult& r, std::size_t i,
                                                    long horizon_index);

// Observers that publish a per-sample solve residual (kSolveResidual: the MVT's ‖X(β)‖): its
// largest finite value over the run; nothing for other observers.
std::optional<double> max_beta_residual(const RunResult& r, std::size_t i);

// Every figure above for one observer of a run, computed once (run_prepared does): what
// summary.json and `nlobs run`'s tables read, so that printing computes nothing.
struct ObserverFigures {
  // The first sample from which ‖x − x̂‖₂ < 1e-3 to the end; −1: never, or no truth.
  long time_index_below_1e3 = -1;
  std::optional<double> max_beta_residual{};
  std::optional<EmbeddedMetrics> embedded{};
  std::optional<ModulatingMetrics> modulating{};
};
// One per observer of `r` (its metrics' order); `horizon_indices` as measure_observers gives them.
std::vector<ObserverFigures> observer_figures(const Measurements& data, const RunResult& r,
                                              const std::vector<long>& horizon_indices);

}  // namespace nlobs
