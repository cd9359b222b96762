// The output directory's promises (docs/cli.md "Output directories"): temporary names, summary.json
// removed first and written last, stale nlobs files removed and nothing else, no temporary left
// (exceptions, a gnuplot that hangs), write errors with the system's reason; and the reduced
// plot data that keeps every excursion.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "cli_test_files.hpp"
#include "modulating_report.hpp"
#include "output_directory.hpp"
#include "run_command.hpp"
#include "run_outputs.hpp"
#include "run_support.hpp"

namespace nlobs::cli {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  return test::scratch_path("nlobs_test_outputs", name);
}

std::vector<std::string> files_in(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

bool has(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

bool any_temporary(const fs::path& dir) {
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (e.path().extension() == ".tmp" || !final_name_of_temporary(name).empty()) return true;
  }
  return false;
}

// The temporaries of `final_name` in `dir` (OutputFile's `.NAME.tmp-XXXXXX`).
int temporaries_of(const fs::path& dir, const std::string& final_name) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    n += is_temporary_name_of(e.path().filename().string(), final_name);
  }
  return n;
}

TEST(OutputDirectory, SummaryFirstRemovedStaleNlobsFilesOnly) {
  const fs::path dir = scratch("stale");
  fs::create_directories(dir / "errors.png");  // a directory by an nlobs name is the user's
  for (const char* f : {"summary.json", "sweep.csv", "signals_3.png", "states.png",
                        "states.png.tmp", "trajectories.csv.tmp", ".plots.gp.tmp-Ab12Cd",
                        "notes.txt", "signals_x.png", "my.tmp", ".notes.txt.tmp-Ab12Cd"}) {
    test::write_file(dir / f, "old");
  }
  OutputDirectory out(dir.string());
  // From the start the directory no longer claims to be complete; old temporaries (of this
  // version's names and the earlier `NAME.tmp`) are gone.
  EXPECT_FALSE(fs::exists(dir / "summary.json"));
  EXPECT_FALSE(fs::exists(dir / "sweep.csv"));  // a sweep's marker too
  EXPECT_FALSE(fs::exists(dir / "states.png.tmp"));
  EXPECT_FALSE(fs::exists(dir / "trajectories.csv.tmp"));
  EXPECT_FALSE(fs::exists(dir / ".plots.gp.tmp-Ab12Cd"));
  out.write("trajectories.csv", "t\n0\n");
  out.remove_stale_files();
  out.write("summary.json", "{}");
  // .nlobs.lock: the run's lock, held while `out` lives.
  EXPECT_EQ(files_in(dir), (std::vector<std::string>{
                               ".nlobs.lock", ".notes.txt.tmp-Ab12Cd", "errors.png", "my.tmp",
                               "notes.txt", "signals_x.png", "summary.json", "trajectories.csv"}));
}

TEST(OutputDirectory, UncommittedAndExternalTemporariesAreRemoved) {
  const fs::path dir = scratch("uncommitted");
  {
    OutputDirectory out(dir.string());
    {
      OutputDirectory::Writer w = out.open("trajectories.csv");
      w.stream() << "half";
      EXPECT_EQ(temporaries_of(dir, "trajectories.csv"), 1);
    }  // dropped, e.g. by an exception
    EXPECT_EQ(temporaries_of(dir, "trajectories.csv"), 0);
    EXPECT_FALSE(fs::exists(dir / "trajectories.csv"));
    const std::string name = out.external("states.png");
    EXPECT_TRUE(is_temporary_name_of(name, "states.png")) << name;
    EXPECT_EQ(out.external("states.png"), name);  // asked twice: the same file
    test::write_file(dir / name, "png");          // as gnuplot would
    test::write_file(dir / out.external("errors.png"), "png");
  }  // destroyed before commit_external()
  EXPECT_TRUE(files_in(dir).empty()) << files_in(dir).size();
  OutputDirectory out(dir.string());
  test::write_file(dir / out.external("states.png"), "png");
  out.external("errors.png");  // never drawn: not renamed, nothing left
  EXPECT_EQ(out.commit_external(), std::vector<std::string>{"states.png"});
  EXPECT_EQ(files_in(dir), (std::vector<std::string>{".nlobs.lock", "states.png"}));
}

