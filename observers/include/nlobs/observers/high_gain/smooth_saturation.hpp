#pragma once
// The smooth saturation of [HG-EMB23] that makes α globally Lipschitz:
//   ᾱ(z) = s_{ρ²}(‖z‖²_P / R²) α(z),   ‖z‖²_P = zᵀ P z,
//   s_b(x) = 1 for x ≤ 1, 0 for x ≥ b, e^{1/(x−b)} / (e^{1/(x−b)} + e^{1/(1−x)}) between
// (C^∞). ᾱ = α on ‖z‖_P ≤ R and 0 beyond ‖z‖_P = ρR: the transition runs between R and ρR, as
// the paper states ("between 1 ≤ ‖z‖ ≤ 2, i.e. R = 1 and ρ = 2"); our working notes wrote s_ρ,
// whose transition would end at √ρ R — we follow the paper's words, see docs/observers.md. And the
// recipe of [HG-EMB23] §6 for P: a box |x_i| ≤ X_i around the invariant set maps into a box |z_j| ≤
// Z_j (here by interval arithmetic through the map — a rigorous enclosure, like the paper's sum of
// |terms|), and ‖z‖²_P = Σ z_j² / (N Z_j²) ≤ 1 on it.
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <boost/numeric/interval.hpp>
#include <cmath>
#include <sstream>
#include <string>

#include "nlobs/observers/core/eigen_scalar.hpp"
#include "nlobs/solvers/status.hpp"

namespace nlobs {

// s_b(x), generic in the scalar (ceres::Jet gives ∂ᾱ/∂z for implicit integration).
template <typename T>
T smooth_step(const T& x, double b) {
  using std::exp;
  if (x <= 1.0) return T(1.0);
  if (x >= b) return T(0.0);
  // e^{1/(x−b)} / (e^{1/(x−b)} + e^{1/(1−x)}) = 1 / (1 + e^{1/(1−x) − 1/(x−b)}), no overflow
  const T exponent = 1.0 / (1.0 - x) - 1.0 / (x - b);
  if (exponent > 700.0) return T(0.0);
  return 1.0 / (1.0 + exp(exponent));
}

struct SmoothSaturation {
  Eigen::MatrixXd P;  // N×N, symmetric positive definite
  double R = 1.0;     // ᾱ = α for ‖z‖_P ≤ R
  double rho = 2.0;   // ᾱ = 0 for ‖z‖_P ≥ ρR (ρ > 1)

  // Throws InvalidInput naming the field.
  void validate(Eigen::Index N) const {
    const auto fail = [](const std::string& what) {
      throw InvalidInput("SmoothSaturation: " + what);
    };
    if (P.rows() != N || P.cols() != N) {
      std::ostringstream os;
      os << "P must be " << N << "x" << N << " (the embedding dimension), got " << P.rows() << "x"
         << P.cols();
      fail(os.str());
    }
    if (!P.allFinite() || !P.isApprox(P.transpose(), 1e-12)) fail("P must be finite and symmetric");
    Eigen::LLT<Eigen::MatrixXd> llt(P);
    if (llt.info() != Eigen::Success || !(P.diagonal().minCoeff() > 0.0)) {
      fail("P is not positive definite");
    }
    if (!(R > 0.0) || !std::isfinite(R)) fail("R must be finite and > 0");
    if (!(rho > 1.0) || !std::isfinite(rho)) fail("rho must be finite and > 1");
  }

  // s_{ρ²}(zᵀPz / R²)
  template <typename T, int N>
  T factor(const Eigen::Matrix<T, N, 1>& z) const {
    T q = T(0.0);
    for (Eigen::Index i = 0; i < z.size(); ++i) {
      for (Eigen::Index j = 0; j < z.size(); ++j) q += P(i, j) * z[i] * z[j];
    }
    return smooth_step(T(q / (R * R)), rho * rho);
  }
};

namespace detail {
using Interval = boost::numeric::interval<double>;
}  // namespace detail

}  // namespace nlobs

namespace Eigen {
template <>
struct NumTraits<nlobs::detail::Interval> : nlobs::DoubleLikeNumTraits<nlobs::detail::Interval> {};
}  // namespace Eigen

namespace nlobs {

// Z_j ≥ sup |q_j(x)| over the box |x_i| ≤ X_i, for a map generic in its scalar (the
// ExplicitObservabilityMap form). Interval arithmetic over-estimates (each occurrence of x_i
// varies independently) but never under-estimates.
template <typename Map>
Eigen::VectorXd embedded_box_bound(const Map& map, const Eigen::VectorXd& X) {
  constexpr int n = Map::kStates, N = Map::kDimension;
  if (X.size() != n || !X.allFinite() || !(X.minCoeff() > 0.0)) {
    throw InvalidInput("embedded_box_bound: the box needs " + std::to_string(n) +
                       " finite half-widths X_i > 0");
  }
  Eigen::Matrix<detail::Interval, n, 1> box;
  for (int i = 0; i < n; ++i) box[i] = detail::Interval(-X[i], X[i]);
  const Eigen::Matrix<detail::Interval, N, 1> z = map(box);
  Eigen::VectorXd Z(N);
  for (int j = 0; j < N; ++j) Z[j] = boost::numeric::norm(z[j]);  // max |z_j|
  return Z;
}

// P = diag(1 / (N Z_j²)): ‖z‖_P ≤ 1 on the box |z_j| ≤ Z_j (then R = 1).
inline Eigen::MatrixXd saturation_weight_from_box(const Eigen::VectorXd& Z) {
  if (Z.size() == 0 || !Z.allFinite() || !(Z.minCoeff() > 0.0)) {
    throw InvalidInput("saturation_weight_from_box: every Z_j must be finite and > 0");
  }
  const double N = static_cast<double>(Z.size());
  return (1.0 / (N * Z.array().square())).matrix().asDiagonal();
}

}  // namespace nlobs
