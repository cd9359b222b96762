#pragma once
// The measured output between samples for observers that integrate in continuous time (MVT,
// high gain, PI bank): the Lagrange polynomial through the last good samples — four by default
// (cubic once four are in, so the interpolation error, O(h⁴), stays below what a held sample,
// O(h), would feed into high gains), two for a linear one. Fixed capacity: nothing allocates.
#include <Eigen/Core>
#include <array>

namespace nlobs {

template <int P>
class SampleInterpolator {
 public:
  using Output = Eigen::Matrix<double, P, 1>;

  // `outputs` entries per sample (P when it is fixed); through the last `points` samples, 2 to 4.
  explicit SampleInterpolator(Eigen::Index outputs = P == Eigen::Dynamic ? 0 : P, int points = 4)
      : points_(points < 2 ? 2 : (points > 4 ? 4 : points)),
        ys_(Eigen::Matrix<double, P, 4>::Zero(outputs, 4)) {}

  void clear() { count_ = 0; }
  int size() const { return count_; }
  Eigen::Index outputs() const { return ys_.rows(); }

  // Appends a sample (times increasing), dropping the oldest beyond `points`.
  void push(double t, const Output& y) {
    if (count_ == points_) {
      for (int j = 0; j + 1 < points_; ++j) {
        times_[j] = times_[j + 1];
        ys_.col(j) = ys_.col(j + 1);
      }
      count_ = points_ - 1;
    }
    times_[count_] = t;
    ys_.col(count_) = y;
    ++count_;
  }

  Output at(double t) const {
    Output y;
    at(t, y);
    return y;
  }

  // The same into `y` (sized once): no allocation for a dynamic P either.
  void at(double t, Output& y) const {
    y.setZero(ys_.rows());
    for (int j = 0; j < count_; ++j) y += basis(j, t) * ys_.col(j);
  }

 private:
  double basis(int j, double t) const {
    double l = 1.0;
    for (int m = 0; m < count_; ++m) {
      if (m != j) l *= (t - times_[m]) / (times_[j] - times_[m]);
    }
    return l;
  }
  int points_ = 4, count_ = 0;
  std::array<double, 4> times_{};
  Eigen::Matrix<double, P, 4> ys_;
};

}  // namespace nlobs
