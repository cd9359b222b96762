#include "nlobs/observers/high_gain/lie_observability_map.hpp"

#include <adolc/drivers/odedrivers.h>

#include <cmath>
#include <mutex>
#include <sstream>
#include <vector>

namespace nlobs {

namespace {
// ADOL-C numbers tapes with shorts, process-wide: ours count up from 20000 so that a user's
// own small tape numbers do not collide; pairs freed by destroyed maps are reused first.
std::mutex tapes_mutex;
int next_tape = 20000;
std::vector<int> free_tapes;
}  // namespace

LieObservabilityMap::Buffers::Buffers(int states, int d)
    : n(states),
      X(myalloc2(states, d + 1)),
      Xs(myalloc2(states, d)),
      Y(myalloc2(1, d)),
      A(myalloc3(states, states, d)),
      B(myalloc3(states, states, d)),
      C(myalloc3(1, states, d + 1)),
      In(myallocI2(states)),
      Im(myallocI2(1)),
      x(myalloc1(states)) {}

LieObservabilityMap::Buffers::~Buffers() {
  myfree2(X);
  myfree2(Xs);
  myfree2(Y);
  myfree3(A);
  myfree3(B);
  myfree3(C);
  myfreeI2(n, In);
  myfreeI2(1, Im);
  myfree1(x);
}

void LieObservabilityMap::init() {
  int tag = 0;
  {
    std::lock_guard<std::mutex> lock(tapes_mutex);
    if (!free_tapes.empty()) {
      tag = free_tapes.back();
      free_tapes.pop_back();
    } else {
      if (next_tape + 1 > 32767) {
        throw InvalidInput(description_ + ": ADOL-C's tape numbers are exhausted");
      }
      tag = next_tape;
      next_tape += 2;
    }
  }
  tape_f_ = static_cast<short>(tag);
  tape_h_ = static_cast<short>(tag + 1);
  buffers_ = std::make_unique<Buffers>(n_, N_);
}

LieObservabilityMap::~LieObservabilityMap() {
  removeTape(tape_f_, ADOLC_REMOVE_COMPLETELY);
  removeTape(tape_h_, ADOLC_REMOVE_COMPLETELY);
  std::lock_guard<std::mutex> lock(tapes_mutex);
  free_tapes.push_back(tape_f_);
}

void LieObservabilityMap::check(const Eigen::VectorXd& x, int order) const {
  if (x.size() != n_) {
    std::ostringstream os;
    os << description_ << ": x must have " << n_ << " entries, got " << x.size();
    throw InvalidInput(os.str());
  }
  if (order < 1 || order > N_) {
    std::ostringstream os;
    os << description_ << ": Lie derivative order " << order << " outside 1.." << N_;
    throw InvalidInput(os.str());
  }
}

bool LieObservabilityMap::lie_derivatives(const Eigen::VectorXd& x, int order,
                                          Eigen::VectorXd& out) const {
  check(x, order);
  Buffers& b = *buffers_;
  if (!x.allFinite()) return false;
  for (int i = 0; i < n_; ++i) b.X[i][0] = x[i];
  // x_{k+1} = f_k / (k+1): the Taylor coefficients of the solution through x.
  if (forodec(tape_f_, n_, 1.0, 0, order, b.X) < 0) return false;  // another branch than taped
  for (int i = 0; i < n_; ++i) {
    b.x[i] = b.X[i][0];
    for (int k = 0; k < order; ++k) b.Xs[i][k] = b.X[i][k + 1];
  }
  double y0 = 0.0;
  if (hos_forward(tape_h_, 1, n_, order, 0, b.x, b.Xs, &y0, b.Y) < 0) return false;
  out.resize(order + 1);
  out[0] = y0;
  double factorial = 1.0;
  for (int k = 1; k <= order; ++k) {
    factorial *= k;
    out[k] = factorial * b.Y[0][k - 1];  // L_f^k h = k! y_k
  }
  return out.allFinite();
}

bool LieObservabilityMap::lie_gradients(const Eigen::VectorXd& x, int order,
                                        Eigen::MatrixXd& out) const {
  check(x, order);
  Buffers& b = *buffers_;
  if (!x.allFinite()) return false;
  const int d = order;
  for (int i = 0; i < n_; ++i) b.X[i][0] = x[i];
  if (forodec(tape_f_, n_, 1.0, 0, d, b.X) < 0) return false;
  // A_k = ∂x'_k/∂x_0 along the taped f, then B_k = dx_{k+1}/dx_0 (ADOL-C's accodec).
  hov_reverse(tape_f_, n_, n_, d - 1, n_, b.In, b.A, nullptr);
  accodec(n_, 1.0, d - 1, b.A, b.B, nullptr);
  for (int i = 0; i < n_; ++i) {
    b.x[i] = b.X[i][0];
    for (int k = 0; k < d; ++k) b.Xs[i][k] = b.X[i][k + 1];
  }
  double y0 = 0.0;
  if (hos_forward(tape_h_, 1, n_, d, d + 1, b.x, b.Xs, &y0, b.Y) < 0) return false;
  hov_reverse(tape_h_, 1, n_, d, 1, b.Im, b.C, nullptr);
  out.resize(d + 1, n_);
  double factorial = 1.0;
  for (int k = 0; k <= d; ++k) {
    if (k > 0) factorial *= k;
    for (int i = 0; i < n_; ++i) {
      // dy_k/dx_0 = C_k + Σ_{l=1..k} C_{k−l} B_{l−1}
      double total = b.C[0][i][k];
      for (int l = 1; l <= k; ++l) {
        for (int j = 0; j < n_; ++j) total += b.C[0][j][k - l] * b.B[j][i][l - 1];
      }
      out(k, i) = factorial * total;
    }
  }
  return out.allFinite();
}

bool LieObservabilityMap::value(const Eigen::VectorXd& x, Eigen::VectorXd& z) const {
  return lie_derivatives(x, N_ - 1, z);
}

bool LieObservabilityMap::jacobian(const Eigen::VectorXd& x, Eigen::MatrixXd& dq) const {
  return lie_gradients(x, N_ - 1, dq);
}

bool LieObservabilityMap::next(const Eigen::VectorXd& x, double& value,
                               Eigen::VectorXd* gradient) const {
  if (gradient) {
    if (!lie_gradients(x, N_, gradients_)) return false;
    *gradient = gradients_.row(N_).transpose();
  }
  if (!lie_derivatives(x, N_, derivatives_)) return false;
  value = derivatives_[N_];
  return std::isfinite(value);
}

}  // namespace nlobs
