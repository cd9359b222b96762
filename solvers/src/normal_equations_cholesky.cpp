// CHOLMOD behind NormalEquationsCholesky (nlobs/solvers/linear/normal_equations_cholesky.hpp).
//
// CHOLMOD factors β I + A Aᵀ for an unsymmetric A (cholmod_factorize_p), so A = [J̃ᵀ | E]
// (n × (m + n), compressed columns) gives J̃ᵀ J̃ + E² + λ I with β = λ and no product formed
// here: J's compressed rows are J̃ᵀ's compressed columns once scaled by 1/d, and E's n columns
// (one entry each, 0 or 1) keep a frozen variable's diagonal at 1 without changing the pattern.
#include "nlobs/solvers/linear/normal_equations_cholesky.hpp"

#include <cholmod.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <new>
#include <stdexcept>
#include <string>

#include "nlobs/common/invalid_input.hpp"

namespace nlobs {

struct NormalEquationsCholesky::Cholmod {
  cholmod_common common{};
  cholmod_factor* factor = nullptr;
  // A = [J̃ᵀ | E], its arrays owned here (CHOLMOD only reads them through `a`).
  std::vector<int> starts, rows;
  std::vector<double> values;
  cholmod_sparse a{};
  // J's pattern at the last analysis: compressed row starts and columns.
  std::vector<int> pattern_starts, pattern_columns;
  Index n = 0, m = 0;
  // cholmod_solve2's solution and workspaces, allocated by the first solve and reused.
  cholmod_dense *x = nullptr, *permuted = nullptr, *y = nullptr, *e = nullptr;

