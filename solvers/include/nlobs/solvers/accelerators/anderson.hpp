#pragma once
// Anderson acceleration (type II, Walker & Ni 2011; the accelerator of KINSOL's fixed-point
// solver). With f_k = G(x_k) − x_k and the last m_k = min(m, k) differences
//   ΔX = [x_{i+1} − x_i], ΔF = [f_{i+1} − f_i]   (oldest column first),
//   γ = argmin ‖f_k − ΔF γ‖₂,   x_{k+1} = x_k + β f_k − (ΔX + β ΔF) γ,
// β the damping (β = 1: x_{k+1} = G(x_k) − ΔG γ). Depth 0 is damped Picard.
//
// The least-squares problem is solved through a thin QR factorisation ΔF = Q R that is updated,
// not recomputed: a new column is orthogonalised against Q (modified Gram–Schmidt, O(nm)); when
// the history is full the oldest column is removed with Givens rotations (O(m² + nm)). Then
// γ = R⁻¹ Qᵀ f and ΔF γ = Q Qᵀ f. A new column that is numerically dependent on the history
// (‖q‖ ≤ 1e-13 ‖Δf‖) is not added, and the oldest columns are dropped while R is
// ill-conditioned (condition_limit). Fixed N: all storage is on the stack (depth ≤
// kMaxFixedDepth), so a solve never allocates; dynamic N allocates in start() when n changes.
#include <cmath>
#include <string>
#include <string_view>
#include <type_traits>

#include "nlobs/solvers/engine_spec.hpp"
#include "nlobs/solvers/options_validation.hpp"
#include "nlobs/solvers/status.hpp"
#include "nlobs/solvers/types.hpp"

namespace nlobs {

struct AndersonOptions {
  int depth = 3;         // m ∈ [0, AndersonMixing::kMaxDepth]
  double damping = 1.0;  // β ∈ (0, 1]
  // Oldest history columns are dropped while max|R_ii| / min|R_ii| (a cheap lower bound on
  // cond(R)) exceeds this: nearly dependent differences otherwise give huge γ and wild steps.
  double condition_limit = 1e8;  // > 1
  // The largest depth at run-time sizes (the history is n × m; more is never useful and would
  // only exhaust memory: m = 1e9 did); fixed sizes allow AndersonMixing::kMaxFixedDepth.
  static constexpr int kMaxDepth = 1000;

  // Throws InvalidInput naming the field, its value and the requirement (options_validation.hpp).
  void validate() const;
  // The `anderson` engine as the registry lists it, the spec keys (field names; older ones as
  // aliases) and their reading over these values (src/options/anderson_options.cpp).
  static EngineDescription describe();
  void read(EngineSpecReader& spec);
};

template <int N = Dynamic>
class AndersonMixing {
 public:
  static constexpr int kMaxFixedDepth = 16;
  static constexpr int kMaxDynamicDepth = AndersonOptions::kMaxDepth;
  static constexpr int kMaxDepth = N != Dynamic ? kMaxFixedDepth : kMaxDynamicDepth;

  explicit AndersonMixing(AndersonOptions options = {}) : options_(options) {
    if constexpr (N != Dynamic) {  // the fixed sizes' range first: it is the one that holds
      require_option(options_.depth >= 0 && options_.depth <= kMaxFixedDepth, "AndersonOptions",
                     "depth", options_.depth, "must be in 0..16 for fixed sizes");
    }
    options_.validate();
  }

  // Its residuals rise and fall: judged by the best residual over a window (StopMonitor).
  static constexpr bool kNonMonotone = true;
  std::string_view name() const { return "anderson"; }
  const AndersonOptions& options() const { return options_; }

  void start(const Vector<N>& x0) {
    const Index n = x0.size(), m = options_.depth;
    dx_.resize(n, m), q_.resize(n, m), r_.resize(m, m), dg_.resize(m);
    f_.resize(n), x_prev_.resize(n), f_prev_.resize(n), v_.resize(n);
    count_ = 0;
    have_prev_ = false;
  }

