#pragma once
// The moving-horizon window map of METHODS §1 for a discrete model x⁺ = f(x), y = h(x):
//   H(w) = [h(w), h(f(w)), …, h(f^{W−1}(w))] ∈ R^{W·p},
// its root problem F(w) = Y − H(w) and, for a square window (W·p = n), the fixed-point form
// G(w) = w + (Y − H(w)) (Ψ = I, the paper's choice). The solution w* is the state at the
// window's first sample; x̂ at its last sample is f^{W−1}(w*).
#include <Eigen/Core>

#include "nlobs/solvers/problem.hpp"
#include "nlobs/solvers/root_adapter.hpp"

namespace nlobs {

template <typename Model, int Window>
class WindowMap {
 public:
  static constexpr int kStates = Model::kStates;
  static constexpr int kOutputs = Model::kOutputs;
  static constexpr int kRows = Window * Model::kOutputs;
  template <typename T>
  using State = Eigen::Matrix<T, kStates, 1>;
  template <typename T>
  using Outputs = Eigen::Matrix<T, kRows, 1>;

  explicit WindowMap(Model model) : model_(std::move(model)) {}
  const Model& model() const { return model_; }

  template <typename T>
  Outputs<T> operator()(const State<T>& w) const {
    Outputs<T> out;
    State<T> x = w;
    for (int k = 0; k < Window; ++k) {
      out.template segment<kOutputs>(k * kOutputs) = model_.h(x);
      if (k + 1 < Window) x = model_.f(x);
    }
    return out;
  }

  // f^{W−1}(w): the state at the window's last sample.
  State<double> last_state(const State<double>& w) const {
    State<double> x = w;
    for (int k = 1; k < Window; ++k) x = model_.f(x);
    return x;
  }

 private:
  Model model_;
};

// F(w) = Y − H(w), Jacobian by forward-mode AD through the model.
template <typename Model, int Window>
RootProblem<Model::kStates, Window * Model::kOutputs> window_root_problem(
    const WindowMap<Model, Window>& map,
    const Eigen::Matrix<double, Window * Model::kOutputs, 1>& outputs) {
  constexpr int n = Model::kStates, rows = Window * Model::kOutputs;
  auto residual = [map, outputs](const auto& w) {
    using T = typename std::decay_t<decltype(w)>::Scalar;
    return Eigen::Matrix<T, rows, 1>(outputs.template cast<T>() - map(w));
  };
  return RootProblem<n, rows>::with_autodiff(residual);
}

// Square window: G(w) = w + (Y − H(w)), ∂G by forward-mode AD. Built directly rather than
// through to_fixed_point() so that one evaluation of G costs one type-erased call.
template <typename Model, int Window>
FixedPointProblem<Model::kStates> window_fixed_point_problem(
    const WindowMap<Model, Window>& map,
    const Eigen::Matrix<double, Window * Model::kOutputs, 1>& outputs) {
  static_assert(Window * Model::kOutputs == Model::kStates,
                "the fixed-point form needs a square window (W·p = n); use a least-squares "
                "engine for longer windows");
  constexpr int n = Model::kStates;
  auto g = [map, outputs](const auto& w) {
    using T = typename std::decay_t<decltype(w)>::Scalar;
    return Eigen::Matrix<T, n, 1>(w + (outputs.template cast<T>() - map(w)));
  };
  return FixedPointProblem<n>::with_autodiff(g);
}

// Noise-free outputs of the first W samples from x0: Y = H(x0).
template <typename Model, int Window>
Eigen::Matrix<double, Window * Model::kOutputs, 1> simulate_window_outputs(
    const WindowMap<Model, Window>& map, const Eigen::Matrix<double, Model::kStates, 1>& x0) {
  return map(x0);
}

}  // namespace nlobs
