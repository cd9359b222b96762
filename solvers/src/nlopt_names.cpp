#include <nlopt.h>

#include "nlobs/solvers/nlopt_engine.hpp"

namespace nlobs {

std::vector<std::string> nlopt_algorithm_names() {
  std::vector<std::string> names;
  // Index = enumerator value (NloptEngine relies on it).
  for (int a = 0; a < NLOPT_NUM_ALGORITHMS; ++a) {
    const char* s = nlopt_algorithm_to_string(static_cast<nlopt_algorithm>(a));
    names.emplace_back(s != nullptr ? s : "");
  }
  return names;
}

}  // namespace nlobs
