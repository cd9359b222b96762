#pragma once
// The modified-Chua window problem of [MGFF23], shared by the CLI, tests and benchmarks:
// true initial state [1.0, 2.1428, −0.1648], the window of its first three outputs, initial
// guess [5, 10, −5]. Its fixed point is the true initial state. As a problem set
// (`nlobs suite chua-window`): that problem from the paper's guess scaled by 1 and 10.
#include <Eigen/Core>
#include <memory>

#include "nlobs/models/modified_chua.hpp"
#include "nlobs/observers/window/window_problems.hpp"
#include "nlobs/registry/problem_sets.hpp"

namespace nlobs::reference {

struct ChuaWindowCase {
  using Model = Discretized<ModifiedChua>;
  Eigen::Vector3d true_state{1.0, 2.1428, -0.1648};
  Eigen::Vector3d initial_guess{5.0, 10.0, -5.0};
  // Behind a pointer: the problems below refer to the window.
  std::unique_ptr<OutputWindow<Model>> window = filled_window(true_state, 3);
  // G(w) = w + (Y − H(w)), ∂G by forward-mode AD.
  FixedPointProblem<3> problem = square_window_problem(*window);

  // The paper's model observed from x0 for `length` noise-free samples.
  static std::unique_ptr<OutputWindow<Model>> filled_window(const Eigen::Vector3d& x0,
                                                            Eigen::Index length) {
    auto w = std::make_unique<OutputWindow<Model>>(paper_modified_chua(), length);
    Eigen::Vector3d x = x0;
    const Eigen::VectorXd u(0);
    for (long k = 0; k < length; ++k) {
      w->push(k, w->model().h(x), u);
      x = w->model().f(x, Model::Input(), k);
    }
    return w;
  }
};

}  // namespace nlobs::reference

namespace nlobs {
// The built-in set "chua-window": one fixed-point problem "window" (n = 3), starts "x1" and
// "x10" (the paper's guess times 1 and 10), the true initial state as its known solution.
ProblemSetEntry chua_window_problem_set();
}  // namespace nlobs
