#pragma once
// How a problem carries a sparse Jacobian of F at run-time size, for the engines' sparse path
// (docs/solvers.md, "Sparse Jacobians"). Light on purpose: problem.hpp includes it, and Eigen's
// sparse module is only declared here (nlobs/solvers/sparse/sparse_jacobian.hpp defines it).
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>

#include "nlobs/common/invalid_input.hpp"
#include "nlobs/solvers/types.hpp"

namespace Eigen {
template <typename Scalar, int Options, typename StorageIndex>
class SparseMatrix;
}  // namespace Eigen

namespace nlobs {

struct SparsityPattern;
// = Eigen::SparseMatrix<double, RowMajor> (nlobs/solvers/sparse/sparse_jacobian.hpp).
using SparseJacobian = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;

// A sparse Jacobian of F: its pattern, and `evaluate(x, f, J)` filling J = ∂F(x) with exactly
// that structure (f = F(x), which differences need) and returning the evaluations of F it made
// (0 for AD). Built by sparse_autodiff_problem / sparse_difference_problem
// (sparse/sparse_problem.hpp), or found by RootProblem::with_autodiff (sparsity_detection.hpp).
struct SparseJacobianSource {
  std::shared_ptr<const SparsityPattern> pattern;
  std::function<int(const Vector<Dynamic>& x, const Vector<Dynamic>& f, SparseJacobian& jac)>
      evaluate;
  int evaluations_per_jacobian = 0;  // what evaluate returns: for the evaluation budget
};

namespace detail {
inline void check_sparse_source(const char* owner, const SparseJacobianSource& sparse) {
  if (!sparse.pattern || !sparse.evaluate || sparse.evaluations_per_jacobian < 0) {
    throw InvalidInput(std::string(owner) +
                       ": a sparse Jacobian needs a pattern, an evaluate function and "
                       "evaluations_per_jacobian >= 0");
  }
}

// A problem's sparse Jacobian, shared by the problem's copies: declared (a source from the
// start), or to be detected at the first point an engine asks with (RootProblem::with_autodiff at
// run-time size). Detection runs once; its answer — a source or none — and the reason are kept.
// Copies may be solved from several threads: detection and each evaluation of J (whose workspace
// the copies share) take a lock, so the copies' Jacobian evaluations take turns.
class SparseJacobianState {
 public:
  // Finds the source at x, or nullopt with the reason in `note`.
  using Detector =
      std::function<std::optional<SparseJacobianSource>(const Vector<Dynamic>& x, std::string&)>;

  static std::shared_ptr<SparseJacobianState> declared(SparseJacobianSource source) {
    auto state = std::make_shared<SparseJacobianState>();
    state->source_ = std::move(source);
    state->note_ = "declared";
    return state;
  }
  // `declared`: a state that wraps a declared one (a scaled problem's) says so, whatever it
  // resolves by (declared() below).
  static std::shared_ptr<SparseJacobianState> detected_later(Detector detect,
                                                             bool declared = false) {
    auto state = std::make_shared<SparseJacobianState>();
    state->detect_ = std::move(detect);
    state->note_ = "not detected yet (an engine with a sparse path detects at its start)";
    state->by_detection_ = !declared;
    return state;
  }

  // The source, detecting it at x first if that is still to do; nullptr for none. An F that
  // throws (a std::exception) while it is traced declines detection, the exception's text in the
  // note: the engines then take the dense path, as before detection existed.
  const SparseJacobianSource* resolve(const Vector<Dynamic>& x) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (detect_) {
      std::string note;
      try {
        source_ = detect_(x, note);
      } catch (const std::exception& e) {
        source_.reset();
        note = std::string("not detected: F threw while traced: ") + e.what();
      }
      note_ = std::move(note);
      detect_ = nullptr;
    }
    return source_ ? &*source_ : nullptr;
  }
  const SparseJacobianSource* get() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return source_ ? &*source_ : nullptr;
  }
  // J = ∂F(x) by the source (resolved: get() != nullptr), f = F(x); returns the evaluations of F
  // it made. Under the lock: the source's workspace is the copies' common one.
  int evaluate(const Vector<Dynamic>& x, const Vector<Dynamic>& f, SparseJacobian& jac) {
    const std::lock_guard<std::mutex> lock(mutex_);
    return source_->evaluate(x, f, jac);
  }
  // Declared by the user, not found by detection (an engine that cannot take the sparse path
  // refuses the first and falls back to the dense Jacobian for the second).
  bool declared() const { return !by_detection_; }
  std::string note() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return note_;
  }

 private:
  mutable std::mutex mutex_;
  std::optional<SparseJacobianSource> source_;
  Detector detect_;
  std::string note_;
  bool by_detection_ = false;
};
}  // namespace detail

}  // namespace nlobs
