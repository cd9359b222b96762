#include <gsl/gsl_errno.h>
#include <gsl/gsl_multiroots.h>

#include <memory>
#include <stdexcept>

#include "nlobs/reference/root_reference.hpp"

namespace nlobs::reference {
namespace {

struct Context {
  const RootProblem<Dynamic>* problem;
  Eigen::VectorXd x, f;
  Eigen::MatrixXd j;
  long f_evals = 0, j_evals = 0;
  long cap = 0;          // the evaluations GSL may make (check_answer takes one more)
  bool refused = false;  // an evaluation beyond the cap was asked for
};

void load(Context* c, const gsl_vector* x) {
  for (Eigen::Index i = 0; i < c->x.size(); ++i) c->x[i] = gsl_vector_get(x, i);
}

int eval_f(const gsl_vector* x, void* p, gsl_vector* f) {
  auto* c = static_cast<Context*>(p);
  if (c->f_evals >= c->cap) {
    c->refused = true;
    return GSL_EBADFUNC;  // GSL stops: iterate() returns it
  }
  load(c, x);
  ++c->f_evals;
  c->problem->evaluate(c->x, c->f);
  for (Eigen::Index i = 0; i < c->f.size(); ++i) gsl_vector_set(f, i, c->f[i]);
  return c->f.allFinite() ? GSL_SUCCESS : GSL_EBADFUNC;
}

int eval_j(const gsl_vector* x, void* p, gsl_matrix* jac) {
  auto* c = static_cast<Context*>(p);
  load(c, x);
  c->problem->jacobian(c->x, c->j);
  ++c->j_evals;
  for (Eigen::Index i = 0; i < c->j.rows(); ++i) {
    for (Eigen::Index k = 0; k < c->j.cols(); ++k) gsl_matrix_set(jac, i, k, c->j(i, k));
  }
  return c->j.allFinite() ? GSL_SUCCESS : GSL_EBADFUNC;
}

int eval_fj(const gsl_vector* x, void* p, gsl_vector* f, gsl_matrix* jac) {
  const int a = eval_f(x, p, f);
  if (static_cast<Context*>(p)->refused) return a;
  const int b = eval_j(x, p, jac);
  return a != GSL_SUCCESS ? a : b;
}

// GSL's error codes in the suite's vocabulary (MINPACK's names where they mean the same).
std::string status_name(int code) {
  switch (code) {
    case GSL_EBADFUNC:
      return "non_finite";
    case GSL_EDOM:  // gnewton: gsl_linalg_LU_solve of a singular Jacobian
      return "singular_jacobian";
    case GSL_ENOPROG:
      return "not_making_progress";
    case GSL_ENOPROGJ:
      return "not_making_progress_jacobian";
    default:
      return "gsl_error_" + std::to_string(code);
  }
}

}  // namespace

ReferenceResult solve_gsl(const std::string& method, const RootProblem<Dynamic>& problem,
                          Eigen::VectorXd& x, const ReferenceOptions& options) {
  const gsl_multiroot_fdfsolver_type* type =
      method == "gnewton" ? gsl_multiroot_fdfsolver_gnewton : gsl_multiroot_fdfsolver_hybridsj;
  if (options.max_evaluations < 2) {
    throw std::invalid_argument("ReferenceOptions::max_evaluations must be >= 2");
  }
  const size_t n = static_cast<size_t>(x.size());
  Context c{&problem, Eigen::VectorXd(x.size()), Eigen::VectorXd(x.size()),
            Eigen::MatrixXd(x.size(), x.size())};
  c.cap = options.max_evaluations - 1;
  gsl_multiroot_function_fdf fdf{&eval_f, &eval_j, &eval_fj, n, &c};
  std::unique_ptr<gsl_vector, decltype(&gsl_vector_free)> x0(gsl_vector_alloc(n), gsl_vector_free);
  for (size_t i = 0; i < n; ++i) gsl_vector_set(x0.get(), i, x[static_cast<Eigen::Index>(i)]);
  std::unique_ptr<gsl_multiroot_fdfsolver, decltype(&gsl_multiroot_fdfsolver_free)> s(
      gsl_multiroot_fdfsolver_alloc(type, n), gsl_multiroot_fdfsolver_free);
  gsl_error_handler_t* previous = gsl_set_error_handler_off();
  ReferenceResult result;
  int status = gsl_multiroot_fdfsolver_set(s.get(), &fdf, x0.get());
  result.status = "max_evaluations";
  if (status != GSL_SUCCESS) {
    result.status = status_name(status);
  } else {
    while (c.f_evals < c.cap) {
      status = gsl_multiroot_fdfsolver_iterate(s.get());
      ++result.iterations;
      if (status != GSL_SUCCESS) {
        result.status = c.refused ? "max_evaluations" : status_name(status);
        break;
      }
      if (gsl_multiroot_test_residual(s.get()->f, options.tolerance) == GSL_SUCCESS ||
          gsl_multiroot_test_delta(s.get()->dx, s.get()->x, 0.0, options.tolerance * 1e-2) ==
              GSL_SUCCESS) {
        result.status = "converged";
        break;
      }
    }
  }
  gsl_set_error_handler(previous);
  for (size_t i = 0; i < n; ++i) x[static_cast<Eigen::Index>(i)] = gsl_vector_get(s.get()->x, i);
  result.f_evals = c.f_evals;
  result.j_evals = c.j_evals;
  check_answer(problem, x, options, result);
  return result;
}

}  // namespace nlobs::reference
