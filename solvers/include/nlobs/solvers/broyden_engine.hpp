#pragma once
// Broyden's "good" method for F(x) = G(x) − x = 0 with a line search and Jacobian restarts
// ([Bro65]; [DS96] §8.1, Algorithm 8.2.1 globalised by backtracking as in [Kel95] §8.3):
//   H_0 = J_F(x_0)⁻¹,  d_k = −H_k F(x_k),  x_{k+1} = x_k + t_k d_k,
//   t_k ∈ {1, ½, ¼, …} the first with ‖F(x_{k+1})‖₂² ≤ (1 − 2c t_k) ‖F(x_k)‖₂²,
//   H_{k+1} = H_k + (s_k − H_k y_k) s_kᵀ H_k / (s_kᵀ H_k y_k),  s_k = x_{k+1} − x_k,
//   y_k = F(x_{k+1}) − F(x_k):
// the Sherman–Morrison form of the rank-one update B_{k+1} = B_k + (y_k − B_k s_k) s_kᵀ/(s_kᵀ s_k)
// of the Jacobian, O(n²) per step against Newton's O(n³) and n (forward) or 2n (central)
// evaluations for a difference Jacobian. A fresh Jacobian (the restart) is taken when the line
// search finds no decrease along a direction of updated H, when the update's denominator
// vanishes, and after max_updates updates (0: never for that reason). A line search that fails
// along the direction of a fresh Jacobian ends the run stagnated.
//
// Bounds (Engine::set_bounds): the trial points are P(x + t d), projected onto the box; when the
// projected path of a fresh Jacobian finds no decrease, the projected steepest-descent path of
// ½‖F‖² is searched from the Cauchy point of the linear model (Armijo on ∇φ = J_Fᵀ F), and a
// point where neither decreases ‖F‖ while a bound holds x against −∇φ is blocked_by_bound.
//
// Stop rules: StopCriteria's, the step criterion on full steps t = 1 that no bound cut short.
//
// Limited memory (run-time size, a problem with a sparse Jacobian: the sparse path). H is never
// formed: H_0 = J_F(x_0)⁻¹ is applied by a sparse direct solver's factors, and the updates are
// kept in product form ([Kel95] §7.3, [DS96] §8.3),
//   H_{k+1} = (I + u_k s_kᵀ) H_k,   u_k = (s_k − H_k y_k) / (s_kᵀ H_k y_k),
// which is the update above (u_k s_kᵀ H_k is its rank-one term), so H_k v costs one solve with
// J_F(x_0) and k dot products and axpys, O(k n). After `memory` updates (two n-vectors each) the
// next step takes a fresh Jacobian: the iterates are the dense path's with max_updates = memory
// (the dense path's default never restarts). Singular J: each linear solver's own pivot rule.
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>

#include "nlobs/solvers/engine.hpp"
#include "nlobs/solvers/engine_spec.hpp"
#include "nlobs/solvers/library_sizes.hpp"
#include "nlobs/solvers/line_search.hpp"
#include "nlobs/solvers/sparse_path.hpp"
#include "nlobs/solvers/square_system.hpp"
#include "nlobs/solvers/stop_monitor.hpp"

namespace nlobs {

struct BroydenOptions {
  int max_backtracks = 10;            // halvings of t before the Jacobian is renewed; 0..60
  double sufficient_decrease = 1e-4;  // c ∈ (0, 0.5) of the test above
  int max_updates = 0;                // updates before a fresh Jacobian regardless; ≥ 0, 0 = off
  // Used only when the problem carries no Jacobian.
  FiniteDifference finite_difference = FiniteDifference::kCentral;
  // The limited-memory form on a problem with a sparse Jacobian (run-time size): H_0 applied by
  // this direct solver — "auto" (band-lu, klu or umfpack by the pattern, as newton chooses),
  // "band-lu", "sparse-lu", "klu", "umfpack[:ordering=…]" — or "dense": the dense path, H n×n.
  // A Krylov solver is refused (H_0 must be applied exactly for the updates to hold).
  std::string linear_solver = "auto";
  // Updates the limited-memory form keeps (2 n doubles each) before a fresh Jacobian; 1..1000.
  int memory = 20;

