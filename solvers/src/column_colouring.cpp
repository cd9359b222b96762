#include "nlobs/solvers/sparse/column_colouring.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <queue>
#include <vector>

namespace nlobs {

PatternColumns::PatternColumns(const SparsityPattern& p)
    : start(static_cast<std::size_t>(p.cols) + 1, 0),
      rows(p.columns.size()),
      positions(p.columns.size()) {
  for (const Index j : p.columns) ++start[static_cast<std::size_t>(j) + 1];
  for (Index j = 0; j < p.cols; ++j) start[j + 1] += start[j];
  std::vector<Index> next(start.begin(), start.end() - 1);
  for (Index i = 0; i < p.rows; ++i) {
    for (Index k = p.row_start[i]; k < p.row_start[i + 1]; ++k) {
      const Index at = next[p.columns[k]]++;
      rows[at] = i;
      positions[at] = k;
    }
  }
}

namespace {

// The columns that share a row with column j (its neighbours), each once, to visit(k); marks is
// scratch of size cols, and must not hold j on entry (each column visited once per fill).
template <typename Visit>
void for_each_neighbour(const SparsityPattern& p, const PatternColumns& by_column, Index j,
                        std::vector<Index>& marks, Visit&& visit) {
  marks[j] = j;
  for (Index e = by_column.start[j]; e < by_column.start[j + 1]; ++e) {
    const Index i = by_column.rows[e];
    for (Index k = p.row_start[i]; k < p.row_start[i + 1]; ++k) {
      const Index other = p.columns[k];
      if (marks[other] == j) continue;
      marks[other] = j;
      visit(other);
    }
  }
}

// Greedy in natural column order: the first colour no neighbour has.
ColumnColouring greedy_natural(const SparsityPattern& p, const PatternColumns& by_column) {
  ColumnColouring c;
  c.colour.assign(static_cast<std::size_t>(p.cols), -1);
  std::vector<Index> marks(static_cast<std::size_t>(p.cols), -1);
  std::vector<Index> forbidden;  // forbidden[k] == j: a neighbour of j has colour k
  for (Index j = 0; j < p.cols; ++j) {
    for_each_neighbour(p, by_column, j, marks, [&](Index other) {
      if (c.colour[other] >= 0) forbidden[c.colour[other]] = j;
    });
    int chosen = 0;
    while (chosen < c.colours && forbidden[chosen] == j) ++chosen;
    if (chosen == c.colours) {
      ++c.colours;
      forbidden.push_back(-1);
    }
    c.colour[j] = chosen;
  }
  return c;
}

}  // namespace

ColumnColouring colour_columns(const SparsityPattern& p) {
  const PatternColumns by_column(p);
  const Index n = p.cols;
  // The fewest possible is the longest row: natural order reaches it on bands (one pass, cheap).
  Index longest = 1;
  for (Index i = 0; i < p.rows; ++i)
    longest = std::max(longest, p.row_start[i + 1] - p.row_start[i]);
  ColumnColouring natural = greedy_natural(p, by_column);
  if (natural.colours <= longest) return natural;

  std::vector<Index> marks(static_cast<std::size_t>(n), -1), degree(static_cast<std::size_t>(n), 0);
  Index max_degree = 0;
  for (Index j = 0; j < n; ++j) {
    for_each_neighbour(p, by_column, j, marks, [&](Index) { ++degree[j]; });
    max_degree = std::max(max_degree, degree[j]);
  }
  // DSATUR keeps, per column, the set of colours its neighbours use as a bit mask of kWords
  // words: greedy never needs more than max_degree + 1 colours. Past that (a pattern with rows
  // of hundreds of entries, where a dense Jacobian is the better choice anyway) natural order.
  constexpr Index kWords = 4;
  if (max_degree + 1 > 64 * kWords || n >= (Index{1} << 32)) return natural;
  std::fill(marks.begin(), marks.end(), -1);  // (each column is visited once more below)
  std::vector<std::uint64_t> seen(static_cast<std::size_t>(n * kWords), 0);
  std::vector<int> saturation(static_cast<std::size_t>(n), 0);
  // Heap keys: saturation, then degree (capped), then the lower column first.
  auto key = [&](Index j) {
    const auto d = static_cast<std::uint64_t>(std::min<Index>(degree[j], (Index{1} << 22) - 1));
    return (static_cast<std::uint64_t>(saturation[j]) << 54) | (d << 32) |
           (0xFFFFFFFFull - static_cast<std::uint64_t>(j));
  };
  ColumnColouring c;
  c.colour.assign(static_cast<std::size_t>(n), -1);
  std::priority_queue<std::uint64_t> queue;
  for (Index j = 0; j < n; ++j) queue.push(key(j));
  while (!queue.empty()) {
    const std::uint64_t top = queue.top();
    queue.pop();
    const auto j = static_cast<Index>(0xFFFFFFFFull - (top & 0xFFFFFFFFull));
    if (c.colour[j] >= 0 || top != key(j)) continue;  // coloured, or a stale entry
    const std::uint64_t* mask = &seen[static_cast<std::size_t>(j * kWords)];
    int chosen = 0;
    for (Index w = 0; w < kWords; ++w, chosen += 64) {
      if (~mask[w] != 0) {
        chosen += std::countr_one(mask[w]);
        break;
      }
    }
    c.colour[j] = chosen;
    c.colours = std::max(c.colours, chosen + 1);
    for_each_neighbour(p, by_column, j, marks, [&](Index other) {
      if (c.colour[other] >= 0) return;
      std::uint64_t& word = seen[static_cast<std::size_t>(other * kWords + chosen / 64)];
      const std::uint64_t bit = std::uint64_t{1} << (chosen % 64);
      if ((word & bit) != 0) return;
      word |= bit;
      ++saturation[other];
      queue.push(key(other));
    });
  }
  return c.colours < natural.colours ? c : natural;
}

bool valid_colouring(const SparsityPattern& p, const ColumnColouring& c) {
  if (static_cast<Index>(c.colour.size()) != p.cols) return false;
  for (const int k : c.colour) {
    if (k < 0 || k >= c.colours) return false;
  }
  std::vector<Index> seen(static_cast<std::size_t>(c.colours), -1);  // row that used a colour
  for (Index i = 0; i < p.rows; ++i) {
    for (Index k = p.row_start[i]; k < p.row_start[i + 1]; ++k) {
      const int colour = c.colour[p.columns[k]];
      if (seen[colour] == i) return false;
      seen[colour] = i;
    }
  }
  return true;
}

}  // namespace nlobs
