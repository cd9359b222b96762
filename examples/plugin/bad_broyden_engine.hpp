#pragma once
// Broyden's second ("bad") method for F(x) = G(x) − x = 0, an engine nlobs does not ship (nlobs'
// `broyden` is the first, "good" one; Broyden, Math. Comp. 19, 1965; Dennis & Schnabel,
// Numerical Methods for Unconstrained Optimization, §8.1): the inverse is updated directly,
//   H_0 = J_F(x_0)⁻¹,  s_k = −t_k H_k F(x_k)  (t_k: nlobs::LineSearch on ‖F‖₂²),
//   H_{k+1} = H_k + (s_k − H_k y_k) y_kᵀ / (y_kᵀ y_k),  y_k = F(x_{k+1}) − F(x_k):  O(n²) per step.
// The Jacobian is computed again (the problem's, or forward differences) when the line search
// finds no decrease along the quasi-Newton direction or the update's denominator vanishes.
// Fixed-size members: a solve at a fixed N allocates nothing.
#include <Eigen/LU>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>

#include "nlobs/solvers/engine.hpp"
#include "nlobs/solvers/engine_spec.hpp"
#include "nlobs/solvers/finite_difference.hpp"
#include "nlobs/solvers/line_search.hpp"
#include "nlobs/solvers/options_validation.hpp"
#include "nlobs/solvers/stop_monitor.hpp"

namespace example {

// The engine's options own their checks and their spec, as nlobs' built-in engines' do
// (bad_broyden_entry.cpp): the registry entry is then nlobs::engine_entry<N, BadBroydenEngine<N>>.
struct BadBroydenOptions {
  int max_backtracks = 10;            // halvings of the step before the Jacobian is renewed; 0..60
  double sufficient_decrease = 1e-4;  // c in ‖F(x + t s)‖² ≤ (1 − 2ct) ‖F(x)‖², in (0, 0.5)

  // Throws nlobs::InvalidInput naming the field, its value and the requirement.
  void validate() const {
    nlobs::require_option(max_backtracks >= 0 && max_backtracks <= 60, "BadBroydenOptions",
                          "max_backtracks", max_backtracks, "must lie in 0..60");
    nlobs::require_option(sufficient_decrease > 0.0 && sufficient_decrease < 0.5,
                          "BadBroydenOptions", "sufficient_decrease", sufficient_decrease,
                          "must lie in (0, 0.5)");
  }
  // The engine as the registry lists it, and the spec's items read over these values (in
  // bad_broyden_entry.cpp: only the registry needs them).
  static nlobs::EngineDescription describe();
  void read(nlobs::EngineSpecReader& spec);
};

template <int N = nlobs::Dynamic>
class BadBroydenEngine final : public nlobs::Engine<N> {
 public:
  using Vec = nlobs::Vector<N>;
  using Mat = nlobs::Matrix<N, N>;

  using Options = BadBroydenOptions;

  explicit BadBroydenEngine(BadBroydenOptions broyden = {}, nlobs::SolverOptions options = {})
      : nlobs::Engine<N>(std::move(options)), broyden_(broyden) {
    broyden_.validate();
    line_search_.sufficient_decrease = broyden_.sufficient_decrease;
    line_search_.max_backtracks = broyden_.max_backtracks;
  }
  std::string_view name() const override { return "bad-broyden"; }

