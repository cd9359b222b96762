#pragma once
// The step every recursive discrete-time observer shares (Luenberger, sliding mode, EKF, UKF),
// written once: check the sample's sizes (InvalidInput naming k), place it by its time
// (SampleClock: refused samples change nothing and the step says why), move the estimate along
// each of the model's moves since the last sample (Derived::predict), then take the sample's
// outputs (Derived::update) and publish the estimate. Derived (CRTP) provides
//   bool predict(long k, const ModelStep& move);   // false: stop moving (the step says why)
//   void update(long k, const Eigen::VectorXd& y); // y's non-finite entries: not measured
//   const Eigen::VectorXd& estimate() const;
// and keeps its own state; the base holds the model, the clock and u_{k−1}, held over the moves.
#include <Eigen/Core>
#include <string>
#include <utility>

#include "nlobs/models/model.hpp"
#include "nlobs/observers/core/model_step.hpp"
#include "nlobs/observers/core/observer.hpp"
#include "nlobs/observers/core/sample_clock.hpp"

namespace nlobs::detail {

template <DiscreteModel Model, typename Derived>
class PredictUpdateObserver : public Observer {
 public:
  const ObserverStep& step(long k, double t, const Eigen::VectorXd& y,
                           const Eigen::VectorXd& u) final {
    require_sample_sizes(name(), k, y, u, model_.outputs(), model_.inputs());
    Derived& self = static_cast<Derived&>(*this);
    step_.failure.clear();
    step_.failure_message.clear();
    step_.measurement_missing = !y.array().isFinite().any();
    if (clock_.place(name(), k, t, step_)) {
      for (long j = 0; j < clock_.moves(); ++j) {
        if (!self.predict(k, clock_.move(j))) break;
      }
      clock_.commit();
      last_u_ = u;
      self.update(k, y);
    }
    step_.estimate = self.estimate();
    return step_;
  }

 protected:
  // `needs_grid`: empty when the observer integrates over an irregular interval, else why it
  // cannot (SampleClock); `same_time`: a second sample of one instant is taken.
  PredictUpdateObserver(Model model, std::string needs_grid, bool same_time)
      : model_(std::move(model)),
        clock_(SampleClock::of(model_, std::move(needs_grid), same_time)) {}

  void reset_clock() { clock_.reset(); }
  // u_{k−1}, held over the moves from the last sample, as the model's input type.
  ModelVector<double, Model::kInputs> held_input() const {
    return ModelVector<double, Model::kInputs>(last_u_);
  }

  Model model_;
  ObserverStep step_;

 private:
  SampleClock clock_;
  Eigen::VectorXd last_u_;
};

}  // namespace nlobs::detail
