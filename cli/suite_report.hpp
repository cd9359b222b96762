#pragma once
// The table, JSON and CSV of `nlobs suite SET` and `nlobs solve SET/NAME` (the same rows).
#include <iosfwd>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "nlobs/reference/problem_suite.hpp"

namespace nlobs::cli {

// One block per (problem, start), then per solver the pairs solved at `threshold`; with show_x,
// each row's answer (its first 8 components) on the line below it.
void print_suite_tables(const std::vector<reference::SuiteRow>& rows, double threshold,
                        std::ostream& out, bool show_x = false);
// Keys: set, problem, n, start, start_scale, solver, solved, residual, error, f_evals, j_evals,
// ns, status, message, scaled_residual, x (an array of n numbers, null for a row without an
// answer), evals_past_progress. Non-finite numbers as null; strings as valid_utf8 makes them, so
// that dump() never throws.
nlohmann::json suite_to_json(const std::vector<reference::SuiteRow>& rows);
// The same columns in that order, one header line, RFC 4180 fields (a field with a comma, quote,
// CR or LF quoted, quotes doubled; the bytes as given), non-finite numbers empty, other numbers
// with 17 significant digits (they read back to the same double); x as answer_field writes it.
std::string suite_to_csv(const std::vector<reference::SuiteRow>& rows);
// The CSV's x: the components separated by single spaces, each with 17 significant digits or
// nan, inf, -inf (what strtod reads back); empty for a row without an answer.
std::string answer_field(const Eigen::VectorXd& x);
// `text` with every byte that is not part of a valid UTF-8 sequence replaced by U+FFFD (what
// nlohmann::json's error_handler_t::replace writes): what the JSON holds of a user's text.
std::string valid_utf8(std::string_view text);

}  // namespace nlobs::cli
