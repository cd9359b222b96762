#include "nlobs/observers/modulating/modulating_kernel.hpp"

#include <Eigen/QR>
#include <boost/math/quadrature/gauss.hpp>
#include <cmath>
#include <sstream>

#include "nlobs/common/printable.hpp"
#include "nlobs/solvers/engine_registry.hpp"
#include "nlobs/solvers/problem.hpp"

namespace nlobs {
namespace {

// l!/(l−i)!: the factor d^i/dσ^i brings down from σ^l.
double falling(int l, int i) {
  double f = 1.0;
  for (int k = 0; k < i; ++k) f *= static_cast<double>(l - k);
  return f;
}

// ‖Q_Jᵀ r‖ relative to ‖r0‖: the cost then exceeds its minimum by ~1e-12 relative (it is
// quadratic in the gradient's error) — far below what the kernel's shape can show.
constexpr double kGradientTolerance = 1e-6;

[[noreturn]] void fail(const std::string& what) {
  throw InvalidInput("modulating kernel: " + what);
}

}  // namespace

SolverOptions modulating_kernel_solver_options() {
  SolverOptions solver;
  solver.stop.step_tolerance = 1e-14;
  solver.stop.max_iterations = 200;
  return solver;
}

ModulatingKernels::ModulatingKernels(int n, double horizon, ModulatingKernelOptions options,
                                     std::unique_ptr<Engine<Eigen::Dynamic>> engine)
    : n_(n),
      r_(options.order == 0 ? n : options.order),
      d_(0),
      T_(horizon),
      engine_(engine ? engine->label() : std::string("ceres")) {
  if (n < 1) fail("the number of canonical states n must be >= 1");
  if (!(horizon > 0.0) || !std::isfinite(horizon)) fail("horizon must be finite and > 0");
  if (r_ < n) {
    std::ostringstream os;
    os << "order " << r_ << " is below n = " << n
       << ": the boundary terms of y⁽ⁱ⁾, i < n, would not vanish at t − T";
    fail(os.str());
  }
  d_ = options.degree == 0 ? r_ + n - 1 : options.degree;
  if (d_ < r_ + n - 1) {
    std::ostringstream os;
    os << "degree " << d_ << " is below order + n − 1 = " << r_ + n - 1
       << " (too few coefficients for the boundary conditions)";
    fail(os.str());
  }
  if (d_ > kMaxDegree) {
    fail("degree " + std::to_string(d_) + " is above " + std::to_string(kMaxDegree));
  }
  abar_ = Eigen::VectorXd::Zero(n + 1);
  abar_[n] = 1.0;
  if (options.noise_weights.size() != 0) {
    if (options.noise_weights.size() != n || !options.noise_weights.allFinite()) {
      fail("noise_weights must be n = " + std::to_string(n) + " finite numbers (ā_0…ā_{n−1})");
    }
    abar_.head(n) = options.noise_weights;
  }

  // Unknowns c_r…c_d (c_k = 0 for k < r is the left condition); the right conditions
  // Σ_l c_l l!/(l−k)! = T^k δ_kj are A c = T^k e_j.
  const int m = d_ - r_ + 1;
  Eigen::MatrixXd A(n, m);
  for (int k = 0; k < n; ++k) {
    for (int l = 0; l < m; ++l) A(k, l) = falling(r_ + l, k);
  }
  // A = Rᵀ Q₁ᵀ through the QR of Aᵀ: the particular solution Q₁ R⁻ᵀ b and the null space Q₂.
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(A.transpose());
  const Eigen::MatrixXd Q = qr.householderQ();
  const Eigen::MatrixXd R = qr.matrixQR().topRows(n).triangularView<Eigen::Upper>();
  const Eigen::MatrixXd Q1 = Q.leftCols(n), Q2 = Q.rightCols(m - n);

  // The cost's residual at 30 Gauss–Legendre nodes on [0, 1] (σ = (1 + x)/2): r = G c, with
  // G(q, l) = √(T w_q / 2) Σ_i (−1)^i ā_i T^{−i} l!/(l−i)! σ_q^{l−i}. Exact for 2d ≤ 59.
  using Gauss = boost::math::quadrature::gauss<double, 30>;
  const auto& x = Gauss::abscissa();
  const auto& w = Gauss::weights();
  const int nodes = 2 * static_cast<int>(x.size());
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(nodes, m);
  for (int q = 0; q < nodes; ++q) {
    const size_t half = static_cast<size_t>(q / 2);
    const double sigma = (1.0 + (q % 2 ? -x[half] : x[half])) / 2.0;
    const double scale = std::sqrt(T_ * w[half] / 2.0);
    for (int l = 0; l < m; ++l) {
      const int power = r_ + l;
      double g = 0.0;
      for (int i = 0; i <= std::min(n, power); ++i) {
        g += (i % 2 ? -1.0 : 1.0) * abar_[i] * std::pow(T_, -i) * falling(power, i) *
             std::pow(sigma, power - i);
      }
      G(q, l) = scale * g;
    }
  }

  C_ = Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic>::Zero(d_ + 1, n);
  if (m > n) {
    if (!engine) {
      engine = EngineRegistry<Eigen::Dynamic>::global().create("ceres",
                                                               modulating_kernel_solver_options());
    }
    if (!engine->least_squares()) {
      fail("engine '" + engine_ + "' solves square systems only; use ceres or nlopt");
    }
  }
  for (int j = 0; j < n; ++j) {
    Eigen::VectorXd b = Eigen::VectorXd::Zero(n);
    b[j] = std::pow(T_, j);
    const Eigen::VectorXd particular = Q1 * R.transpose().triangularView<Eigen::Lower>().solve(b);
    Eigen::VectorXd c = particular;
    if (m > n) {
      // min_p ‖r0 + J p‖, J = G Q₂: linear least squares, solved by the engine in the
      // coordinates q = R_J p (J = Q_J R_J), where the problem is r0 + Q_J q — perfectly
      // conditioned, so the engine's tolerances do not meet the monomial basis' conditioning.
      const Eigen::MatrixXd J = G * Q2;
      const Eigen::HouseholderQR<Eigen::MatrixXd> jqr(J);
      const Eigen::MatrixXd QJ = jqr.householderQ() * Eigen::MatrixXd::Identity(nodes, m - n);
      const Eigen::MatrixXd RJ = jqr.matrixQR().topRows(m - n).triangularView<Eigen::Upper>();
      const Eigen::VectorXd r0 = G * particular;
      auto problem = RootProblem<Eigen::Dynamic, Eigen::Dynamic>::with_jacobian(
          [&](const Eigen::VectorXd& q, Eigen::VectorXd& res) { res = r0 + QJ * q; },
          [&](const Eigen::VectorXd&, Eigen::MatrixXd& jac) { jac = QJ; }, m - n, nodes);
      Eigen::VectorXd q = Eigen::VectorXd::Zero(m - n);
      // The optimum of a linear least-squares problem: the gradient Q_Jᵀ r vanishes. Engines
      // stop on the step or the relative cost change (Levenberg–Marquardt's damped first step
      // leaves ~1e-4 of the gradient), so restart from the result until the gradient is gone.
      Summary s;
      Eigen::VectorXd gradient = QJ.transpose() * r0;
      for (int pass = 0; pass < 6 && gradient.norm() > kGradientTolerance * (1.0 + r0.norm());
           ++pass) {
        try {
          s = engine->solve_least_squares(problem, q);
        } catch (...) {  // an engine by name may be a user's: whatever it throws is named
          fail("engine '" + engine_ +
               "' failed on the noise-optimal kernel: " + current_exception_text());
        }
        gradient = QJ.transpose() * (r0 + QJ * q);
      }
      if (!q.allFinite() || gradient.norm() > kGradientTolerance * (1.0 + r0.norm())) {
        std::ostringstream os;
        os << "the noise-optimal kernel " << j << " did not converge with engine '" << engine_
           << "' (status " << to_string(s.status) << ", ‖Jᵀr‖ " << gradient.norm() << ")";
        fail(os.str());
      }
      summary_ = s;  // its engine name is its own copy (EngineName): valid after the engine
      c = particular + Q2 * RJ.triangularView<Eigen::Upper>().solve(q);
    }
    // Monomial coefficients of a degree-d kernel alternate in sign and grow like 2^d: the
    // boundary sums cancel to ~1e-11 in double. Refine them in long double (two Newton steps on
    // A c = b with the residual in extended precision) and evaluate in long double.
    Eigen::Matrix<long double, Eigen::Dynamic, 1> refined = c.cast<long double>();
    for (int pass = 0; pass < 2; ++pass) {
      Eigen::VectorXd residual(n);
      for (int k = 0; k < n; ++k) {
        long double sum = 0.0L;
        for (int l = 0; l < m; ++l) sum += refined[l] * static_cast<long double>(A(k, l));
        residual[k] = static_cast<double>(sum - static_cast<long double>(b[k]));
      }
      const Eigen::VectorXd correction =
          Q1 * R.transpose().triangularView<Eigen::Lower>().solve(residual);
      refined -= correction.cast<long double>();
    }
    C_.col(j).tail(m) = refined;
  }
}

double ModulatingKernels::value(int j, int i, double s) const {
  const long double sigma = static_cast<long double>(s) / T_;
  long double v = 0.0L;  // Horner on the i-th derivative's coefficients
  for (int k = d_; k >= i; --k) v = v * sigma + C_(k, j) * static_cast<long double>(falling(k, i));
  return static_cast<double>(v * std::pow(static_cast<long double>(T_), -i));
}

double ModulatingKernels::noise_gain(int j) const {
  using Gauss = boost::math::quadrature::gauss<double, 30>;
  const auto f = [&](double sigma) {
    double g = 0.0;
    for (int i = 0; i <= n_; ++i) g += (i % 2 ? -1.0 : 1.0) * abar_[i] * value(j, i, sigma * T_);
    return g * g;
  };
  return std::sqrt(T_ * Gauss::integrate(f, 0.0, 1.0));
}

}  // namespace nlobs
