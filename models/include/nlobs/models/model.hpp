#pragma once
// What a model is. Two shapes, both with sizes fixed at compile time where known
// (Eigen::Dynamic allowed) and functions generic in the scalar T, so that solvers can
// differentiate them by AD:
//
//   continuous:  x' = F(x, u, t),  y = h(x)
//     static constexpr int kStates, kInputs, kOutputs;
//     template <class T> State<T>  vector_field(const State<T>& x, const Input& u, double t) const;
//     template <class T> Output<T> h(const State<T>& x) const;
//
//   discrete:    x⁺ = f(x, u, k),  y = h(x)   (a continuous model with a discretisation, or
//     a model defined in discrete time)
//     template <class T> State<T>  f(const State<T>& x, const Input& u, long k) const;
//     template <class T> Output<T> h(const State<T>& x) const;
//   and, optionally, what observers of samples with times use:
//     double sample_time() const;  (or step())  T, the time between samples k and k + 1
//     template <class T> State<T>  flow(const State<T>& x, const Input& u, double t,
//                                       double dt) const;   x(t + dt) from x(t), u held
//   A model with a flow (the discretisations of a continuous model) integrates over any
//   interval, so it takes irregular samples; one without (a map defined in discrete time) has a
//   fixed step, and observers refuse a sample off its grid (observers/core/sample_clock.hpp).
//
// Both may declare a domain: `std::string domain_violation(const State<double>& x) const`
// returns an empty string inside and a message naming the state and the bound outside (the
// lunar lander's mass must stay positive). Inputs are plain doubles: nothing differentiates
// with respect to u.
#include <Eigen/Core>
#include <concepts>
#include <string>

namespace nlobs {

template <typename T, int N>
using ModelVector = Eigen::Matrix<T, N, 1>;

template <typename M>
concept ContinuousModel = requires(const M m, const ModelVector<double, M::kStates>& x,
                                   const ModelVector<double, M::kInputs>& u) {
  {m.vector_field(x, u, 0.0)};
  {m.h(x)};
};

template <typename M>
concept DiscreteModel = requires(const M m, const ModelVector<double, M::kStates>& x,
                                 const ModelVector<double, M::kInputs>& u) {
  {m.f(x, u, 0L)};
  {m.h(x)};
};

// Sizes and vector types of a model with compile-time sizes.
template <int N, int M, int P>
struct ModelSizes {
  static constexpr int kStates = N;
  static constexpr int kInputs = M;
  static constexpr int kOutputs = P;
  template <typename T>
  using State = ModelVector<T, N>;
  template <typename T>
  using Output = ModelVector<T, P>;
  using Input = ModelVector<double, M>;
  static constexpr Eigen::Index states() { return N; }
  static constexpr Eigen::Index inputs() { return M; }
  static constexpr Eigen::Index outputs() { return P; }
};

// The domain of a model that declares none: everywhere.
template <typename M>
std::string domain_violation_of(const M& model, const ModelVector<double, M::kStates>& x) {
  if constexpr (requires { model.domain_violation(x); }) {
    return model.domain_violation(x);
  } else {
    return {};
  }
}

// Whether observers may evaluate a model on SparsityTracer scalars (solvers/sparse/) to find the
// pattern of its Jacobians once and keep it. A model opts in with
// `static constexpr bool kTracesSparsity = true;` when it has a run-time size, its functions
// compile with that scalar as they do with ceres::Jet, and its coupling between states does not
// change with k, t or u (comparisons of those are not seen by the tracer, so a pattern that
// depends on them would be kept stale). Others — the default — keep the dense AD Jacobian, whose
// exact zeros the EKF still skips (observers/core/move_covariance.hpp).
template <typename M>
constexpr bool traces_sparsity() {
  if constexpr (requires { M::kTracesSparsity; }) {
    return M::kTracesSparsity && M::kStates == Eigen::Dynamic;
  } else {
    return false;
  }
}

// Whether this model, as configured, may be traced: it opts in (traces_sparsity) and, when it
// says so at run time with `bool traceable() const`, its moves take the same steps at every x
// (Discretized: not dopri5, whose steps follow the values, nor sdirk3, whose move is dense).
template <typename M>
bool traces_sparsity_now(const M& model) {
  if constexpr (!traces_sparsity<M>()) {
    return false;
  } else if constexpr (requires { model.traceable(); }) {
    return model.traceable();
  } else {
    return true;
  }
}

// A discrete model that integrates over any interval: flow(x, u, t, dt).
template <typename M>
concept IntervalModel = DiscreteModel<M> &&
    requires(const M m, const ModelVector<double, M::kStates>& x,
             const ModelVector<double, M::kInputs>& u) {
  {m.flow(x, u, 0.0, 0.0)};
};

// T, the time between samples k and k + 1 a discrete model declares (sample_time() or step());
// 0 when it declares none.
template <DiscreteModel M>
double sample_time_of(const M& model) {
  if constexpr (requires { model.sample_time(); }) {
    return static_cast<double>(model.sample_time());
  } else if constexpr (requires { model.step(); }) {
    return static_cast<double>(model.step());
  } else {
    return 0.0;
  }
}

// Whether the model integrates over any interval: it has a flow (a model chosen at run time
// says so with has_flow()).
template <DiscreteModel M>
bool has_interval_flow(const M& model) {
  if constexpr (requires { model.has_flow(); }) {
    return model.has_flow();
  } else {
    return IntervalModel<M>;
  }
}

// True when F(x, 0, t) changes with t at a few probe states: a time-varying model (observers
// built for x' = f(x), such as the high-gain observer of [HG-EMB23], refuse it).
template <ContinuousModel M>
bool vector_field_depends_on_time(const M& model) {
  static_assert(M::kStates != Eigen::Dynamic && M::kInputs != Eigen::Dynamic,
                "vector_field_depends_on_time needs compile-time sizes");
  using State = ModelVector<double, M::kStates>;
  const ModelVector<double, M::kInputs> u = ModelVector<double, M::kInputs>::Zero();
  for (const State& x : {State(State::LinSpaced(M::kStates, 0.3, 1.1)),
                         State(State::LinSpaced(M::kStates, -0.7, 0.4))}) {
    const State f0 = model.vector_field(x, u, 0.0);
    for (double t : {0.7, 3.1}) {
      if (!(model.vector_field(x, u, t) == f0)) return true;
    }
  }
  return false;
}

}  // namespace nlobs
