// libFuzzer target: the rows of `nlobs suite` / `nlobs solve` as CSV and JSON (cli/suite_report)
// and as the table. The bytes make the rows: arbitrary strings for set, problem, start, solver,
// status and message (commas, quotes, CR, LF, NUL, escape sequences, invalid UTF-8) and arbitrary
// doubles (every bit pattern: NaN, ±inf, subnormals, −0) and integers. A finding is a crash, a
// sanitizer report, an exception, or output that does not read back to the same fields:
// * CSV, read by the small RFC 4180 reader below: the header, one record per row, every string
//   byte for byte, every finite double exactly (17 significant digits), a non-finite one empty;
//   the answer x as space-separated components that read back exactly (nan, inf, -inf too);
// * JSON, parsed by nlohmann::json: every string as valid_utf8 makes it (U+FFFD for a byte that
//   is not UTF-8), every finite double exactly, a non-finite one null;
// * the table: no control character but the line feed, no invalid UTF-8.
// `make fuzz` runs it; docs/fuzzing.md says what it found.
#include <fuzzer/FuzzedDataProvider.h>

#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "nlobs/common/printable.hpp"
#include "suite_report.hpp"

namespace {

using nlobs::reference::SuiteRow;

void check(bool invariant) {
  if (!invariant) std::abort();
}

double any_double(FuzzedDataProvider& in) {
  return std::bit_cast<double>(in.ConsumeIntegral<std::uint64_t>());
}

// RFC 4180: records end at CRLF or LF outside quotes; a quoted field may hold anything, "" is a
// quote. Returns false for text that is not well formed.
bool read_csv(const std::string& text, std::vector<std::vector<std::string>>& records) {
  std::vector<std::string> record;
  std::string field;
  std::size_t i = 0;
  bool fresh = true;  // at the start of a field
  while (i < text.size()) {
    const char c = text[i];
    if (fresh && c == '"') {
      ++i;
      for (;;) {
        if (i >= text.size()) return false;  // an unterminated quote
        if (text[i] == '"') {
          if (i + 1 < text.size() && text[i + 1] == '"') {
            field += '"';
            i += 2;
            continue;
          }
          ++i;
          break;
        }
        field += text[i++];
      }
      fresh = false;
      if (i < text.size() && text[i] != ',' && text[i] != '\n' && text[i] != '\r') return false;
      continue;
    }
    if (c == ',') {
      record.push_back(std::move(field));
      field.clear();
      fresh = true;
      ++i;
    } else if (c == '\n' || c == '\r') {
      if (c == '\r') {
        if (i + 1 >= text.size() || text[i + 1] != '\n') return false;  // a bare CR
        ++i;
      }
      ++i;
      record.push_back(std::move(field));
      field.clear();
      records.push_back(std::move(record));
      record.clear();
      fresh = true;
    } else {
      if (c == '"') return false;  // a quote inside an unquoted field
      field += c;
      fresh = false;
      ++i;
    }
  }
  return field.empty() && record.empty();  // the text ends with a line break
}

void check_number(const std::string& cell, double v) {
  if (!std::isfinite(v)) {
    check(cell.empty());
    return;
  }
  char* end = nullptr;
  const double back = std::strtod(cell.c_str(), &end);
  check(!cell.empty() && *end == '\0');
  check(back == v && std::signbit(back) == std::signbit(v));
}

void check_number(const nlohmann::json& j, double v) {
  if (!std::isfinite(v)) {
    check(j.is_null());
    return;
  }
  check(j.is_number());
  const double back = j.get<double>();
  check(back == v && std::signbit(back) == std::signbit(v));
}

// The CSV's x: components separated by single spaces, each reading back to the same double
// (any NaN as nan), none for an empty x.
void check_answer(const std::string& cell, const Eigen::VectorXd& x) {
  if (x.size() == 0) {
    check(cell.empty());
    return;
  }
  const char* at = cell.c_str();
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    if (i > 0) {
      check(*at == ' ');
      ++at;
    }
    check(*at != ' ' && *at != '\0');
    char* end = nullptr;
    const double back = std::strtod(at, &end);
    check(end != at);
    if (std::isnan(x[i])) {
      check(std::isnan(back));
    } else {
      check(back == x[i] && std::signbit(back) == std::signbit(x[i]));
    }
    at = end;
  }
  check(*at == '\0');
}

