#pragma once
// q_N(x) = [h, L_f h, …, L_f^{N−1} h] of any autonomous SISO model x' = f(x), y = h(x), by
// Taylor-mode AD through ADOL-C: f and h are recorded once on two tapes; the Taylor
// coefficients x_k of the solution through x (forodec) give y's, and L_f^k h(x) = k! y_k. The
// Jacobian ∂q_N/∂x follows from the tapes' reverse sweeps and the total-derivative recursion
// dy_k/dx = ∂y_k/∂x + Σ_{l=1..k} ∂y_k/∂x_l · dx_l/dx (Griewank & Walther, ch. 13) — ADOL-C's
// own lie_gradient does the same but leaks four buffers per call and mishandles N = 2, so we
// call the same drivers with buffers allocated once.
//
// The model's vector field and output must be generic in the scalar (templates on T) and free
// of value-dependent branches (a tape records one path; a different branch at x is reported
// as a failure). Inputs are held at zero and time at 0: the maps are for x' = f(x) ([HG-EMB23]).
// Not thread-safe: ADOL-C's tapes are process-wide state; one map per thread.
#include <adolc/adolc.h>

#include <Eigen/Core>
#include <array>
#include <memory>
#include <string>

#include "nlobs/models/model.hpp"
#include "nlobs/observers/core/adolc_scalar.hpp"
#include "nlobs/observers/high_gain/observability_map.hpp"

namespace nlobs {

class LieObservabilityMap final : public ObservabilityMap {
 public:
  // Records the tapes of `model`; N ≥ 2 Lie derivatives (z has N entries).
  template <ContinuousModel Model>
  LieObservabilityMap(const Model& model, int N, std::string description = "q_N by ADOL-C");
  ~LieObservabilityMap() override;
  LieObservabilityMap(const LieObservabilityMap&) = delete;
  LieObservabilityMap& operator=(const LieObservabilityMap&) = delete;

  Eigen::Index states() const override { return n_; }
  Eigen::Index dimension() const override { return N_; }
  std::string description() const override { return description_; }
  bool value(const Eigen::VectorXd& x, Eigen::VectorXd& z) const override;
  bool jacobian(const Eigen::VectorXd& x, Eigen::MatrixXd& dq) const override;
  bool has_next() const override { return true; }
  bool next(const Eigen::VectorXd& x, double& value, Eigen::VectorXd* gradient) const override;

  // L_f^0 h … L_f^order h at x (order ≤ N); `out` gets order + 1 entries.
  bool lie_derivatives(const Eigen::VectorXd& x, int order, Eigen::VectorXd& out) const;
  // Their gradients, one row per order.
  bool lie_gradients(const Eigen::VectorXd& x, int order, Eigen::MatrixXd& out) const;

 private:
  // ADOL-C's drivers take C arrays; all sized once for order N (the largest used).
  struct Buffers {
    Buffers(int n, int d);
    ~Buffers();
    Buffers(const Buffers&) = delete;
    Buffers& operator=(const Buffers&) = delete;
    int n;
    double** X;   // Taylor coefficients of x(t): X[i][k]
    double** Xs;  // the same shifted by one (hos_forward's input form)
    double** Y;   // y's coefficients 1..d
    double*** A;  // ∂f_k/∂x_j of the coefficients (hov_reverse of f)
    double*** B;  // dx_{k+1}/dx_0 (accodec)
    double*** C;  // ∂y_k/∂x_j (hov_reverse of h)
    double** In;  // identities: the weights of the reverse sweeps
    double** Im;
    double* x;
  };
  void init();
  void check(const Eigen::VectorXd& x, int order) const;
  short tape_f_ = 0, tape_h_ = 0;
  int n_ = 0, N_ = 0;
  std::string description_;
  std::unique_ptr<Buffers> buffers_;
  mutable Eigen::VectorXd derivatives_;  // next()'s scratch
  mutable Eigen::MatrixXd gradients_;
};

template <ContinuousModel Model>
LieObservabilityMap::LieObservabilityMap(const Model& model, int N, std::string description)
    : n_(Model::kStates), N_(N), description_(std::move(description)) {
  static_assert(Model::kStates != Eigen::Dynamic, "the model needs a compile-time state size");
  static_assert(Model::kOutputs == 1, "observability maps here are for one output y = h(x)");
  constexpr int n = Model::kStates;
  if (N < 2 || N < n) {
    throw InvalidInput(description_ + ": N = " + std::to_string(N) +
                       " must be >= 2 and >= the state dimension " + std::to_string(n));
  }
  if (vector_field_depends_on_time(model)) {
    throw InvalidInput(description_ +
                       ": the model's vector field depends on t; observability maps here are for "
                       "autonomous systems x' = f(x)");
  }
  init();  // tape numbers and buffers
  using ADState = ModelVector<adouble, n>;
  const typename Model::Input u = Model::Input::Zero();
  std::array<double, n> sink{};
  // A generic taping point: the tape holds the operations, not the values.
  const auto point = [](int i) { return 0.3 + 0.1 * i; };
  trace_on(tape_f_);
  {
    ADState x;
    for (int i = 0; i < n; ++i) x[i] <<= point(i);
    ADState f = model.vector_field(x, u, 0.0);
    for (int i = 0; i < n; ++i) f[i] >>= sink[static_cast<size_t>(i)];
  }
  trace_off();
  trace_on(tape_h_);
  {
    ADState x;
    for (int i = 0; i < n; ++i) x[i] <<= point(i);
    ModelVector<adouble, 1> y = model.h(x);
    y[0] >>= sink[0];
  }
  trace_off();
}

}  // namespace nlobs
