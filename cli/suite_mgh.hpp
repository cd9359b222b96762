#pragma once
// `nlobs suite mgh`: the MINPACK test-driver systems with our engines and the references.
#include <iosfwd>
#include <nlohmann/json.hpp>
#include <vector>

#include "reference/mgh_suite.hpp"

namespace nlobs::cli {

void print_suite_tables(const std::vector<reference::SuiteRow>& rows, std::ostream& out);
nlohmann::json suite_to_json(const std::vector<reference::SuiteRow>& rows);

}  // namespace nlobs::cli
