#pragma once
// The arrival cost of moving-horizon estimation, ‖x_{k−N+1} − x̄‖²_{P⁻¹}: the prior on the
// horizon's first state, and its filtering update when sample j leaves the horizon ([RRM03]):
//   P⁺ = (P⁻¹ + Hᵀ R⁻¹ H)⁻¹,  x̄ ← f(x̂_{j|j}, u_j, j),  P ← F P⁺ Fᵀ + w Q,
// H = ∂h/∂x, F = ∂f/∂x at the filtered estimate x̂_{j|j} (forward-mode AD), R⁻¹ that of the
// outputs measured at j (none measured: P⁺ = P), w the move's noise weight (an interval off the
// model's grid, ModelStep). On a linear model this is the Kalman filter's prior. Fixed sizes
// allocate nothing.
#include <Eigen/Cholesky>

#include "nlobs/models/model.hpp"
#include "nlobs/observers/core/discrete_jacobians.hpp"
#include "nlobs/observers/core/model_step.hpp"

namespace nlobs {
namespace detail {

// M⁻¹ of a symmetric positive definite M (validated covariances, or P⁻¹ + Hᵀ R⁻¹ H).
template <typename Matrix>
Matrix spd_inverse(const Matrix& m) {
  Matrix out = Matrix::Identity(m.rows(), m.cols());
  m.llt().solveInPlace(out);
  return out;
}

}  // namespace detail

template <DiscreteModel Model>
class ArrivalCost {
 public:
  using State = ModelVector<double, Model::kStates>;
  using Input = ModelVector<double, Model::kInputs>;
  using StateMatrix = Eigen::Matrix<double, Model::kStates, Model::kStates>;
  using OutputMatrix = Eigen::Matrix<double, Model::kOutputs, Model::kOutputs>;
  using OutputJacobian = Eigen::Matrix<double, Model::kOutputs, Model::kStates>;

  // x̄, P and P⁻¹ (the caller's: validated, P⁻¹ its inverse).
  void reset(const State& mean, const StateMatrix& covariance, const StateMatrix& information) {
    mean_ = mean;
    covariance_ = covariance;
    information_ = information;
  }

  // The update along the sample that leaves the horizon: its filtered estimate, input, move to
  // the next sample, and R⁻¹ of its measured outputs (`measured` false: none). False, x̄ and P
  // kept, when the new x̄ or P is not finite or P is not positive definite.
  bool update(const Model& model, const State& filtered, const Input& u, const ModelStep& move,
              bool measured, const OutputMatrix& r_inv, const StateMatrix& q) {
    const Eigen::Index n = model.states();
    StateMatrix fj(n, n);
    OutputJacobian hj(model.outputs(), n);
    state_jacobian(model, filtered, u, move, fj);
    StateMatrix updated = covariance_;  // nothing measured: P⁺ = P
    if (measured) {
      output_jacobian(model, filtered, hj);
      updated = detail::spd_inverse(StateMatrix(information_ + hj.transpose() * r_inv * hj));
    }
    StateMatrix covariance = fj * updated * fj.transpose() + move.weight * q;
    covariance = 0.5 * (covariance + covariance.transpose());
    const State mean = advance(model, filtered, u, move);
    const Eigen::LLT<StateMatrix> llt(covariance);
    if (!mean.allFinite() || !covariance.allFinite() || llt.info() != Eigen::Success) return false;
    mean_ = mean;
    covariance_ = covariance;
    information_ = llt.solve(StateMatrix::Identity(n, n));
    return true;
  }

  // ‖x − x̄‖²_{P⁻¹}, the cost's first term at the horizon's first state x.
  double cost(const State& x) const {
    const State e = x - mean_;
    return e.dot(information_ * e);
  }

  const State& mean() const { return mean_; }
  const StateMatrix& covariance() const { return covariance_; }
  const StateMatrix& information() const { return information_; }  // P⁻¹

 private:
  State mean_;
  StateMatrix covariance_, information_;
};

}  // namespace nlobs