  Cholmod() {
    cholmod_start(&common);
    common.print = 0;     // failures are reported by message(), not printed
    common.final_ll = 1;  // L Lᵀ also when simplicial: solve_lower needs L
  }
  ~Cholmod() {
    release();
    cholmod_finish(&common);
  }
  void release() {
    for (cholmod_dense** d : {&x, &permuted, &y, &e}) {
      if (*d != nullptr) cholmod_free_dense(d, &common);
    }
    if (factor != nullptr) cholmod_free_factor(&factor, &common);
  }
  // A header over b's storage (CHOLMOD only reads a right-hand side).
  static cholmod_dense dense_view(const Vector<Dynamic>& b) {
    cholmod_dense d{};
    d.nrow = d.d = d.nzmax = static_cast<std::size_t>(b.size());
    d.ncol = 1;
    d.x = const_cast<double*>(b.data());
    d.xtype = CHOLMOD_REAL;
    d.dtype = CHOLMOD_DOUBLE;
    return d;
  }
  // out = the systems applied to b in turn (CHOLMOD_A; or CHOLMOD_P then CHOLMOD_L) with the
  // factor (`factored`: the last factorisation succeeded); a first system's output goes to
  // `permuted` when a second follows.
  void apply(const char* caller, bool factored, std::initializer_list<int> systems,
             const Vector<Dynamic>& b, Vector<Dynamic>& out) {
    if (!factored || b.size() != n) {
      throw InvalidInput(std::string("NormalEquationsCholesky::") + caller +
                         " without a factor of size " + std::to_string(b.size()));
    }
    cholmod_dense rhs = dense_view(b);
    cholmod_dense* in = &rhs;
    for (auto system = systems.begin(); system != systems.end(); ++system) {
      cholmod_dense** result = system + 1 == systems.end() ? &x : &permuted;
      if (!cholmod_solve2(*system, factor, in, nullptr, result, nullptr, &y, &e, &common)) {
        check("cholmod_solve2");
        throw std::runtime_error("CHOLMOD: cholmod_solve2 failed");
      }
      in = *result;
    }
    out = Eigen::Map<const Vector<Dynamic>>(static_cast<const double*>(x->x), n);
  }
  void check(const char* call) const {
    if (common.status == CHOLMOD_OUT_OF_MEMORY) throw std::bad_alloc();
    if (common.status < 0) {
      throw std::runtime_error(std::string("CHOLMOD: ") + call + " failed with status " +
                               std::to_string(common.status));
    }
  }
};

NormalEquationsCholesky::NormalEquationsCholesky() : cholmod_(std::make_unique<Cholmod>()) {}
NormalEquationsCholesky::~NormalEquationsCholesky() = default;

Index NormalEquationsCholesky::size() const {
  return cholmod_->n;
}

void NormalEquationsCholesky::load(const SparseJacobian& jac, const Vector<Dynamic>& d,
                                   const std::vector<char>& frozen) {
  Cholmod& c = *cholmod_;
  const Index m = jac.rows(), n = jac.cols();
  if (!jac.isCompressed() || d.size() != n || (!frozen.empty() && std::ssize(frozen) != n)) {
    throw InvalidInput("NormalEquationsCholesky::load: J is " + std::to_string(m) + "x" +
                       std::to_string(n) + (jac.isCompressed() ? "" : " (not compressed)") +
                       ", the scaling has " + std::to_string(d.size()) + " entries and the " +
                       "frozen flags " + std::to_string(frozen.size()));
  }
  for (Index j = 0; j < n; ++j) {
    if (!(d[j] > 0.0) || !std::isfinite(d[j])) {
      throw InvalidInput("NormalEquationsCholesky::load: scaling d[" + std::to_string(j) +
                         "] = " + std::to_string(d[j]) + " must be finite and > 0");
    }
  }
  const int* outer = jac.outerIndexPtr();
  const int* inner = jac.innerIndexPtr();
  const double* value = jac.valuePtr();
  const Index nnz = jac.nonZeros();
  // (Checked before anything is changed: a refused J leaves the last factor as it was.)
  for (Index k = 0; k < nnz; ++k) {
    if (!std::isfinite(value[k])) {
      throw InvalidInput("NormalEquationsCholesky::load: J has a non-finite entry in column " +
                         std::to_string(inner[k]));
    }
  }
  const bool same_pattern =
      c.factor != nullptr && c.m == m && c.n == n &&
      std::equal(outer, outer + m + 1, c.pattern_starts.begin(), c.pattern_starts.end()) &&
      std::equal(inner, inner + nnz, c.pattern_columns.begin(), c.pattern_columns.end());
  if (!same_pattern) {
    c.release();
    c.m = m, c.n = n;
    c.pattern_starts.assign(outer, outer + m + 1);
    c.pattern_columns.assign(inner, inner + nnz);
    c.starts.resize(static_cast<std::size_t>(m + n) + 1);
    c.rows.resize(static_cast<std::size_t>(nnz + n));
    c.values.resize(static_cast<std::size_t>(nnz + n));
    std::copy(outer, outer + m + 1, c.starts.begin());
    std::copy(inner, inner + nnz, c.rows.begin());
    for (Index j = 0; j < n; ++j) {
      c.starts[static_cast<std::size_t>(m + j + 1)] = static_cast<int>(nnz + j + 1);
      c.rows[static_cast<std::size_t>(nnz + j)] = static_cast<int>(j);
    }
    c.a = cholmod_sparse{};
    c.a.nrow = static_cast<std::size_t>(n);
    c.a.ncol = static_cast<std::size_t>(m + n);
    c.a.nzmax = static_cast<std::size_t>(nnz + n);
    c.a.p = c.starts.data();
    c.a.i = c.rows.data();
    c.a.x = c.values.data();
    c.a.stype = 0;  // unsymmetric: CHOLMOD analyses and factors A Aᵀ
    c.a.itype = CHOLMOD_INT;
    c.a.xtype = CHOLMOD_REAL;
    c.a.dtype = CHOLMOD_DOUBLE;
    c.a.sorted = 1;
    c.a.packed = 1;
  }
  for (Index k = 0; k < nnz; ++k) {
    const bool held = !frozen.empty() && frozen[static_cast<std::size_t>(inner[k])] != 0;
    c.values[static_cast<std::size_t>(k)] = held ? 0.0 : value[k] / d[inner[k]];
  }
  for (Index j = 0; j < n; ++j) {
    c.values[static_cast<std::size_t>(nnz + j)] =
        !frozen.empty() && frozen[static_cast<std::size_t>(j)] != 0 ? 1.0 : 0.0;
  }
  factored_ = false;
  if (!same_pattern) {
    c.factor = cholmod_analyze(&c.a, &c.common);
    c.check("cholmod_analyze");
    ++analyses_;
  }
}

bool NormalEquationsCholesky::factor(double lambda) {
  Cholmod& c = *cholmod_;
  if (c.factor == nullptr) throw InvalidInput("NormalEquationsCholesky::factor before load");
  if (!(lambda >= 0.0) || !std::isfinite(lambda)) {
    throw InvalidInput("NormalEquationsCholesky::factor: lambda = " + std::to_string(lambda) +
                       " must be finite and >= 0");
  }
  factored_ = false;  // (until CHOLMOD has finished: a throw below leaves no stale factor)
  double beta[2] = {lambda, 0.0};
  cholmod_factorize_p(&c.a, beta, nullptr, 0, c.factor, &c.common);
  ++factorisations_;
  c.check("cholmod_factorize_p");
  lambda_ = lambda;
  factored_ = c.common.status != CHOLMOD_NOT_POSDEF && c.factor->minor >= c.factor->n;
  if (!factored_) {
    message_ = "J^T J + lambda I is not positive definite at lambda = " + std::to_string(lambda) +
               " (CHOLMOD stopped at column " + std::to_string(c.factor->minor) + " of " +
               std::to_string(c.n) + ")";
  } else {
    message_.clear();
  }
  return factored_;
}

void NormalEquationsCholesky::solve(const Vector<Dynamic>& b, Vector<Dynamic>& q) {
  cholmod_->apply("solve", factored_, {CHOLMOD_A}, b, q);
}

void NormalEquationsCholesky::solve_lower(const Vector<Dynamic>& b, Vector<Dynamic>& y) {
  cholmod_->apply("solve_lower", factored_, {CHOLMOD_P, CHOLMOD_L}, b, y);
}

}  // namespace nlobs
