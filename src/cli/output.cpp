// Output files of the commands (see output.hpp).
#include "cli/output.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <lcsim/io/io.hpp>
#include <sstream>
#include <stdexcept>
#include <vector>

extern char** environ;

namespace lcsim::cli {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void cannot_write(const std::string& path, const std::string& why) {
  throw io::InputError(path + ": cannot write: " + why);
}

// A new empty file beside `path`: ".<name>.tmp-XXXXXX<ext>"; returns its name.
std::string temp_beside(const std::string& path) {
  const fs::path p(path);
  if (!p.has_filename()) cannot_write(path, "not a file name");
  std::error_code ec;
  if (fs::is_directory(p, ec)) cannot_write(path, std::strerror(EISDIR));
  fs::path dir = p.parent_path();
  if (dir.empty()) dir = ".";
  const std::string ext = p.extension().string();
  std::string name = (dir / ("." + p.stem().string() + ".tmp-XXXXXX" + ext)).string();
  const int fd = ::mkstemps(name.data(), static_cast<int>(ext.size()));
  if (fd < 0) cannot_write(path, std::strerror(errno));
  // mkstemps creates the file 0600: give it the mode a plain open would have.
  const mode_t mask = ::umask(0);
  ::umask(mask);
  (void)::fchmod(fd, 0666 & ~mask);
  ::close(fd);
  io::track_temporary_file(name);
  return name;
}

// Removes a temporary made by temp_beside (or renamed away) from the table.
void drop_temp(const std::string& name) {
  ::unlink(name.c_str());
  io::untrack_temporary_file(name);
}

std::string last_line(const fs::path& log) {
  std::ifstream in(log);
  std::string line, last;
  while (std::getline(in, line))
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  const auto b = last.find_first_not_of(" \t");
  return b == std::string::npos ? std::string("no message") : last.substr(b);
}

}  // namespace

void check_writable(const std::string& path) { drop_temp(temp_beside(path)); }

PlotScript find_plot_script(const std::string& kind, const char* env_var) {
  if (const char* env = std::getenv(env_var)) return {env, kind};
  const std::string name = "plot.py";
  std::vector<fs::path> places;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec)
    places.push_back((exe.parent_path() / ".." / "share" / "lcsim" / name).lexically_normal());
#ifdef LCSIM_SOURCE_DIR
  places.push_back(fs::path(LCSIM_SOURCE_DIR) / "python" / "lcsim" / name);
#endif
  std::string looked;
  for (const auto& p : places) {
    if (fs::is_regular_file(p, ec)) return {p, kind};
    looked += (looked.empty() ? "" : ", ") + p.string();
  }
  throw std::runtime_error("the plotting module " + name + " is not installed: looked in " +
                           (looked.empty() ? std::string("no place") : looked) + " (set " +
                           env_var + " to its path)");
}

void draw_plot(const PlotScript& script, const fs::path& input, const std::string& out,
               const std::string& title, const std::string& option) {
  const std::string tmp = temp_beside(out);
  const fs::path log =
      fs::temp_directory_path() / ("lcsim_plot_" + std::to_string(::getpid()) + ".log");
  io::track_temporary_file(log.string());
  std::vector<std::string> args{
      "/usr/bin/python3", script.path.string(), script.kind, input.string(), tmp, "--title", title};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                   0600);
  posix_spawn_file_actions_adddup2(&fa, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = -1;
  const int err = ::posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  int status = 0;
  if (err == 0)
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
  const bool ok = err == 0 && WIFEXITED(status) && WEXITSTATUS(status) == 0;
  std::string why;
  if (err != 0)
    why = std::string("cannot run /usr/bin/python3: ") + std::strerror(err);
  else if (!ok)
    why = "the plot script " + script.path.string() + " " + script.kind +
          " failed: " + last_line(log);
  drop_temp(log.string());
  if (ok && ::rename(tmp.c_str(), out.c_str()) == 0) {
    io::untrack_temporary_file(tmp);
    return;
  }
  if (ok) why = out + ": cannot write: " + std::strerror(errno);
  drop_temp(tmp);
  if (ok) throw io::InputError(option + ": " + why);
  throw std::runtime_error(option + ": " + why);
}

void draw_plot_of_text(const std::string& text, const std::string& name, const PlotScript& script,
                       const std::string& out, const std::string& title,
                       const std::string& option) {
  const fs::path n(name);
  const fs::path tmp =
      fs::temp_directory_path() /
      (n.stem().string() + "_" + std::to_string(::getpid()) + n.extension().string());
  io::write_file_atomic(tmp, text);
  io::track_temporary_file(tmp.string());
  try {
    draw_plot(script, tmp, out, title, option);
  } catch (...) {
    drop_temp(tmp.string());
    throw;
  }
  drop_temp(tmp.string());
}

namespace {
double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
}  // namespace

ProgressLine::ProgressLine(double t_end, Mode mode)
    : t_end_(t_end), mode_(mode), tty_(::isatty(STDERR_FILENO) != 0), start_(now_s()) {
  if (mode_ == Mode::kAlways) draw(0.0);
}

ProgressLine::~ProgressLine() {
  if (drawn_ && tty_ && mode_ == Mode::kAuto && !finished_) std::fputc('\n', stderr);
}

void ProgressLine::update(double t) {
  if (mode_ == Mode::kNever || (mode_ == Mode::kAuto && !tty_)) return;
  const double now = now_s();
  if (mode_ == Mode::kAuto && now - start_ < 1.0) return;
  if (last_ >= 0.0 && now - last_ < 0.5) return;
  draw(t);
}

void ProgressLine::done() {
  if (finished_) return;
  if (mode_ == Mode::kAlways || drawn_) draw(t_end_);
  if (drawn_ && tty_ && mode_ == Mode::kAuto) std::fputc('\n', stderr);
  finished_ = true;
}

void ProgressLine::draw(double t) {
  const double now = now_s(), elapsed = now - start_;
  const double frac = t_end_ > 0.0 ? std::clamp(t / t_end_, 0.0, 1.0) : 1.0;
  char left[64] = "";
  if (frac > 0.0 && frac < 1.0)
    std::snprintf(left, sizeof left, ", about %.3g s left", elapsed * (1.0 - frac) / frac);
  const bool in_place = tty_ && mode_ == Mode::kAuto;
  std::fprintf(stderr, "%slcsim: t = %.6g of %.6g (%.0f %%), %.3g s so far%s%s",
               in_place ? "\r" : "", t, t_end_, 100.0 * frac, elapsed, left,
               in_place ? "\x1b[K" : "\n");
  std::fflush(stderr);
  drawn_ = true;
  last_ = now;
}

void print_warnings(const sim::Trajectory& tr) {
  for (const auto& w : tr.warnings) {
    std::cerr << "lcsim: warning: " << w.message;
    if (w.count > 1)
      std::cerr << " (and " << w.count - 1 << " more like it, the first at t = " << w.first_t
                << ")";
    std::cerr << "\n";
  }
}

}  // namespace lcsim::cli
