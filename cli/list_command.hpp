#pragma once
// `nlobs list [engines]`: what can be named on the command line.
#include <iosfwd>
#include <string>

namespace nlobs::cli {

// `what`: "" (everything) or "engines". Throws std::invalid_argument otherwise.
void print_list(const std::string& what, std::ostream& out);

}  // namespace nlobs::cli
