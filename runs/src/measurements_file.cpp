#include "nlobs/runs/measurements_file.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <istream>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "nlobs/runs/input_file.hpp"
#include "nlobs/solvers/status.hpp"

namespace nlobs {
namespace {

enum class CellKind { kNumber, kMissing, kText, kOutOfRange };

struct Cell {
  CellKind kind;
  double value;
};

std::string_view trimmed(std::string_view s) {
  const auto first = s.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  return s.substr(first, s.find_last_not_of(" \t") - first + 1);
}

// `buffer`: strtod needs a terminated string; reused from cell to cell.
Cell classify(std::string_view raw, std::string& buffer) {
  const std::string_view s = trimmed(raw);
  if (s.empty()) return {CellKind::kMissing, NAN};
  buffer.assign(s);
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(buffer.c_str(), &end);
  // The whole cell, embedded NUL bytes included ("1\0abc" is not the number 1).
  if (end != buffer.c_str() + buffer.size()) return {CellKind::kText, NAN};
  if (std::isnan(v)) return {CellKind::kMissing, NAN};
  // ERANGE with ±HUGE_VAL: an overflow ("1e400"); with a tiny result an underflow, which is
  // the closest double and kept.
  if (errno == ERANGE && std::isinf(v)) return {CellKind::kOutOfRange, v};
  return {CellKind::kNumber, v};
}

// Splits on commas, keeping empty cells (a trailing comma gives an empty last cell).
void split_cells(std::string_view line, std::vector<std::string_view>& cells) {
  cells.clear();
  for (std::size_t from = 0;;) {
    const auto comma = line.find(',', from);
    cells.push_back(line.substr(from, comma == std::string_view::npos ? line.npos : comma - from));
    if (comma == std::string_view::npos) return;
    from = comma + 1;
  }
}

class Reader {
 public:
  Reader(const std::string& name, Eigen::Index outputs, Eigen::Index inputs, bool late_rows)
      : name_(name),
        p_(outputs),
        m_(inputs),
        columns_(static_cast<std::size_t>(1 + p_ + m_)),
        late_rows_(late_rows) {}

