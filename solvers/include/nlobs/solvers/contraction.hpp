#pragma once
// Contraction check on a box D = [lower, upper] ([MGFF23], the paper's Theorem 1). Samples D
// (its corners, its centre and seeded uniform points), evaluates ∂G there and reports
//   - the largest ‖∂G‖∞ (max row sum): < 1 on a convex D makes G a contraction in the max norm
//     (the rigorous condition), and
//   - the largest entry |∂g_i/∂x_j|: the paper's entry-wise condition (necessary, not sufficient).
// Sampling gives evidence, not a proof: a maximum between samples can be missed.
#include <cstdint>
#include <random>
#include <sstream>

#include "nlobs/solvers/finite_difference.hpp"
#include "nlobs/solvers/problem.hpp"

namespace nlobs {

struct ContractionCheckOptions {
  int samples = 2000;         // random points in addition to corners (n ≤ 12) and the centre
  std::uint64_t seed = 2024;  // results are reproducible for a given seed
};

template <int N = Dynamic>
struct ContractionReport {
  double max_jacobian_norm = 0.0;  // max over samples of ‖∂G(x)‖∞
  Vector<N> max_norm_point;
  double max_entry = 0.0;  // max over samples of |∂g_i/∂x_j|
  Index max_entry_row = 0, max_entry_col = 0;
  Vector<N> max_entry_point;
  int points = 0;  // Jacobians evaluated
  bool is_contraction() const { return max_jacobian_norm < 1.0; }
  bool entrywise_condition() const { return max_entry < 1.0; }
};

template <int N>
ContractionReport<N> check_contraction(const FixedPointProblem<N>& problem, const Vector<N>& lower,
                                       const Vector<N>& upper,
                                       ContractionCheckOptions options = {}) {
  const Index n = problem.size();
  if (lower.size() != n || upper.size() != n) {
    std::ostringstream os;
    os << "check_contraction: box bounds have sizes " << lower.size() << " and " << upper.size()
       << ", expected " << n;
    throw InvalidInput(os.str());
  }
  for (Index i = 0; i < n; ++i) {
    if (!std::isfinite(lower[i]) || !std::isfinite(upper[i]) || lower[i] > upper[i]) {
      std::ostringstream os;
      os << "check_contraction: box component " << i << " = [" << lower[i] << ", " << upper[i]
         << "] must be finite with lower <= upper";
      throw InvalidInput(os.str());
    }
  }
  if (options.samples < 0) {
    throw InvalidInput("check_contraction: ContractionCheckOptions::samples = " +
                       std::to_string(options.samples) + " must be >= 0");
  }

  ContractionReport<N> report;
  report.max_norm_point = lower;
  report.max_entry_point = lower;
  Matrix<N, N> jac(n, n);
  Vector<N> x(n), gx(n);
  FiniteDifferenceWorkspace<N> work;
  work.resize(n);

  auto visit = [&](const Vector<N>& at) {
    if (problem.has_jacobian()) {
      problem.jacobian(at, jac);
    } else {
      problem.evaluate(at, gx);
      finite_difference_jacobian(problem, at, gx, jac, FiniteDifference::kCentral, work);
    }
    ++report.points;
    const double norm = jac.cwiseAbs().rowwise().sum().maxCoeff();
    if (norm > report.max_jacobian_norm || !std::isfinite(norm)) {
      report.max_jacobian_norm = norm;
      report.max_norm_point = at;
    }
    Index r = 0, c = 0;
    const double entry = jac.cwiseAbs().maxCoeff(&r, &c);
    if (entry > report.max_entry || !std::isfinite(entry)) {
      report.max_entry = entry;
      report.max_entry_row = r;
      report.max_entry_col = c;
      report.max_entry_point = at;
    }
  };

  x = 0.5 * (lower + upper);
  visit(x);
  if (n <= 12) {
    for (std::uint64_t corner = 0; corner < (std::uint64_t{1} << n); ++corner) {
      for (Index i = 0; i < n; ++i) x[i] = (corner >> i) & 1U ? upper[i] : lower[i];
      visit(x);
    }
  }
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int s = 0; s < options.samples; ++s) {
    for (Index i = 0; i < n; ++i) x[i] = lower[i] + unit(rng) * (upper[i] - lower[i]);
    visit(x);
  }
  return report;
}

}  // namespace nlobs
