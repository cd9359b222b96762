#pragma once
// The one way the CLI writes a file (`--out DIR`'s files and plots, `--csv FILE`, gnuplot's log
// and PNGs): what it promises, kept in one place (docs/cli.md, "Output files").
//
// What the path holds decides how it is written:
// * nothing, or a regular file: the content goes to a new temporary beside it, created with
//   O_CREAT | O_EXCL (never through a link someone left there) under an unpredictable name
//   (`.NAME.tmp-XXXXXX`, mkostemp), is flushed to disk (fsync) and renamed over the path when
//   complete: a file with its final name is whole, and a failed write keeps the earlier file.
//   A replaced file keeps its permission bits (and, when nlobs runs as root, its owner);
// * a symbolic link to a regular file: the file it points to is replaced as above, in its own
//   directory; the link stays a link;
// * the file this process's standard output or error writes to (`--csv /dev/stdout > rows.csv`,
//   `--csv rows.csv > rows.csv`), whatever it is: written through a duplicate of that descriptor,
//   after what the process printed, never replaced (that would leave the redirection writing to
//   an unlinked file);
// * a FIFO or a character device (a pipe `>(gzip > x)`, /dev/stdout, /dev/null): written in
//   place, never replaced; a FIFO nobody reads is refused at once instead of blocking;
// * a directory, a block device, a socket, a link to none of the above or to nothing: refused,
//   naming the path and what it is. Nothing is touched.
// Errors (std::runtime_error) name the file and give the system's reason
// ("No space left on device").
//
// Temporaries are removed when a file is not committed (an exception, the destructor) and on
// SIGINT, SIGTERM or SIGHUP once install_interrupt_cleanup() has run.
#include <sys/types.h>

#include <filesystem>
#include <memory>
#include <ostream>
#include <string>
#include <string_view>

namespace nlobs::cli {

// Installs the SIGINT/SIGTERM/SIGHUP handler that removes pending temporaries (the CLI's main
// calls it; a program embedding run_scenario() may keep its own handlers).
void install_interrupt_cleanup();
// The child process the handler must stop first (gnuplot writing a temporary); 0 for none.
void set_interruptible_child(pid_t pid);

// A path as messages about output files show it: quoted, printable, at most 300 bytes.
std::string shown(const std::filesystem::path& p);

// Whether `name` (no directory) is a temporary this class makes for `final_name`
// (`.FINAL.tmp-XXXXXX`).
bool is_temporary_name_of(std::string_view name, std::string_view final_name);
// The final name of a temporary this class makes, or an empty view for any other name.
std::string_view final_name_of_temporary(std::string_view name);

class OutputFile {
 public:
  // Decides how `path` is written (above) and opens the temporary or the FIFO/device; throws
  // std::runtime_error naming the path when it cannot be written.
  explicit OutputFile(const std::filesystem::path& path);
  ~OutputFile();  // not committed: the temporary is removed
  OutputFile(OutputFile&&) noexcept;
  OutputFile& operator=(OutputFile&&) = delete;
  OutputFile(const OutputFile&) = delete;

  std::ostream& stream();
  // The open descriptor of what is written (the temporary, or the FIFO/device): for a child
  // process (gnuplot's stderr). Valid until commit().
  int descriptor() const;
  // The temporary's path, for a program that writes it by name (gnuplot's PNGs); empty when the
  // file is written in place.
  const std::filesystem::path& temporary() const;
  // The path as given.
  const std::filesystem::path& path() const;
  // Whether anything has been written to the temporary (by us or by another program).
  bool empty() const;

  // Flushes, syncs and renames into place (in place: flushes); throws naming the file and the
  // system's reason. After it, the object holds nothing.
  void commit();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// Writes `content` to `path` through an OutputFile.
void write_output_file(const std::filesystem::path& path, std::string_view content);

}  // namespace nlobs::cli
