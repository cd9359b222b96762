#pragma once
// The `--out DIR` of `nlobs run`: what the docs promise about it, kept in one place.
//
// * Every file is written through an OutputFile (output_file.hpp): under an unpredictable
//   temporary name, renamed when complete, so a file with its final name is whole; gnuplot's
//   PNGs and log too (gnuplot is given the temporary). A name in DIR that holds a FIFO, a
//   device or a link is written as OutputFile says, never replaced by a regular file.
// * One run at a time: the directory is locked (flock on DIR/.nlobs.lock) while a run writes
//   into it; a second run into it fails at once, naming the directory and the first run's pid.
// * `summary.json` (a sweep: `sweep.csv`) marks a complete directory: both are removed when a
//   run starts writing, and the run's marker is written last.
// * Files an earlier run left that this run does not write are removed, but only regular files
//   under names nlobs itself writes (output_file_names(), `signals_N.png`, their temporaries):
//   nothing else in DIR is touched.
// * No temporary is left: on a clean exit, on an exception (the destructors), and on SIGINT,
//   SIGTERM or SIGHUP once install_interrupt_cleanup() has run (the handler also stops a
//   running gnuplot, then the signal takes its default course).
// Errors (std::runtime_error) name the file and give the system's reason.
#include <filesystem>
#include <memory>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "output_file.hpp"

namespace nlobs::cli {

// The fixed names nlobs writes into an output directory (besides `signals_N.png`).
const std::vector<std::string>& output_file_names();
// Whether `name` (a file name, no directory) is one nlobs writes, or a temporary of one (this
// version's `.NAME.tmp-XXXXXX` or an earlier version's `NAME.tmp`).
bool is_output_file_name(std::string_view name);
// The lock file of an output directory.
inline constexpr std::string_view kOutputLockName = ".nlobs.lock";

// Holds the lock of an output directory (created if needed) while it lives: a run takes it
// before it computes, so that a second run into the same directory fails at once rather than
// after its computation. An OutputDirectory of this process shares a lock held here.
class OutputDirectoryLock {
 public:
  explicit OutputDirectoryLock(const std::string& path);
  ~OutputDirectoryLock();
  OutputDirectoryLock(const OutputDirectoryLock&) = delete;
  OutputDirectoryLock& operator=(const OutputDirectoryLock&) = delete;

 private:
  std::shared_ptr<void> lock_;
};

class OutputDirectory {
 public:
  // Creates `path` (made absolute) if needed, locks it and removes its summary.json,
  // sweep.csv and leftover temporaries of nlobs files. Throws naming the directory when it
  // cannot, or when another run holds its lock.
  explicit OutputDirectory(const std::string& path);
  ~OutputDirectory();  // removes temporaries not committed, unlocks
  OutputDirectory(const OutputDirectory&) = delete;
  OutputDirectory& operator=(const OutputDirectory&) = delete;

  const std::filesystem::path& path() const { return path_; }

  // A file written in pieces (streamed): write to stream(), then commit(). Dropped without a
  // commit, the temporary is removed. A Writer must not outlive its OutputDirectory.
  class Writer {
   public:
    std::ostream& stream() { return file_.stream(); }
    void commit();  // flushes, syncs, renames into place; throws naming the reason

   private:
    friend class OutputDirectory;
    Writer(OutputDirectory& owner, std::string name);
    OutputDirectory* owner_;
    std::string name_;
    OutputFile file_;
  };
  Writer open(const std::string& name);
  void write(const std::string& name, std::string_view content);  // open, write, commit

  // A file another program writes (gnuplot): the temporary's name to give it (relative to
  // path()), created empty and registered for cleanup; commit_external() renames every such
  // file the program wrote into (not empty) and returns their final names, discard_external()
  // removes them.
  std::string external(const std::string& name);
  std::vector<std::string> commit_external();
  void discard_external();
  // A file this run has written (every committed file): not stale.
  void note_written(const std::string& name);

  // Removes the nlobs files of earlier runs that this run has not written.
  void remove_stale_files();

 private:
  std::filesystem::path path_;
  std::shared_ptr<void> lock_;
  std::vector<std::string> written_;
  struct External {
    std::string name;  // the final name
    OutputFile file;   // gnuplot writes file.temporary()
  };
  std::vector<External> external_;
};

}  // namespace nlobs::cli
