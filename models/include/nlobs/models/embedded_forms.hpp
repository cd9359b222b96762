#pragma once
// The embeddings of [HG-EMB23], expanded by hand (checked symbolically, and in the tests
// against the maps ADOL-C computes from the models): q_N for the Duffing oscillator (N = 6),
// the oscillator with output x1² + x1 (N = 4), Lorenz (N = 4) and Van der Pol (N = 5); the
// explicit α(z) = d/dt z_N of the normal form z' = (z2, …, zN, α(z)) for the first two, and the
// oscillator's explicit inverse. Each map has the ExplicitObservabilityMap form; α and the
// inverse are generic in the scalar too (∂α by AD for implicit integration).
#include <Eigen/Core>
#include <optional>

#include "nlobs/models/systems.hpp"

namespace nlobs {

// Duffing x1' = x2, x2' = x1 − x1³, y = x2 (models: Duffing).
struct DuffingEmbedding {
  static constexpr int kStates = 2, kDimension = 6;
  template <typename T>
  Eigen::Matrix<T, 6, 1> operator()(const Eigen::Matrix<T, 2, 1>& x) const {
    const T a = x[0], b = x[1], a2 = a * a, a3 = a2 * a, a4 = a2 * a2, a5 = a4 * a, b2 = b * b;
    Eigen::Matrix<T, 6, 1> z;
    z[0] = b;
    z[1] = a - a3;
    z[2] = (1.0 - 3.0 * a2) * b;
    z[3] = 3.0 * a5 - 4.0 * a3 - 6.0 * a * b2 + a;
    z[4] = 27.0 * a4 * b - 24.0 * a2 * b - 6.0 * b2 * b + b;
    z[5] = -27.0 * a5 * a2 + 51.0 * a5 + 126.0 * a3 * b2 - 25.0 * a3 - 66.0 * a * b2 + a;
    return z;
  }
  // α = −9 z5 − 126 z1² z3 − 6 z3 − 441 z1 z2² + 6 z1³ + 16 z1 ([HG-EMB23])
  template <typename T>
  T alpha(const Eigen::Matrix<T, 6, 1>& z) const {
    return -9.0 * z[4] - 126.0 * z[0] * z[0] * z[2] - 6.0 * z[2] - 441.0 * z[0] * z[1] * z[1] +
           6.0 * z[0] * z[0] * z[0] + 16.0 * z[0];
  }
};

// x1' = x2, x2' = −x1, y = x1² + x1 (models: OscillatorNonlinearOutput).
struct OscillatorEmbedding {
  static constexpr int kStates = 2, kDimension = 4;
  template <typename T>
  Eigen::Matrix<T, 4, 1> operator()(const Eigen::Matrix<T, 2, 1>& x) const {
    const T a = x[0], b = x[1];
    Eigen::Matrix<T, 4, 1> z;
    z[0] = a * a + a;
    z[1] = (2.0 * a + 1.0) * b;
    z[2] = -2.0 * a * a - a + 2.0 * b * b;
    z[3] = -(8.0 * a + 1.0) * b;
    return z;
  }
  // α = (2/3) z4² + (16/3) z2 z4 − 7 z3 + (32/3) z2² − 6 z1 ([HG-EMB23])
  template <typename T>
  T alpha(const Eigen::Matrix<T, 4, 1>& z) const {
    return (2.0 / 3.0) * z[3] * z[3] + (16.0 / 3.0) * z[1] * z[3] - 7.0 * z[2] +
           (32.0 / 3.0) * z[1] * z[1] - 6.0 * z[0];
  }
  // x2 = (z4 + 4 z2)/3, x1 = z3 + 2 z1 − 2 x2² — exact on the image of q4.
  template <typename T>
  Eigen::Matrix<T, 2, 1> inverse(const Eigen::Matrix<T, 4, 1>& z) const {
    const T x2 = (z[3] + 4.0 * z[1]) / 3.0;
    return Eigen::Matrix<T, 2, 1>(z[2] + 2.0 * z[0] - 2.0 * x2 * x2, x2);
  }
};

// Lorenz (σ, ρ, β) = (10, 28, 8/3), y = x1: the paper's q4 (models: Lorenz, default parameters).
struct LorenzEmbedding {
  static constexpr int kStates = 3, kDimension = 4;
  template <typename T>
  Eigen::Matrix<T, 4, 1> operator()(const Eigen::Matrix<T, 3, 1>& x) const {
    const T a = x[0], b = x[1], c = x[2];
    Eigen::Matrix<T, 4, 1> z;
    z[0] = a;
    z[1] = -10.0 * a + 10.0 * b;
    z[2] = -10.0 * a * c + 380.0 * a - 110.0 * b;
    z[3] = -10.0 * a * a * b + (710.0 / 3.0) * a * c - 6880.0 * a - 100.0 * b * c + 3910.0 * b;
    return z;
  }
};

// Van der Pol x1' = x2, x2' = −x1 − x2(x1² − 1), y = x2 (models: VanDerPol, μ = 1).
struct VanDerPolEmbedding {
  static constexpr int kStates = 2, kDimension = 5;
  template <typename T>
  Eigen::Matrix<T, 5, 1> operator()(const Eigen::Matrix<T, 2, 1>& x) const {
    const T a = x[0], b = x[1], a2 = a * a, a3 = a2 * a, a4 = a2 * a2, b2 = b * b;
    Eigen::Matrix<T, 5, 1> z;
    z[0] = b;
    z[1] = -a2 * b - a + b;
    z[2] = a4 * b + a3 - 2.0 * a2 * b - 2.0 * a * b2 - a;
    z[3] = -a4 * a2 * b - a4 * a + 3.0 * a4 * b + 8.0 * a3 * b2 + 2.0 * a3 + 5.0 * a2 * b -
           8.0 * a * b2 - 2.0 * b2 * b - b;
    z[4] = a4 * a4 * b + a4 * a3 - 4.0 * a4 * a2 * b - 22.0 * a4 * a * b2 - 3.0 * a4 * a -
           23.0 * a4 * b + 44.0 * a3 * b2 - 5.0 * a3 + 30.0 * a2 * b2 * b + 28.0 * a2 * b + a -
           14.0 * b2 * b - b;
    return z;
  }
};

// The customisation point the model registry looks for (nlobs/registry/register_model.hpp):
// hand_embedding(const Model&), found by argument-dependent lookup, gives the model's hand q_N
// where it holds (empty elsewhere: Lorenz and Van der Pol at their documented parameters only),
// for the high-gain observer's "map": "explicit", "alpha": "explicit", "inverse" and
// "saturation.box".
inline std::optional<DuffingEmbedding> hand_embedding(const Duffing&) {
  return DuffingEmbedding{};
}
inline std::optional<OscillatorEmbedding> hand_embedding(const OscillatorNonlinearOutput&) {
  return OscillatorEmbedding{};
}
inline std::optional<LorenzEmbedding> hand_embedding(const Lorenz& m) {
  const LorenzParameters d;
  if (m.p.sigma != d.sigma || m.p.rho != d.rho || m.p.beta != d.beta) return std::nullopt;
  return LorenzEmbedding{};
}
inline std::optional<VanDerPolEmbedding> hand_embedding(const VanDerPol& m) {
  if (m.mu != 1.0) return std::nullopt;
  return VanDerPolEmbedding{};
}

}  // namespace nlobs
