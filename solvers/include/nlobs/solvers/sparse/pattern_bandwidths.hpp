#pragma once
// The band that holds a sparsity pattern: what auto's choice of band LU and a band solver's
// storage (KINSOL's SUNBandMatrix) are sized by; in a header of its own because
// sparsity_pattern.hpp is in nearly every engine, and only these two need it.
#include "nlobs/solvers/types.hpp"

namespace nlobs {

struct SparsityPattern;

struct PatternBandwidths {
  Index lower = 0;  // max over the entries (i, j) of i − j, at least 0
  Index upper = 0;  // max over the entries of j − i, at least 0
};
PatternBandwidths pattern_bandwidths(const SparsityPattern& pattern);

}  // namespace nlobs