TEST(OutputDirectory, WriteErrorsGiveTheSystemsReason) {
  const fs::path dir = scratch("vanishing");
  OutputDirectory out(dir.string());
  fs::remove_all(dir);
  try {
    out.write("summary.json", "{}");
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("summary.json': cannot create a file in"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("No such file or directory"), std::string::npos)
        << e.what();
  }
  const fs::path file = scratch("a-file");
  test::write_file(file, "x");
  try {
    OutputDirectory bad((file / "sub").string());
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot create"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("Not a directory"), std::string::npos) << e.what();
  }
}

TEST(PlotRows, ShortTablesWhole_LongOnesKeepEveryExtreme) {
  std::vector<double> t(100'000), v(100'000, 1.0), gaps(100'000, 0.0);
  for (size_t k = 0; k < t.size(); ++k) t[k] = 0.01 * static_cast<double>(k);
  v[54'321] = 50.0;  // a one-sample spike
  v[77'777] = -3.0;
  for (size_t k = 0; k < 1000; ++k) gaps[k] = NAN;  // a signal not published yet
  const ColumnTable table{3, 100'000, [&](Eigen::Index j, Eigen::Index k) {
                            const auto i = static_cast<size_t>(k);
                            return j == 0 ? t[i] : j == 1 ? v[i] : gaps[i];
                          }};
  std::ostringstream out;
  write_plot_rows(out, "t,v,g", table);
  std::istringstream in(out.str());
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "t,v,g");
  long rows = 0, nan_rows = 0;
  double high = -1e300, low = 1e300, last_t = -1.0;
  while (std::getline(in, line)) {
    ++rows;
    std::stringstream ss(line);
    std::string a, b, c;
    std::getline(ss, a, ',');
    std::getline(ss, b, ',');
    std::getline(ss, c, ',');
    const double time = std::stod(a), value = std::stod(b);
    EXPECT_GE(time, last_t);
    last_t = time;
    high = std::max(high, value);
    low = std::min(low, value);
    nan_rows += c == "nan";
  }
  EXPECT_EQ(rows, kPlotRows);
  EXPECT_EQ(high, 50.0);
  EXPECT_EQ(low, -3.0);
  EXPECT_EQ(last_t, t.back());
  EXPECT_EQ(nan_rows, 2 * (1000 / 50));  // 50 samples a span: the first 20 spans have no value

  std::ostringstream whole;
  write_plot_rows(whole, "t,v,g", ColumnTable{3, 10, [&](Eigen::Index j, Eigen::Index k) {
                                                return table.value(j, k);
                                              }});
  const std::string text = whole.str();
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 11);
}

TEST(RunOutputs, ASecondRunLeavesNothingOfTheFirst) {
  const fs::path dir = scratch("two-runs");
  std::ostringstream out, err;
  // pi-linear writes signals_N.png (its banks publish signals); chua-fp writes none.
  run_scenario("pi-linear", {.steps = 200, .out_dir = dir.string()}, out, err);
  if (have_gnuplot()) {  // the run's own signal plots are kept (and named in its "wrote" line)
    EXPECT_TRUE(fs::exists(dir / "signals_1.png"));
    EXPECT_NE(out.str().find("signals_1.png"), std::string::npos) << out.str();
  }
  test::write_file(dir / "signals_9.png", "stale");
  test::write_file(dir / "mine.txt", "the user's");
  run_scenario("chua-fp", {.steps = 60, .out_dir = dir.string()}, out, err);
  const auto names = files_in(dir);
  for (const auto& n : names) EXPECT_EQ(n.rfind("signals_", 0), std::string::npos) << n;
  EXPECT_TRUE(has(names, "mine.txt"));
  EXPECT_FALSE(any_temporary(dir));
  std::ifstream in(dir / "summary.json");
  EXPECT_EQ(nlohmann::json::parse(in)["scenario"], "chua-fp");
  EXPECT_TRUE(has(names, "plot_data.csv"));
}

