#pragma once
// KINSOL's scaling of a square system (KINSol's u_scale and f_scale): the engine's norms are those
// of D_u x and D_f F, D_u = diag(u_scale), D_f = diag(f_scale). A Newton-type engine that takes
// one (Engine::set_scaling) solves the same system in the scaled variables x̃ = D_u x,
//   F̃(x̃) = D_f F(D_u⁻¹ x̃),   J̃ = D_f J D_u⁻¹,
// (as a fixed-point problem G̃(x̃) = x̃ + F̃(x̃)): the Newton step is the same step, and every test
// an engine makes of ‖F‖ and ‖Δx‖ — residual and step tolerances, the line search's and the trust
// region's merit ½‖F‖₂², the trust region ‖Δx‖₂ ≤ Δ, stagnation, the rounding floor,
// acceptance — is then made of ‖D_f F‖ and ‖D_u Δx‖ ([SUNDIALS05], KINSOL; [DS96] §7.1).
// A problem's sparse Jacobian is scaled alike (D_f J D_u⁻¹, the same pattern): newton and
// pseudo-transient keep their sparse path under a scaling.
// Summary::residual_norm and step_norm are those scaled norms; x and the trace's points are
// returned in the problem's own variables. Pseudo-transient continuation, not affine invariant,
// follows the scaled flow ẋ = −D_u⁻¹ D_f F (a mass matrix D_f⁻¹ D_u in [KK98]'s form).
// Choose D_u so that D_u x is of order 1 and D_f so that D_f F is, as KINSOL asks.
#include <Eigen/Core>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <string_view>
#include <tuple>

#include "nlobs/solvers/box_bounds.hpp"
#include "nlobs/solvers/problem.hpp"

