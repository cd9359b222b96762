#pragma once
// The two problem forms of [MGFF23]:
//   fixed point  G: Rⁿ → Rⁿ,  find p = G(p)        (FixedPointProblem)
//   root         F: Rⁿ → Rᵐ,  find F(x) = 0         (RootProblem)
// Engines solve a FixedPointProblem; a square RootProblem becomes one through
// to_fixed_point() (G(x) = x + Ψ F(x)), and Newton solves G(x) − x = 0, which is F when Ψ = I.
//
// A problem type-erases the user's callable once, at construction: build it once and solve it
// many times (a window estimator does); evaluating it never allocates for fixed sizes.
#include <functional>
#include <memory>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>

#include "nlobs/solvers/autodiff.hpp"
#include "nlobs/solvers/callable.hpp"
#include "nlobs/solvers/sparse/sparsity_detection.hpp"
#include "nlobs/solvers/status.hpp"
#include "nlobs/solvers/types.hpp"

namespace nlobs {

// Where an engine that needs ∂G (Newton, the contraction check) gets it.
enum class JacobianSource {
  kFiniteDifference,  // none given: engines difference G themselves
  kUserSupplied,      // the user's ∂G / ∂F
  kAutoDiff,          // forward-mode AD of the user's scalar-generic function
};

inline std::string_view to_string(JacobianSource source) {
  switch (source) {
    case JacobianSource::kFiniteDifference:
      return "finite_difference";
    case JacobianSource::kUserSupplied:
      return "user_supplied";
    case JacobianSource::kAutoDiff:
      return "autodiff";
  }
  return "unknown";
}

namespace detail {
inline void check_size(const char* what, Index expected, Index got) {
  if (expected != got) {
    std::ostringstream os;
    os << what << ": size " << got << " does not match the problem dimension " << expected;
    throw InvalidInput(os.str());
  }
}
}  // namespace detail

template <int N = Dynamic>
class FixedPointProblem {
 public:
  using VectorType = Vector<N>;
  using JacobianType = Matrix<N, N>;
  using Map = std::function<void(const VectorType&, VectorType&)>;
  using JacobianMap = std::function<void(const VectorType&, JacobianType&)>;

  // G alone; Jacobians (if an engine needs them) by finite differences.
  template <typename G>
  static FixedPointProblem from_map(G g, Index n = N) {
    return FixedPointProblem(n, wrap(std::move(g)), {}, JacobianSource::kFiniteDifference);
  }
  // G generic in its scalar type: ∂G by forward-mode AD.
  template <typename G>
  static FixedPointProblem with_autodiff(G g, Index n = N) {
    JacobianMap dg = [g, n](const VectorType& x, JacobianType& jac) mutable {
      static_cast<void>(n);  // read at Dynamic size only
      if constexpr (N == Dynamic) jac.resize(n, n);
      autodiff_jacobian<N, N>(g, x, jac);
    };
    return FixedPointProblem(n, wrap(std::move(g)), std::move(dg), JacobianSource::kAutoDiff);
  }
  // G and the user's ∂G (called as dg(x, J) with J n×n, or J = dg(x)).
  // `source` lets adapters that forward an AD Jacobian report it as such.
  template <typename G, typename DG>
  static FixedPointProblem with_jacobian(G g, DG dg, Index n = N,
                                         JacobianSource source = JacobianSource::kUserSupplied) {
    JacobianMap jm = [dg = std::move(dg), n](const VectorType& x, JacobianType& jac) mutable {
      static_cast<void>(n);  // read at Dynamic size only
      if constexpr (N == Dynamic) jac.resize(n, n);
      detail::invoke_map(dg, x, jac);
    };
    return FixedPointProblem(n, wrap(std::move(g)), std::move(jm), source);
  }

  Index size() const { return n_; }
  JacobianSource jacobian_source() const { return source_; }
  bool has_jacobian() const { return static_cast<bool>(dg_); }

  // g = G(x). For dynamic sizes g must already have size n (engines keep it so).
  void evaluate(const VectorType& x, VectorType& g) const { g_(x, g); }
  // jac = ∂G(x); only when has_jacobian().
  void jacobian(const VectorType& x, JacobianType& jac) const { dg_(x, jac); }

