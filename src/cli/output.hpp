// Output files of the commands: every file a command writes appears whole or
// not at all. Text goes through io::write_file_atomic; plots drawn by a Python
// script are drawn into a temporary file beside the target and renamed into
// place; temporaries are tracked (io::track_temporary_file) so a signal
// removes them. Paths are checked before any work starts, so a typo in --out or
// --plot fails at once with one line, not after a long run.
#pragma once

#include <filesystem>
#include <lcsim/sim/sim.hpp>
#include <string>

namespace lcsim::cli {

// io::InputError "<path>: cannot write: <reason>" unless a file can be
// created beside `path` (its folder exists and is writable) and `path` is not
// a folder. Creates and removes a temporary file to find out.
void check_writable(const std::string& path);

// A figure of the Python package's plotting module, lcsim/plot.py (the one
// place lcsim's figures are drawn; it needs matplotlib, not the extension
// module): the file and the figure's subcommand ("impact-map", ...).
struct PlotScript {
  std::filesystem::path path;
  std::string kind;
};

// The plotting module for figure `kind`: the path in the environment
// variable `env_var` if set, else <dir of the lcsim binary>/../share/lcsim/plot.py
// (installed), else the source tree's python/lcsim/plot.py (the build-tree
// binary; LCSIM_SOURCE_DIR is set at build time). std::runtime_error listing
// where it looked when nowhere.
PlotScript find_plot_script(const std::string& kind, const char* env_var);

// Runs `/usr/bin/python3 script kind input <tmp> --title title` without a shell,
// where <tmp> is a new file beside `out` with the same extension, then renames
// <tmp> to `out`. The script's own output goes to a log that is dropped on
// success; on failure <tmp> is removed and std::runtime_error names `option`,
// the script and the last line it printed (one line).
void draw_plot(const PlotScript& script, const std::filesystem::path& input, const std::string& out,
               const std::string& title, const std::string& option);

// draw_plot with its input `text` in a temporary file of the system's
// temporary folder (`name` with the process id before its extension), which
// is removed afterwards, and by a signal (io::track_temporary_file).
void draw_plot_of_text(const std::string& text, const std::string& name, const PlotScript& script,
                       const std::string& out, const std::string& title, const std::string& option);

// Progress of a long run on stderr, fed by sim::Options::progress:
//   lcsim: t = 12.5 of 100 (12 %), 3.1 s so far, about 22 s left
// Modes: kAuto draws only when stderr is a terminal and the run has taken
// 1 s, rewriting one line in place; kAlways (--progress) writes a line at the
// start of the run and then at most twice a second, plus the final one, each
// on its own line (for logs); kNever (--no-progress) writes nothing.
class ProgressLine {
 public:
  enum class Mode { kAuto, kAlways, kNever };
  ProgressLine(double t_end, Mode mode);
  ~ProgressLine();  // ends an in-place line with a newline
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;
  void update(double t);
  void done();  // the 100 % line (kAlways, or when a line was drawn)

 private:
  void draw(double t);
  double t_end_;
  Mode mode_;
  bool tty_ = false, drawn_ = false, finished_ = false;
  double start_ = 0.0, last_ = -1.0;
};

// One line on stderr per kind of warning of the run:
//   lcsim: warning: <first message> (and N more like it, the first at t = ...)
void print_warnings(const sim::Trajectory& tr);

}  // namespace lcsim::cli
