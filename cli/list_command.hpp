#pragma once
// `nlobs list [models|engines|observers|scenarios|problems]`: what can be named on the command
// line, from the registries.
#include <iosfwd>
#include <string>

namespace nlobs::cli {

// `what`: "" (everything) or one section. Throws std::invalid_argument otherwise.
void print_list(const std::string& what, std::ostream& out);

}  // namespace nlobs::cli