  // The residual form F(x) = G(x) − x, when the problem knows F itself (a root problem through
  // to_fixed_point with Ψ = I): the engines that solve F(x) = 0 evaluate it instead of forming
  // G(x) − x, which keeps none of F's digits below ulp(x) — all of them for a residual of 1e-20
  // beside x ~ 1e-6, and what a scaling D_f = 1e20 would magnify (scaling.hpp).
  bool has_residual() const { return static_cast<bool>(f_); }
  void residual(const VectorType& x, VectorType& f) const { f_(x, f); }
  // jac = ∂F(x); only when has_residual() and has_jacobian().
  void residual_jacobian(const VectorType& x, JacobianType& jac) const { df_(x, jac); }
  // This problem with its residual form attached: f must be G(x) − x, df (empty without a
  // Jacobian) ∂G − I.
  FixedPointProblem with_residual(Map f, JacobianMap df = {}) const {
    FixedPointProblem out = *this;
    out.f_ = std::move(f);
    out.df_ = std::move(df);
    out.sparse_.reset();  // it was the old residual's
    return out;
  }
  // ∂F of the residual form as a sparse matrix (run-time size only): the engines' sparse path.
  // nullptr when the problem has none, or has not detected it yet; sparse_residual_jacobian(x)
  // detects it at x first when the problem came from RootProblem::with_autodiff.
  const SparseJacobianSource* sparse_residual_jacobian() const {
    return sparse_ ? sparse_->get() : nullptr;
  }
  const SparseJacobianSource* sparse_residual_jacobian(const VectorType& x) const {
    if constexpr (N == Dynamic) {
      detail::check_size("sparse_residual_jacobian: x", n_, x.size());
      if (sparse_) return sparse_->resolve(x);
    }
    return nullptr;
  }
  FixedPointProblem with_sparse_residual_jacobian(SparseJacobianSource sparse) const {
    detail::check_sparse_source("FixedPointProblem", sparse);
    return with_sparse_jacobian_state(detail::SparseJacobianState::declared(std::move(sparse)));
  }
  // For adapters (to_fixed_point) and engines: the sparse Jacobian declared or to be detected,
  // shared with the root problem it came from; null for none.
  const std::shared_ptr<detail::SparseJacobianState>& sparse_jacobian_state() const {
    return sparse_;
  }
  FixedPointProblem with_sparse_jacobian_state(
      std::shared_ptr<detail::SparseJacobianState> state) const {
    static_assert(N == Dynamic, "a sparse Jacobian is for run-time sizes");
    if (!has_residual()) {
      throw InvalidInput("FixedPointProblem: a sparse residual Jacobian needs the residual form");
    }
    FixedPointProblem out = *this;
    out.sparse_ = std::move(state);
    return out;
  }

 private:
  FixedPointProblem(Index n, Map g, JacobianMap dg, JacobianSource source)
      : n_(n), g_(std::move(g)), dg_(std::move(dg)), source_(source) {
    if (n_ < 1 || (N != Dynamic && n_ != N)) {
      std::ostringstream os;
      os << "FixedPointProblem: dimension n = " << n_
         << (N != Dynamic ? " differs from the compile-time size " + std::to_string(N)
                          : std::string(" must be >= 1"));
      throw InvalidInput(os.str());
    }
  }
  template <typename G>
  static Map wrap(G g) {
    return [g = std::move(g)](const VectorType& x, VectorType& out) mutable {
      detail::invoke_map(g, x, out);
    };
  }

  Index n_;
  Map g_;
  JacobianMap dg_;
  JacobianSource source_;
  Map f_;
  JacobianMap df_;
  std::shared_ptr<detail::SparseJacobianState> sparse_;
};

namespace detail {
// Dynamic-size user functions may resize their output; catch a wrong size at once.
template <int N>
void check_output_size(const FixedPointProblem<N>& problem, const Vector<N>& g) {
  if constexpr (N == Dynamic) {
    if (g.size() != problem.size()) {
      std::ostringstream os;
      os << "G returned a vector of size " << g.size() << ", expected " << problem.size();
      throw InvalidInput(os.str());
    }
  }
}
}  // namespace detail

// F: Rⁿ → Rᵐ (m ≥ n for least squares; m = n for engines through to_fixed_point).
template <int N = Dynamic, int M = N>
class RootProblem {
 public:
  using VectorType = Vector<N>;
  using ResidualType = Vector<M>;
  using JacobianType = Matrix<M, N>;
  using Map = std::function<void(const VectorType&, ResidualType&)>;
  using JacobianMap = std::function<void(const VectorType&, JacobianType&)>;

