// Writers: atomic file output, CSV trajectories, JSON run summaries.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <lcsim/io/io.hpp>
#include <stdexcept>

#include "io/detail.hpp"

namespace lcsim::io {

std::string format_number(double x) {
  char buf[64];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, x);
  return ec == std::errc() ? std::string(buf, end) : std::string("?");
}

std::string one_line(const std::string& text, std::size_t max_chars) {
  std::string out;
  for (const char ch : text) {
    if (out.size() >= max_chars) return out + "...";
    const auto c = static_cast<unsigned char>(ch);
    if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c == '\t') {
      out += "\\t";
    } else if (c < 0x20 || c == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
    } else {
      out += ch;
    }
  }
  return out;
}

namespace {

// %.17g: enough significant digits that every double reads back exactly.
void append_number(std::string& out, double x) {
  char buf[32];
  const int n = std::snprintf(buf, sizeof buf, "%.17g", x);
  out.append(buf, static_cast<std::size_t>(n));
}

// RFC 4180 quoting for names that contain separators or quotes.
std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += (c == '"') ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

// prefix + text, appended in place (GCC 12 warns falsely, -Wrestrict, on
// `"literal" + std::string&&`).
std::string prefixed(std::string_view prefix, const std::string& text) {
  std::string s(prefix);
  s += text;
  return s;
}

std::string_view run_status_name(sim::RunStatus s) { return to_string(s, "completed"); }

nlohmann::json index_set_json(const std::vector<int>& s) {
  nlohmann::json a = nlohmann::json::array();
  for (int i : s) a.push_back(i);
  return a;
}

}  // namespace

