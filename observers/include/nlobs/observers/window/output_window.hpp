#pragma once
// The moving-horizon output window of [MGFF23]: the last N samples of y (and u) in a ring
// buffer, and the window map
//   H(w) = [h(w), h(f(w, u_{k0}, k0)), …, h(f^{N−1}(w))] ∈ R^{N·p},  k0 = k − N + 1,
// with the residual Y − H(w). N = n/p is the paper's square window; N > n/p overdetermines it.
// Samples are pushed in time order; a non-finite sample is refused (the caller decides what a
// missing measurement means).
#include <limits>
#include <sstream>
#include <stdexcept>

#include "nlobs/models/integration_failure.hpp"
#include "nlobs/models/model.hpp"
#include "nlobs/solvers/status.hpp"

namespace nlobs {

template <DiscreteModel Model>
class OutputWindow {
 public:
  static constexpr int kStates = Model::kStates;
  template <typename T>
  using State = ModelVector<T, kStates>;
  using Input = ModelVector<double, Model::kInputs>;

  // Throws InvalidInput when N·p < n (the window cannot determine the state) or N < 1.
  OutputWindow(Model model, Eigen::Index length)
      : model_(std::move(model)),
        n_(model_.states()),
        p_(model_.outputs()),
        m_(model_.inputs()),
        length_(length) {
    if (length_ < 1 || length_ * p_ < n_) {
      std::ostringstream os;
      os << "OutputWindow: length N = " << length_ << " with p = " << p_
         << " outputs gives N*p = " << length_ * p_ << " < n = " << n_
         << " states: the window cannot determine the state";
      throw InvalidInput(os.str());
    }
    y_.resize(p_, length_);
    u_.resize(m_, length_);
    stacked_.resize(length_ * p_);
  }

  const Model& model() const { return model_; }
  Eigen::Index length() const { return length_; }
  Eigen::Index rows() const { return length_ * p_; }
  Eigen::Index states() const { return n_; }
  bool full() const { return count_ >= length_; }
  Eigen::Index count() const { return count_ < length_ ? count_ : length_; }
  // Sample index of the window's first (oldest) sample: k − N + 1.
  long first_index() const { return last_index_ - static_cast<long>(length_) + 1; }
  long last_index() const { return last_index_; }

  void clear() {
    count_ = 0;
    head_ = 0;
  }

  // Appends sample k. Throws InvalidInput for wrong sizes, non-finite values, or a k that
  // does not follow the previous one (the window map assumes consecutive samples).
  void push(long k, const Eigen::VectorXd& y, const Eigen::VectorXd& u) {
    if (y.size() != p_ || u.size() != m_) {
      std::ostringstream os;
      os << "OutputWindow::push: sample " << k << " has " << y.size() << " outputs and " << u.size()
         << " inputs, the model has " << p_ << " and " << m_;
      throw InvalidInput(os.str());
    }
    if (!y.allFinite() || !u.allFinite()) {
      std::ostringstream os;
      os << "OutputWindow::push: sample " << k << " is not finite";
      throw InvalidInput(os.str());
    }
    if (count_ > 0 && k != last_index_ + 1) {
      std::ostringstream os;
      os << "OutputWindow::push: sample " << k << " does not follow sample " << last_index_
         << " (clear() the window after a gap)";
      throw InvalidInput(os.str());
    }
    y_.col(head_) = y;
    u_.col(head_) = u;
    head_ = (head_ + 1) % length_;
    ++count_;
    last_index_ = k;
    // Oldest first: the slot after the newest is the oldest once the ring is full.
    for (Eigen::Index j = 0; j < length_; ++j) {
      stacked_.segment(j * p_, p_) = y_.col((head_ + j) % length_);
    }
  }

  // Y = [y_{k0}; …; y_k] (valid when full()).
  const Eigen::VectorXd& outputs() const { return stacked_; }
  // u at window position j (0 = oldest).
  auto input(Eigen::Index j) const { return u_.col((head_ + j) % length_); }

  // out = H(w), for any scalar T; `out` has rows() entries (a fixed-size vector for a square
  // window keeps the evaluation allocation-free). Where the model's discretisation cannot
  // integrate on from w (IntegrationFailure: an adaptive or implicit scheme at a state far
  // outside its range) the rest of H is NaN: to an engine, a trial point that is not finite,
  // rejected as one where an explicit step overflowed.
  template <typename T, typename Out>
  void map_into(const State<T>& w, Out& out) const {
    State<T> x = w;
    const long k0 = first_index();
    for (Eigen::Index j = 0; j < length_; ++j) {
      out.segment(j * p_, p_) = model_.h(x);
      if (j + 1 == length_) break;
      try {
        x = model_.f(x, Input(input(j)), k0 + static_cast<long>(j));
      } catch (const IntegrationFailure&) {
        out.tail((length_ - j - 1) * p_).setConstant(T(std::numeric_limits<double>::quiet_NaN()));
        return;
      }
    }
  }

  template <typename T>
  ModelVector<T, Eigen::Dynamic> map(const State<T>& w) const {
    ModelVector<T, Eigen::Dynamic> out(rows());
    map_into(w, out);
    return out;
  }

  // Y − H(w).
  template <typename T>
  ModelVector<T, Eigen::Dynamic> residual(const State<T>& w) const {
    return stacked_.template cast<T>() - map(w);
  }

  // f^{steps}(x0) along the window's inputs, x0 being the state at window position `from`
  // (0 = the first sample).
  State<double> propagate(const State<double>& x0, Eigen::Index steps,
                          Eigen::Index from = 0) const {
    State<double> x = x0;
    const long k0 = first_index();
    for (Eigen::Index j = from; j < from + steps; ++j) {
      x = model_.f(x, Input(input(j)), k0 + static_cast<long>(j));
    }
    return x;
  }

 private:
  Model model_;
  Eigen::Index n_, p_, m_, length_;
  Eigen::MatrixXd y_, u_;
  Eigen::VectorXd stacked_;
  Eigen::Index head_ = 0, count_ = 0;
  long last_index_ = -1;
};

}  // namespace nlobs
