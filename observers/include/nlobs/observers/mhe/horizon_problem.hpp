#pragma once
// The MHE's least-squares problem over its horizon (mhe_estimator.hpp; [RRM03]):
//   V(z) = ‖x_0 − x̄‖²_{P⁻¹} + Σ_{i<M−1} ‖x_{i+1} − f(x_i, u_i, i)‖²_{(w_i Q)⁻¹}
//          + Σ_i ‖y_i − h(x_i)‖²_{R_i⁻¹},     l ≤ x_i ≤ u,
// over the states z = (x_0, …, x_{M−1}) of the horizon's first M nodes, the arrival cost's x̄
// and P⁻¹ (arrival_cost.hpp), w_i the move's noise weight (an interval off the model's grid) and
// R_i⁻¹ that of the outputs measured at node i. Its Gauss–Newton matrix is block tridiagonal
// (block_tridiagonal.hpp, O(M n³)), the states at a bound whose gradient points out of the box
// are held ([Ber82]): the linear algebra ProjectedGaussNewton
// (solvers/least_squares/projected_gauss_newton.hpp) asks of a problem. The workspace is sized
// once for the longest horizon: with compile-time sizes a solve allocates nothing.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>
#include <vector>

#include "nlobs/models/integration_failure.hpp"
#include "nlobs/models/model.hpp"
#include "nlobs/observers/core/discrete_jacobians.hpp"
#include "nlobs/observers/core/model_step.hpp"
#include "nlobs/observers/mhe/arrival_cost.hpp"
#include "nlobs/observers/mhe/block_tridiagonal.hpp"

namespace nlobs {

// One sample of the horizon.
template <DiscreteModel Model>
struct MheNode {
  using State = ModelVector<double, Model::kStates>;
  using Input = ModelVector<double, Model::kInputs>;
  using Output = ModelVector<double, Model::kOutputs>;
  using OutputMatrix = Eigen::Matrix<double, Model::kOutputs, Model::kOutputs>;

  long k = 0;
  double t = 0.0;
  Output y;            // the measured outputs; 0 where missing
  Output measured;     // 1 where y was measured, 0 where missing
  OutputMatrix r_inv;  // R⁻¹ of the outputs measured; zero rows and columns where missing
  Input u;             // held from t to the next sample's time
  ModelStep next;      // the model's move to the next sample (w weighted by next.weight)
  State x;             // the horizon's current estimate of this sample's state
  State filtered;      // x̂_{i|i}: the estimate from the samples up to this one
};

template <DiscreteModel Model>
class MheHorizonProblem {
 public:
  using Node = MheNode<Model>;
  using State = ModelVector<double, Model::kStates>;
  using Output = ModelVector<double, Model::kOutputs>;
  using StateMatrix = Eigen::Matrix<double, Model::kStates, Model::kStates>;
  using OutputJacobian = Eigen::Matrix<double, Model::kOutputs, Model::kStates>;

  // Q⁻¹, the box (±inf where a side is free) and the longest horizon the workspace holds.
  MheHorizonProblem(const StateMatrix& q_inv, const State& lower, const State& upper,
                    std::size_t horizon, Eigen::Index states, Eigen::Index outputs)
      : q_inv_(q_inv), lower_(lower), upper_(upper) {
    const Eigen::Index n = states, p = outputs;
    diag_.assign(horizon, StateMatrix::Zero(n, n));
    sub_.assign(horizon, StateMatrix::Zero(n, n));
    grad_.assign(horizon, State::Zero(n));
    direction_.assign(horizon, State::Zero(n));
    trial_.assign(horizon, State::Zero(n));
    f_jac_.assign(horizon, StateMatrix::Zero(n, n));
    h_jac_.assign(horizon, OutputJacobian::Zero(p, n));
    w_res_.assign(horizon, State::Zero(n));
    y_res_.assign(horizon, Output::Zero(p));
    solver_.reserve(static_cast<long>(horizon), n);
  }

  // The problem over nodes[0..m−1] with this model and arrival cost (held by reference until the
  // next bind).
  void bind(const Model& model, std::vector<Node>& nodes, std::size_t m,
            const ArrivalCost<Model>& arrival) {
    model_ = &model;
    nodes_ = &nodes;
    arrival_ = &arrival;
    active_ = m;
  }

  // ProjectedGaussNewtonProblem.
  double start_cost() {
    for (std::size_t i = 0; i < active_; ++i) trial_[i] = (*nodes_)[i].x;
    return cost(trial_);
  }
  double linearise() {
    assemble();
    return hold_active_bounds();
  }
  bool newton_direction() {
    for (std::size_t i = 0; i < active_; ++i) direction_[i] = -grad_[i];
    if (!solver_.factor(diag_, sub_, active_)) return false;
    solver_.solve(direction_, active_);
    return true;
  }
  void gradient_direction() {
    for (std::size_t i = 0; i < active_; ++i) {
      direction_[i] = -grad_[i].cwiseQuotient(diag_[i].diagonal());
    }
  }
  double trial_cost() { return cost(trial_); }
  void accept() {
    for (std::size_t i = 0; i < active_; ++i) (*nodes_)[i].x = trial_[i];
  }

