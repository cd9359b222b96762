#include <cminpack-1/cminpack.h>

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <vector>

#include "nlobs/reference/root_reference.hpp"

namespace nlobs::reference {
namespace {

struct Context {
  const RootProblem<Dynamic>* problem;
  Eigen::VectorXd x, f;
  Eigen::MatrixXd j;
  long f_evals = 0, cap = 0;  // cap: the evaluations hybrj may make
  bool refused = false;       // an evaluation beyond the cap was asked for
};

int callback(void* p, int n, const double* x, double* fvec, double* fjac, int ldfjac, int iflag) {
  auto* c = static_cast<Context*>(p);
  c->x = Eigen::Map<const Eigen::VectorXd>(x, n);
  if (iflag == 1) {
    if (c->f_evals >= c->cap) {
      c->refused = true;
      return -1;  // negative: terminate
    }
    ++c->f_evals;
    c->problem->evaluate(c->x, c->f);
    if (!c->f.allFinite()) return -1;
    Eigen::Map<Eigen::VectorXd>(fvec, n) = c->f;
  } else if (iflag == 2) {
    c->problem->jacobian(c->x, c->j);
    if (!c->j.allFinite()) return -1;
    Eigen::Map<Eigen::MatrixXd, 0, Eigen::OuterStride<>>(fjac, n, n, Eigen::OuterStride<>(ldfjac)) =
        c->j;
  }
  return 0;
}

}  // namespace

ReferenceResult solve_minpack_hybrj(const RootProblem<Dynamic>& problem, Eigen::VectorXd& x,
                                    const ReferenceOptions& options) {
  if (options.max_evaluations < 2) {
    throw std::invalid_argument("ReferenceOptions::max_evaluations must be >= 2");
  }
  const int n = static_cast<int>(x.size());
  // hybrj's own evaluations; check_answer takes the last one of the budget.
  const long cap = std::min<long>(options.max_evaluations - 1, std::numeric_limits<int>::max());
  Context c{&problem, Eigen::VectorXd(n), Eigen::VectorXd(n), Eigen::MatrixXd(n, n), 0, cap};
  std::vector<double> fvec(n), fjac(static_cast<std::size_t>(n) * n), diag(n, 1.0),
      r(static_cast<std::size_t>(n) * (n + 1) / 2), qtf(n), wa1(n), wa2(n), wa3(n), wa4(n);
  int nfev = 0, njev = 0;
  // As hybrj1 calls it: mode 2 with diag = 1 (the variables as given: no rescaling by the
  // Jacobian's column norms, which mode 1 would do), factor 100, no printing.
  const int info =
      hybrj(&callback, &c, n, x.data(), fvec.data(), fjac.data(), n, options.minpack_xtol,
            static_cast<int>(cap), diag.data(), 2, 100.0, 0, &nfev, &njev, r.data(),
            static_cast<int>(r.size()), qtf.data(), wa1.data(), wa2.data(), wa3.data(), wa4.data());
  ReferenceResult result;
  result.f_evals = c.f_evals;
  result.j_evals = njev;
  switch (info) {
    case 1:
      result.status = "converged";
      break;
    case 2:
      result.status = "max_evaluations";
      break;
    case 3:
      result.status = "xtol_too_small";
      break;
    case 4:
      result.status = "not_making_progress_jacobian";
      break;
    case 5:
      result.status = "not_making_progress";
      break;
    default:
      result.status = c.refused ? "max_evaluations" : info < 0 ? "non_finite" : "improper_input";
  }
  check_answer(problem, x, options, result);
  return result;
}

}  // namespace nlobs::reference
