#pragma once
// A discrete model chosen at run time (scenario files, the CLI): sizes are dynamic and f, h
// (and the flow over any interval, when the model has one) are virtual, instantiated for the
// two scalars the library evaluates them with — double and the AD scalar
// ceres::Jet<double, kJetStride> that run-time-size Jacobians use.
#include <memory>
#include <stdexcept>
#include <string>

#include "nlobs/models/model.hpp"
#include "nlobs/solvers/autodiff.hpp"

namespace nlobs {

class AnyModel {
 public:
  static constexpr int kStates = Eigen::Dynamic;
  static constexpr int kInputs = Eigen::Dynamic;
  static constexpr int kOutputs = Eigen::Dynamic;
  static constexpr bool kTracesSparsity = false;  // double and Jet only (models/model.hpp)
  using Jet = ceres::Jet<double, kJetStride>;
  template <typename T>
  using State = ModelVector<T, Eigen::Dynamic>;
  using Input = ModelVector<double, Eigen::Dynamic>;

  // `sample_time`: the time between samples k and k + 1 (0: the model's own sample_time_of).
  template <DiscreteModel Model>
  AnyModel(std::string name, Model model, double sample_time = 0.0)
      : name_(std::move(name)),
        sample_time_(sample_time != 0.0 ? sample_time : sample_time_of(model)),
        has_flow_(IntervalModel<Model>),
        impl_(std::make_shared<Impl<Model>>(std::move(model))) {}

  const std::string& name() const { return name_; }
  double sample_time() const { return sample_time_; }
  // Whether flow() integrates over any interval (the model has a flow); otherwise it throws.
  bool has_flow() const { return has_flow_; }
  Eigen::Index states() const { return impl_->states(); }
  Eigen::Index inputs() const { return impl_->inputs(); }
  Eigen::Index outputs() const { return impl_->outputs(); }

  template <typename T>
  State<T> f(const State<T>& x, const Input& u, long k) const {
    static_assert(std::is_same_v<T, double> || std::is_same_v<T, Jet>,
                  "AnyModel is evaluated with double or ceres::Jet<double, kJetStride>");
    return impl_->f(x, u, k);
  }
  // x(t + dt) from x(t), u held. Throws std::logic_error when !has_flow() (the observers ask
  // has_flow() first: sample_clock.hpp).
  template <typename T>
  State<T> flow(const State<T>& x, const Input& u, double t, double dt) const {
    static_assert(std::is_same_v<T, double> || std::is_same_v<T, Jet>,
                  "AnyModel is evaluated with double or ceres::Jet<double, kJetStride>");
    return impl_->flow(x, u, t, dt);
  }
  template <typename T>
  State<T> h(const State<T>& x) const {
    static_assert(std::is_same_v<T, double> || std::is_same_v<T, Jet>,
                  "AnyModel is evaluated with double or ceres::Jet<double, kJetStride>");
    return impl_->h(x);
  }
  std::string domain_violation(const State<double>& x) const { return impl_->domain(x); }

 private:
  struct Base {
    virtual ~Base() = default;
    virtual Eigen::Index states() const = 0;
    virtual Eigen::Index inputs() const = 0;
    virtual Eigen::Index outputs() const = 0;
    virtual State<double> f(const State<double>&, const Input&, long) const = 0;
    virtual State<Jet> f(const State<Jet>&, const Input&, long) const = 0;
    virtual State<double> flow(const State<double>&, const Input&, double, double) const = 0;
    virtual State<Jet> flow(const State<Jet>&, const Input&, double, double) const = 0;
    virtual State<double> h(const State<double>&) const = 0;
    virtual State<Jet> h(const State<Jet>&) const = 0;
    virtual std::string domain(const State<double>&) const = 0;
  };

  template <typename Model>
  struct Impl final : Base {
    explicit Impl(Model m) : model(std::move(m)) {}
    Model model;
    Eigen::Index states() const override { return model.states(); }
    Eigen::Index inputs() const override { return model.inputs(); }
    Eigen::Index outputs() const override { return model.outputs(); }
    template <typename T>
    State<T> f_impl(const State<T>& x, const Input& u, long k) const {
      using S = ModelVector<T, Model::kStates>;
      using U = ModelVector<double, Model::kInputs>;
      return model.f(S(x), U(u), k);
    }
    template <typename T>
    State<T> flow_impl(const State<T>& x, const Input& u, double t, double dt) const {
      if constexpr (IntervalModel<Model>) {
        using S = ModelVector<T, Model::kStates>;
        using U = ModelVector<double, Model::kInputs>;
        return model.flow(S(x), U(u), t, dt);
      } else {
        throw std::logic_error("AnyModel::flow: the model has no flow over an interval");
      }
    }
    template <typename T>
    State<T> h_impl(const State<T>& x) const {
      using S = ModelVector<T, Model::kStates>;
      return model.h(S(x));
    }
    State<double> f(const State<double>& x, const Input& u, long k) const override {
      return f_impl(x, u, k);
    }
    State<Jet> f(const State<Jet>& x, const Input& u, long k) const override {
      return f_impl(x, u, k);
    }
    State<double> flow(const State<double>& x, const Input& u, double t, double dt) const override {
      return flow_impl(x, u, t, dt);
    }
    State<Jet> flow(const State<Jet>& x, const Input& u, double t, double dt) const override {
      return flow_impl(x, u, t, dt);
    }
    State<double> h(const State<double>& x) const override { return h_impl(x); }
    State<Jet> h(const State<Jet>& x) const override { return h_impl(x); }
    std::string domain(const State<double>& x) const override {
      return domain_violation_of(model, ModelVector<double, Model::kStates>(x));
    }
  };

  std::string name_;
  double sample_time_ = 0.0;
  bool has_flow_ = false;
  std::shared_ptr<const Base> impl_;
};

}  // namespace nlobs