namespace nlobs {

struct Scaling {
  // Each empty (ones) or of the problem's size, finite and > 0.
  Eigen::VectorXd u_scale{}, f_scale{};
  bool empty() const { return u_scale.size() == 0 && f_scale.size() == 0; }
};

namespace detail {

// The sparse Jacobian of the scaled problem below, ∂F̃(x̃) = D_f ∂F(x) D_u⁻¹ at x = D_u⁻¹ x̃ held
// inside `box`, on `original`'s pattern: the scaled problem keeps the sparse path
// (src/scaled_sparse_jacobian.cpp). An exact source (AD) is scaled entry by entry; a
// difference source differences `scaled_f` (F̃) in x̃ instead, with steps in the scaled
// variables, as the dense path's differences of the scaled problem take them. Resolved
// (detected, if the original is still to be) at the first point an engine asks with; declared
// when the original is.
using ScaledResidual = std::function<void(const Vector<Dynamic>&, Vector<Dynamic>&)>;
std::shared_ptr<SparseJacobianState> scaled_sparse_jacobian_state(
    std::shared_ptr<SparseJacobianState> original, const Vector<Dynamic>& du,
    const Vector<Dynamic>& df, const BoxBounds& box, ScaledResidual scaled_f);

// Entries finite and > 0, the two of one size where both are given. Throws InvalidInput naming
// `owner`.
inline void validate_scaling(std::string_view owner, const Scaling& s) {
  auto check = [owner](const Eigen::VectorXd& d, const char* name) {
    for (Index i = 0; i < d.size(); ++i) {
      if (!(d[i] > 0.0) || !std::isfinite(d[i])) {
        std::ostringstream os;
        os << owner << ": " << name << "[" << i << "] = " << d[i] << " is not finite and > 0";
        throw InvalidInput(os.str());
      }
    }
  };
  check(s.u_scale, "u_scale");
  check(s.f_scale, "f_scale");
  if (s.u_scale.size() > 0 && s.f_scale.size() > 0 && s.u_scale.size() != s.f_scale.size()) {
    std::ostringstream os;
    os << owner << ": u_scale and f_scale differ in size (" << s.u_scale.size() << " vs "
       << s.f_scale.size() << ")";
    throw InvalidInput(os.str());
  }
}

// The scales at the problem's size n (ones where a side is empty); InvalidInput for another size.
template <int N>
void scaling_for(std::string_view owner, const Scaling& s, Index n, Vector<N>& du, Vector<N>& df) {
  for (const auto& [given, out, name] :
       {std::tuple{&s.u_scale, &du, "u_scale"}, std::tuple{&s.f_scale, &df, "f_scale"}}) {
    if (given->size() != 0 && given->size() != n) {
      std::ostringstream os;
      os << owner << ": " << name << " has size " << given->size()
         << " but the problem has dimension " << n;
      throw InvalidInput(os.str());
    }
    if constexpr (N == Dynamic) out->resize(n);
    if (given->size() == n) {
      *out = *given;
    } else {
      out->setOnes();
    }
  }
}

// F̃(x̃) = D_f F(x) with x = D_u⁻¹ x̃ held inside `box` (rounding in the round trip D_u⁻¹(D_u b)
// must not step past a bound b), as the fixed-point problem G̃(x̃) = x̃ + F̃(x̃) with F̃ as its
// residual form, and ∂F̃ = D_f ∂F D_u⁻¹ when the problem has a Jacobian (else the engine
// differences G̃, in the scaled variables). F is the problem's own residual form when it has one
// (FixedPointProblem::residual): formed as G(x) − x it would carry D_f,i·ulp(x_i) of rounding.
// Holds `problem` by reference; point buffers sized here: an evaluation allocates nothing.
template <int N>
FixedPointProblem<N> scaled_problem(const FixedPointProblem<N>& problem, const Vector<N>& du,
                                    const Vector<N>& df, const BoxBounds& box) {
  const FixedPointProblem<N>* p = &problem;
  const Vector<N> inverse_du = du.cwiseInverse();
  const Index n = problem.size();
  Box<N> limits;
  limits.set(box, n);
  // x = D_u⁻¹ x̃, inside the box (off its strict sides); then F̃ = D_f F(x) into `out`.
  auto scaled_f = [p, inverse_du, df, limits, x = Vector<N>(inverse_du), g = Vector<N>(inverse_du)](
                      const Vector<N>& xs, Vector<N>& out) mutable {
    for (Index i = 0; i < x.size(); ++i) x[i] = limits.clamp(i, xs[i] * inverse_du[i]);
    if (p->has_residual()) {
      p->residual(x, out);
      check_output_size(*p, out);
      out = df.cwiseProduct(out);
    } else {
      p->evaluate(x, g);
      check_output_size(*p, g);
      out = df.cwiseProduct(g - x);
    }
  };
  auto map = [scaled_f](const Vector<N>& xs, Vector<N>& out) mutable {
    scaled_f(xs, out);
    out += xs;
  };
  // The problem's sparse Jacobian, scaled alike: the sparse path stays open under a scaling.
  const auto with_sparse = [&problem, &du, &df, &box, scaled_f](FixedPointProblem<N> out) {
    if constexpr (N == Dynamic) {
      if (problem.sparse_jacobian_state()) {
        return out.with_sparse_jacobian_state(scaled_sparse_jacobian_state(
            problem.sparse_jacobian_state(), du, df, box, ScaledResidual(scaled_f)));
      }
    }
    return out;
  };
  if (!problem.has_jacobian()) {
    return with_sparse(
        FixedPointProblem<N>::from_map(std::move(map), n).with_residual(std::move(scaled_f)));
  }
  auto scaled_df = [p, inverse_du, df, limits, x = Vector<N>(inverse_du)](
                       const Vector<N>& xs, Matrix<N, N>& jac) mutable {
    for (Index i = 0; i < x.size(); ++i) x[i] = limits.clamp(i, xs[i] * inverse_du[i]);
    if (p->has_residual()) {
      p->residual_jacobian(x, jac);
    } else {
      p->jacobian(x, jac);
      if (jac.rows() == jac.cols()) jac.diagonal().array() -= 1.0;
    }
    if (jac.rows() != x.size() || jac.cols() != x.size()) {
      std::ostringstream os;
      os << "the Jacobian is " << jac.rows() << "x" << jac.cols() << ", expected " << x.size()
         << "x" << x.size();
      throw InvalidInput(os.str());
    }
    jac.array().colwise() *= df.array();
    jac.array().rowwise() *= inverse_du.transpose().array();
  };
  auto dmap = [scaled_df](const Vector<N>& xs, Matrix<N, N>& jac) mutable {
    scaled_df(xs, jac);
    jac.diagonal().array() += 1.0;
  };
  return with_sparse(FixedPointProblem<N>::with_jacobian(std::move(map), std::move(dmap), n,
                                                         problem.jacobian_source())
                         .with_residual(std::move(scaled_f), std::move(scaled_df)));
}

// lower and upper times D_u (±inf and empty sides stay as they are).
inline BoxBounds scaled_bounds(const BoxBounds& b, const Eigen::VectorXd& du) {
  BoxBounds out = b;
  if (du.size() == 0) return out;
  for (Eigen::VectorXd* side : {&out.lower, &out.upper}) {
    if (side->size() == du.size()) *side = side->cwiseProduct(du);
  }
  return out;
}

}  // namespace detail
}  // namespace nlobs
