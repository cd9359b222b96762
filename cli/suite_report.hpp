#pragma once
// The table, JSON and CSV of `nlobs suite SET` and `nlobs solve SET/NAME` (the same rows).
#include <iosfwd>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "nlobs/reference/problem_suite.hpp"

namespace nlobs::cli {

// One block per (problem, start), then per solver the pairs solved at `threshold`.
void print_suite_tables(const std::vector<reference::SuiteRow>& rows, double threshold,
                        std::ostream& out);
// Keys: set, problem, n, start, start_scale, solver, solved, residual, error, f_evals, j_evals,
// ns, status (non-finite numbers as null).
nlohmann::json suite_to_json(const std::vector<reference::SuiteRow>& rows);
// The same columns in that order, one header line, RFC 4180 fields.
std::string suite_to_csv(const std::vector<reference::SuiteRow>& rows);
// `text` to `path` through a temporary file renamed over it, so a failed write leaves an
// earlier file as it was; "-" is stdout. Throws std::runtime_error naming the path.
void write_text_file(const std::string& path, const std::string& text, std::ostream& stdout_);

}  // namespace nlobs::cli
