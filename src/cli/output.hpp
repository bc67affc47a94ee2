// Output files of the commands: every file a command writes appears whole or
// not at all. Text goes through io::write_file_atomic; plots drawn by a Python
// script are drawn into a temporary file beside the target and renamed into
// place. Paths are checked before any work starts, so a typo in --out or
// --plot fails at once with one line, not after a long run.
#pragma once

#include <filesystem>
#include <string>

namespace lcsim::cli {

// io::InputError "<path>: cannot write: <reason>" unless a file can be
// created beside `path` (its folder exists and is writable) and `path` is not
// a folder. Creates and removes a temporary file to find out.
void check_writable(const std::string& path);

// The plotting script bench/<name> (a Python file shipped with lcsim): the
// path in the environment variable `env_var` if set, else the first
// bench/<name> found in the working directory or a parent folder of the
// lcsim executable (the build tree sits inside the source tree).
// std::runtime_error naming both when it is nowhere.
std::filesystem::path find_plot_script(const std::string& name, const char* env_var);

// Runs `/usr/bin/python3 script input <tmp> --title title` without a shell,
// where <tmp> is a new file beside `out` with the same extension, then renames
// <tmp> to `out`. The script's own output goes to a log that is dropped on
// success; on failure <tmp> is removed and std::runtime_error names `option`,
// the script and the last line it printed (one line).
void draw_plot(const std::filesystem::path& script, const std::filesystem::path& input,
               const std::string& out, const std::string& title, const std::string& option);

}  // namespace lcsim::cli
