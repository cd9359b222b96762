#pragma once
// The measured output between samples for observers that integrate in continuous time (MVT,
// high gain): the Lagrange polynomial through the last four good samples (cubic once four are
// in), so the interpolation error, O(h⁴), stays below what a held sample (O(h)) would feed into
// high gains. Fixed size: nothing allocates.
#include <Eigen/Core>
#include <array>

namespace nlobs {

template <int P>
class SampleInterpolator {
 public:
  using Output = Eigen::Matrix<double, P, 1>;

  void clear() { count_ = 0; }
  int size() const { return count_; }

  // Appends a sample (times increasing), dropping the oldest of four.
  void push(double t, const Output& y) {
    if (count_ == 4) {
      for (int j = 0; j < 3; ++j) {
        times_[j] = times_[j + 1];
        ys_.col(j) = ys_.col(j + 1);
      }
      count_ = 3;
    }
    times_[count_] = t;
    ys_.col(count_) = y;
    ++count_;
  }

  Output at(double t) const {
    Output y = Output::Zero();
    for (int j = 0; j < count_; ++j) y += basis(j, t) * ys_.col(j);
    return y;
  }

 private:
  double basis(int j, double t) const {
    double l = 1.0;
    for (int m = 0; m < count_; ++m) {
      if (m != j) l *= (t - times_[m]) / (times_[j] - times_[m]);
    }
    return l;
  }
  int count_ = 0;
  std::array<double, 4> times_{};
  Eigen::Matrix<double, P, 4> ys_ = Eigen::Matrix<double, P, 4>::Zero();
};

}  // namespace nlobs
