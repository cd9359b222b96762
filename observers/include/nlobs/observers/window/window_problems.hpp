#pragma once
// The problems a window poses ([MGFF23]), built once and re-evaluated on whatever the window
// holds at the time (the window must outlive them):
//   square_window_problem:  G(w) = w + Ψ (Y − H(w))     (N·p = n; Ψ = I, the paper's form, when
//                           no gain is given; any invertible Ψ has the same fixed points)
//   square_window_residual:  F(w) = Y − H(w) ∈ Rⁿ        (N·p = n; its Jacobian is −∂H/∂w)
//   window_residual_problem: F(w) = Y − H(w) ∈ R^{N·p}  (any N; least squares when N·p > n)
// Jacobians by forward-mode AD through the model. For fixed-size models the square problem
// evaluates without allocating.
#include <sstream>

#include "nlobs/observers/window/output_window.hpp"
#include "nlobs/solvers/problem.hpp"

namespace nlobs {

namespace detail {

template <DiscreteModel Model>
void require_square_window(const char* who, const OutputWindow<Model>& window) {
  if (window.rows() != window.states()) {
    std::ostringstream os;
    os << who << ": the window has " << window.rows() << " equations for " << window.states()
       << " states; use window_residual_problem (least squares)";
    throw InvalidInput(os.str());
  }
}

}  // namespace detail

// `gain`: Ψ (n × n), read at every evaluation (it may change between solves and must outlive
// the problem); nullptr = Ψ = I.
template <DiscreteModel Model>
FixedPointProblem<Model::kStates> square_window_problem(
    const OutputWindow<Model>& window,
    const Matrix<Model::kStates, Model::kStates>* gain = nullptr) {
  constexpr int N = Model::kStates;
  detail::require_square_window("square_window_problem", window);
  const OutputWindow<Model>* win = &window;
  return FixedPointProblem<N>::with_autodiff(
      [win, gain](const auto& w) {
        using T = typename std::decay_t<decltype(w)>::Scalar;
        Vector<N, T> h(w.size());
        win->map_into(Vector<N, T>(w), h);
        if (gain == nullptr) return Vector<N, T>(w + win->outputs().template cast<T>() - h);
        return Vector<N, T>(w + gain->template cast<T>() * (win->outputs().template cast<T>() - h));
      },
      window.states());
}

template <DiscreteModel Model>
RootProblem<Model::kStates, Model::kStates> square_window_residual(
    const OutputWindow<Model>& window) {
  constexpr int N = Model::kStates;
  detail::require_square_window("square_window_residual", window);
  const OutputWindow<Model>* win = &window;
  // Dense AD: a window's state is small, and a type-erased model (AnyModel) evaluates only double
  // and ceres::Jet, not the SparsityTracer that detection would pass.
  return RootProblem<N, N>::with_dense_autodiff(
      [win](const auto& w) {
        using T = typename std::decay_t<decltype(w)>::Scalar;
        Vector<N, T> h(w.size());
        win->map_into(Vector<N, T>(w), h);
        return Vector<N, T>(win->outputs().template cast<T>() - h);
      },
      window.states(), window.states());
}

template <DiscreteModel Model>
RootProblem<Model::kStates, Dynamic> window_residual_problem(const OutputWindow<Model>& window) {
  constexpr int N = Model::kStates;
  const OutputWindow<Model>* win = &window;
  return RootProblem<N, Dynamic>::with_dense_autodiff(  // (as square_window_residual)
      [win](const auto& w) {
        using T = typename std::decay_t<decltype(w)>::Scalar;
        return Vector<Dynamic, T>(win->residual(Vector<N, T>(w)));
      },
      window.states(), window.rows());
}

}  // namespace nlobs
