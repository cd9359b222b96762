#pragma once
// One move of a discrete model between two samples (what SampleClock, sample_clock.hpp, gives
// an observer for each sample), and advance(), which applies it.
#include "nlobs/models/model.hpp"

namespace nlobs {

// One move of a discrete model: f(x, u, index) for a fixed-step model, or its flow over
// [time, time + length] for one that integrates over any interval.
struct ModelStep {
  long index = 0;       // k of f(x, u, k)
  double time = 0.0;    // t of flow(x, u, t, dt)
  double length = 0.0;  // dt
  bool flow = false;
  double weight = 1.0;  // length / T: a process noise Q given per step T is weight · Q here
};

// x after the move s from x (u held over it).
template <DiscreteModel Model, typename State>
State advance(const Model& model, const State& x, const ModelVector<double, Model::kInputs>& u,
              const ModelStep& s) {
  if constexpr (IntervalModel<Model>) {
    if (s.flow) return State(model.flow(x, u, s.time, s.length));
  }
  return State(model.f(x, u, s.index));
}

}  // namespace nlobs
