#pragma once
// Opening a file the user named: a missing file, a directory and an unreadable file each get
// their own message (with the system's reason), naming what the file was meant to be.
#include <fstream>
#include <string>

namespace nlobs {

// `what` says what the file is for ("data file", "scenario file"). Throws std::invalid_argument.
std::ifstream open_input_file(const std::string& path, const std::string& what);

}  // namespace nlobs