TEST(RunOutputs, AGnuplotThatHangsIsStoppedAndTheRunCompletes) {
  std::optional<test::FakeProgramOnPath> fake;
  // It starts its PNG, then never finishes.
  fake.emplace(scratch("hanging_bin"), "gnuplot",
               "#!/bin/sh\n"
               "out=$(sed -n \"s/^set output '\\(.*\\)'$/\\1/p\" \"$1\" | head -n 1)\n"
               "printf partial > \"$out\"\nexec /bin/sleep 60\n");
  const fs::path dir = scratch("hanging");
  std::ostringstream out, err;
  RunOptions o;
  o.steps = 50;
  o.out_dir = dir.string();
  o.plot_timeout = 0.5;
  EXPECT_NO_THROW(run_scenario("chua-fp", o, out, err));
  fake.reset();
  EXPECT_NE(err.str().find("gnuplot did not finish within 0.5 s and was stopped"),
            std::string::npos)
      << err.str();
  EXPECT_TRUE(fs::exists(dir / "summary.json"));
  EXPECT_FALSE(fs::exists(dir / "states.png"));
  EXPECT_FALSE(any_temporary(dir));
  o.plot_timeout = 0.0;
  try {
    run_scenario("chua-fp", o, out, err);
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("plot timeout 0 s is out of range"), std::string::npos);
  }
}

// Two observers of one name (two EKFs with different covariances) were indistinguishable: the
// same columns in trajectories.csv, the same key in plots, two summary entries of one name.
TEST(RunOutputs, ObserversOfOneNameAreToldApart) {
  const fs::path f = scratch("two-ekfs.json");
  test::write_file(f, R"({"name": "two-ekfs", "model": {"name": "modified-chua", "step": 0.05},
    "x0": [1, 2.1428, -0.1648], "initial_guess": [5, 10, -5], "steps": 40,
    "observers": [{"type": "ekf"}, {"type": "ekf", "initial_covariance": [[10, 0, 0], [0, 10, 0], [0, 0, 10]]},
                  {"type": "ekf"}]})");
  const fs::path dir = scratch("two-ekfs");
  std::ostringstream out, err;
  run_scenario(f.string(), {.out_dir = dir.string()}, out, err);
  std::ifstream in(dir / "summary.json");
  const auto summary = nlohmann::json::parse(in);
  std::vector<std::string> names;
  for (const auto& o : summary["observers"]) names.push_back(o["name"]);
  EXPECT_EQ(names, (std::vector<std::string>{"ekf", "ekf #2", "ekf #3"}));
  std::ifstream csv(dir / "trajectories.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_NE(header.find(",ekf.x1,ekf.x2,ekf.x3,ekf #2.x1,"), std::string::npos) << header;
  EXPECT_NE(header.find("ekf #3.x3"), std::string::npos) << header;
}

// ---- typed signals: the reports read a signal's kind, never its spelling --------------------

// A user's own observer that estimates in coordinates of its own, w = 2x, and publishes ŵ under
// names of its own: ŵ = (2y, 1 + t) for x = (y, 0), so ‖w − ŵ‖ = 1 + t exactly; its fit
// residual is t / 4. `kind` says which coordinates; a signal spelt "zhat1" but of kind
// kDiagnostic is never mistaken for an estimate.
class OwnCoordinatesObserver final : public Observer {
 public:
  explicit OwnCoordinatesObserver(SignalKind kind) {
    info_.name = "own";
    info_.signals = {{"zhat1"},  // a diagnostic, whatever its name
                     {"w_first", kind},
                     {"w_second", kind},
                     {"fit", SignalKind::kProjectionResidual}};
    step_.signals.resize(4);
  }
  void reset() override {}
  const ObserverStep& step(long, double t, const Eigen::VectorXd& y,
                           const Eigen::VectorXd&) override {
    step_.estimate = Eigen::Vector2d(y[0], 0.0);
    step_.signals << -1e6, 2.0 * y[0], 1.0 + t, 0.25 * t;
    return step_;
  }
  Eigen::VectorXd coordinates_at(const Eigen::VectorXd& x, double) const override {
    return 2.0 * x;
  }

 private:
  ObserverStep step_;
};

