#pragma once
// The catalogue's continuous models as C++ types, listed once for the explicit instantiations
// of the observers library (observers/src/instances/): the observers the CLI builds for these
// models are compiled there, once, and their headers declare them extern. A model added here
// needs its line in observers/src/instances/, in the unit of its state size (state_size_<n>*.cpp:
// NLOBS_INSTANTIATE_HIGH_GAIN_MODEL or _MVT_MODEL, whose static_asserts check the lists), or its
// users fail to link.
#include "nlobs/models/modified_chua.hpp"
#include "nlobs/models/systems.hpp"

// clang-format off
// X(Model) for every catalogue model (the MVT observer takes any of them).
#define NLOBS_FOR_EACH_CATALOGUE_MODEL(X) \
  X(ModifiedChua)                         \
  X(CubicChua)                            \
  X(Lorenz)                               \
  X(Duffing)                              \
  X(VanDerPol)                            \
  X(OscillatorNonlinearOutput)            \
  X(ChaoticNoLinear)                      \
  X(FlexibleJointRobot)                   \
  X(LunarLander)                          \
  X(LunarLanderImmersed)                  \
  X(UnknownInputIntegrator)               \
  X(LtiOutputInjection)                   \
  X(PendulumTimeVaryingFriction)

// X(Model, lowest) for the input-free one-output models (kInputs = 0, kOutputs = 1: those the
// CLI builds high-gain observers for; a time-varying one is refused when built), with
// lowest = max(2, n), the smallest order of their observability maps.
#define NLOBS_FOR_EACH_AUTONOMOUS_SINGLE_OUTPUT_CATALOGUE_MODEL(X) \
  X(ModifiedChua, 3)                                               \
  X(CubicChua, 3)                                                  \
  X(Lorenz, 3)                                                     \
  X(Duffing, 2)                                                    \
  X(VanDerPol, 2)                                                  \
  X(OscillatorNonlinearOutput, 2)                                  \
  X(LtiOutputInjection, 2)                                         \
  X(PendulumTimeVaryingFriction, 2)
// clang-format on
