#pragma once
// A scenario's input signal as a schedule of knots (t_i, u_i): piecewise constant (steps) or
// piecewise linear (ramps), from the scenario file or from a CSV file of t, u1..um. The
// simulated plant samples it at t_k = k T and holds u_k over the sample.
#include <Eigen/Core>
#include <vector>

namespace nlobs {

// u(t) from knots t_0 < t_1 < … < t_{K−1} (finite) with values u_i (columns of `values`, m × K,
// finite): u_0 before t_0 and u_{K−1} from t_{K−1} on; in between u_i on [t_i, t_{i+1})
// (kPrevious) or the straight line from u_i to u_{i+1} (kLinear).
struct InputSchedule {
  enum class Interpolation { kPrevious, kLinear };
  std::vector<double> times;
  Eigen::MatrixXd values;  // m × K
  Interpolation interpolation = Interpolation::kPrevious;

  // Throws InvalidInput naming the knot (from 0): no knot, a time that is not finite or not
  // after the one before, a value that is not finite, `values` not `inputs` × K.
  void validate(Eigen::Index inputs) const;
  // u(t); t must not be NaN. A knot within `tolerance` after t counts as reached (t = k T
  // computed in floating point lands just before the knot at 0.9 when T = 0.3: 3 · 0.3 <
  // 0.9), and the line between knots is clamped to them.
  Eigen::VectorXd at(double t, double tolerance = 0.0) const;
};

}  // namespace nlobs
