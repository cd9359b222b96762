#pragma once
// Recorded measurements (`nlobs run --data FILE.csv`, ScenarioRequest::data_file): columns t,
// y1..yp[, u1..um].
//
// The format, checked line by line (every error names FILE:LINE):
// * a line is at most kMaxDataLineBytes long;
// * a UTF-8 byte-order mark at the start is skipped; blank lines are skipped; CRLF is accepted;
// * an optional header as the first line, recognised only when no cell is a number or empty
//   (then it must have the data's column count); any other line that is not all numbers is an
//   error naming the cell;
// * y cells: a number, or a missing measurement written as an empty cell (the last one too) or
//   `nan`; an infinite or out-of-range value (`inf`, `1e400`) is an error;
// * t and u cells: finite numbers; times strictly increase, unless `late_rows` (--allow-late):
//   then a row may come at or before an earlier time, and goes to the observers in file order
//   (the MHE takes a late measurement into its horizon; the others refuse it, by name).
// The run layer's, so that every program reads a data file as `nlobs run` does.
#include <Eigen/Core>
#include <cstddef>
#include <iosfwd>
#include <string>

#include "nlobs/observers/core/simulation.hpp"

namespace nlobs {

// The longest line a data file may have (bytes, without the line break): 1 MiB, room for rows
// of some 40 000 numbers; a longer line is an error naming it.
inline constexpr std::size_t kMaxDataLineBytes = std::size_t{1} << 20;

// Reads `in` (named `name` in messages) for a model with `outputs` outputs and `inputs` inputs.
// Throws std::invalid_argument naming name:line and what was wrong; nothing is returned then.
Measurements parse_measurements_csv(std::istream& in, const std::string& name, Eigen::Index outputs,
                                    Eigen::Index inputs, bool late_rows = false);

// The same from a file; a missing file, a directory or an unreadable file is named as such.
Measurements read_measurements_csv(const std::string& file, Eigen::Index outputs,
                                   Eigen::Index inputs, bool late_rows = false);

}  // namespace nlobs
