#pragma once
// The modified-Chua window problem of METHODS §1, shared by the CLI and the benchmarks:
// true initial state [1.0, 2.1428, −0.1648], the window of its first three outputs,
// initial guess [5, 10, −5]. Its fixed point is the true initial state.
#include <Eigen/Core>

#include "nlobs/models/modified_chua.hpp"
#include "nlobs/observers/window_map.hpp"

namespace nlobs::reference {

struct ChuaWindowCase {
  using Map = WindowMap<ModifiedChua, 3>;
  Map map{ModifiedChua{}};
  Eigen::Vector3d true_state{1.0, 2.1428, -0.1648};
  Eigen::Vector3d initial_guess{5.0, 10.0, -5.0};
  Eigen::Vector3d outputs = simulate_window_outputs(map, true_state);
  // G(w) = w + (Y − H(w)), ∂G by forward-mode AD.
  FixedPointProblem<3> problem = window_fixed_point_problem(map, outputs);
};

}  // namespace nlobs::reference