  // Throws InvalidInput naming the field, its value and the requirement (options_validation.hpp).
  void validate() const;
  // The engine as the registry lists it, the spec keys (field names; older ones as aliases) and
  // their reading over these values (src/options/broyden_options.cpp).
  static EngineDescription describe();
  void read(EngineSpecReader& spec);
};

template <int N = Dynamic>
class BroydenEngine : public Engine<N> {
 public:
  using Options = BroydenOptions;

  explicit BroydenEngine(BroydenOptions broyden = {}, SolverOptions options = {})
      : Engine<N>(std::move(options)), broyden_(broyden) {
    broyden_.validate();
    detail::require_lipschitz_for_error_bound(name(), this->options_.stop);
  }

  std::string_view name() const override { return "broyden"; }
  const BroydenOptions& broyden_options() const { return broyden_; }
  bool accepts_bounds() const override { return true; }
  bool accepts_strict_bounds() const override { return true; }
  bool accepts_scaling() const override { return true; }
  bool has_sparse_path() const override { return broyden_.linear_solver != "dense"; }

  Summary solve(const FixedPointProblem<N>& problem, Vector<N>& x) override;

 private:
  // H = J_F(x_)⁻¹ from a fresh Jacobian (kept in jac_, or factored from sparse_jac_ on the
  // sparse path); nullopt or the status to stop with.
  std::optional<Status> renew(std::string& message);
  // out = H v; nullopt or the status to stop with (the sparse path's solve failed).
  std::optional<Status> apply_inverse(const Vector<N>& v, Vector<N>& out, std::string& message);
  // H ← (I + u sᵀ) H with s = d_, H y = hy_, denominator sᵀ H y; false when the limited-memory
  // store is full (then a fresh Jacobian).
  bool update(double denominator);
  // J_Fᵀ f_ into gradient_ and ‖J_F gradient_‖², at the last fresh Jacobian.
  double gradient_at_jacobian();
  // Backtracking (LineSearch, t halved) from t0 along P(x_ + t d): the sufficient-decrease test
  // above (armijo = false), or Armijo's with the slope from ∇φ = gradient_ (armijo = true).
  // Trial in xt_, ft_; false when none.
  bool search(const Vector<N>& d, double t0, bool armijo);

