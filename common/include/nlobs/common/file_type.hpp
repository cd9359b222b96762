#pragma once
// What a stat() says a path is, in words, for messages that refuse it: the CLI's output files
// (cli/output_file.hpp) and the plugin loader say it the same way.
#include <sys/stat.h>

namespace nlobs {

// "a directory", "a FIFO", … ; "a regular file" for one.
inline const char* file_type_name(mode_t mode) {
  if (S_ISREG(mode)) return "a regular file";
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISLNK(mode)) return "a symbolic link";
  return "not a regular file";
}

}  // namespace nlobs
