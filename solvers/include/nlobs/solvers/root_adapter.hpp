#pragma once
// Root → fixed point: G(x) = x + Ψ F(x), ∂G = I + Ψ ∂F.
// Ψ = I is [MGFF23]'s choice for the square window; a scalar ψ damps (ψ < 0 flips the sign
// when ∂F ≈ +I); a matrix Ψ ≈ −(∂F)⁻¹ turns Picard into a chord/Newton-like iteration.
#include <cmath>
#include <sstream>
#include <variant>

#include "nlobs/solvers/problem.hpp"

namespace nlobs {

struct IdentityScaling {};

template <int N = Dynamic>
using Preconditioner = std::variant<IdentityScaling, double, Matrix<N, N>>;

template <int N>
FixedPointProblem<N> to_fixed_point(const RootProblem<N, N>& root,
                                    Preconditioner<N> psi = IdentityScaling{}) {
  const Index n = root.size();
  if (root.residual_size() != n) {
    std::ostringstream os;
    os << "to_fixed_point: F maps R^" << n << " to R^" << root.residual_size()
       << "; a fixed-point form needs a square system (use a least-squares engine)";
    throw InvalidInput(os.str());
  }
  if (const double* s = std::get_if<double>(&psi); s && !(std::isfinite(*s) && *s != 0.0)) {
    std::ostringstream os;
    os << "to_fixed_point: scalar Psi = " << *s << " must be finite and non-zero";
    throw InvalidInput(os.str());
  }
  if (const auto* m = std::get_if<Matrix<N, N>>(&psi)) {
    if (m->rows() != n || m->cols() != n) {
      std::ostringstream os;
      os << "to_fixed_point: Psi is " << m->rows() << "x" << m->cols() << ", expected " << n << "x"
         << n;
      throw InvalidInput(os.str());
    }
    if (!m->allFinite()) throw InvalidInput("to_fixed_point: Psi has non-finite entries");
  }

  using Vec = Vector<N>;
  using Jac = Matrix<N, N>;
  // Scratch for Ψ F(x) when Ψ is a matrix: an aliasing-free product without allocating.
  auto g = [root, psi, scratch = Vec(n)](const Vec& x, Vec& out) mutable {
    if (const auto* m = std::get_if<Matrix<N, N>>(&psi)) {
      root.evaluate(x, scratch);
      out.noalias() = *m * scratch;
      out += x;
    } else {
      root.evaluate(x, out);
      if (const double* s = std::get_if<double>(&psi)) out *= *s;
      out += x;
    }
  };
  // With Ψ = I the engines that solve G(x) − x = 0 get F itself (FixedPointProblem::residual).
  const bool identity = std::holds_alternative<IdentityScaling>(psi);
  auto f = [root](const Vec& x, Vec& out) { root.evaluate(x, out); };
  // F's sparse Jacobian is the residual form's (Ψ = I).
  auto with_sparse = [&root](FixedPointProblem<N> out) {
    if constexpr (N == Dynamic) {
      if (root.sparse_jacobian_state()) {
        return out.with_sparse_jacobian_state(root.sparse_jacobian_state());
      }
    }
    return out;
  };
  if (!root.has_jacobian()) {
    FixedPointProblem<N> out = FixedPointProblem<N>::from_map(std::move(g), n);
    return identity ? with_sparse(out.with_residual(std::move(f))) : out;
  }
  // A problem with a sparse Jacobian (declared, or to be detected) may be too large for a dense
  // one: its scratch is sized only if a dense Jacobian is ever asked for.
  const bool lazy = N == Dynamic && root.sparse_jacobian_state() != nullptr;
  auto dg = [root, psi, scratch = lazy ? Jac() : Jac(n, n)](const Vec& x, Jac& jac) mutable {
    if constexpr (N == Dynamic) {
      if (scratch.rows() != root.size()) scratch.resize(root.size(), root.size());
    }
    root.jacobian(x, scratch);
    if (const auto* m = std::get_if<Matrix<N, N>>(&psi)) {
      jac.noalias() = *m * scratch;
    } else {
      jac = scratch;
      if (const double* s = std::get_if<double>(&psi)) jac *= *s;
    }
    jac.diagonal().array() += 1.0;
  };
  FixedPointProblem<N> out =
      FixedPointProblem<N>::with_jacobian(std::move(g), std::move(dg), n, root.jacobian_source());
  if (!identity) return out;
  return with_sparse(out.with_residual(std::move(f), [root](const Vec& x, Jac& jac) {
    if constexpr (N == Dynamic) jac.resize(root.size(), root.size());
    root.jacobian(x, jac);
  }));
}

}  // namespace nlobs
