#pragma once
// q_N(x) = [h, L_f h, …, L_f^{N−1} h] and L_f^N h of any autonomous SISO model x' = f(x),
// y = h(x), by Taylor-mode AD through Boost.Math's autodiff: its fvar<G, D> is a polynomial
// truncated after t^D with coefficients G, and the model's f and h, written for any scalar,
// run on it directly. The Taylor coefficients of the solution through x (Griewank & Walther,
// ch. 13) follow from
//     x(t) = Σ_k x_k t^k,   x_0 = x,   x_{k+1} = [f(x(t))]_k / (k + 1),
// since [f(x(t))]_k needs x_0 … x_k only; then y(t) = h(x(t)) has y_k = L_f^k h(x) / k!.
// Gradients ∂(L_f^k h)/∂x_j: the same recursion with coefficients G = fvar<double, 1> seeded
// in direction e_j (one pass per state).
//
// Against LieObservabilityMap (ADOL-C): no tape, so value-dependent branches in f and h are
// fine; the map is const and stateless, so thread-safe; nothing allocates (fvar is a
// std::array), which makes a whole high-gain step with the projection allocation-free; and it is
// faster — per call 34–41× for q_N, 12–13× for ∂q_N/∂x, 12–16× for L_f^N h with its gradient
// (Duffing N = 6, Lorenz N = 4; bench BM_ObservabilityMap*), the gap narrowing with N (Lorenz
// N = 8: 3.3× for the Jacobian). But N is a compile-time parameter:
// make_taylor_observability_map dispatches a run-time N up to kMaxTaylorObservabilityOrder;
// past it, ADOL-C.
// Inputs are held at zero and time at 0: the maps are for x' = f(x) ([HG-EMB23]).
#include <Eigen/Core>
#include <array>
#include <boost/math/differentiation/autodiff.hpp>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>

#include "nlobs/models/catalogue.hpp"
#include "nlobs/models/model.hpp"
#include "nlobs/observers/high_gain/observability_map.hpp"

namespace nlobs {

template <ContinuousModel Model, int N>
class TaylorObservabilityMap final : public ObservabilityMap {
 public:
  static constexpr int n = Model::kStates;
  static_assert(n != Eigen::Dynamic, "the model needs a compile-time state size");
  static_assert(Model::kOutputs == 1, "observability maps here are for one output y = h(x)");
  static_assert(N >= 2 && N >= n, "N must be >= 2 and >= the state dimension");

  explicit TaylorObservabilityMap(Model model = {},
                                  std::string description = "q_N by Taylor mode (Boost autodiff)")
      : model_(std::move(model)), description_(std::move(description)) {
    if (vector_field_depends_on_time(model_)) {
      throw InvalidInput(description_ +
                         ": the model's vector field depends on t; observability maps here are "
                         "for autonomous systems x' = f(x)");
    }
  }

  Eigen::Index states() const override { return n; }
  Eigen::Index dimension() const override { return N; }
  std::string description() const override { return description_; }

  bool value(const Eigen::VectorXd& x, Eigen::VectorXd& z) const override;

  bool jacobian(const Eigen::VectorXd& x, Eigen::MatrixXd& dq) const override;

  bool has_next() const override { return true; }

  bool next(const Eigen::VectorXd& x, double& value, Eigen::VectorXd* gradient) const override;

  const Model& model() const { return model_; }

 private:
  // A first-order derivative in one direction, the coefficient type of the gradient passes.
  using Tangent = boost::math::differentiation::autodiff_fvar<double, 1>;

  // fvar in t of order D over coefficients G: autodiff_fvar nests the first order outermost.
  template <typename G, int D>
  struct Series;
  template <int D>
  struct Series<double, D> {
    using type = boost::math::differentiation::autodiff_fvar<double, D>;
  };
  template <int D>
  struct Series<Tangent, D> {
    using type = boost::math::differentiation::autodiff_fvar<double, D, 1>;
  };

