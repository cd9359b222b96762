#pragma once
// The FitzHugh–Nagumo neuron (FitzHugh, Biophys. J. 1, 1961), a model nlobs does not ship:
//   x1' = x1 − x1³/3 − x2 + I,   x2' = ε (x1 + a − b x2),   y = x1 (the membrane potential).
// One output, no input and y = [1 0] x: besides the window estimators, EKF, Luenberger and
// sliding mode, the MVT and high-gain observers accept it.
#include "nlobs/models/model.hpp"

namespace example {

struct FitzHughNagumo : nlobs::ModelSizes<2, 0, 1> {
  double a = 0.7, b = 0.8, epsilon = 0.08, current = 0.5;  // a limit cycle

  template <typename T>
  State<T> vector_field(const State<T>& x, const Input&, double) const {
    State<T> dx;
    dx << x[0] - x[0] * x[0] * x[0] / 3.0 - x[1] + current, epsilon * (x[0] + a - b * x[1]);
    return dx;
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return x.template head<1>();
  }
};

}  // namespace example