  bool propose(const Vector<N>& x, const Vector<N>& gx, Vector<N>& next, Vector<N>& estimate) {
    const double beta = options_.damping;
    f_ = gx - x;
    if (options_.depth > 0 && have_prev_) add_column(x);
    x_prev_ = x;
    f_prev_ = f_;
    have_prev_ = true;

    next = x + beta * f_;
    if (count_ > 0) {
      const int k = count_;
      // c = Qᵀ f;  γ = R⁻¹ c (back substitution);  ΔF γ = Q c.
      for (int i = 0; i < k; ++i) dg_[i] = q_.col(i).dot(f_);
      next -= beta * (q_.leftCols(k) * dg_.head(k));
      for (int i = k - 1; i >= 0; --i) {
        double s = dg_[i];
        for (int j = i + 1; j < k; ++j) s -= r_(i, j) * dg_[j];
        dg_[i] = s / r_(i, i);
      }
      next -= dx_.leftCols(k) * dg_.head(k);
    }
    estimate = next;
    return true;
  }

 private:
  // Appends Δx = x − x_prev, Δf = f − f_prev to the history and to its QR factorisation.
  void add_column(const Vector<N>& x) {
    const int m = options_.depth;
    v_ = f_ - f_prev_;
    const double dfnorm = v_.norm();
    if (!(dfnorm > 0.0) || !std::isfinite(dfnorm)) return;
    if (count_ == m) remove_oldest();
    const int k = count_;
    for (int i = 0; i < k; ++i) {  // modified Gram–Schmidt
      r_(i, k) = q_.col(i).dot(v_);
      v_ -= r_(i, k) * q_.col(i);
    }
    const double rkk = v_.norm();
    if (!(rkk > 1e-13 * dfnorm)) return;  // dependent on the history: skip it
    r_(k, k) = rkk;
    q_.col(k) = v_ / rkk;
    dx_.col(k) = x - x_prev_;
    ++count_;
    while (count_ > 1 && condition_estimate() > options_.condition_limit) remove_oldest();
  }

  double condition_estimate() const {
    const auto d = r_.diagonal().head(count_).cwiseAbs();
    return d.maxCoeff() / d.minCoeff();
  }

  // Drops column 0 of ΔF = QR (and of ΔX): R without its first column is upper Hessenberg;
  // Givens rotations on rows (i, i+1) restore the triangle, applied to Q's columns alike.
  void remove_oldest() {
    const int k = count_;
    for (int i = 0; i + 1 < k; ++i) {
      const double a = r_(i, i + 1), b = r_(i + 1, i + 1);
      const double h = std::hypot(a, b);
      const double c = a / h, s = b / h;
      r_(i, i + 1) = h;
      r_(i + 1, i + 1) = 0.0;
      for (int j = i + 2; j < k; ++j) {
        const double t1 = r_(i, j), t2 = r_(i + 1, j);
        r_(i, j) = c * t1 + s * t2;
        r_(i + 1, j) = -s * t1 + c * t2;
      }
      for (Index row = 0; row < q_.rows(); ++row) {
        const double t1 = q_(row, i), t2 = q_(row, i + 1);
        q_(row, i) = c * t1 + s * t2;
        q_(row, i + 1) = -s * t1 + c * t2;
      }
    }
    // Shift R's columns (and ΔX's) left by one; Q keeps its first k − 1 columns.
    for (int j = 0; j + 1 < k; ++j) {
      for (int i = 0; i <= j; ++i) r_(i, j) = r_(i, j + 1);
      dx_.col(j) = dx_.col(j + 1);
    }
    --count_;
  }

  // Eigen requires a one-row matrix to be row-major.
  static constexpr int kHistoryLayout = N == 1 ? Eigen::RowMajor : Eigen::ColMajor;
  using History = std::conditional_t<
      N == Dynamic, Eigen::MatrixXd,
      Eigen::Matrix<double, N, Eigen::Dynamic, kHistoryLayout, N, kMaxFixedDepth>>;
  using Square = std::conditional_t<
      N == Dynamic, Eigen::MatrixXd,
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxFixedDepth, kMaxFixedDepth>>;
  using Coefficients =
      std::conditional_t<N == Dynamic, Eigen::VectorXd,
                         Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxFixedDepth, 1>>;

  AndersonOptions options_;
  History dx_, q_;
  Square r_;
  Coefficients dg_;
  Vector<N> f_ = zero_vector<N>(), x_prev_ = zero_vector<N>(), f_prev_ = zero_vector<N>(),
            v_ = zero_vector<N>();
  int count_ = 0;
  bool have_prev_ = false;
};

}  // namespace nlobs