void write_file_atomic(const std::filesystem::path& path, const std::string& content) {
  const std::string where = path.string();
  if (!path.has_filename()) throw InputError(where + ": cannot write: not a file name");
  std::filesystem::path dir = path.parent_path();
  if (dir.empty()) dir = ".";
  std::string name = (dir / (prefixed(".", path.filename().string()) + ".tmp-XXXXXX")).string();
  const int fd = ::mkstemp(name.data());
  if (fd < 0) throw InputError(where + ": cannot write: " + std::strerror(errno));
  const auto give_up = [&](int err, bool close_fd) {
    if (close_fd) ::close(fd);
    ::unlink(name.c_str());
    throw InputError(where + ": cannot write: " + std::strerror(err));
  };
  // mkstemp creates the file 0600; give it the mode a plain open would have:
  // the existing file's, or 0666 less the umask (umask can only be read by
  // setting it, so it is set back at once).
  struct stat st {};
  mode_t mode;
  if (::stat(where.c_str(), &st) == 0 && S_ISREG(st.st_mode)) {
    mode = st.st_mode & 07777;
  } else {
    const mode_t mask = ::umask(0);
    ::umask(mask);
    mode = 0666 & ~mask;
  }
  if (::fchmod(fd, mode) != 0) give_up(errno, true);
  std::size_t done = 0;
  while (done < content.size()) {
    const ssize_t n = ::write(fd, content.data() + done, content.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      give_up(errno, true);
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) give_up(errno, true);
  if (::close(fd) != 0) give_up(errno, false);
  if (::rename(name.c_str(), where.c_str()) != 0) give_up(errno, false);
}

std::string trajectory_csv(const mech::Model& model, const sim::Trajectory& traj) {
  const int n = model.state_size();
  const int k = model.num_constraints();
  std::vector<std::string> header{"t"};
  if (model.is_mechanical()) {
    const mech::MechanicalModel& m = *model.mechanical;
    for (const auto& c : m.coordinates) header.push_back(c);
    for (const auto& c : m.coordinates) header.push_back("v_" + c);
    for (const auto& c : m.constraints) header.push_back("u_" + c);
    for (const auto& c : m.constraints) header.push_back("y_" + c);
  } else {
    for (int i = 1; i <= n; ++i) header.push_back(prefixed("x", std::to_string(i)));
    for (int i = 1; i <= k; ++i) header.push_back(prefixed("u", std::to_string(i)));
    for (int i = 1; i <= k; ++i) header.push_back(prefixed("y", std::to_string(i)));
  }
  header.push_back("mode");

  std::string out;
  for (std::size_t i = 0; i < header.size(); ++i)
    out += prefixed(i ? "," : "", csv_field(header[i]));
  out += '\n';
  // u and y may be empty in a sample (e.g. an event-only record): blank cells.
  const auto append_vector = [&](const VectorXd& v, int size, const char* what, std::size_t row) {
    if (v.size() != 0 && v.size() != size)
      throw std::logic_error("trajectory_csv: sample " + std::to_string(row) + " has " + what +
                             " of size " + std::to_string(v.size()) + ", expected " +
                             std::to_string(size));
    for (int j = 0; j < size; ++j) {
      out += ',';
      if (v.size() != 0) append_number(out, v(j));
    }
  };
  for (std::size_t r = 0; r < traj.samples.size(); ++r) {
    const sim::Sample& s = traj.samples[r];
    if (s.x.size() != n)
      throw std::logic_error("trajectory_csv: sample " + std::to_string(r) +
                             " has a state of size " + std::to_string(s.x.size()) + ", expected " +
                             std::to_string(n));
    append_number(out, s.t);
    append_vector(s.x, n, "x", r);
    append_vector(s.u, k, "u", r);
    append_vector(s.y, k, "y", r);
    out += ',';
    for (std::size_t j = 0; j < s.mode.size(); ++j)
      out += prefixed(j ? ";" : "", std::to_string(s.mode[j]));
    out += '\n';
  }
  return out;
}

nlohmann::json trajectory_json(const mech::Model& model, const sim::Trajectory& traj) {
  nlohmann::json j;
  j["model"] = model.name;
  j["method"] = traj.method;
  j["t_end"] = traj.t_end;
  j["final_state"] = to_json(traj.final_state);
  nlohmann::json events = nlohmann::json::array();
  for (const sim::Event& e : traj.events) {
    events.push_back({{"t", e.t},
                      {"type", std::string(sim::to_string(e.type))},
                      {"state_before", to_json(e.state_before)},
                      {"state_after", to_json(e.state_after)},
                      {"mode_after", index_set_json(e.mode_after)},
                      {"impulse", to_json(e.impulse)}});
    if (!e.note.empty()) events.back()["note"] = e.note;
  }
  j["events"] = std::move(events);
  j["events_not_recorded"] = traj.events_not_recorded;
  j["impact_law"] =
      traj.impact_law.empty() ? nlohmann::json(nullptr) : nlohmann::json(traj.impact_law);
  // Energies are defined for mechanical models only (null for a general LCS).
  if (model.is_mechanical()) {
    j["energy_initial"] = traj.energy_initial;
    j["energy_final"] = traj.energy_final;
  } else {
    j["energy_initial"] = nullptr;
    j["energy_final"] = nullptr;
  }
  j["max_violation"] = traj.max_violation;
  j["lcp_solves"] = traj.lcp_solves;
  j["steps"] = traj.steps;
  j["warnings"] = traj.warnings;
  j["warning_messages"] = traj.warning_messages;
  j["status"] = std::string(run_status_name(traj.status));
  j["message"] = traj.message;
  j["wall_time_s"] = traj.wall_time_s;
  return j;
}

nlohmann::json to_json(const VectorXd& v) {
  nlohmann::json a = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(v(i));
  return a;
}

nlohmann::json to_json(const Eigen::MatrixXd& m) {
  nlohmann::json a = nlohmann::json::array();
  for (Eigen::Index i = 0; i < m.rows(); ++i) a.push_back(to_json(VectorXd(m.row(i).transpose())));
  return a;
}

}  // namespace lcsim::io
