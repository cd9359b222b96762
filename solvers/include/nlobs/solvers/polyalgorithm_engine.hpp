#pragma once
// A polyalgorithm: engines tried in order within one evaluation budget, each from the start or
// from the best point so far (smallest ‖F‖∞), until one returns a usable answer
// (Summary::usable()). The registry's `auto` is this with the stages of kAutoOrder
// (builtin_engines.hpp), the order measured on the MGH set (docs/solvers.md). Summary::stage names
// the engine whose answer is returned; Summary::message lists how every stage before it ended.
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "nlobs/solvers/engine.hpp"

namespace nlobs {

struct PolyalgorithmOptions {
  // true: a stage starts where the stages before it left the smallest ‖F‖∞; false (default):
  // every stage starts from the caller's x0. Measured on the MGH set, a stage that stagnated
  // often leaves its best point at a local minimum of ‖F‖ that traps the next one (auto solves
  // 52 of 57 runs from the best point, 53 from the start).
  bool restart_from_best = false;
};

template <int N = Dynamic>
class PolyalgorithmEngine : public Engine<N> {
 public:
  // `stages` run in this order; each gets the evaluations (SolverOptions::stop.max_evaluations
  // of this engine) that the stages before it left. At least one stage, none null.
  PolyalgorithmEngine(std::vector<std::unique_ptr<Engine<N>>> stages,
                      PolyalgorithmOptions poly = {}, SolverOptions options = {})
      : Engine<N>(std::move(options)), stages_(std::move(stages)), poly_(poly) {
    if (stages_.empty()) throw InvalidInput("auto: needs at least one engine to try");
    for (const auto& s : stages_) {
      if (!s) throw InvalidInput("auto: a stage engine is null");
    }
  }

  std::string_view name() const override { return "auto"; }
  const std::vector<std::unique_ptr<Engine<N>>>& stages() const { return stages_; }

  Summary solve(const FixedPointProblem<N>& problem, Vector<N>& x) override {
    detail::check_initial_guess(name(), problem, x);
    const int budget = this->options_.stop.max_evaluations;
    const Vector<N> start = x;
    Vector<N> best = x, trial = x;
    double best_residual = std::numeric_limits<double>::infinity();
    Summary best_summary, last;
    bool have_best = false;
    int evaluations = 0, jacobians = 0, iterations = 0;
    std::ostringstream history;
    for (const auto& stage : stages_) {
      const int left = budget - evaluations;
      if (left < 1) break;
      stage->limit_evaluations(left);
      trial = poly_.restart_from_best && have_best ? best : start;
      last = stage->solve(problem, trial);
      evaluations += last.function_evaluations;
      jacobians += last.jacobian_evaluations;
      iterations += last.iterations;
      last.stage = stage->label();
      if (last.usable()) {
        best = trial;
        best_summary = std::move(last);
        have_best = true;
        break;
      }
      if (history.tellp() > 0) history << "; ";
      history << stage->label() << ' ' << to_string(last.status);
      if (!last.message.empty()) history << " (" << last.message << ')';
      // The best point so far: finite, with the smallest residual any stage returned.
      if (trial.allFinite() && last.residual_norm < best_residual) {
        best_residual = last.residual_norm;
        best = trial;
        best_summary = last;
        have_best = true;
      }
    }
    Summary s = have_best ? std::move(best_summary) : std::move(last);
    if (!have_best) {
      best = start;
      if (s.stage.empty()) s.status = Status::kMaxEvaluations;
    }
    // A failed run reports the budget when it ran out, else the best stage's own status.
    if (!s.usable() && evaluations >= budget) s.status = Status::kMaxEvaluations;
    const std::string before = history.str();
    if (!before.empty()) {
      s.message = s.usable() ? "after " + before : before;
    }
    s.engine = name();
    s.function_evaluations = evaluations;
    s.jacobian_evaluations = jacobians;
    s.iterations = iterations;
    x = best;
    s.record_answer(x, this->options_.stop);
    return s;
  }

 private:
  std::vector<std::unique_ptr<Engine<N>>> stages_;
  PolyalgorithmOptions poly_;
};

}  // namespace nlobs
