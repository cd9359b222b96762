#include "nlobs/runs/input_file.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <system_error>

namespace nlobs {

std::ifstream open_input_file(const std::string& path, const std::string& what) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec && ec != std::errc::no_such_file_or_directory) {  // e.g. a directory on the way denied
    throw std::invalid_argument("cannot read " + what + " '" + path + "': " + ec.message());
  }
  if (fs::is_directory(status)) {
    throw std::invalid_argument(what + " '" + path + "' is a directory, not a file");
  }
  if (!fs::exists(status)) {
    throw std::invalid_argument(what + " '" + path + "' does not exist");
  }
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int reason = errno;
    throw std::invalid_argument("cannot read " + what + " '" + path +
                                "': " + (reason ? std::strerror(reason) : "open failed"));
  }
  return in;
}

}  // namespace nlobs