  static Eigen::Matrix<Tangent, n, 1> seeded(const Eigen::VectorXd& x, int direction) {
    Eigen::Matrix<Tangent, n, 1> g;
    for (int i = 0; i < n; ++i) g[i] = Tangent(x[i], i == direction);
    return g;
  }

  // t^k and ε t^k (ε the inner direction, for Tangent coefficients): the monomials g t^k are
  // built from them by scalar products. Not T(g) t^k: for g = Tangent, T(g) picks fvar's
  // converting constructor, which puts g's derivative into the t¹ coefficient; and t comes from a
  // depth-one fvar converted to T, since one mixed into T directly would land outermost too.
  // Constants of (T, D): built once per type (thread-safe static initialisation), not per call.
  template <typename T, int D>
  struct Monomials {
    std::array<T, D + 1> power, inner;
  };
  template <typename T, int D>
  static const Monomials<T, D>& monomials() {
    static const Monomials<T, D> basis = [] {
      Monomials<T, D> b;
      b.power[0] = T(1.0);
      const T t = T(boost::math::differentiation::make_fvar<double, D>(0.0));
      for (size_t k = 1; k <= D; ++k) b.power[k] = b.power[k - 1] * t;
      if constexpr (T::depth > 1) {      // Tangent coefficients
        const T epsilon = T(0.0, true);  // 0 + ε, constant in t
        for (size_t k = 0; k <= D; ++k) b.inner[k] = b.power[k] * epsilon;
      }
      return b;
    }();
    return basis;
  }

  // L_f^0 h … L_f^D h at x0 (coefficients G: values, or values with one directional derivative).
  template <int D, typename G>
  std::array<G, D + 1> series(const Eigen::Matrix<G, n, 1>& x0) const {
    using T = typename Series<G, D>::type;
    const Monomials<T, D>& basis = monomials<T, D>();
    const auto& power = basis.power;
    const auto& inner = basis.inner;
    const auto monomial = [&](const G& g, size_t k) {
      if constexpr (std::is_same_v<G, double>) {
        return T(power[k] * g);
      } else {
        return T(power[k] * g[0] + inner[k] * g[1]);
      }
    };
    Eigen::Matrix<T, n, 1> X;
    for (int i = 0; i < n; ++i) X[i] = monomial(x0[i], 0);
    const typename Model::Input u = Model::Input::Zero();
    for (int k = 0; k < D; ++k) {
      const Eigen::Matrix<T, n, 1> F = model_.vector_field(X, u, 0.0);
      for (int i = 0; i < n; ++i) {
        const G next = F[i][static_cast<size_t>(k)] / static_cast<double>(k + 1);
        X[i] += monomial(next, static_cast<size_t>(k + 1));
      }
    }
    const T y = model_.h(X)[0];
    std::array<G, D + 1> out;
    double factorial = 1.0;
    for (int k = 0; k <= D; ++k) {
      if (k > 0) factorial *= k;
      out[static_cast<size_t>(k)] = y[static_cast<size_t>(k)] * factorial;  // L_f^k h = k! y_k
    }
    return out;
  }

