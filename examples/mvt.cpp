// The continuous-time family on a model of your own: the mean-value-theorem observer ([BMH])
// integrates x' = F(x, u, t) between samples and corrects it with the measured states. The
// Rössler system here, with y = (x1, x2) and x3 hidden, is not one nlobs ships.
#include <cstdio>
#include <nlobs/observers.hpp>

// x1' = −x2 − x3,  x2' = x1 + a x2,  x3' = b + x3 (x1 − c);  y = (x1, x2) = [I 0] x.
struct Rossler : nlobs::ModelSizes<3, 0, 2> {
  double a = 0.2, b = 0.2, c = 5.7;
  template <typename T>
  State<T> vector_field(const State<T>& x, const Input&, double) const {
    return State<T>(-x[1] - x[2], x[0] + a * x[1], b + x[2] * (x[0] - c));
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return x.template head<2>();
  }
};

int main() {
  constexpr double kSampleTime = 0.01;
  using Sampled = nlobs::Discretized<Rossler>;  // the plant, sampled for the simulation and EKF
  const Sampled plant(Rossler{}, kSampleTime, nlobs::Scheme::kRk4);
  nlobs::SimulationOptions simulation;
  simulation.steps = 3000;  // 30 s
  const Eigen::Vector3d x0(1.0, 1.0, 0.5);
  const nlobs::Measurements data = nlobs::simulate(plant, x0, simulation);

  const Eigen::Vector3d guess(0.0, 0.0, 2.0);  // x3 is the state to find
  nlobs::MvtOptions mvt;
  mvt.sample_time = kSampleTime;
  mvt.initial_estimate = guess;
  mvt.initial_error_estimate = Eigen::Vector3d(0.1, 0.1, 0.1);
  std::vector<std::unique_ptr<nlobs::Observer>> observers;
  for (nlobs::MvtVariant variant :
       {nlobs::MvtVariant::kPublished, nlobs::MvtVariant::kOutputInjection}) {
    mvt.variant = variant;
    mvt.name = variant == nlobs::MvtVariant::kPublished ? "mvt published" : "mvt injection";
    observers.push_back(std::make_unique<nlobs::MvtObserver<Rossler>>(Rossler{}, mvt));
  }
  nlobs::EkfOptions ekf;
  ekf.initial_estimate = guess;
  observers.push_back(std::make_unique<nlobs::ExtendedKalmanFilter<Sampled>>(plant, ekf));

  const long settle = simulation.steps / 2;  // judged over the last 15 s
  const nlobs::RunResult run = nlobs::run_observers(data, observers, settle);
  std::printf("%-16s %12s %12s %12s\n", "observer", "max |e1|", "max |e2|", "max |e3|");
  for (const nlobs::ObserverMetrics& m : run.metrics) {
    std::printf("%-16s %12.3e %12.3e %12.3e\n", m.name.c_str(), m.max_error_after[0],
                m.max_error_after[1], m.max_error_after[2]);
  }
  // What the table must show: every observer finds the hidden x3. (Here even the published
  // variant does, because x3' = b + x3 (x1 − c) is stable where x1 < c: the unmeasured error
  // decays on its own, the case that variant needs. The EKF uses the plant's own
  // discretisation, so it is exact to rounding; the MVT observers integrate the continuous
  // model along interpolated samples.)
  int failures = 0;
  for (const nlobs::ObserverMetrics& m : run.metrics) {
    if (!(m.max_error_after.maxCoeff() < 1e-3)) {
      std::printf("FAIL: %s leaves an error of %.3e\n", m.name.c_str(),
                  m.max_error_after.maxCoeff());
      ++failures;
    }
  }
  return failures == 0 ? 0 : 1;
}
