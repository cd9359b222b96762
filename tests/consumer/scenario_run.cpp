// A scenario run through the installed run layer, without the CLI: the built-in chua-fp, made
// shorter, every observer run on one simulation, and its summary as summary.json holds it; then
// the same as a ScenarioRequest (what `nlobs run` calls).
#include <cstdio>
#include <nlobs/runs/measurements_file.hpp>
#include <nlobs/runs/scenario_run.hpp>
#include <sstream>

int main() {
  nlobs::Scenario scenario = nlobs::load_scenario("chua-fp");
  scenario.steps = 60;
  const nlobs::ScenarioRun run = nlobs::run_scenario(scenario);
  const nlohmann::json summary = nlobs::summary_json(run);
  std::printf("%s: %zu observers on %ld samples\n", summary["scenario"].get<std::string>().c_str(),
              summary["observers"].size(), static_cast<long>(run.prepared.data.steps()));
  int failures = 0;
  for (const auto& o : summary["observers"]) {
    for (const auto& mse : o["mse"]) {
      if (!mse.is_number()) ++failures;  // null: not finite
    }
    // Newton's window reaches the truth in its first window (the paper's 3 iterations).
    if (o["name"] == "window:newton") {
      for (const auto& after : o["mse_after_window"]) {
        if (!(after.is_number() && after.get<double>() < 1e-6)) ++failures;
      }
    }
  }
  // The same run as `nlobs run chua-fp --steps 60` asks for it: the same estimates.
  const nlobs::ScenarioRun asked = nlobs::run_request({.scenario = "chua-fp", .steps = 60});
  if (asked.result.estimates.size() != run.result.estimates.size()) ++failures;
  for (size_t i = 0; i < run.result.estimates.size() && i < asked.result.estimates.size(); ++i) {
    if (!(asked.result.estimates[i] == run.result.estimates[i])) ++failures;
  }
  // The --data reader, installed with the run layer.
  std::istringstream csv("t,y1\n0,1\n0.1,0.5\n");
  if (nlobs::parse_measurements_csv(csv, "inline.csv", 1, 0).steps() != 2) ++failures;
  return failures == 0 && summary["observers"].size() == scenario.observers.size() ? 0 : 1;
}