Measurements own_data() {
  Measurements data;
  const Eigen::Index K = 5;
  data.t = Eigen::VectorXd::LinSpaced(K, 0.0, 2.0);
  data.x = Eigen::MatrixXd::Zero(2, K);
  data.x.row(0) = data.t.transpose().array().sin();
  data.y = data.x.topRows(1);
  data.u = Eigen::MatrixXd::Zero(0, K);
  return data;
}

TEST(TypedSignals, AnOwnEmbeddedObserverGetsTheEmbeddedFigures) {
  const Measurements data = own_data();
  std::vector<std::unique_ptr<Observer>> observers;
  observers.push_back(std::make_unique<OwnCoordinatesObserver>(SignalKind::kEmbeddedEstimate));
  RunResult r = run_observers(data, observers, 2);
  add_coordinate_errors(data, observers, r);
  ASSERT_EQ(r.signal_info[0].size(), 5u);
  EXPECT_EQ(r.signal_info[0][4].name, "z_error");
  EXPECT_EQ(r.signal_info[0][4].kind, SignalKind::kEmbeddedError);
  for (Eigen::Index k = 0; k < data.steps(); ++k) {
    EXPECT_NEAR(r.signals[0](4, k), 1.0 + data.t[k], 1e-15) << k;
  }
  add_coordinate_errors(data, observers, r);  // a second call adds nothing
  EXPECT_EQ(r.signal_info[0].size(), 5u);
  EXPECT_EQ(r.signals[0].rows(), 5);
  const auto m = embedded_metrics(r, 0);
  ASSERT_TRUE(m.has_value());
  double peak = 0.0;  // ‖ŵ‖ over the two estimate rows only (not the -1e6 diagnostic)
  for (Eigen::Index k = 0; k < data.steps(); ++k) {
    peak = std::max(peak, std::hypot(2.0 * data.y(0, k), 1.0 + data.t[k]));
  }
  EXPECT_DOUBLE_EQ(m->max_zhat_norm, peak);
  EXPECT_DOUBLE_EQ(m->final_z_error, 3.0);
  EXPECT_DOUBLE_EQ(m->max_residual_after, 0.5);  // t / 4 at t = 2
  EXPECT_EQ(m->time_index_below, -1);
  EXPECT_FALSE(modulating_metrics(r, 0, 0).has_value());  // not canonical coordinates
}

TEST(TypedSignals, AnOwnCanonicalObserverGetsTheModulatingFigures) {
  const Measurements data = own_data();
  std::vector<std::unique_ptr<Observer>> observers;
  observers.push_back(std::make_unique<OwnCoordinatesObserver>(SignalKind::kCanonicalEstimate));
  RunResult r = run_observers(data, observers, 0);
  add_coordinate_errors(data, observers, r);
  ASSERT_EQ(r.signal_info[0].size(), 6u);
  EXPECT_EQ(r.signal_info[0][4].kind, SignalKind::kCanonicalError);
  EXPECT_EQ(r.signal_info[0][5].name, "eta_norm");
  const auto m = modulating_metrics(r, 0, 0);
  ASSERT_TRUE(m.has_value());
  double scale = 0.0;  // max_k ‖2 x_k‖
  for (Eigen::Index k = 0; k < data.steps(); ++k)
    scale = std::max(scale, 2.0 * data.x.col(k).norm());
  EXPECT_DOUBLE_EQ(m->abs_after_horizon, 3.0);
  EXPECT_DOUBLE_EQ(m->rel_after_horizon, 3.0 / scale);
  EXPECT_FALSE(embedded_metrics(r, 0).has_value());
}

TEST(TypedSignals, ANameAloneMakesNoEstimate) {
  const Measurements data = own_data();
  std::vector<std::unique_ptr<Observer>> observers;
  observers.push_back(std::make_unique<OwnCoordinatesObserver>(SignalKind::kDiagnostic));
  RunResult r = run_observers(data, observers, 0);
  add_coordinate_errors(data, observers, r);
  EXPECT_EQ(r.signal_info[0].size(), 4u);  // no z_error, no eta_error: nothing of either kind
  EXPECT_FALSE(embedded_metrics(r, 0).has_value());
  EXPECT_FALSE(modulating_metrics(r, 0, 0).has_value());
}

}  // namespace
}  // namespace nlobs::cli