  void line(std::string_view text, long number) {
    number_ = number;
    if (number == 1 && text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
    if (!text.empty() && text.back() == '\r') text.remove_suffix(1);
    if (trimmed(text).empty()) return;
    split_cells(text, cells_);
    kinds_.clear();
    values_.clear();
    bool all_text = true;
    for (const std::string_view c : cells_) {
      const Cell cell = classify(c, buffer_);
      kinds_.push_back(cell.kind);
      values_.push_back(cell.value);
      all_text = all_text && cell.kind == CellKind::kText;
    }
    const bool first = !seen_line_;
    seen_line_ = true;
    if (first && all_text) {  // a header: only its width is checked
      if (cells_.size() != columns_) {
        fail("a header of " + std::to_string(cells_.size()) + " columns; expected " +
             std::to_string(columns_) + " " + layout());
      }
      return;
    }
    check_row(first);
    times_.push_back(values_[0]);
    for (std::size_t j = 1; j < columns_; ++j) samples_.push_back(values_[j]);
  }

  Measurements finish() const {
    if (times_.empty()) {
      throw std::invalid_argument(name_ + ": no data rows (expected " + layout() + ")");
    }
    Measurements data;
    const auto k = static_cast<Eigen::Index>(times_.size());
    data.t = Eigen::Map<const Eigen::VectorXd>(times_.data(), k);
    const Eigen::Map<const Eigen::MatrixXd> block(samples_.data(), p_ + m_, k);
    data.y = block.topRows(p_);
    data.u = block.bottomRows(m_);
    return data;
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    throw std::invalid_argument(name_ + ":" + std::to_string(number_) + ": " + what);
  }

  std::string layout() const {
    std::string text = "(t, " + std::to_string(p_) + (p_ == 1 ? " output" : " outputs");
    if (m_ > 0) text += ", " + std::to_string(m_) + (m_ == 1 ? " input" : " inputs");
    return text + ")";
  }

  std::string column_name(std::size_t j) const {
    if (j == 0) return "t";
    const bool output = j <= static_cast<std::size_t>(p_);
    // Appended, not "y" + to_string(j): GCC 12's -Wrestrict misfires on that operator+.
    std::string name(output ? "y" : "u");
    name += std::to_string(output ? j : j - static_cast<std::size_t>(p_));
    return name;
  }

  void check_row(bool first) const {
    for (std::size_t j = 0; j < cells_.size(); ++j) {
      if (kinds_[j] == CellKind::kText) {
        fail("cell " + std::to_string(j + 1) + " " + quoted_excerpt(trimmed(cells_[j])) +
             " is not a number" +
             (first ? " (a header line has no numbers and no empty cells)" : ""));
      }
    }
    if (cells_.size() != columns_) {
      fail("expected " + std::to_string(columns_) + " columns " + layout() + ", got " +
           std::to_string(cells_.size()));
    }
    for (std::size_t j = 0; j < columns_; ++j) {
      const bool output = j >= 1 && j <= static_cast<std::size_t>(p_);
      if (kinds_[j] == CellKind::kOutOfRange) {
        fail(column_name(j) + " " + quoted_excerpt(trimmed(cells_[j])) +
             " is out of the range of a double");
      }
      if (kinds_[j] == CellKind::kMissing && !output) fail(column_name(j) + " is missing");
      if (std::isinf(values_[j])) {
        fail(column_name(j) + " is infinite" +
             (output ? " (a missing measurement is an empty cell or nan)" : ""));
      }
    }
    if (!late_rows_ && !times_.empty() && !(values_[0] > times_.back())) {
      std::ostringstream os;
      os.precision(17);
      os << "time " << values_[0] << " does not come after the previous row's " << times_.back()
         << ": times must increase";
      // Late rows are measurements; a file without output columns (a scenario's input
      // schedule) has none, and --allow-late does not apply to it.
      if (p_ > 0) os << " (--allow-late passes late rows to the observers)";
      fail(os.str());
    }
  }

  const std::string& name_;
  const Eigen::Index p_, m_;
  const std::size_t columns_;
  const bool late_rows_;  // a time may come before the previous row's (--allow-late)
  long number_ = 0;
  bool seen_line_ = false;
  std::vector<std::string_view> cells_;
  std::vector<CellKind> kinds_;
  std::vector<double> values_;
  std::string buffer_;
  std::vector<double> times_, samples_;  // samples_: y and u of each row, row after row
};

}  // namespace

Measurements parse_measurements_csv(std::istream& in, const std::string& name, Eigen::Index outputs,
                                    Eigen::Index inputs, bool late_rows) {
  Reader reader(name, outputs, inputs, late_rows);
  // Lines are read into a buffer of the limit's size, never grown: a file without line breaks
  // (/dev/zero) is refused at the limit, not read until memory runs out.
  std::vector<char> buffer(kMaxDataLineBytes + 1);
  long number = 1;
  for (;; ++number) {
    errno = 0;
    in.getline(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    const auto count = static_cast<std::size_t>(in.gcount());
    if (in.bad()) break;
    if (in.fail()) {
      if (count == 0) break;  // the end of the file
      throw std::invalid_argument(name + ":" + std::to_string(number) +
                                  ": the line is longer than " + std::to_string(kMaxDataLineBytes) +
                                  " bytes, the limit of a data file's line");
    }
    const bool ended = !in.eof();  // the delimiter was extracted (and counted)
    reader.line(std::string_view(buffer.data(), ended ? count - 1 : count), number);
    if (!ended) break;
  }
  if (in.bad()) {
    const int error = errno;
    throw std::invalid_argument(name + ":" + std::to_string(number) + ": read error" +
                                (error != 0 ? std::string(": ") + std::strerror(error) : ""));
  }
  return reader.finish();
}

Measurements read_measurements_csv(const std::string& file, Eigen::Index outputs,
                                   Eigen::Index inputs, bool late_rows) {
  std::ifstream in = open_input_file(file, "data file");
  return parse_measurements_csv(in, file, outputs, inputs, late_rows);
}

}  // namespace nlobs
