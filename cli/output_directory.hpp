#pragma once
// The `--out DIR` of `nlobs run`: what the docs promise about it, kept in one place.
//
// * Every file is written under a temporary name (`NAME.tmp`) and renamed when complete, so a
//   file with its final name is whole; gnuplot's PNGs too (the script names the temporary).
// * `summary.json` (a sweep: `sweep.csv`) marks a complete directory: both are removed when a
//   run starts writing, and the run's marker is written last.
// * Files an earlier run left that this run does not write are removed, but only names nlobs
//   itself writes (output_file_names(), `signals_N.png`, their temporaries): nothing else in
//   DIR is touched.
// * No temporary is left: on a clean exit, on an exception (the destructor), and on SIGINT,
//   SIGTERM or SIGHUP once install_interrupt_cleanup() has run (the handler also stops a
//   running gnuplot, then the signal takes its default course).
// Errors (std::runtime_error) name the file and give the system's reason.
#include <sys/types.h>

#include <filesystem>
#include <memory>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace nlobs::cli {

// The fixed names nlobs writes into an output directory (besides `signals_N.png`).
const std::vector<std::string>& output_file_names();
// Whether `name` (a file name, no directory) is one nlobs writes, or a temporary of one.
bool is_output_file_name(std::string_view name);

// Installs the SIGINT/SIGTERM/SIGHUP handler that removes pending temporaries (the CLI's main
// calls it; a program embedding run_scenario() may keep its own handlers).
void install_interrupt_cleanup();
// The child process the handler must stop first (gnuplot writing a temporary); 0 for none.
void set_interruptible_child(pid_t pid);

class OutputDirectory {
 public:
  // Creates `path` (made absolute) if needed and removes its summary.json and leftover
  // temporaries of nlobs files.
  explicit OutputDirectory(const std::string& path);
  ~OutputDirectory();  // removes temporaries not committed
  OutputDirectory(const OutputDirectory&) = delete;
  OutputDirectory& operator=(const OutputDirectory&) = delete;

  const std::filesystem::path& path() const { return path_; }

  // A file written in pieces (streamed): write to stream(), then commit(). Dropped without a
  // commit, the temporary is removed. A Writer must not outlive its OutputDirectory.
  class Writer {
   public:
    Writer(Writer&&) noexcept;
    ~Writer();
    std::ostream& stream();
    void commit();  // flushes, checks, renames into place; throws naming the reason

   private:
    friend class OutputDirectory;
    struct State;
    explicit Writer(std::unique_ptr<State> state);
    std::unique_ptr<State> state_;
  };
  Writer open(const std::string& name);
  void write(const std::string& name, std::string_view content);  // open, write, commit

  // A file another program writes (gnuplot): the temporary name to give it (relative to
  // path()), registered for cleanup; commit_external() renames every such file that exists
  // and returns their final names, discard_external() removes them.
  std::string external(const std::string& name);
  std::vector<std::string> commit_external();
  void discard_external();
  // A file this run has written (gnuplot.log, under its final name; every committed file):
  // not stale.
  void note_written(const std::string& name);

  // Removes the nlobs files of earlier runs that this run has not written.
  void remove_stale_files();

 private:
  std::filesystem::path path_;
  std::vector<std::string> written_;
  struct External {
    std::string name;  // the final name; gnuplot writes temporary_name(name)
    int slot;          // in the signal handler's table, or -1
  };
  std::vector<External> external_;
};

}  // namespace nlobs::cli
