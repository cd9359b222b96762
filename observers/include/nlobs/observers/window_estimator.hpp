#pragma once
// Window estimator = any engine × any output window (METHODS §1). Once the window of N samples
// is full, at each k it solves for w = x̂[k−N+1] and outputs x̂[k] = f^{N−1}(w*):
//   square window (N·p = n): G(w) = w + (Y − H(w)) with any engine (Picard, Aitken,
//     Steffensen, Anderson, Newton, Ceres, NLopt);
//   longer window (N·p > n): min ½‖Y − H(w)‖² with a least-squares engine (Ceres, NLopt).
// Before the window is full, and at a missing (non-finite) measurement, no window is solved:
// the estimate coasts on the model, x̂[k] = f(x̂[k−1], u[k−1], k−1), starting from the initial
// guess at k = 0; after a missing sample the window refills from scratch.
// Warm start of each solve: the previous solution w* (the paper's choice) or its propagation
// f(w*) to the next window's first sample (measured better; the default, docs/observers.md).
// The engine's Summary of each solve is exposed per step.
#include <memory>
#include <sstream>
#include <string>

#include "nlobs/observers/observer.hpp"
#include "nlobs/observers/output_window.hpp"
#include "nlobs/observers/window_problems.hpp"
#include "nlobs/solvers/engine.hpp"

namespace nlobs {

enum class WarmStart {
  kPrevious,    // w0 = w* of the previous window (the paper)
  kPropagated,  // w0 = f(w*): the previous solution moved to the new window's first sample
};

struct WindowEstimatorOptions {
  Eigen::Index window = 0;  // N; 0 = the square window n / p
  WarmStart warm_start = WarmStart::kPropagated;
};

template <DiscreteModel Model>
class WindowEstimator final : public Observer {
 public:
  static constexpr int N = Model::kStates;
  using State = Vector<N>;

  // Throws InvalidInput for a window that cannot determine the state, an initial guess of the
  // wrong size or not finite, a missing engine, or a square-system engine on a longer window.
  WindowEstimator(Model model, std::unique_ptr<Engine<N>> engine, std::string engine_spec,
                  const State& initial_guess, WindowEstimatorOptions options = {})
      : options_(options),
        engine_(std::move(engine)),
        spec_(std::move(engine_spec)),
        initial_guess_(initial_guess),
        state_(std::make_unique<Shared>(std::move(model), window_length(model, options))) {
    if (!engine_) throw InvalidInput("WindowEstimator: no engine");
    const Eigen::Index n = state_->window.states();
    if (initial_guess_.size() != n || !initial_guess_.allFinite()) {
      std::ostringstream os;
      os << "WindowEstimator: the initial guess must be " << n << " finite numbers";
      throw InvalidInput(os.str());
    }
    square_ = state_->window.rows() == n;
    // Built once; they read the window, which never moves (it lives behind a unique_ptr).
    if (square_) {
      fixed_point_ = std::make_unique<FixedPointProblem<N>>(square_window_problem(state_->window));
    } else {
      require_least_squares_engine();
      root_ = std::make_unique<RootProblem<N, Dynamic>>(window_residual_problem(state_->window));
    }
    reset();
  }

  std::string name() const override {
    return "window:" + spec_ + (square_ ? "" : ",N=" + std::to_string(state_->window.length()));
  }
  // An engine for the first window after each reset only (e.g. one that records its trace for
  // a convergence plot), so that the engine of every other step stays lean.
  void set_first_window_engine(std::unique_ptr<Engine<N>> engine) {
    first_engine_ = std::move(engine);
  }
  std::string engine() const override { return spec_; }
  Eigen::Index window() const override { return state_->window.length(); }
  const OutputWindow<Model>& output_window() const { return state_->window; }
  const WindowEstimatorOptions& options() const { return options_; }

  void reset() override {
    state_->window.clear();
    step_ = ObserverStep{};
    coast_ = initial_guess_;
    history_.assign(static_cast<size_t>(state_->window.length()), initial_guess_);
    have_solution_ = false;
    solved_once_ = false;
  }

  const ObserverStep& step(long k, const Eigen::VectorXd& y, const Eigen::VectorXd& u) override {
    const OutputWindow<Model>& window = state_->window;
    const Eigen::Index length = window.length();
    step_.summary.reset();
    step_.measurement_missing = !y.allFinite();
    if (step_.measurement_missing) {
      state_->window.clear();  // consecutive samples only: refill after the gap
      have_solution_ = false;
    } else {
      state_->window.push(k, y, u);
    }
    step_.ready = window.full();
    bool solved = false;
    if (step_.ready) {
      // Guess for w = x̂[k−N+1]: warm start, or the estimate kept for that sample.
      State w = have_solution_ ? next_guess_ : history_[static_cast<size_t>((k + 1) % length)];
      Engine<N>& engine = (first_engine_ && !solved_once_) ? *first_engine_ : *engine_;
      solved_once_ = true;
      step_.summary =
          square_ ? engine.solve(*fixed_point_, w) : engine.solve_least_squares(*root_, w);
      if (usable(step_.summary->status) && w.allFinite()) {
        solved = have_solution_ = true;
        const State w1 = window.propagate(w, 1);  // x̂[k−N+2]
        next_guess_ = options_.warm_start == WarmStart::kPrevious ? w : w1;
        // x̂[k] = f^{N−1}(w*): w* itself for a one-sample window.
        coast_ = length == 1 ? w : window.propagate(w1, length - 2, 1);
      }
    }
    // Otherwise x̂[k] comes from the model, f(x̂[k−1], u[k−1], k−1), from the guess at k = 0.
    if (!solved && k > 0) {
      coast_ = window.model().f(coast_, typename OutputWindow<Model>::Input(last_u_), k - 1);
    }
    last_u_ = u;
    history_[static_cast<size_t>(k % length)] = coast_;
    step_.estimate = coast_;
    return step_;
  }

 private:
  struct Shared {
    Shared(Model m, Eigen::Index length) : window(std::move(m), length) {}
    OutputWindow<Model> window;
  };

  static Eigen::Index window_length(const Model& model, const WindowEstimatorOptions& o) {
    if (o.window > 0) return o.window;
    const Eigen::Index n = model.states(), p = model.outputs();
    return (n + p - 1) / p;  // the square window when p divides n
  }

  void require_least_squares_engine() const {
    if (engine_->least_squares()) return;
    std::ostringstream os;
    os << "a window of N = " << state_->window.length() << " samples gives "
       << state_->window.rows() << " > " << state_->window.states() << " equations; engine '"
       << spec_ << "' solves square systems only: use ceres or nlopt (or N = n/p)";
    throw InvalidInput(os.str());
  }

  // A solve whose answer is worth using (an iteration cut short still improved the guess).
  static bool usable(Status s) {
    return s == Status::kConverged || s == Status::kMaxIterations || s == Status::kMaxEvaluations ||
           s == Status::kStagnated || s == Status::kRepeatedIterates;
  }

  WindowEstimatorOptions options_;
  std::unique_ptr<Engine<N>> engine_;
  std::string spec_;
  State initial_guess_;
  std::unique_ptr<Shared> state_;
  std::unique_ptr<FixedPointProblem<N>> fixed_point_;
  std::unique_ptr<RootProblem<N, Dynamic>> root_;
  bool square_ = true;
  ObserverStep step_;
  State coast_, next_guess_;
  Eigen::VectorXd last_u_;
  std::vector<State> history_;  // estimates of the last N samples, by k mod N
  bool have_solution_ = false;
  std::unique_ptr<Engine<N>> first_engine_;
  bool solved_once_ = false;
};

}  // namespace nlobs
