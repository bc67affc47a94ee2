// One run of a study and its row (run.hpp).
#include <array>
#include <chrono>
#include <lcsim/core/format.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/io/text.hpp>
#include <lcsim/sim/reference.hpp>
#include <lcsim/study/run.hpp>

namespace lcsim::study {

namespace {

using K = Quantity::Kind;

// The model, x0, method and options of one run.
struct Setup {
  mech::Model model;
  Eigen::VectorXd x0;
  std::string method;
  sim::Options opt;
};

void scale(mech::MechanicalModel& m, const Quantity& q, double v) {
  if (q.matrix == "f" || q.matrix == "g") {
    Eigen::VectorXd& x = q.matrix == "f" ? m.f : m.g;
    if (q.row < 0)
      x *= v;
    else
      x(q.row) *= v;
    return;
  }
  mech::SparseMatrix& a = q.matrix == "M" ? m.M : q.matrix == "D" ? m.D : m.K;
  if (q.row < 0) {
    a *= v;
    return;
  }
  a.coeffRef(q.row, q.col) *= v;
  if (q.row != q.col) a.coeffRef(q.col, q.row) *= v;  // the mirror: symmetry kept
}

// The point's quantities applied in order to the study's defaults.
Setup setup_of(const Study& s, const RunPoint& p) {
  std::vector<const Quantity*> qs;
  for (const auto& a : s.axes)
    for (const auto& q : a.quantities) qs.push_back(&q);
  std::size_t model = 0;
  for (std::size_t i = 0; i < qs.size(); ++i)
    if (qs[i]->kind == K::kModel) model = static_cast<std::size_t>(p.values[i].number);
  Setup u{s.models[model], s.models[model].initial, s.method, s.base};
  const int n = u.model.state_size();
  for (std::size_t i = 0; i < qs.size(); ++i) {
    const Quantity& q = *qs[i];
    const double v = p.values[i].number;
    if ((q.kind == K::kX0 || q.kind == K::kV0) && u.x0.size() != n) u.x0 = Eigen::VectorXd::Zero(n);
    switch (q.kind) {
      case K::kModel:
        break;
      case K::kMethod:
        u.method = p.values[i].name;
        break;
      case K::kImpact:
        u.opt.impact = p.values[i].name;
        break;
      case K::kH:
        u.opt.h = v;
        break;
      case K::kTheta:
        u.opt.theta = v;
        break;
      case K::kTEnd:
        u.opt.t_end = v;
        break;
      case K::kX0:
        u.x0(q.row) = v;
        break;
      case K::kV0:
        u.x0(n / 2 + q.row) = v;
        break;
      case K::kRestitution:
        u.model.mechanical->restitution(q.row) = v;
        break;
      case K::kMu:  // a value < 0 is the run's invalid input (mech::check_model)
        for (mech::FrictionalContact& c : u.model.mechanical->friction)
          if (c.contact == q.row) c.mu = v;
        break;
      case K::kScale:
        scale(*u.model.mechanical, q, v);
        break;
    }
  }
  u.opt.dt_out = 0.0;
  u.opt.record_samples = false;
  return u;
}

std::string status_word(const sim::Trajectory& t) {
  return std::string(to_string(t.status, "completed"));
}

// Final-state column names: a single model's state names as its trajectory
// CSV has them (io::state_names), else x1...
std::vector<std::string> state_names(const Study& s) {
  if (s.models.size() == 1) return io::state_names(s.models.front());
  std::vector<std::string> names;
  int n = 0;
  for (const auto& mm : s.models) n = std::max(n, mm.state_size());
  for (int i = 1; i <= n; ++i) names.push_back("x" + std::to_string(i));
  return names;
}

const std::array<std::pair<sim::EventType, const char*>, 4> kEventColumns = {
    {{sim::EventType::kImpact, "events_impact"},
     {sim::EventType::kRelease, "events_release"},
     {sim::EventType::kContact, "events_contact"},
     {sim::EventType::kAccumulation, "events_accumulation"}}};

void run_cells(std::vector<std::string>& c, const sim::Trajectory& t) {
  c.push_back(status_word(t));
  c.push_back(io::one_line(t.message));
  c.push_back(format_number(t.t_end));
  for (const auto& [type, name] : kEventColumns) {
    long count = 0;
    for (const auto& e : t.events) count += e.type == type;
    c.push_back(std::to_string(count));
  }
  c.push_back(std::to_string(t.events_not_recorded));
  const bool energy = t.status != sim::RunStatus::kInvalidInput;
  c.push_back(energy ? format_number(t.energy_final - t.energy_initial) : "");
  c.push_back(energy ? format_number(t.max_violation) : "");
  c.push_back(std::to_string(t.steps));
  c.push_back(std::to_string(t.lcp_solves));
  c.push_back(std::to_string(t.warning_count()));
}

// reference, reference_status, error_final; `completed` false when the
// reference failed.
void reference_cells(std::vector<std::string>& c, const Study& s, const Setup& u,
                     const sim::Trajectory& t, bool& completed) {
  if (s.reference == "none" || t.status == sim::RunStatus::kInvalidInput) {
    c.insert(c.end(), {"", "", ""});
    return;
  }
  const sim::ReferenceLaw law = sim::reference_law(u.method, u.opt.impact, u.model);
  c.push_back(law.label());
  // The exact method of its own law is its own reference.
  const bool itself = u.method == "event" && !law.inelastic;
  const sim::Trajectory ref =
      itself ? sim::Trajectory{} : sim::run_reference(u.model, u.x0, law, u.opt);
  const sim::Trajectory& r = itself ? t : ref;
  c.push_back(status_word(r));
  if (r.status != sim::RunStatus::kCompleted) completed = false;
  const bool both =
      t.status == sim::RunStatus::kCompleted && r.status == sim::RunStatus::kCompleted;
  c.push_back(both ? format_number((t.final_state - r.final_state).cwiseAbs().maxCoeff()) : "");
}

Row row_of(const Study& s, const RunPoint& p) {
  Row row;
  row.index = p.index;
  auto& c = row.cells;
  c.push_back(std::to_string(p.index));
  const std::vector<Column> cols = columns(s);
  for (std::size_t i = 0; i < p.values.size(); ++i)
    c.push_back(cols[1 + i].text ? p.values[i].name : format_number(p.values[i].number));
  const Setup u = setup_of(s, p);
  const auto integ = sim::make_integrator(u.method);
  const sim::Trajectory t = integ->run(u.model, u.x0, sim::keep_used(u.opt, integ->options_used()));
  row.completed = t.status == sim::RunStatus::kCompleted;
  run_cells(c, t);
  reference_cells(c, s, u, t, row.completed);
  const std::size_t n = state_names(s).size();
  for (std::size_t i = 0; i < n; ++i)
    c.push_back(static_cast<Eigen::Index>(i) < t.final_state.size() &&
                        t.status != sim::RunStatus::kInvalidInput
                    ? format_number(t.final_state(static_cast<Eigen::Index>(i)))
                    : "");
  return row;
}

}  // namespace

std::vector<Column> columns(const Study& s) {
  std::vector<Column> cols{{"index", false}};
  for (const auto& a : s.axes)
    for (const auto& q : a.quantities) cols.push_back({q.key, q.text() || q.kind == K::kModel});
  cols.insert(cols.end(), {{"status", true}, {"message", true}, {"t_reached", false}});
  for (const auto& [type, name] : kEventColumns) cols.push_back({name, false});
  for (const char* name :
       {"events_unrecorded", "energy_change", "max_violation", "steps", "lcp_solves", "warnings"})
    cols.push_back({name, false});
  cols.insert(cols.end(),
              {{"reference", true}, {"reference_status", true}, {"error_final", false}});
  for (const auto& n : state_names(s)) cols.push_back({"final_" + n, false});
  return cols;
}

Row run_one(const Study& s, std::size_t index) {
  const auto start = std::chrono::steady_clock::now();
  const RunPoint p = expand(s, index);
  Row row;
  try {
    row = row_of(s, p);
  } catch (const std::exception& e) {
    // Nothing the library throws for bad values should get here (runs
    // report through their status); if it does, the study goes on.
    row = Row{};
    row.index = index;
    row.cells.push_back(std::to_string(index));
    const std::vector<Column> cols = columns(s);
    for (std::size_t i = 0; i < p.values.size(); ++i)
      row.cells.push_back(cols[1 + i].text ? p.values[i].name : format_number(p.values[i].number));
    row.cells.push_back("error");
    row.cells.push_back(io::one_line(e.what()));
    row.cells.resize(cols.size());
  }
  row.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return row;
}

}  // namespace lcsim::study