bool valid_utf8_text(const std::string& text) {
  for (std::size_t i = 0; i < text.size();) {
    if (static_cast<unsigned char>(text[i]) < 0x80) {
      ++i;
      continue;
    }
    const std::size_t length = nlobs::detail::utf8_sequence_length(text, i);
    if (length == 0) return false;
    i += length;
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* bytes, std::size_t size) {
  FuzzedDataProvider in(bytes, size);
  std::vector<SuiteRow> rows(in.ConsumeIntegralInRange<int>(0, 6));
  for (SuiteRow& r : rows) {
    r.set = in.ConsumeRandomLengthString(40);
    r.problem = in.ConsumeRandomLengthString(40);
    r.n = in.ConsumeIntegral<int>();
    r.start = in.ConsumeRandomLengthString(40);
    r.start_scale = any_double(in);
    r.solver = in.ConsumeRandomLengthString(60);
    r.solved = in.ConsumeBool();
    r.residual = any_double(in);
    r.error = any_double(in);
    r.f_evals = in.ConsumeIntegral<long>();
    r.j_evals = in.ConsumeIntegral<long>();
    r.ns = any_double(in);
    r.status = in.ConsumeRandomLengthString(40);
    r.message = in.ConsumeRandomLengthString(300);
    r.scaled_residual = any_double(in);
    r.x.resize(in.ConsumeIntegralInRange<int>(0, 5));
    for (Eigen::Index i = 0; i < r.x.size(); ++i) r.x[i] = any_double(in);
    r.evals_past_progress = in.ConsumeIntegral<long>();
  }

  // CSV.
  std::vector<std::vector<std::string>> records;
  check(read_csv(nlobs::cli::suite_to_csv(rows), records));
  check(records.size() == rows.size() + 1);
  const std::vector<std::string> header = {"set",
                                           "problem",
                                           "n",
                                           "start",
                                           "start_scale",
                                           "solver",
                                           "solved",
                                           "residual",
                                           "error",
                                           "f_evals",
                                           "j_evals",
                                           "ns",
                                           "status",
                                           "message",
                                           "scaled_residual",
                                           "x",
                                           "evals_past_progress"};
  check(records[0] == header);
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const SuiteRow& r = rows[k];
    const std::vector<std::string>& c = records[k + 1];
    check(c.size() == header.size());
    check(c[0] == r.set && c[1] == r.problem && c[2] == std::to_string(r.n) && c[3] == r.start);
    check_number(c[4], r.start_scale);
    check(c[5] == r.solver && c[6] == (r.solved ? "true" : "false"));
    check_number(c[7], r.residual);
    check_number(c[8], r.error);
    check(c[9] == std::to_string(r.f_evals) && c[10] == std::to_string(r.j_evals));
    check_number(c[11], r.ns);
    check(c[12] == r.status && c[13] == r.message);
    check_number(c[14], r.scaled_residual);
    check_answer(c[15], r.x);
    check(c[16] == std::to_string(r.evals_past_progress));
  }

  // JSON: dump() must not throw (invalid UTF-8 reaches it as U+FFFD), and parses back.
  const nlohmann::json parsed = nlohmann::json::parse(nlobs::cli::suite_to_json(rows).dump(2));
  check(parsed.is_array() && parsed.size() == rows.size());
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const SuiteRow& r = rows[k];
    const nlohmann::json& j = parsed[k];
    using nlobs::cli::valid_utf8;
    check(j.at("set") == valid_utf8(r.set) && j.at("problem") == valid_utf8(r.problem));
    check(j.at("n").get<long>() == r.n && j.at("start") == valid_utf8(r.start));
    check_number(j.at("start_scale"), r.start_scale);
    check(j.at("solver") == valid_utf8(r.solver) && j.at("solved").get<bool>() == r.solved);
    check_number(j.at("residual"), r.residual);
    check_number(j.at("error"), r.error);
    check(j.at("f_evals").get<long>() == r.f_evals && j.at("j_evals").get<long>() == r.j_evals);
    check_number(j.at("ns"), r.ns);
    check(j.at("status") == valid_utf8(r.status) && j.at("message") == valid_utf8(r.message));
    check_number(j.at("scaled_residual"), r.scaled_residual);
    check(j.at("evals_past_progress").get<long>() == r.evals_past_progress);
    if (r.x.size() == 0) {
      check(j.at("x").is_null());
    } else {
      check(j.at("x").is_array() && j.at("x").size() == static_cast<std::size_t>(r.x.size()));
      for (Eigen::Index i = 0; i < r.x.size(); ++i) check_number(j.at("x")[i], r.x[i]);
    }
  }

  // The table: whatever the names, nothing a terminal would act on.
  std::ostringstream table;
  const double threshold = any_double(in);
  nlobs::cli::print_suite_tables(rows, threshold, table, in.ConsumeBool());
  const std::string text = table.str();
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto b = static_cast<unsigned char>(text[i]);
    check(b == '\n' || (b >= 0x20 && b != 0x7F));
    // No C1 control (U+0080..U+009F) either.
    check(!(b == 0xC2 && i + 1 < text.size() && static_cast<unsigned char>(text[i + 1]) < 0xA0));
  }
  check(valid_utf8_text(text));
  return 0;
}
