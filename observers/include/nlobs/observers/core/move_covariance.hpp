#pragma once
// The covariance propagation through one move of a discrete model, P ← F P Fᵀ + w Q with
// F = ∂x⁺/∂x at (x, u) (what the EKF predicts with), dense or sparse by the model's size:
//   fixed sizes, or n < SparsityDetectionRule::kSmallestSize (100): the dense AD Jacobian
//     (state_jacobian, which allocates nothing for fixed sizes) and dense products, as always;
//   run-time n ≥ 100, a model that opts in to tracing (kTracesSparsity, models/model.hpp): the
//     pattern of the move found by evaluating it once on SparsityTracer scalars, by the solver
//     layer's rule (solvers/sparse/sparsity_detection.hpp: no branch on x, no dense row), then F
//     by compressed forward-mode AD [CPR74] — ⌈colours / 8⌉ evaluations of the move instead of
//     ⌈n / 8⌉ (two for an RK4 step of a tridiagonal vector field: bandwidth 4, 9 colours) —
//     and F P Fᵀ in O(nnz(F) n) instead of O(n³);
//   run-time n ≥ 100 otherwise (the default; AnyModel; a model with a branch on x; a pattern
//     declined): the dense AD Jacobian, and the same sparse product over F's exact nonzeros when
//     they are at most 10 % of n² (skipping exact zeros changes no sum).
// A traced pattern is kept for its kind of move — one step f(x, u, k), or the flow over an
// interval of a given length — and traced again (and coloured twice: once by the solver
// layer's detection, once here) when the kind changes, as with samples at irregular times.
// note() says which path the last propagation took.
#include <Eigen/Core>
#include <optional>
#include <string>

#include "nlobs/models/model.hpp"
#include "nlobs/observers/core/discrete_jacobians.hpp"
#include "nlobs/observers/core/model_step.hpp"
#include "nlobs/solvers/sparse/compressed_jacobian.hpp"
#include "nlobs/solvers/sparse/sparse_jacobian.hpp"
#include "nlobs/solvers/sparse/sparsity_detection.hpp"

namespace nlobs::detail {

template <DiscreteModel Model>
class MoveCovariance {
 public:
  using State = ModelVector<double, Model::kStates>;
  using Input = ModelVector<double, Model::kInputs>;

  // `sparse`: false keeps the dense Jacobian and products at every size.
  explicit MoveCovariance(bool sparse = true) : sparse_(sparse) {}

  // out = F P Fᵀ + w Q along the move s from x (u held); w = s.weight.
  void propagate(const Model& model, const State& x, const Input& u, const ModelStep& s,
                 const Eigen::MatrixXd& p, const Eigen::MatrixXd& q, Eigen::MatrixXd& out) {
    const Eigen::Index n = x.size();
    if constexpr (Model::kStates == Eigen::Dynamic) {
      if (sparse_ && n >= SparsityDetectionRule::kSmallestSize) {
        if (traced_jacobian(model, x, u, s)) {
          note_ = traced_note_;
          sparse_product(p, q, s.weight, out);
          return;
        }
        state_jacobian(model, x, u, s, dense_);
        const Eigen::Index nonzeros = (dense_.array() != 0.0).count();
        if (nonzeros <= n * n / 10) {
          jacobian_ = dense_.sparseView();  // exact zeros only
          shaped_by_trace_ = false;
          note_ = traced_note_ + "; sparse product over the dense Jacobian's " +
                  std::to_string(nonzeros) + " nonzeros";
          sparse_product(p, q, s.weight, out);
          return;
        }
        note_ = traced_note_ + "; dense: " + std::to_string(nonzeros) + " nonzeros";
        dense_product(p, q, s.weight, out);
        return;
      }
    }
    state_jacobian(model, x, u, s, dense_);
    note_ = "dense";
    dense_product(p, q, s.weight, out);
  }

