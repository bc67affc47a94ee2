// Writers: atomic file output, CSV trajectories, JSON run summaries.
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <lcsim/io/io.hpp>
#include <lcsim/io/text.hpp>
#include <stdexcept>

namespace lcsim::io {

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
constexpr int kCsvDigits = 17;

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

// ---- Temporary files, removed on a signal ----
//
// A fixed table of paths as char buffers: a signal handler may walk it and
// unlink(2) each path (both async-signal-safe) while no allocation or lock is
// involved. A slot is 0 (free), 1 (being filled) or 2 (holds a path).
namespace {
constexpr std::size_t kMaxTemporaryFiles = 32;
constexpr std::size_t kMaxTemporaryPath = 4096;
struct TemporarySlot {
  std::atomic<int> state{0};
  char path[kMaxTemporaryPath];
};
TemporarySlot g_temporary[kMaxTemporaryFiles];
static_assert(std::atomic<int>::is_always_lock_free);
}  // namespace

void track_temporary_file(const std::string& path) {
  if (path.size() >= kMaxTemporaryPath) return;  // not tracked: removed on errors only
  for (auto& slot : g_temporary) {
    int expected = 0;
    if (!slot.state.compare_exchange_strong(expected, 1)) continue;
    std::memcpy(slot.path, path.c_str(), path.size() + 1);
    slot.state.store(2);
    return;
  }
}

void untrack_temporary_file(const std::string& path) {
  for (auto& slot : g_temporary) {
    int expected = 2;
    if (slot.state.load() == 2 && path == slot.path &&
        slot.state.compare_exchange_strong(expected, 1))
      slot.state.store(0);
  }
}

void remove_temporary_files() noexcept {
  for (auto& slot : g_temporary)
    if (slot.state.load() == 2) ::unlink(slot.path);
}

namespace {

// A new empty file ".<name>.tmp-XXXXXX" beside `path`, tracked for removal on
// a signal, with the mode a plain open would give `path`: the existing
// file's, or 0666 less the umask. mkstemp creates it 0600; umask can only be
// read by setting it, so it is set back at once.
struct TemporaryFile {
  int fd = -1;
  std::string name;
};
[[noreturn]] void cannot_write(const std::string& where, int err) {
  throw InputError(where + ": cannot write: " + std::strerror(err));
}
TemporaryFile temporary_beside(const std::filesystem::path& path) {
  const std::string where = path.string();
  if (!path.has_filename()) throw InputError(where + ": cannot write: not a file name");
  std::filesystem::path dir = path.parent_path();
  if (dir.empty()) dir = ".";
  TemporaryFile t;
  t.name = (dir / (prefixed(".", path.filename().string()) + ".tmp-XXXXXX")).string();
  // Signals wait while the file is made and tracked: a SIGINT between the
  // two would leave it behind.
  sigset_t all, old;
  sigfillset(&all);
  ::pthread_sigmask(SIG_BLOCK, &all, &old);
  t.fd = ::mkstemp(t.name.data());
  const int mkstemp_errno = errno;
  if (t.fd >= 0) track_temporary_file(t.name);
  ::pthread_sigmask(SIG_SETMASK, &old, nullptr);
  if (t.fd < 0) cannot_write(where, mkstemp_errno);
  struct stat st {};
  mode_t mode;
  if (::stat(where.c_str(), &st) == 0 && S_ISREG(st.st_mode)) {
    mode = st.st_mode & 07777;
  } else {
    const mode_t mask = ::umask(0);
    ::umask(mask);
    mode = 0666 & ~mask;
  }
  if (::fchmod(t.fd, mode) != 0) {
    const int err = errno;
    ::close(t.fd);
    ::unlink(t.name.c_str());
    untrack_temporary_file(t.name);
    cannot_write(where, err);
  }
  return t;
}

// All of `data` to fd; 0 or the errno of the failure.
int write_all(int fd, const char* data, std::size_t size) {
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::write(fd, data + done, size - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    done += static_cast<std::size_t>(n);
  }
  return 0;
}

// fsync, close and rename the temporary into place: 0 or the errno. The
// temporary is untracked once it is gone (renamed or removed).
int finish_temporary(TemporaryFile& t, const std::string& where, int err) {
  if (err == 0 && ::fsync(t.fd) != 0) err = errno;
  if (::close(t.fd) != 0 && err == 0) err = errno;
  t.fd = -1;
  if (err == 0 && ::rename(t.name.c_str(), where.c_str()) != 0) err = errno;
  if (err != 0) ::unlink(t.name.c_str());
  untrack_temporary_file(t.name);
  return err;
}

}  // namespace

std::vector<std::string> state_names(const mech::Model& model) {
  std::vector<std::string> out;
  if (model.is_mechanical()) {
    for (const auto& c : model.mechanical->coordinates) out.push_back(c);
    for (const auto& c : model.mechanical->coordinates) out.push_back(prefixed("v_", c));
  } else if (!model.state_names.empty()) {
    out = model.state_names;
  } else {
    for (int i = 1; i <= model.state_size(); ++i) out.push_back(prefixed("x", std::to_string(i)));
  }
  return out;
}

namespace {

std::vector<std::string> csv_header(const mech::Model& model) {
  const int n = model.state_size();
  const int k = model.num_constraints();
  std::vector<std::string> header{"t"};
  if (model.is_mechanical()) {
    const mech::MechanicalModel& m = *model.mechanical;
    for (const auto& c : m.coordinates) header.push_back(c);
    for (const auto& c : m.coordinates) header.push_back("v_" + c);
    for (const auto& c : m.constraints) header.push_back("u_" + c);
    for (const auto& c : m.constraints) header.push_back("y_" + c);
    // Friction only: models without it keep their columns byte for byte.
    for (const auto& f : m.friction) header.push_back("ut_" + m.constraints[f.contact]);
    // 3-D friction only: planar models keep their columns byte for byte.
    if (m.has_friction_3d())
      for (const auto& f : m.friction) header.push_back("ut2_" + m.constraints[f.contact]);
    for (const auto& f : m.friction) header.push_back("fm_" + m.constraints[f.contact]);
  } else {
    // Names when the model gives them (circuits), else x1.., u1.., y1...
    const auto& xs = model.state_names;
    const auto& ps = model.pair_names;
    for (int i = 1; i <= n; ++i)
      header.push_back(xs.empty() ? prefixed("x", std::to_string(i)) : xs[i - 1]);
    for (int i = 1; i <= k; ++i)
      header.push_back(ps.empty() ? prefixed("u", std::to_string(i)) : "u_" + ps[i - 1]);
    for (int i = 1; i <= k; ++i)
      header.push_back(ps.empty() ? prefixed("y", std::to_string(i)) : "y_" + ps[i - 1]);
    for (const auto& o : model.output_names) header.push_back(o);
  }
  header.push_back("mode");
  return header;
}

void append_csv_header(std::string& out, const mech::Model& model) {
  const std::vector<std::string> header = csv_header(model);
  for (std::size_t i = 0; i < header.size(); ++i)
    out += prefixed(i ? "," : "", csv_field(header[i]));
  out += '\n';
}

// u and y may be empty in a sample (e.g. an event-only record): blank cells.
void append_csv_vector(std::string& out, const VectorXd& v, int size, const char* what,
                       std::size_t row) {
  if (v.size() != 0 && v.size() != size)
    throw std::logic_error("trajectory_csv: sample " + std::to_string(row) + " has " + what +
                           " of size " + std::to_string(v.size()) + ", expected " +
                           std::to_string(size));
  for (int j = 0; j < size; ++j) {
    out += ',';
    if (v.size() != 0) append_number(out, v(j), kCsvDigits);
  }
}

int friction_count(const mech::Model& model) {
  return model.is_mechanical() ? static_cast<int>(model.mechanical->friction.size()) : 0;
}

bool friction_3d(const mech::Model& model) {
  return model.is_mechanical() && model.mechanical->has_friction_3d();
}

// The friction modes of a sample (nf cells, blank when it records none).
void append_csv_friction_modes(std::string& out, const sim::Sample& s, int nf, std::size_t r) {
  const std::size_t size = s.friction_mode.size();
  if (size != 0 && size != static_cast<std::size_t>(nf))
    throw std::logic_error("trajectory_csv: sample " + std::to_string(r) + " has " +
                           std::to_string(size) + " friction modes, expected " +
                           std::to_string(nf));
  for (std::size_t j = 0; j < static_cast<std::size_t>(nf); ++j) {
    out += ',';
    if (size == 0) continue;
    if (s.friction_facet.size() == size)
      out += sim::friction_mode_text(s.friction_mode[j], s.friction_facet[j]);
    else
      out += sim::to_string(s.friction_mode[j]);
  }
}

// The outputs z = output_x x + output_u u of an LCS model (blank cells when
// the model has pairs and the sample records no u); nothing for a model
// without outputs.
void append_csv_outputs(std::string& out, const sim::Sample& s, const CsvOutputs& o) {
  if (o.names == 0) return;
  if (s.u.size() == 0 && o.u.cols() > 0) {
    out.append(static_cast<std::size_t>(o.names), ',');
    return;
  }
  const auto c = static_cast<std::size_t>(s.configuration);
  const Eigen::MatrixXd& ox = c < o.config_x.size() ? o.config_x[c] : o.x;
  const Eigen::MatrixXd& ou = c < o.config_u.size() ? o.config_u[c] : o.u;
  const VectorXd z = ou.cols() > 0 ? VectorXd(ox * s.x + ou * s.u) : VectorXd(ox * s.x);
  for (Eigen::Index j = 0; j < z.size(); ++j) {
    out += ',';
    append_number(out, z(j), kCsvDigits);
  }
}

CsvOutputs csv_outputs(const mech::Model& model) {
  CsvOutputs o{static_cast<int>(model.output_names.size()), model.output_x, model.output_u, {}, {}};
  for (const mech::Model::Configuration& c : model.configurations) {
    o.config_x.push_back(c.output_x);
    o.config_u.push_back(c.output_u);
  }
  return o;
}

// Row `r` of the CSV: t, x, u, y, the outputs (LCS models that have them),
// the tangential multipliers and friction modes (nf of each, models with
// friction only; the multipliers along the second tangents when `cone`, the
// model has 3-D friction), mode.
void append_csv_row(std::string& out, const sim::Sample& s, int n, int k, int nf, bool cone,
                    std::size_t r, const CsvOutputs& outputs) {
  if (s.x.size() != n)
    throw std::logic_error("trajectory_csv: sample " + std::to_string(r) + " has a state of size " +
                           std::to_string(s.x.size()) + ", expected " + std::to_string(n));
  append_number(out, s.t, kCsvDigits);
  append_csv_vector(out, s.x, n, "x", r);
  append_csv_vector(out, s.u, k, "u", r);
  append_csv_vector(out, s.y, k, "y", r);
  append_csv_outputs(out, s, outputs);
  if (nf > 0) {
    append_csv_vector(out, s.u_t, nf, "u_t", r);
    if (cone) append_csv_vector(out, s.u_t2, nf, "u_t2", r);
    append_csv_friction_modes(out, s, nf, r);
  }
  out += ',';
  for (std::size_t j = 0; j < s.mode.size(); ++j)
    out += prefixed(j ? ";" : "", std::to_string(s.mode[j]));
  out += '\n';
}

}  // namespace

void write_file_atomic(const std::filesystem::path& path, const std::string& content) {
  TemporaryFile t = temporary_beside(path);
  const int err =
      finish_temporary(t, path.string(), write_all(t.fd, content.data(), content.size()));
  if (err != 0) cannot_write(path.string(), err);
}

std::string trajectory_csv(const mech::Model& model, const sim::Trajectory& traj) {
  std::string out;
  append_csv_header(out, model);
  const int n = model.state_size(), k = model.num_constraints(), nf = friction_count(model);
  const CsvOutputs outputs = csv_outputs(model);
  for (std::size_t r = 0; r < traj.samples.size(); ++r)
    append_csv_row(out, traj.samples[r], n, k, nf, friction_3d(model), r, outputs);
  return out;
}

// ---- TrajectoryCsvWriter ----

TrajectoryCsvWriter::TrajectoryCsvWriter(const std::filesystem::path& path,
                                         const mech::Model& model)
    : path_(path.string()),
      n_(model.state_size()),
      k_(model.num_constraints()),
      nf_(friction_count(model)),
      cone_(friction_3d(model)),
      outputs_(csv_outputs(model)) {
  TemporaryFile t = temporary_beside(path);
  fd_ = t.fd;
  temporary_ = std::move(t.name);
  append_csv_header(buffer_, model);
}

TrajectoryCsvWriter::~TrajectoryCsvWriter() {
  if (fd_ < 0) return;
  ::close(fd_);
  ::unlink(temporary_.c_str());
  untrack_temporary_file(temporary_);
}

void TrajectoryCsvWriter::write(const sim::Sample& s) noexcept {
  if (fd_ < 0 || error_ != 0 || !logic_error_.empty()) return;
  try {
    append_csv_row(buffer_, s, n_, k_, nf_, cone_, rows_++, outputs_);
  } catch (const std::exception& e) {
    logic_error_ = e.what();
    return;
  }
  if (buffer_.size() >= kBufferBytes) flush();
}

void TrajectoryCsvWriter::flush() noexcept {
  if (error_ == 0) error_ = write_all(fd_, buffer_.data(), buffer_.size());
  buffer_.clear();
}

void TrajectoryCsvWriter::commit() {
  if (fd_ < 0) throw std::logic_error("TrajectoryCsvWriter::commit: called twice");
  if (!logic_error_.empty()) throw std::logic_error(logic_error_);
  flush();
  TemporaryFile t{fd_, temporary_};
  fd_ = -1;
  const int err = finish_temporary(t, path_, error_);
  if (err != 0) cannot_write(path_, err);
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
    if (!model.pair_names.empty()) {  // models without names keep their keys
      nlohmann::json names = nlohmann::json::array();
      for (int i : e.mode_after) names.push_back(model.pair_names[static_cast<std::size_t>(i)]);
      events.back()["mode_after_names"] = std::move(names);
    }
    if (friction_count(model) > 0) {  // frictionless models keep their keys
      events.back()["friction_impulse"] = to_json(e.friction_impulse);
      nlohmann::json modes = nlohmann::json::array();
      const auto& fa = e.friction_facet_after;
      for (std::size_t j = 0; j < e.friction_mode_after.size(); ++j)
        modes.push_back(fa.size() == e.friction_mode_after.size()
                            ? sim::friction_mode_text(e.friction_mode_after[j], fa[j])
                            : std::string(sim::to_string(e.friction_mode_after[j])));
      events.back()["friction_mode_after"] = std::move(modes);
      if (friction_3d(model))  // planar models keep their keys
        events.back()["friction_impulse2"] = to_json(e.friction_impulse2);
    }
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
  j["warnings"] = nlohmann::json::array();
  for (const auto& w : traj.warnings)
    j["warnings"].push_back(
        {{"kind", w.kind}, {"count", w.count}, {"first_t", w.first_t}, {"message", w.message}});
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