  BroydenOptions broyden_;
  detail::SquareSystem<N> system_;
  Vector<N> x_ = zero_vector<N>(), f_ = zero_vector<N>(), d_ = zero_vector<N>(),
            xt_ = zero_vector<N>(), ft_ = zero_vector<N>(), hy_ = zero_vector<N>(),
            gradient_ = zero_vector<N>();
  Matrix<N, N> h_, jac_;
  Eigen::PartialPivLU<Matrix<N, N>> lu_;
  bool projected_ = false;  // the last trial point was projected onto the box
  double t_ = 1.0;          // the last trial's t
  // The sparse path (run-time size only): J_F(x_0), its factors, and the updates' u_k, s_k as
  // columns, `stored_` of them; the columns grow (doubling) up to `memory` as updates arrive.
  bool sparse_ = false;
  SparseJacobian sparse_jac_;
  detail::SparseLinearStep linear_;
  Matrix<Dynamic, Dynamic> updates_u_, updates_s_;
  Index stored_ = 0;
};

template <int N>
std::optional<Status> BroydenEngine<N>::renew(std::string& message) {
  if constexpr (N == Dynamic) {
    if (sparse_) {
      if (auto s = system_.sparse_jacobian(x_, f_, sparse_jac_, message)) return s;
      stored_ = 0;
      return linear_.failure(linear_.setup(sparse_jac_), message);
    }
  }
  if (auto s = system_.jacobian(x_, f_, jac_, message)) return s;
  lu_.compute(jac_);
  // A pivot below this fraction of the largest |J_ij|: singular, as NewtonEngine judges.
  const double smallest_pivot = lu_.matrixLU().diagonal().cwiseAbs().minCoeff();
  if (smallest_pivot > 1e-13 * jac_.cwiseAbs().maxCoeff()) {
    h_ = lu_.inverse();
    if (h_.allFinite()) return std::nullopt;
  }
  std::ostringstream os;
  os << "Jacobian of F is singular (smallest LU pivot " << smallest_pivot << ")";
  message = os.str();
  return Status::kSingularJacobian;
}

template <int N>
std::optional<Status> BroydenEngine<N>::apply_inverse(const Vector<N>& v, Vector<N>& out,
                                                      std::string& message) {
  if constexpr (N == Dynamic) {
    if (sparse_) {
      // (A direct solver: the tolerances do not apply.)
      if (auto s = linear_.failure(linear_.resolve(v, out, 0.5, 1.0), message)) return s;
      for (Index k = 0; k < stored_; ++k) {
        out.noalias() += updates_u_.col(k) * updates_s_.col(k).dot(out);
      }
      return std::nullopt;
    }
  }
  out.noalias() = h_ * v;
  static_cast<void>(message);
  return std::nullopt;
}

template <int N>
bool BroydenEngine<N>::update(double denominator) {
  if constexpr (N == Dynamic) {
    if (sparse_) {
      if (stored_ == broyden_.memory) return false;
      if (stored_ == updates_u_.cols()) {
        const Index columns = std::min<Index>(broyden_.memory, std::max<Index>(4, 2 * stored_));
        updates_u_.conservativeResize(Eigen::NoChange, columns);
        updates_s_.conservativeResize(Eigen::NoChange, columns);
      }
      updates_u_.col(stored_) = (d_ - hy_) / denominator;
      updates_s_.col(stored_) = d_;
      ++stored_;
      return true;
    }
  }
  gradient_.noalias() = h_.transpose() * d_;  // Hᵀ s, so that the update is O(n²)
  h_.noalias() += ((d_ - hy_) / denominator) * gradient_.transpose();
  return true;
}

template <int N>
double BroydenEngine<N>::gradient_at_jacobian() {
  if constexpr (N == Dynamic) {
    if (sparse_) {
      gradient_.noalias() = sparse_jac_.transpose() * f_;
      return (sparse_jac_ * gradient_).squaredNorm();
    }
  }
  gradient_.noalias() = jac_.transpose() * f_;
  return (jac_ * gradient_).squaredNorm();
}

template <int N>
bool BroydenEngine<N>::search(const Vector<N>& d, double t0, bool armijo) {
  const LineSearch rule{.sufficient_decrease = broyden_.sufficient_decrease,
                        .shrink = 0.5,
                        .max_backtracks = broyden_.max_backtracks};
  const double phi0 = f_.squaredNorm();
  detail::ResidualPath<N> path(system_, x_, phi0, d, gradient_, armijo, xt_, ft_);
  const LineSearch::Result result = rule.search(path, t0, phi0);
  t_ = result.t;
  projected_ = path.projected();
  return result.accepted();
}

template <int N>
Summary BroydenEngine<N>::solve(const FixedPointProblem<N>& problem, Vector<N>& x) {
  if (std::optional<Summary> scaled = this->solve_scaled(*this, problem, x)) {
    return std::move(*scaled);
  }
  const StopCriteria& stop = this->options_.stop;
  system_.start(name(), problem, x, this->bounds_, broyden_.finite_difference, stop);
  const detail::Box<N>& box = system_.box();
  const Index n = x.size();
  sparse_ = false;
  if constexpr (N == Dynamic) {
    for (Vector<N>* v : {&x_, &f_, &d_, &xt_, &ft_, &hy_, &gradient_}) v->resize(n);
    const SparseJacobianSource* source =
        detail::sparse_path_source(problem, x, broyden_.linear_solver, nullptr);
    sparse_ = source != nullptr;
    if (sparse_) {
      linear_.choose(broyden_.linear_solver, *source->pattern, n);
      updates_u_.resize(n, 0), updates_s_.resize(n, 0);
      stored_ = 0;
    } else {
      h_.resize(n, n), jac_.resize(n, n);
      if (lu_.rows() != n) lu_ = Eigen::PartialPivLU<Matrix<N, N>>(n);
    }
  }
  Summary summary;
  summary.engine = name();
  StopMonitor monitor(stop, x.template lpNorm<Eigen::Infinity>(), /*estimate_lipschitz=*/false);

  x_ = x;
  std::optional<Status> status = system_.first_residual(x_, f_, stop);
  double fnorm = f_.template lpNorm<Eigen::Infinity>();
  bool fresh = false;  // H is the inverse of a Jacobian computed at x_
  int updates = 0;
  if (!status) {
    status = renew(summary.message);
    fresh = !status;
  }
  // The budget or the progress window is spent: why (blocked where a bound holds x against
  // −Jᵀ F, J the last Jacobian computed).
  auto spent_status = [&] {
    if (box.active()) {
      gradient_at_jacobian();
      gradient_ = -gradient_;
    }
    return system_.spent_status(summary.message, x_, gradient_, fnorm);
  };
  while (!status) {
    if (system_.budget_spent()) {
      status = spent_status();
      break;
    }
    if ((status = apply_inverse(f_, d_, summary.message))) break;
    d_ = -d_;
    bool accepted = search(d_, 1.0, false), descent_step = false;
    if (!accepted && fresh && box.active() && !system_.budget_spent()) {
      const double curvature = gradient_at_jacobian();
      if (curvature > 0.0) {
        d_ = -gradient_;
        accepted = search(d_, gradient_.squaredNorm() / curvature, true);
        descent_step = true;
      }
    }
    if (!accepted) {
      if (system_.budget_spent()) {
        status = spent_status();
      } else if (!fresh) {  // a stale H: try again along the Newton direction
        status = renew(summary.message);
        fresh = !status;
        updates = 0;
        if (fresh) continue;
      } else {
        gradient_at_jacobian();
        gradient_ = -gradient_;
        if (const std::optional<Index> i =
                box.blocking(x_, gradient_, detail::BoxMove::kDirection)) {
          summary.message = box.blocked_message(*i, x_, fnorm, "the descent direction");
          status = Status::kBlockedByBound;
        } else {
          summary.message = "line search found no decrease of |F| along the Newton direction";
          status = Status::kStagnated;
        }
      }
      break;
    }
    d_ = xt_ - x_;           // s, the step taken
    f_ = ft_ - f_;           // y = F(x + s) − F(x), until f_ takes F(x + s)
    std::string hy_failure;  // (a failed H y only restarts: its message is not the run's)
    const std::optional<Status> failed = apply_inverse(f_, hy_, hy_failure);
    const double denominator = failed ? std::numeric_limits<double>::quiet_NaN() : d_.dot(hy_);
    const double step = d_.template lpNorm<Eigen::Infinity>();
    const bool full_step = t_ == 1.0 && !projected_ && !descent_step;
    x_ = xt_;
    f_ = ft_;
    fnorm = f_.template lpNorm<Eigen::Infinity>();
    status = monitor.update(step, fnorm, x_.template lpNorm<Eigen::Infinity>(), full_step);
    this->after_iteration(summary, status, monitor.iterations(), step, fnorm, x_);
    if (status) break;
    const bool restart = broyden_.max_updates > 0 && updates >= broyden_.max_updates;
    if (!restart && std::isfinite(denominator) &&
        std::abs(denominator) > 1e-14 * d_.norm() * hy_.norm() && update(denominator)) {
      fresh = false;
      ++updates;
    } else {
      status = renew(summary.message);
      fresh = !status;
      updates = 0;
    }
  }

  x = x_;
  system_.finish(summary, *status, monitor, x, f_, stop);
  if constexpr (N == Dynamic) {
    if (sparse_) linear_.report(summary);
  }
  return summary;
}

// Compiled once in the library for its sizes (nlobs/solvers/library_sizes.hpp).
#define NLOBS_EXTERN_BROYDEN_ENGINE(n) extern template class BroydenEngine<n>;
NLOBS_FOR_EACH_LIBRARY_SIZE(NLOBS_EXTERN_BROYDEN_ENGINE)
#undef NLOBS_EXTERN_BROYDEN_ENGINE

}  // namespace nlobs
