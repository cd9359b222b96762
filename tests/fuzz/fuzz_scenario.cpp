// libFuzzer target: the scenario reader (JSON with a depth limit, then every key checked) on
// arbitrary bytes. Either it refuses the input with std::invalid_argument (InvalidInput is
// one), or the scenario it returns writes back to JSON that reads to the same scenario, and
// its model can be built or refused the same way. Anything else is a finding.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <string>

#include "nlobs/registry/json_reader.hpp"
#include "nlobs/runs/scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* bytes, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(bytes), size));
  nlobs::Scenario scenario;
  try {
    const nlohmann::json json = nlobs::parse_json(in, "fuzz.json");
    // An input file is read at parse: a fuzzed path could name a FIFO or /dev/stdin and block.
    // Its reader is the --data reader, which fuzz_data_csv covers.
    if (json.is_object() && json.contains("input") && json["input"].is_object() &&
        json["input"].contains("kind") && json["input"]["kind"] == "file") {
      return 0;
    }
    scenario = nlobs::parse_scenario(json, "fuzz.json");
  } catch (const std::invalid_argument&) {
    return 0;  // refused with a message: fine
  }
  // What was accepted round-trips (scenario.json in an output directory relies on it).
  const nlohmann::json written = nlobs::to_json(scenario);
  const nlohmann::json again = nlobs::to_json(nlobs::parse_scenario(written, "again"));
  if (again != written) std::abort();
  try {
    (void)nlobs::scenario_model(scenario);
  } catch (const std::invalid_argument&) {
    // a model that refuses its parameters: fine
  }
  return 0;
}