  // Which path the last propagation took, and why: "dense", "sparse: traced, 1000 x 1000, 8980
  // entries, 9 colours", or why the pattern was declined.
  const std::string& note() const { return note_; }

 private:
  // F by compressed AD over the move's traced pattern, tracing it first for a new kind of move;
  // false when there is none (the model does not trace, or the rule declined: traced_note_ says).
  bool traced_jacobian(const Model& model, const State& x, const Input& u, const ModelStep& s) {
    if constexpr (!traces_sparsity<Model>()) {
      traced_note_ = "not traced: the model does not opt in (kTracesSparsity)";
      return false;
    } else {
      if (!traces_sparsity_now(model)) {
        traced_note_ =
            "not traced: the model's scheme takes steps that depend on the state, or "
            "its move is dense (traceable() is false)";
        return false;
      }
      auto move = [&model, &u, &s](const auto& v) {
        using T = typename std::decay_t<decltype(v)>::Scalar;
        return ModelVector<T, Eigen::Dynamic>(
            advance(model, ModelVector<T, Model::kStates>(v), u, s));
      };
      const Vector<Dynamic> xd = x;
      if (!traced_ || traced_->flow != s.flow || (s.flow && traced_->length != s.length)) {
        traced_ = TracedMove{s.flow, s.length};
        compressed_.reset();
        shaped_by_trace_ = false;
        std::string why;
        try {
          if (const auto source = detect_sparse_jacobian(move, xd, xd.size(), why)) {
            compressed_.emplace(*source->pattern);
          }
        } catch (const std::exception& e) {  // what the model throws on tracers declines
          why = std::string("not detected: the model threw while traced: ") + e.what();
        }
        traced_note_ = compressed_
                           ? "sparse: traced, " + std::to_string(xd.size()) + " x " +
                                 std::to_string(xd.size()) + ", " +
                                 std::to_string(compressed_->pattern().nonzeros()) + " entries, " +
                                 std::to_string(compressed_->colouring().colours) + " colours"
                           : why;
      }
      if (!compressed_) return false;
      if (!shaped_by_trace_) {
        // CompressedJacobian keeps J's structure when its size and count match: start afresh
        // after another pattern, so that no value lands in another pattern's position.
        jacobian_ = SparseJacobian();
        shaped_by_trace_ = true;
      }
      compressed_->autodiff(move, xd, jacobian_);
      return true;
    }
  }

  // B = F P one sparse product per column of P; then column j of B Fᵀ is Σ_k F_jk B_:k, the
  // row j of F combining whole columns of B: every access runs down a column (F times Bᵀ would
  // read B across its rows, a cache miss per entry).
  void sparse_product(const Eigen::MatrixXd& p, const Eigen::MatrixXd& q, double w,
                      Eigen::MatrixXd& out) {
    work_.noalias() = jacobian_ * p;
    out.resize(p.rows(), p.cols());
    for (Eigen::Index j = 0; j < out.cols(); ++j) {
      out.col(j) = w * q.col(j);
      for (SparseJacobian::InnerIterator f(jacobian_, j); f; ++f) {
        out.col(j) += f.value() * work_.col(f.index());
      }
    }
  }
  void dense_product(const Eigen::MatrixXd& p, const Eigen::MatrixXd& q, double w,
                     Eigen::MatrixXd& out) {
    out = dense_ * p * dense_.transpose() + w * q;
  }

  struct TracedMove {
    bool flow = false;
    double length = 0.0;
  };
  bool sparse_ = true;
  bool shaped_by_trace_ = false;  // jacobian_ has compressed_'s structure
  Matrix<Model::kStates, Model::kStates> dense_;
  SparseJacobian jacobian_;
  Eigen::MatrixXd work_;
  std::optional<CompressedJacobian> compressed_;
  std::optional<TracedMove> traced_;
  std::string traced_note_, note_;
};

}  // namespace nlobs::detail
