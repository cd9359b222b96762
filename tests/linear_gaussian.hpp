#pragma once
// A linear Gaussian model nlobs does not ship and the Kalman filter written out against it, the
// reference the Kalman-type observers (EKF, UKF, MHE) are tested with: independent of the
// library's filters.
#include <Eigen/Dense>
#include <cmath>
#include <vector>

#include "nlobs/models/model.hpp"

namespace nlobs::test {

// x⁺ = A x + B u, y = C x: three states, one input, two outputs, a map in discrete time (no
// flow: a fixed step).
struct Linear3 : ModelSizes<3, 1, 2> {
  Eigen::Matrix3d a{{0.95, 0.1, 0.0}, {-0.1, 0.9, 0.05}, {0.0, 0.02, 0.99}};
  Eigen::Vector3d b{0.0, 1.0, 0.5};
  Eigen::Matrix<double, 2, 3> c{{1.0, 0.0, 1.0}, {0.0, 1.0, 0.0}};
  template <typename T>
  State<T> f(const State<T>& x, const Input& u, long) const {
    return a.cast<T>() * x + (b * u[0]).cast<T>();
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return c.cast<T>() * x;
  }
};

inline const Eigen::Matrix3d kLinearQ = 1e-3 * Eigen::Matrix3d::Identity();
inline const Eigen::Matrix2d kLinearR{{1e-2, 2e-3}, {2e-3, 5e-3}};
inline const Eigen::Matrix3d kLinearP0{{1.0, 0.1, 0.0}, {0.1, 2.0, 0.0}, {0.0, 0.0, 0.5}};
inline const Eigen::Vector3d kLinearPrior(0.5, -0.2, 0.1);

// The options of any Kalman-type observer (EkfOptions, UkfOptions, MheOptions) with the
// statistics above.
template <typename Options>
Options linear_statistics(Options o) {
  o.initial_estimate = kLinearPrior;
  o.process_covariance = kLinearQ;
  o.measurement_covariance = kLinearR;
  o.initial_covariance = kLinearP0;
  return o;
}

// The Kalman filter for x⁺ = Φ x + Γ u + w, w ~ (0, weight · Q), y = C x + v, v ~ (0, R):
// update with the measured (finite) entries of y, predict along a given transition.
struct KalmanReference {
  Eigen::Matrix<double, 2, 3> c = Linear3{}.c;
  Eigen::Matrix3d q = kLinearQ;
  Eigen::Matrix2d r = kLinearR;
  Eigen::Vector3d x = kLinearPrior;
  Eigen::Matrix3d p = kLinearP0;

  void update(const Eigen::Vector2d& y) {
    std::vector<Eigen::Index> rows;
    for (Eigen::Index i = 0; i < 2; ++i) {
      if (std::isfinite(y[i])) rows.push_back(i);
    }
    if (rows.empty()) return;
    const Eigen::MatrixXd cm = c(rows, Eigen::all);
    const Eigen::MatrixXd rm = r(rows, rows);
    const Eigen::VectorXd ym = y(rows);
    const Eigen::MatrixXd s = cm * p * cm.transpose() + rm;
    const Eigen::MatrixXd k = p * cm.transpose() * s.inverse();
    x += k * (ym - cm * x);
    p = (Eigen::Matrix3d::Identity() - k * cm) * p;
  }
  void predict(const Eigen::Matrix3d& phi, const Eigen::Vector3d& gamma_u, double weight = 1.0) {
    x = phi * x + gamma_u;
    p = phi * p * phi.transpose() + weight * q;
  }
  // Update with y, then predict along Linear3 with input u; returns the filtered estimate.
  Eigen::Vector3d step(const Eigen::Vector2d& y, double u) {
    update(y);
    const Eigen::Vector3d filtered = x;
    const Linear3 model;
    predict(model.a, model.b * u);
    return filtered;
  }
};

}  // namespace nlobs::test
