#pragma once
// gnuplot, safely: started without a shell (posix_spawn with an argument vector, the working
// directory set directly), and every user-provided string written into a script through one
// quoting function, so that a scenario name, an observer name or an --out path may contain any
// bytes without running a command.
#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace nlobs::cli {

// `text` as a gnuplot single-quoted string literal: in single quotes gnuplot performs no
// backquote (command) substitution, no @ macro expansion and no backslash processing; a quote
// is written twice, and a control character (newline, carriage return, tab, …), which would end
// or break the command line, is written as its visible escape ("\n", "\x1b"), i.e. literally.
std::string gnuplot_quoted(std::string_view text);

// `text` as one whitespace-separated field of a data file gnuplot reads: blanks, control
// characters and '#' (a comment) become '_'.
std::string gnuplot_data_token(std::string_view text);
// `text` for a "# …" comment line of a data file: control characters written as visible
// escapes, so a newline cannot start a data line or a blank line a new index block.
std::string gnuplot_comment_text(std::string_view text);

// The gnuplot executable found on PATH's absolute entries (searched directly, no shell).
std::optional<std::filesystem::path> find_gnuplot();

class OutputDirectory;

// How long gnuplot may run before it is stopped (nlobs run --plot-timeout).
inline constexpr std::chrono::milliseconds kDefaultPlotTimeout{120'000};

// Writes `script` as dir/script_name and runs gnuplot on it with the directory as its working
// directory (stderr to gnuplot.log), stopping it after `timeout`. The script names its outputs
// by OutputDirectory::external(); the caller commits or discards them. Returns an empty string
// on success, else why it failed: the first line of gnuplot's message, the timeout, or the
// system's reason it could not start.
std::string run_gnuplot_script(OutputDirectory& dir, const std::string& script_name,
                               const std::string& script,
                               std::chrono::milliseconds timeout = kDefaultPlotTimeout);

}  // namespace nlobs::cli
