#include "nlobs/registry/problem_sets/mgh_problems.hpp"

#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>

namespace nlobs::reference {
namespace {

// F for MINPACK problem `number` at x, for any scalar T (double or an AD type).
struct MghFunction {
  int number;
  int n;

  template <typename T>
  Eigen::Matrix<T, Eigen::Dynamic, 1> operator()(
      const Eigen::Matrix<T, Eigen::Dynamic, 1>& x) const {
    using std::atan2;
    using std::cos;
    using std::exp;
    using std::sin;
    using std::sqrt;
    Eigen::Matrix<T, Eigen::Dynamic, 1> f(n);
    for (int k = 0; k < n; ++k) f[k] = T(0.0);
    const double dn = n;
    switch (number) {
      case 1:  // Rosenbrock
        f[0] = 1.0 - x[0];
        f[1] = 10.0 * (x[1] - x[0] * x[0]);
        break;
      case 2:  // Powell singular
        f[0] = x[0] + 10.0 * x[1];
        f[1] = std::sqrt(5.0) * (x[2] - x[3]);
        f[2] = (x[1] - 2.0 * x[2]) * (x[1] - 2.0 * x[2]);
        f[3] = std::sqrt(10.0) * (x[0] - x[3]) * (x[0] - x[3]);
        break;
      case 3:  // Powell badly scaled
        f[0] = 1e4 * x[0] * x[1] - 1.0;
        f[1] = exp(-x[0]) + exp(-x[1]) - 1.0001;
        break;
      case 4: {  // Wood
        const T t1 = x[1] - x[0] * x[0], t2 = x[3] - x[2] * x[2];
        f[0] = -200.0 * x[0] * t1 - (1.0 - x[0]);
        f[1] = 200.0 * t1 + 20.2 * (x[1] - 1.0) + 19.8 * (x[3] - 1.0);
        f[2] = -180.0 * x[2] * t2 - (1.0 - x[2]);
        f[3] = 180.0 * t2 + 20.2 * (x[3] - 1.0) + 19.8 * (x[1] - 1.0);
        break;
      }
      case 5: {  // helical valley
        const double tpi = 2.0 * std::numbers::pi;
        // atan(x2/x1) written with atan2 and a positive second argument (Eigen's AutoDiffScalar
        // has atan2 but no atan): x1 > 0: atan2(x2, x1); x1 < 0: atan2(−x2, −x1).
        T theta = T(x[1] >= 0.0 ? 0.25 : -0.25);  // Fortran sign(0.25, x2)
        if (x[0] > 0.0) theta = atan2(T(x[1]), T(x[0])) / tpi;
        if (x[0] < 0.0) theta = atan2(T(-x[1]), T(-x[0])) / tpi + 0.5;
        f[0] = 10.0 * (x[2] - 10.0 * theta);
        f[1] = 10.0 * (sqrt(x[0] * x[0] + x[1] * x[1]) - 1.0);
        f[2] = x[2];
        break;
      }
      case 6: {  // Watson
        for (int i = 1; i <= 29; ++i) {
          const double ti = i / 29.0;
          T sum1 = T(0.0), sum2 = T(0.0);
          double p = 1.0;
          for (int j = 1; j < n; ++j) {
            sum1 += double(j) * p * x[j];
            p *= ti;
          }
          p = 1.0;
          for (int j = 0; j < n; ++j) {
            sum2 += p * x[j];
            p *= ti;
          }
          const T t1 = sum1 - sum2 * sum2 - 1.0;
          const T t2 = 2.0 * ti * sum2;
          double q = 1.0 / ti;
          for (int k = 0; k < n; ++k) {
            f[k] += q * (double(k) - t2) * t1;
            q *= ti;
          }
        }
        const T t = x[1] - x[0] * x[0] - 1.0;
        f[0] += x[0] * (1.0 - 2.0 * t);
        f[1] += t;
        break;
      }
      case 7: {  // Chebyquad
        for (int j = 0; j < n; ++j) {
          T t1 = T(1.0), t2 = 2.0 * x[j] - 1.0;
          const T t = 2.0 * t2;
          for (int i = 0; i < n; ++i) {
            f[i] += t2;
            const T ti = t * t2 - t1;
            t1 = t2;
            t2 = ti;
          }
        }
        for (int k = 0; k < n; ++k) {
          f[k] = f[k] / dn;
          if ((k + 1) % 2 == 0) f[k] += 1.0 / ((k + 1.0) * (k + 1.0) - 1.0);
        }
        break;
      }
      case 8: {  // Brown almost-linear
        T sum = T(-(dn + 1.0)), prod = T(1.0);
        for (int j = 0; j < n; ++j) {
          sum += x[j];
          prod *= x[j];
        }
        for (int k = 0; k < n; ++k) f[k] = x[k] + sum;
        f[n - 1] = prod - 1.0;
        break;
      }
      case 9: {  // discrete boundary value
        const double h = 1.0 / (dn + 1.0);
        for (int k = 0; k < n; ++k) {
          const T t = x[k] + (k + 1.0) * h + 1.0;
          const T left = k > 0 ? x[k - 1] : T(0.0);
          const T right = k + 1 < n ? x[k + 1] : T(0.0);
          f[k] = 2.0 * x[k] - left - right + t * t * t * (h * h / 2.0);
        }
        break;
      }
      case 10: {  // discrete integral equation
        const double h = 1.0 / (dn + 1.0);
        for (int k = 0; k < n; ++k) {
          const double tk = (k + 1.0) * h;
          T sum1 = T(0.0), sum2 = T(0.0);
          for (int j = 0; j <= k; ++j) {
            const double tj = (j + 1.0) * h;
            const T t = x[j] + tj + 1.0;
            sum1 += tj * (t * t * t);
          }
          for (int j = k + 1; j < n; ++j) {
            const double tj = (j + 1.0) * h;
            const T t = x[j] + tj + 1.0;
            sum2 += (1.0 - tj) * (t * t * t);
          }
          f[k] = x[k] + h * ((1.0 - tk) * sum1 + tk * sum2) / 2.0;
        }
        break;
      }
      case 11: {  // trigonometric
        T sum = T(0.0);
        for (int j = 0; j < n; ++j) sum += cos(x[j]);
        for (int k = 0; k < n; ++k) {
          f[k] = (dn + k + 1.0) - sin(x[k]) - sum - (k + 1.0) * cos(x[k]);
        }
        break;
      }
      case 12: {  // variably dimensioned
        T sum = T(0.0);
        for (int j = 0; j < n; ++j) sum += (j + 1.0) * (x[j] - 1.0);
        const T t = sum * (1.0 + 2.0 * sum * sum);
        for (int k = 0; k < n; ++k) f[k] = x[k] - 1.0 + (k + 1.0) * t;
        break;
      }
      case 13:  // Broyden tridiagonal
        for (int k = 0; k < n; ++k) {
          const T left = k > 0 ? x[k - 1] : T(0.0);
          const T right = k + 1 < n ? x[k + 1] : T(0.0);
          f[k] = (3.0 - 2.0 * x[k]) * x[k] - left - 2.0 * right + 1.0;
        }
        break;
      case 14:  // Broyden banded (ml = 5, mu = 1)
        for (int k = 0; k < n; ++k) {
          T t = T(0.0);
          for (int j = std::max(0, k - 5); j <= std::min(n - 1, k + 1); ++j) {
            if (j != k) t += x[j] * (1.0 + x[j]);
          }
          f[k] = x[k] * (2.0 + 5.0 * x[k] * x[k]) + 1.0 - t;
        }
        break;
      default:
        throw std::invalid_argument("MGH problem number must be 1..14");
    }
    return f;
  }
};

MghCase make_case(const char* name, int number, int n) {
  const MghFunction f{number, n};
  return MghCase{name, number, n,
                 RootProblem<Dynamic>::with_autodiff(
                     [f](const auto& x) {
                       using V = std::decay_t<decltype(x)>;
                       return f(Eigen::Matrix<typename V::Scalar, Eigen::Dynamic, 1>(x));
                     },
                     n, n)};
}

}  // namespace

Eigen::VectorXd MghCase::start(double scale) const {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  const double dn = n;
  switch (number) {
    case 1:
      x << -1.2, 1.0;
      break;
    case 2:
      x << 3.0, -1.0, 0.0, 1.0;
      break;
    case 3:
      x << 0.0, 1.0;
      break;
    case 4:
      x << -3.0, -1.0, -3.0, -1.0;
      break;
    case 5:
      x << -1.0, 0.0, 0.0;
      break;
    case 6:
      break;  // zero
    case 7:
      for (int j = 0; j < n; ++j) x[j] = (j + 1.0) / (dn + 1.0);
      break;
    case 8:
      x.setConstant(0.5);
      break;
    case 9:
    case 10:
      for (int j = 0; j < n; ++j) {
        const double t = (j + 1.0) / (dn + 1.0);
        x[j] = t * (t - 1.0);
      }
      break;
    case 11:
      x.setConstant(1.0 / dn);
      break;
    case 12:
      for (int j = 0; j < n; ++j) x[j] = 1.0 - (j + 1.0) / dn;
      break;
    case 13:
    case 14:
      x.setConstant(-1.0);
      break;
    default:
      throw std::invalid_argument("MGH problem number must be 1..14");
  }
  if (scale != 1.0) {
    if (number == 6) {
      x.setConstant(scale);
    } else {
      x *= scale;
    }
  }
  return x;
}

std::vector<MghCase> mgh_cases() {
  std::vector<MghCase> cases;
  cases.push_back(make_case("rosenbrock", 1, 2));
  cases.push_back(make_case("powell_singular", 2, 4));
  cases.push_back(make_case("powell_badly_scaled", 3, 2));
  cases.push_back(make_case("wood", 4, 4));
  cases.push_back(make_case("helical_valley", 5, 3));
  cases.push_back(make_case("watson", 6, 6));
  cases.push_back(make_case("watson", 6, 9));
  for (int n = 5; n <= 9; ++n) cases.push_back(make_case("chebyquad", 7, n));
  cases.push_back(make_case("brown_almost_linear", 8, 10));
  cases.push_back(make_case("discrete_boundary_value", 9, 10));
  cases.push_back(make_case("discrete_integral_equation", 10, 10));
  cases.push_back(make_case("trigonometric", 11, 10));
  cases.push_back(make_case("variably_dimensioned", 12, 10));
  cases.push_back(make_case("broyden_tridiagonal", 13, 10));
  cases.push_back(make_case("broyden_banded", 14, 10));
  return cases;
}

MghCase mgh_case(int number, int n) {
  for (MghCase& c : mgh_cases()) {
    if (c.number == number && c.n == n) return c;
  }
  throw std::invalid_argument("no MGH case with number " + std::to_string(number) +
                              " and n = " + std::to_string(n));
}

}  // namespace nlobs::reference

