#pragma once
// The residual F: Rⁿ → Rᵐ that a least-squares or minimisation engine works on, seen the same
// way whether the user gave a RootProblem<N, M> (F itself) or a FixedPointProblem<N>
// (F = G − x, ∂F = ∂G − I). Jacobians come from the problem or from finite differences.
#include "nlobs/solvers/finite_difference.hpp"
#include "nlobs/solvers/problem.hpp"

namespace nlobs::detail {

template <int N, int M>
class ResidualSource {
 public:
  explicit ResidualSource(const RootProblem<N, M>& root)
      : root_(&root), n_(root.size()), m_(root.residual_size()) {}
  explicit ResidualSource(const FixedPointProblem<N>& fixed_point) requires(M == N)
      : fixed_point_(&fixed_point), n_(fixed_point.size()), m_(fixed_point.size()) {}

  Index size() const { return n_; }
  Index residual_size() const { return m_; }
  bool has_jacobian() const { return root_ ? root_->has_jacobian() : fixed_point_->has_jacobian(); }

  void residual(const Vector<N>& x, Vector<M>& f) const {
    if constexpr (M == N) {
      if (fixed_point_) {
        fixed_point_->evaluate(x, f);
        f -= x;
        return;
      }
    }
    root_->evaluate(x, f);
  }

  // ∂F(x) from the problem; only when has_jacobian().
  void jacobian(const Vector<N>& x, Matrix<M, N>& j) const {
    if constexpr (M == N) {
      if (fixed_point_) {
        fixed_point_->jacobian(x, j);
        j.diagonal().array() -= 1.0;
        return;
      }
    }
    root_->jacobian(x, j);
  }

 private:
  const RootProblem<N, M>* root_ = nullptr;
  const FixedPointProblem<N>* fixed_point_ = nullptr;
  Index n_, m_;
};

// ∂F(x) from the source, or by finite differences (fx = F(x)); returns evaluations spent.
template <int N, int M>
int residual_jacobian(const ResidualSource<N, M>& source, const Vector<N>& x, const Vector<M>& fx,
                      Matrix<M, N>& j, FiniteDifference scheme, FiniteDifferenceWorkspace<N>& work,
                      Vector<M>& fp, Vector<M>& fm) {
  if (source.has_jacobian()) {
    source.jacobian(x, j);
    return 0;
  }
  return finite_difference_jacobian<N, M>(
      [&source](const Vector<N>& at, Vector<M>& out) { source.residual(at, out); }, x, fx, j,
      scheme, work, fp, fm);
}

}  // namespace nlobs::detail