  // trial_ = Π(x + α d), the trial point; returns ∇(V/2)ᵀ(trial − x) and the step's ‖·‖∞.
  std::pair<double, double> project(double alpha) {
    double slope = 0.0, step = 0.0;
    for (std::size_t i = 0; i < active_; ++i) {
      trial_[i] = ((*nodes_)[i].x + alpha * direction_[i]).cwiseMax(lower_).cwiseMin(upper_);
      const State s = trial_[i] - (*nodes_)[i].x;
      slope += grad_[i].dot(s);
      step = std::max(step, s.cwiseAbs().maxCoeff());
    }
    return {slope, step};
  }

  // ‖z‖∞.
  double norm() const {
    double largest = 0.0;
    for (std::size_t i = 0; i < active_; ++i) {
      largest = std::max(largest, (*nodes_)[i].x.cwiseAbs().maxCoeff());
    }
    return largest;
  }

 private:
  bool inside_domain(const State& x) const { return domain_violation_of(*model_, x).empty(); }

  // V at the states xs[0..M−1] (+inf when a term is not finite, a state leaves the model's
  // domain, or a move cannot be integrated: IntegrationFailure, an adaptive or implicit scheme
  // at a trial state far outside its range — the line search backtracks from it).
  double cost(const std::vector<State>& xs) const {
    try {
      return cost_or_throw(xs);
    } catch (const IntegrationFailure&) {
      return std::numeric_limits<double>::infinity();
    }
  }
  double cost_or_throw(const std::vector<State>& xs) const {
    const std::size_t m = active_;
    double v = arrival_->cost(xs[0]);
    for (std::size_t i = 0; i < m; ++i) {
      if (!inside_domain(xs[i])) return std::numeric_limits<double>::infinity();
      const Output e = (*nodes_)[i].y - Output(model_->h(xs[i]));
      v += e.dot((*nodes_)[i].r_inv * e);
      if (i + 1 < m) {
        const State w = xs[i + 1] - advance(*model_, xs[i], (*nodes_)[i].u, (*nodes_)[i].next);
        v += w.dot(q_inv_ * w) / (*nodes_)[i].next.weight;
      }
    }
    return std::isfinite(v) ? v : std::numeric_limits<double>::infinity();
  }

  // The Gauss–Newton system at the current states: diag_, sub_ (H) and grad_ (∇(V/2)).
  void assemble() {
    const std::size_t m = active_;
    for (std::size_t i = 0; i < m; ++i) {
      const Node& node = (*nodes_)[i];
      if (i + 1 < m) state_jacobian(*model_, node.x, node.u, node.next, f_jac_[i]);
      output_jacobian(*model_, node.x, h_jac_[i]);
      y_res_[i] = node.y - Output(model_->h(node.x));
      const Output ry = node.r_inv * y_res_[i];
      diag_[i].noalias() = h_jac_[i].transpose() * (node.r_inv * h_jac_[i]);
      grad_[i].noalias() = -h_jac_[i].transpose() * ry;
    }
    diag_[0] += arrival_->information();
    grad_[0].noalias() += arrival_->information() * ((*nodes_)[0].x - arrival_->mean());
    for (std::size_t i = 0; i + 1 < m; ++i) {
      // The move's noise is weight · Q (an interval off the grid): its inverse weighs the term.
      const double scale = 1.0 / (*nodes_)[i].next.weight;
      w_res_[i] =
          (*nodes_)[i + 1].x - advance(*model_, (*nodes_)[i].x, (*nodes_)[i].u, (*nodes_)[i].next);
      const State qw = scale * (q_inv_ * w_res_[i]);
      sub_[i].noalias() = -scale * (q_inv_ * f_jac_[i]);
      diag_[i].noalias() -= f_jac_[i].transpose() * sub_[i];
      diag_[i + 1] += scale * q_inv_;
      grad_[i].noalias() -= f_jac_[i].transpose() * qw;
      grad_[i + 1] += qw;
    }
  }

  // Holds the states at a bound whose gradient points out of the box ([Ber82]): their rows and
  // columns of H become the identity's, their gradient 0, so that the step leaves them. Returns
  // the projected gradient's ‖·‖∞.
  double hold_active_bounds() {
    const std::size_t m = active_;
    double projected = 0.0;
    for (std::size_t i = 0; i < m; ++i) {
      for (Eigen::Index c = 0; c < model_->states(); ++c) {
        const double x = (*nodes_)[i].x[c], g = grad_[i][c];
        if ((x <= lower_[c] && g > 0.0) || (x >= upper_[c] && g < 0.0)) {
          diag_[i].row(c).setZero();
          diag_[i].col(c).setZero();
          diag_[i](c, c) = 1.0;
          grad_[i][c] = 0.0;
          if (i + 1 < m) sub_[i].col(c).setZero();
          if (i > 0) sub_[i - 1].row(c).setZero();
        } else {
          projected = std::max(projected, std::abs(g));
        }
      }
    }
    return projected;
  }

  StateMatrix q_inv_;
  State lower_, upper_;
  const Model* model_ = nullptr;
  std::vector<Node>* nodes_ = nullptr;
  const ArrivalCost<Model>* arrival_ = nullptr;
  std::size_t active_ = 0;  // the nodes of the problem (the first active_)
  // Gauss–Newton workspace, one entry per sample of the horizon.
  std::vector<StateMatrix> diag_, sub_, f_jac_;
  std::vector<OutputJacobian> h_jac_;
  std::vector<State> grad_, direction_, trial_, w_res_;
  std::vector<Output> y_res_;
  detail::BlockTridiagonalCholesky<Model::kStates> solver_;
};

}  // namespace nlobs