namespace nlobs {

ProblemSetEntry mgh_problem_set() {
  ProblemSetEntry set;
  set.name = "mgh";
  set.description =
      "the square systems of MINPACK's test driver (More, Garbow & Hillstrom), standard starts "
      "scaled by 1, 10 and 100";
  set.problems = [] {
    std::vector<TestProblem> problems;
    for (reference::MghCase& c : reference::mgh_cases()) {
      TestProblem p{.name = c.name, .residual = std::move(c.problem)};
      for (double scale : {1.0, 10.0, 100.0}) {
        char label[16];
        std::snprintf(label, sizeof label, "x%g", scale);
        p.starts.push_back({label, c.start(scale), scale});
      }
      switch (c.number) {
        case 4:  // Wood: ∇f = 0 has a second root, a saddle of Wood's function, where
                 // MINPACK, KINSOL and GSL go from the standard start (Newton-polished digits)
          p.solutions.push_back(Eigen::VectorXd::Ones(c.n));
          p.solutions.push_back((Eigen::VectorXd(4) << -0.96797402493758955, 0.94713914081783468,
                                 -0.96951631033159491, 0.95124766579233244)
                                    .finished());
          break;
        case 1:   // Rosenbrock
        case 8:   // Brown almost-linear
        case 12:  // variably dimensioned
          p.solutions.push_back(Eigen::VectorXd::Ones(c.n));
          break;
        case 2:  // Powell singular
          p.solutions.push_back(Eigen::VectorXd::Zero(c.n));
          break;
        case 5:  // helical valley
          p.solutions.push_back(Eigen::Vector3d(1.0, 0.0, 0.0));
          break;
        default:
          break;
      }
      p.description = "MINPACK problem " + std::to_string(c.number);
      problems.push_back(std::move(p));
    }
    return problems;
  };
  return set;
}

}  // namespace nlobs
