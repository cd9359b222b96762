#pragma once
// The built-in scenarios' text by name, compiled from runs/scenarios/*.json (runs/CMakeLists.txt
// generates the definition).
#include <map>
#include <string>

namespace nlobs::detail {

const std::map<std::string, const char*>& builtin_scenario_texts();

}  // namespace nlobs::detail