  Model model_;
  std::string description_;
};

template <ContinuousModel Model, int N>
bool TaylorObservabilityMap<Model, N>::value(const Eigen::VectorXd& x, Eigen::VectorXd& z) const {
  check_states(x);
  if (!x.allFinite()) return false;
  const auto c = series<N - 1>(Eigen::Matrix<double, n, 1>(x));
  z.resize(N);
  for (int k = 0; k < N; ++k) z[k] = c[static_cast<size_t>(k)];
  return z.allFinite();
}

template <ContinuousModel Model, int N>
bool TaylorObservabilityMap<Model, N>::jacobian(const Eigen::VectorXd& x,
                                                Eigen::MatrixXd& dq) const {
  check_states(x);
  dq.resize(N, n);
  if (!x.allFinite()) return false;
  for (int j = 0; j < n; ++j) {
    const auto c = series<N - 1>(seeded(x, j));
    for (int k = 0; k < N; ++k) dq(k, j) = c[static_cast<size_t>(k)][1];
  }
  return dq.allFinite();
}

template <ContinuousModel Model, int N>
bool TaylorObservabilityMap<Model, N>::next(const Eigen::VectorXd& x, double& value,
                                            Eigen::VectorXd* gradient) const {
  check_states(x);
  if (!x.allFinite()) return false;
  if (!gradient) {
    value = series<N>(Eigen::Matrix<double, n, 1>(x))[N];
    return std::isfinite(value);
  }
  gradient->resize(n);
  for (int j = 0; j < n; ++j) {
    const auto c = series<N>(seeded(x, j));
    value = c[N][0];
    (*gradient)[j] = c[N][1];
  }
  return std::isfinite(value) && gradient->allFinite();
}

// The largest N make_taylor_observability_map instantiates: each N is a separate type, compiled
// once per catalogue model in the observers library (src/instances/). Past it,
// LieObservabilityMap.
inline constexpr int kMaxTaylorObservabilityOrder = 8;

// TaylorObservabilityMap<Model, N> for a run-time N in [max(2, n), kMaxTaylorObservabilityOrder].
template <ContinuousModel Model>
std::shared_ptr<ObservabilityMap> make_taylor_observability_map(
    const Model& model, int N, std::string description = "q_N by Taylor mode (Boost autodiff)") {
  constexpr int lowest = Model::kStates > 2 ? Model::kStates : 2;
  std::shared_ptr<ObservabilityMap> map;
  const auto make = [&]<int... Ns>(std::integer_sequence<int, Ns...>) {
    (void)((N == lowest + Ns ? (map = std::make_shared<TaylorObservabilityMap<Model, lowest + Ns>>(
                                    model, description),
                                true)
                             : false) ||
           ...);
  };
  if constexpr (lowest <= kMaxTaylorObservabilityOrder) {
    make(std::make_integer_sequence<int, kMaxTaylorObservabilityOrder - lowest + 1>{});
  }
  if (!map) {
    throw InvalidInput(description + ": N = " + std::to_string(N) + " outside " +
                       std::to_string(lowest) + ".." +
                       std::to_string(kMaxTaylorObservabilityOrder) +
                       " (N >= 2 and >= the state dimension; larger N: LieObservabilityMap)");
  }
  return map;
}

// X(Model, N) for every order make_taylor_observability_map builds, from `lowest` = max(2, n):
// the extern declarations below and the instantiations in src/instances/ use the same list.
#define NLOBS_TAYLOR_ORDERS_FROM_3(X, M) X(M, 3) X(M, 4) X(M, 5) X(M, 6) X(M, 7) X(M, 8)
#define NLOBS_TAYLOR_ORDERS_FROM(X, M, lowest) NLOBS_TAYLOR_ORDERS_FROM_##lowest(X, M)
#define NLOBS_TAYLOR_ORDERS_FROM_2(X, M) X(M, 2) NLOBS_TAYLOR_ORDERS_FROM_3(X, M)
static_assert(kMaxTaylorObservabilityOrder == 8, "NLOBS_TAYLOR_ORDERS_FROM_3 stops at 8");

// Compiled once in the observers library for the catalogue's models (src/instances/).
#define NLOBS_EXTERN_TAYLOR_MAP(M, N) extern template class TaylorObservabilityMap<M, N>;
#define NLOBS_EXTERN_TAYLOR_MAPS(M, lowest)                                           \
  extern template std::shared_ptr<ObservabilityMap> make_taylor_observability_map<M>( \
      const M&, int, std::string);                                                    \
  NLOBS_TAYLOR_ORDERS_FROM(NLOBS_EXTERN_TAYLOR_MAP, M, lowest)
NLOBS_FOR_EACH_AUTONOMOUS_SINGLE_OUTPUT_CATALOGUE_MODEL(NLOBS_EXTERN_TAYLOR_MAPS)
#undef NLOBS_EXTERN_TAYLOR_MAPS
#undef NLOBS_EXTERN_TAYLOR_MAP

}  // namespace nlobs