  template <typename F>
  static RootProblem from_map(F f, Index n = N, Index m = M) {
    return RootProblem(n, m, wrap(std::move(f)), {}, JacobianSource::kFiniteDifference);
  }
  // F generic in its scalar type: ∂F by forward-mode AD. At run-time size (N = M = Dynamic) the
  // problem also finds J's sparsity pattern itself, once, at the first point an engine with a
  // sparse path (newton) asks with, and gives that engine a compressed sparse Jacobian when the
  // pattern is sparse enough — the rule in sparse/sparsity_detection.hpp; with_dense_jacobian()
  // switches it off. F must then also accept SparsityTracer scalars, as it accepts ceres::Jet (an
  // F that cannot — one that takes only double and Jet — is built with_dense_autodiff).
  template <typename F>
  static RootProblem with_autodiff(F f, Index n = N, Index m = M) {
    RootProblem out = with_dense_autodiff(f, n, m);
    if constexpr (N == Dynamic && M == Dynamic) {
      out.sparse_ = detail::SparseJacobianState::detected_later(
          [f = std::move(f), m](const Vector<Dynamic>& x, std::string& note) mutable {
            return detail::detect_sparse_jacobian(f, x, m, note);
          });
    }
    return out;
  }
  // ∂F by forward-mode AD, dense at every size: no sparsity detection (F is never evaluated on
  // SparsityTracer scalars).
  template <typename F>
  static RootProblem with_dense_autodiff(F f, Index n = N, Index m = M) {
    JacobianMap df = [f, n, m](const VectorType& x, JacobianType& jac) mutable {
      if constexpr (N == Dynamic || M == Dynamic) jac.resize(m, n);
      autodiff_jacobian<N, M>(f, x, jac);
    };
    return RootProblem(n, m, wrap(std::move(f)), std::move(df), JacobianSource::kAutoDiff);
  }
  // `source` lets adapters that forward an AD Jacobian report it as such.
  template <typename F, typename DF>
  static RootProblem with_jacobian(F f, DF df, Index n = N, Index m = M,
                                   JacobianSource source = JacobianSource::kUserSupplied) {
    JacobianMap jm = [df = std::move(df), n, m](const VectorType& x, JacobianType& jac) mutable {
      if constexpr (N == Dynamic || M == Dynamic) jac.resize(m, n);
      detail::invoke_map(df, x, jac);
    };
    return RootProblem(n, m, wrap(std::move(f)), std::move(jm), source);
  }

  Index size() const { return n_; }
  Index residual_size() const { return m_; }
  JacobianSource jacobian_source() const { return source_; }
  bool has_jacobian() const { return static_cast<bool>(df_); }
  void evaluate(const VectorType& x, ResidualType& f) const { f_(x, f); }
  void jacobian(const VectorType& x, JacobianType& jac) const { df_(x, jac); }
  // ∂F as a sparse matrix (run-time size only), or nullptr: declared (sparse/sparse_problem.hpp)
  // or detected (with_autodiff). sparse_jacobian(x) detects it at x first if that is still to do.
  const SparseJacobianSource* sparse_jacobian() const { return sparse_ ? sparse_->get() : nullptr; }
  const SparseJacobianSource* sparse_jacobian(const VectorType& x) const {
    if constexpr (N == Dynamic && M == Dynamic) {
      detail::check_size("sparse_jacobian: x", n_, x.size());
      if (sparse_) return sparse_->resolve(x);
    }
    return nullptr;
  }
  RootProblem with_sparse_jacobian(SparseJacobianSource sparse) const {
    static_assert(N == Dynamic && M == Dynamic, "a sparse Jacobian is for run-time sizes");
    detail::check_sparse_source("RootProblem", sparse);
    RootProblem out = *this;
    out.sparse_ = detail::SparseJacobianState::declared(std::move(sparse));
    return out;
  }
  // This problem without a sparse Jacobian, declared or to be detected: every engine uses the
  // dense one.
  RootProblem with_dense_jacobian() const {
    RootProblem out = *this;
    out.sparse_.reset();
    return out;
  }
  // What became of the sparse Jacobian: "declared", what detection found or why it declined
  // (n too small, F branches on x, a row too dense), or "" when the problem has none.
  std::string sparse_jacobian_note() const { return sparse_ ? sparse_->note() : std::string(); }
  // For adapters (to_fixed_point): the sparse Jacobian's state, shared by the problem's copies.
  const std::shared_ptr<detail::SparseJacobianState>& sparse_jacobian_state() const {
    return sparse_;
  }

 private:
  RootProblem(Index n, Index m, Map f, JacobianMap df, JacobianSource source)
      : n_(n), m_(m), f_(std::move(f)), df_(std::move(df)), source_(source) {
    if (n_ < 1 || m_ < 1 || (N != Dynamic && n_ != N) || (M != Dynamic && m_ != M)) {
      std::ostringstream os;
      os << "RootProblem: dimensions n = " << n_ << ", m = " << m_
         << " are invalid or differ from the compile-time sizes";
      throw InvalidInput(os.str());
    }
  }
  template <typename F>
  static Map wrap(F f) {
    return [f = std::move(f)](const VectorType& x, ResidualType& out) mutable {
      detail::invoke_map(f, x, out);
    };
  }

  Index n_, m_;
  Map f_;
  JacobianMap df_;
  JacobianSource source_;
  // Shared by the problem's copies, workspace included (evaluate() holds its scratch; the state
  // locks around it, so copies solved concurrently take turns evaluating J).
  std::shared_ptr<detail::SparseJacobianState> sparse_;
};

}  // namespace nlobs