  nlobs::Summary solve(const nlobs::FixedPointProblem<N>& problem, Vec& x) override {
    nlobs::detail::check_initial_guess(name(), problem, x);
    const nlobs::StopCriteria& stop = this->options().stop;
    const nlobs::Index n = x.size();
    if constexpr (N == nlobs::Dynamic) {
      x_.resize(n), g_.resize(n), f_.resize(n), s_.resize(n), xt_.resize(n), ft_.resize(n);
      hy_.resize(n), y_.resize(n), h_.resize(n, n), jac_.resize(n, n), fd_.resize(n);
    }
    nlobs::Summary summary;
    summary.engine = name();
    nlobs::StopMonitor monitor(stop, x.template lpNorm<Eigen::Infinity>(), false);
    int evaluations = 0, jacobians = 0;
    auto residual_at = [&](const Vec& at, Vec& f) {
      problem.evaluate(at, g_);
      ++evaluations;
      nlobs::detail::check_output_size(problem, g_);
      f = g_ - at;
      return f.allFinite();
    };
    // H = J_F(x)⁻¹, or the status to stop with: kMaxEvaluations (differences would exceed the
    // budget), kNonFinite, kSingularJacobian (with the message).
    auto renew_inverse = [&](const char* where) -> std::optional<nlobs::Status> {
      if (problem.has_jacobian()) {
        problem.jacobian(x_, jac_);
      } else {
        if (evaluations + static_cast<int>(n) > stop.max_evaluations) {
          return nlobs::Status::kMaxEvaluations;
        }
        g_ = f_ + x_;
        evaluations += nlobs::finite_difference_jacobian(problem, x_, g_, jac_,
                                                         nlobs::FiniteDifference::kForward, fd_);
      }
      ++jacobians;
      jac_.diagonal().array() -= 1.0;
      if (!jac_.allFinite()) {
        summary.message = std::string("Jacobian of F is not finite ") + where;
        return nlobs::Status::kNonFinite;
      }
      // A pivot below this fraction of the largest |J_ij|: singular, as NewtonEngine judges.
      Eigen::PartialPivLU<Mat> lu(jac_);
      const double smallest_pivot = lu.matrixLU().diagonal().cwiseAbs().minCoeff();
      if (smallest_pivot > 1e-13 * jac_.cwiseAbs().maxCoeff()) {
        h_ = lu.inverse();
        if (h_.allFinite()) return std::nullopt;
      }
      summary.message = std::string("Jacobian of F is singular ") + where;
      return nlobs::Status::kSingularJacobian;
    };

    x_ = x;
    std::optional<nlobs::Status> status;
    if (!residual_at(x_, f_)) status = nlobs::Status::kNonFinite;
    double fnorm = f_.template lpNorm<Eigen::Infinity>();
    if (!status && stop.residual_tolerance && fnorm <= *stop.residual_tolerance) {
      status = nlobs::Status::kConverged;
    }
    bool fresh = false;  // H is the inverse of a Jacobian computed at x_
    if (!status) {
      status = renew_inverse("at the initial guess");
      fresh = !status;
    }
    while (!status) {
      if (evaluations >= stop.max_evaluations) {
        status = nlobs::Status::kMaxEvaluations;
        break;
      }
      s_ = -(h_ * f_);
      const double phi0 = f_.squaredNorm();
      // nlobs' backtracking line search along the engine's own path x + t s.
      LinePath<decltype(residual_at)> path{*this, residual_at, evaluations, stop.max_evaluations,
                                           phi0};
      const nlobs::LineSearch::Result search = line_search_.search(path, 1.0, phi0);
      const double t = search.t;
      if (!search.accepted()) {
        // At a root to rounding, no step decreases |F|: a full Newton step (H fresh, not a
        // stale Broyden update) below the step tolerance is the step criterion met; x stays
        // where |F| is smallest.
        const double full_step = s_.template lpNorm<Eigen::Infinity>();
        if (fresh && stop.step_tolerance && full_step <= *stop.step_tolerance) {
          status = monitor.update(full_step, fnorm, x_.template lpNorm<Eigen::Infinity>());
          if (status) break;
        }
        if (evaluations >= stop.max_evaluations) {
          status = nlobs::Status::kMaxEvaluations;
        } else if (!fresh) {  // a stale H: try again along the Newton direction
          status = renew_inverse("where the line search failed");
          fresh = !status;
          if (fresh) continue;
        } else {
          summary.message = "line search found no decrease of |F| along the Newton direction";
          status = nlobs::Status::kStagnated;
        }
        break;
      }
      s_ *= t;
      y_ = ft_ - f_;  // y = F(x + s) − F(x)
      hy_ = h_ * y_;
      const double denominator = y_.squaredNorm();
      const double step = s_.template lpNorm<Eigen::Infinity>();
      x_ = xt_;
      f_ = ft_;
      fnorm = f_.template lpNorm<Eigen::Infinity>();
      status = monitor.update(step, fnorm, x_.template lpNorm<Eigen::Infinity>());
      if (status) break;
      if (denominator > 0.0 && std::isfinite(denominator)) {
        h_ += ((s_ - hy_) / denominator) * y_.transpose();
        fresh = false;
      } else {
        status = renew_inverse("where the Broyden update broke down");
        fresh = !status;
      }
    }
    x = x_;
    summary.status = *status;
    summary.function_evaluations = evaluations;
    summary.jacobian_evaluations = jacobians;
    monitor.fill(summary, f_.allFinite() ? fnorm : std::numeric_limits<double>::infinity());
    summary.record_answer(x, stop);
    return summary;
  }

 private:
  // The path x + t s for nlobs::LineSearch (line_search.hpp): m = ‖F‖₂², whose first-order
  // change −2t‖F‖₂² is the linear model's (s a quasi-Newton step); the trial in xt_, F in ft_.
  template <typename Residual>
  struct LinePath {
    BadBroydenEngine& engine;
    Residual& residual_at;
    const int& evaluations;
    int max_evaluations;
    double phi0, t = 0.0;
    bool exhausted() const { return evaluations >= max_evaluations; }
    bool move(double step) {
      t = step;
      engine.xt_ = engine.x_ + t * engine.s_;
      return false;
    }
    double slope() const { return -2.0 * t * phi0; }
    double merit() {
      return residual_at(engine.xt_, engine.ft_) ? engine.ft_.squaredNorm()
                                                 : std::numeric_limits<double>::quiet_NaN();
    }
  };

  BadBroydenOptions broyden_;
  nlobs::LineSearch line_search_;  // Armijo, t halved
  Vec x_ = nlobs::zero_vector<N>(), g_ = nlobs::zero_vector<N>(), f_ = nlobs::zero_vector<N>(),
      s_ = nlobs::zero_vector<N>(), xt_ = nlobs::zero_vector<N>(), ft_ = nlobs::zero_vector<N>(),
      hy_ = nlobs::zero_vector<N>(), y_ = nlobs::zero_vector<N>();
  Mat h_, jac_;
  nlobs::FiniteDifferenceWorkspace<N> fd_;
};

}  // namespace example
