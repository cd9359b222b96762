// A scenario's input schedules (InputSpec: piecewise_constant, piecewise_linear, file) on a model
// nlobs does not ship, with two inputs: the simulated plant sees u(t_k) held over each sample;
// the knots are validated (times strictly increasing and finite, values finite, one per time,
// one number or one per input), a file is read beside the scenario (a link too) by the data
// file's reader, and the scenario written back reads to the same schedule.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "cli_test_files.hpp"
#include "nlobs/registry/register_model.hpp"
#include "nlobs/runs/scenario.hpp"
#include "nlobs/runs/scenario_run.hpp"

namespace nlobs {
namespace {

// x' = u1 − u2, y = x: an integrator of two inputs, so that the state records what was applied.
struct TwoInputIntegrator : ModelSizes<1, 2, 1> {
  template <typename T>
  State<T> vector_field(const State<T>&, const Input& u, double) const {
    return State<T>(T(u[0] - u[1]));
  }
  template <typename T>
  Output<T> h(const State<T>& x) const {
    return x;
  }
};

void register_integrator() {
  static const bool done = [] {
    model_registry().add(model_entry(ModelDefinition<TwoInputIntegrator>{
                             .name = "two-input-integrator",
                             .description = "x' = u1 - u2, y = x (test_scenario_input)",
                             .default_step = 0.25,
                             .default_scheme = Scheme::kEuler}),
                         "test_scenario_input");
    return true;
  }();
  (void)done;
}

nlohmann::json scenario_with(const nlohmann::json& input) {
  return {{"name", "schedule-test"},
          {"model", {{"name", "two-input-integrator"}}},
          {"x0", {0.0}},
          {"initial_guess", {0.0}},
          {"steps", 12},
          {"input", input},
          {"observers", {{{"type", "luenberger"}, {"gain", {0.5}}}}}};
}

Measurements simulated(const nlohmann::json& input) {
  register_integrator();
  return prepare_scenario(parse_scenario(scenario_with(input), "schedule-test")).data;
}

std::string error_of(const nlohmann::json& input) {
  register_integrator();
  try {
    parse_scenario(scenario_with(input), "schedule-test");
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "<no error>";
}

TEST(ScenarioInput, StepsAndRampsDriveThePlant) {
  // Steps: u1 = 1 before t = 1, 3 from t = 1 on; u2 = 0 then 1. t_k = k / 4.
  const Measurements steps = simulated({{"kind", "piecewise_constant"},
                                        {"times", {0.0, 1.0}},
                                        {"values", {{1.0, 0.0}, {3.0, 1.0}}}});
  for (long k = 0; k < 12; ++k) {
    const double t = 0.25 * static_cast<double>(k);
    EXPECT_EQ(steps.u(0, k), t < 1.0 ? 1.0 : 3.0) << k;
    EXPECT_EQ(steps.u(1, k), t < 1.0 ? 0.0 : 1.0) << k;
  }
  // x_k = Σ_{j<k} (u1 − u2) / 4: 4 samples of 1, then 2 per sample.
  EXPECT_DOUBLE_EQ(steps.x(0, 11), 0.25 * (4 * 1.0 + 7 * 2.0));

  // A ramp of both inputs alike (one number per knot), held outside [0.5, 2.5]: u(t) = 2 (t − 0.5).
  const Measurements ramp =
      simulated({{"kind", "piecewise_linear"}, {"times", {0.5, 2.5}}, {"values", {0.0, 4.0}}});
  for (long k = 0; k < 12; ++k) {
    const double t = 0.25 * static_cast<double>(k);
    const double expected = t <= 0.5 ? 0.0 : (t >= 2.5 ? 4.0 : 2.0 * (t - 0.5));
    EXPECT_NEAR(ramp.u(0, k), expected, 1e-15) << k;
    EXPECT_EQ(ramp.u(1, k), ramp.u(0, k)) << k;
  }
  EXPECT_EQ(ramp.x(0, 11), 0.0);  // u1 − u2 = 0 throughout

  // Written back (scenario.json), each knot's values per input: the same schedule again.
  register_integrator();
  const Scenario s = parse_scenario(
      scenario_with({{"kind", "piecewise_linear"}, {"times", {0.5, 2.5}}, {"values", {0.0, 4.0}}}),
      "schedule-test");
  const Scenario again = parse_scenario(to_json(s), "written back");
  EXPECT_EQ(again.input.kind, "piecewise_linear");
  EXPECT_EQ(again.input.schedule.times, s.input.schedule.times);
  EXPECT_EQ(again.input.schedule.values, s.input.schedule.values);
}

// t_k = k T in floating point: 3 · 0.3 = 0.8999999999999999 < 0.9, yet the step at 0.9 is
// applied at k = 3, as u_i on [t_i, t_{i+1}) says (a knot within rounding counts as reached).
TEST(ScenarioInput, AKnotOnASampleIsReachedDespiteRounding) {
  register_integrator();
  nlohmann::json spec = scenario_with(
      {{"kind", "piecewise_constant"}, {"times", {0.0, 0.9}}, {"values", {0.0, 1.0}}});
  spec["model"]["step"] = 0.3;
  const Measurements data = prepare_scenario(parse_scenario(spec, "schedule-test")).data;
  ASSERT_LT(3 * 0.3, 0.9);
  EXPECT_EQ(data.u(0, 2), 0.0);
  EXPECT_EQ(data.u(0, 3), 1.0);
  // A ramp between knots at ∓1e308 (t1 − t0 overflows) still moves: u(t) ≈ 1/2 near t = 0.
  const Measurements far =
      simulated({{"kind", "piecewise_linear"}, {"times", {-1e308, 1e308}}, {"values", {0.0, 1.0}}});
  EXPECT_NEAR(far.u(0, 0), 0.5, 1e-12);
}

// A scenario built or edited in C++ after its parse is checked before it is simulated.
TEST(ScenarioInput, AScheduleEditedInCppIsCheckedBeforeTheSimulation) {
  register_integrator();
  Scenario s = parse_scenario(
      scenario_with(
          {{"kind", "piecewise_constant"}, {"times", {0.0, 1.0}}, {"values", {1.0, 2.0}}}),
      "schedule-test");
  const ModelInstance model = scenario_model(s);
  Scenario short_values = s;
  short_values.input.schedule.values.conservativeResize(2, 1);
  EXPECT_THROW(simulate_scenario(short_values, model.discrete), InvalidInput);
  Scenario backwards = s;
  backwards.input.schedule.times = {1.0, 0.0};
  EXPECT_THROW(simulate_scenario(backwards, model.discrete), InvalidInput);
  Scenario unknown = s;
  unknown.input.kind = "cubic";
  EXPECT_THROW(simulate_scenario(unknown, model.discrete), InvalidInput);
  Scenario emptied = s;
  emptied.input.schedule = {};
  EXPECT_THROW(simulate_scenario(emptied, model.discrete), InvalidInput);
}

TEST(ScenarioInput, BadSchedulesAreRefusedNamingTheKnot) {
  const nlohmann::json two = {0.0, 1.0};
  const auto knots = [](const nlohmann::json& times, const nlohmann::json& values) {
    return nlohmann::json{{"kind", "piecewise_linear"}, {"times", times}, {"values", values}};
  };
  EXPECT_NE(error_of(knots({0.0, 2.0, 1.0}, {1.0, 2.0, 3.0}))
                .find("input: input schedule: knot 2: time 1 does not come after the knot before "
                      "(2): times must strictly increase"),
            std::string::npos)
      << error_of(knots({0.0, 2.0, 1.0}, {1.0, 2.0, 3.0}));
  EXPECT_NE(error_of(knots({1.0, 1.0}, {1.0, 2.0})).find("knot 1: time 1 does not come after"),
            std::string::npos);
  EXPECT_NE(error_of(knots({0.0, nullptr}, {1.0, 2.0})).find("'times[1]' must be a finite number"),
            std::string::npos);
  EXPECT_NE(error_of(knots(two, {1.0, 2.0, 3.0}))
                .find("'values' has 3 entries for 2 'times': one per time"),
            std::string::npos);
  EXPECT_NE(error_of(knots(two, {{1.0, 2.0, 3.0}, {4.0, 5.0, 6.0}}))
                .find("one number (every input) or 2 numbers (the model's inputs), not 3"),
            std::string::npos);
  // JSON has no infinity, but a program building the scenario in C++ may pass one.
  EXPECT_NE(error_of(knots(two, {1.0, std::numeric_limits<double>::infinity()}))
                .find("knot 1: a value is not a finite number"),
            std::string::npos);
  EXPECT_NE(error_of(knots(nlohmann::json::array(), nlohmann::json::array()))
                .find("'values' must be a non-empty array"),
            std::string::npos);
  EXPECT_NE(
      error_of({{"kind", "piecewise_constant"}, {"times", two}}).find("needs 'times' and 'values'"),
      std::string::npos);
  EXPECT_NE(
      error_of({{"kind", "piecewise_constant"}, {"times", two}, {"values", two}, {"value", 3}})
          .find("'value'"),
      std::string::npos);
  EXPECT_NE(
      error_of({{"kind", "cubic"}})
          .find("'kind' must be zero, constant, sin, piecewise_constant, piecewise_linear or file"),
      std::string::npos);
  // A schedule for a model without inputs drives nothing: refused rather than ignored.
  register_integrator();
  nlohmann::json no_inputs = scenario_with(knots(two, two));
  no_inputs["model"] = {{"name", "lorenz"}};
  no_inputs["x0"] = {1.0, 1.0, 1.0};
  no_inputs["initial_guess"] = {1.0, 1.0, 1.0};
  try {
    parse_scenario(no_inputs, "schedule-test");
    ADD_FAILURE() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "'kind' piecewise_linear: model 'lorenz' has no input for the schedule to drive"),
              std::string::npos)
        << e.what();
  }
}

TEST(ScenarioInput, AFileScheduleIsReadBesideTheScenarioAndWrittenBackAbsolute) {
  register_integrator();
  const std::filesystem::path dir = test::scratch_path("nlobs_input", "x").parent_path();
  test::write_file(dir / "coolant.csv", "t,u1,u2\n0,1,0\n1,3,1\n");
  std::filesystem::remove(dir / "link.csv");
  std::filesystem::create_symlink(dir / "coolant.csv", dir / "link.csv");
  for (const char* name : {"coolant.csv", "link.csv"}) {
    nlohmann::json spec = scenario_with({{"kind", "file"}, {"file", name}});
    test::write_file(dir / "scenario.json", spec.dump());
    const Scenario s = load_scenario((dir / "scenario.json").string());
    const Measurements data = prepare_scenario(s).data;
    EXPECT_EQ(data.u(0, 3), 1.0) << name;  // t = 0.75: held at the first row
    EXPECT_EQ(data.u(0, 4), 3.0) << name;  // t = 1
    EXPECT_EQ(data.u(1, 11), 1.0) << name;
    // Written back with the file's absolute path: the same schedule from any directory.
    const nlohmann::json back = to_json(s);
    EXPECT_TRUE(std::filesystem::path(back["input"]["file"].get<std::string>()).is_absolute());
    const Scenario again = parse_scenario(back, "written back");
    EXPECT_EQ(again.input.schedule.times, s.input.schedule.times);
    EXPECT_EQ(again.input.schedule.values, s.input.schedule.values);
  }
  // A relative path through a directory link is the operating system's: link/../u.csv is the
  // link target's parent's u.csv, not the scenario directory's (a decoy there).
  std::filesystem::create_directories(dir / "a" / "b");
  test::write_file(dir / "a" / "u.csv", "t,u1,u2\n0,1,0\n");
  test::write_file(dir / "u.csv", "t,u1,u2\n0,5,0\n");
  std::filesystem::remove(dir / "lnk");
  std::filesystem::create_directory_symlink(dir / "a" / "b", dir / "lnk");
  test::write_file(dir / "scenario.json",
                   scenario_with({{"kind", "file"}, {"file", "lnk/../u.csv"}}).dump());
  EXPECT_EQ(prepare_scenario(load_scenario((dir / "scenario.json").string())).data.u(0, 0), 1.0);

  // A file of 10^5 rows (knots every 0.001 s): read whole, each sample at its knot.
  {
    std::ostringstream rows;
    rows << "t,u1,u2\n";
    for (long i = 0; i < 100000; ++i) rows << 0.001 * static_cast<double>(i) << ',' << i << ",0\n";
    test::write_file(dir / "long.csv", rows.str());
    test::write_file(dir / "scenario.json",
                     scenario_with({{"kind", "file"}, {"file", "long.csv"}}).dump());
    const Scenario s = load_scenario((dir / "scenario.json").string());
    ASSERT_EQ(s.input.schedule.times.size(), 100000u);
    const Measurements data = prepare_scenario(s).data;
    EXPECT_EQ(data.u(0, 11), 2750.0);  // t = 2.75 is the knot of row 2750
  }

  // Linear between the file's rows: u1 = 1 + 2 t on [0, 1].
  test::write_file(
      dir / "scenario.json",
      scenario_with({{"kind", "file"}, {"file", "coolant.csv"}, {"interpolation", "linear"}})
          .dump());
  const Measurements linear =
      prepare_scenario(load_scenario((dir / "scenario.json").string())).data;
  EXPECT_DOUBLE_EQ(linear.u(0, 2), 2.0);  // t = 0.5

  const auto file_error = [&](const nlohmann::json& input) {
    test::write_file(dir / "scenario.json", scenario_with(input).dump());
    try {
      load_scenario((dir / "scenario.json").string());
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("<no error>");
  };
  EXPECT_NE(file_error({{"kind", "file"}, {"file", "missing.csv"}}).find("does not exist"),
            std::string::npos)
      << file_error({{"kind", "file"}, {"file", "missing.csv"}});
  EXPECT_NE(file_error({{"kind", "file"}, {"file", "missing.csv"}}).find("input file"),
            std::string::npos);
  std::filesystem::create_directories(dir / "a-directory");
  EXPECT_NE(file_error({{"kind", "file"}, {"file", "a-directory"}}).find("is a directory"),
            std::string::npos)
      << file_error({{"kind", "file"}, {"file", "a-directory"}});
  test::write_file(dir / "backwards.csv", "t,u1,u2\n0,1,0\n2,3,1\n1,3,1\n");
  EXPECT_NE(file_error({{"kind", "file"}, {"file", "backwards.csv"}}).find("backwards.csv:4"),
            std::string::npos)
      << file_error({{"kind", "file"}, {"file", "backwards.csv"}});
  // --allow-late is for measurements: not offered for an input file.
  EXPECT_EQ(file_error({{"kind", "file"}, {"file", "backwards.csv"}}).find("--allow-late"),
            std::string::npos);
  test::write_file(dir / "nan.csv", "t,u1,u2\n0,nan,0\n");
  EXPECT_NE(file_error({{"kind", "file"}, {"file", "nan.csv"}}).find("nan.csv:2"),
            std::string::npos)
      << file_error({{"kind", "file"}, {"file", "nan.csv"}});
  test::write_file(dir / "narrow.csv", "t,u1\n0,1\n");
  EXPECT_NE(file_error({{"kind", "file"}, {"file", "narrow.csv"}}).find("narrow.csv:"),
            std::string::npos);
  EXPECT_NE(file_error({{"kind", "file"}, {"file", "coolant.csv"}, {"interpolation", "cubic"}})
                .find("'interpolation' must be previous or linear"),
            std::string::npos);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace nlobs
