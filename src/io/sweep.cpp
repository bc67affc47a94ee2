// The work-precision sweep: reference laws, reference runs, rows (sweep.hpp).
#include <algorithm>
#include <cmath>
#include <deque>
#include <lcsim/impact/impact.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/io/sweep.hpp>
#include <limits>
#include <map>
#include <memory>

#include "io/detail.hpp"

namespace lcsim::io {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

bool has_restitution(const mech::Model& model) {
  return model.is_mechanical() && model.mechanical->restitution.size() > 0 &&
         model.mechanical->restitution.maxCoeff() > 0.0;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Largest max-abs state error of the run's samples against the reference's
// samples on the same grid (both sorted by time).
double max_sample_error(const sim::Trajectory& ts, const sim::Trajectory& exact, double h) {
  double worst = 0.0;
  size_t e = 0;
  for (const auto& s : ts.samples) {
    const double tol = 1e-9 * std::max(h, std::abs(s.t) * 1e-6);
    while (e < exact.samples.size() && exact.samples[e].t < s.t - tol) ++e;
    double best = kInf;
    for (size_t j = e; j < exact.samples.size() && exact.samples[j].t <= s.t + tol; ++j)
      best = std::min(best, (s.x - exact.samples[j].x).cwiseAbs().maxCoeff());
    if (std::isfinite(best)) worst = std::max(worst, best);
  }
  return worst;
}

// The status word of a run: a time-stepping guard's refusal ("euler:
// refused: ...", src/sim/time_stepping.cpp) is told apart from a failure.
std::string status_of(const sim::Trajectory& t) {
  if (t.status == sim::RunStatus::kCompleted) return "completed";
  return (t.message.find(": refused:") != std::string::npos ? "refused: " : "failed: ") + t.message;
}

void check_options(const SweepOptions& o) {
  if (o.methods.empty()) throw InputError("methods: empty list");
  for (const auto& m : o.methods) {
    try {
      (void)sim::make_integrator(m);
    } catch (const std::invalid_argument& e) {
      throw InputError(std::string("methods: ") + e.what());
    }
  }
  if (o.hs.empty()) throw InputError("h: empty list");
  for (double h : o.hs)
    if (!(h > 0.0) || !std::isfinite(h) || h > o.base.t_end.value_or(0.0))
      throw InputError("h: every step must be finite, > 0 and <= the horizon (got " +
                       format_number(h) + ")");
  if (o.repeat < 1) throw InputError("repeat: must be >= 1 (got " + std::to_string(o.repeat) + ")");
  if (!(o.base.theta >= 0.0 && o.base.theta <= 1.0))
    throw InputError("theta: must lie in [0, 1] (got " + format_number(o.base.theta) + ")");
  try {
    (void)impact::make_impact_law(o.base.impact);
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("impact: ") + e.what());
  }
  try {
    (void)lcp::make_solver(o.base.lcp_solver);
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("lcp solver: ") + e.what());
  }
}

// The exact runs of the sweep, one per distinct reference law, each sampled
// on the grids the rows ask for (cached by dt_out).
class References {
 public:
  References(const mech::Model& model, const Eigen::VectorXd& x0, const sim::Options& base)
      : model_(model), x0_(x0), base_(base) {}

  ReferenceRun& get(const ReferenceLaw& law) {
    for (auto& r : runs_)
      if (r.law == law) return r;
    ReferenceRun r;
    r.law = law;
    r.run = run_reference(model_, x0_, law, options(0.0));
    r.status = status_of(r.run);
    r.warnings = r.run.warning_count();
    r.first_warning = r.run.first_warning();
    runs_.push_back(std::move(r));
    return runs_.back();
  }
  // The reference sampled on the grid dt_out (the law's run must exist).
  const sim::Trajectory& on_grid(const ReferenceLaw& law, double dt_out) {
    size_t i = 0;
    while (!(runs_[i].law == law)) ++i;
    const auto key = std::make_pair(i, dt_out);
    auto it = grids_.find(key);
    if (it == grids_.end())
      it = grids_.emplace(key, run_reference(model_, x0_, law, options(dt_out))).first;
    return it->second;
  }
  std::vector<ReferenceRun> take() { return std::vector<ReferenceRun>(runs_.begin(), runs_.end()); }

 private:
  sim::Options options(double dt_out) const {
    sim::Options o = base_;
    o.dt_out = dt_out;
    o.progress = nullptr;
    return o;
  }
  const mech::Model& model_;
  Eigen::VectorXd x0_;
  sim::Options base_;
  std::deque<ReferenceRun> runs_;  // stable addresses
  std::map<std::pair<size_t, double>, sim::Trajectory> grids_;
};

double timed(const sim::Integrator& integ, const mech::Model& model, const Eigen::VectorXd& x0,
             sim::Options opt, int repeat) {
  opt.record_samples = false;
  opt.dt_out = 0.0;
  std::vector<double> times;
  opt = sim::keep_used(opt, integ.options_used());
  for (int r = 0; r < repeat; ++r) times.push_back(integ.run(model, x0, opt).wall_time_s);
  return median(times);
}

void fill_reference(SweepRow& row, const ReferenceRun& ref) {
  row.reference = ref.law;
  row.reference_warnings = ref.warnings;
  row.reference_first_warning = ref.first_warning;
}

SweepRow event_row(const sim::Integrator& integ, const mech::Model& model,
                   const Eigen::VectorXd& x0, const SweepOptions& o, const ReferenceRun& ref) {
  SweepRow r;
  r.method = "event";
  fill_reference(r, ref);
  r.status = ref.status;
  r.warnings = ref.warnings;
  r.first_warning = ref.first_warning;
  r.max_violation = ref.run.max_violation;
  r.steps = ref.run.steps;
  r.lcp_solves = ref.run.lcp_solves;
  if (ref.status == "completed")
    r.wall_time_s = timed(integ, model, x0, o.base, o.repeat);
  else
    r.error_final = r.error_max = kInf;
  return r;
}

SweepRow stepping_row(const std::string& method, const sim::Integrator& integ, double h,
                      const mech::Model& model, const Eigen::VectorXd& x0, const SweepOptions& o,
                      References& refs) {
  SweepRow r;
  r.method = method;
  r.h = h;
  const ReferenceLaw law = reference_law(method, o.base.impact, model);
  const ReferenceRun& ref = refs.get(law);
  fill_reference(r, ref);
  r.reference = law;  // the run may be shared with a method of another reason
  sim::Options opt = o.base;
  opt.h = h;
  // Comparison grid: a multiple of h, at most ~2000 points.
  opt.dt_out = std::max(1.0, std::round(o.base.t_end.value_or(model.t_end) / (2000.0 * h))) * h;
  const sim::Trajectory tr = integ.run(model, x0, sim::keep_used(opt, integ.options_used()));
  r.status = status_of(tr);
  r.warnings = tr.warning_count();
  r.first_warning = tr.first_warning();
  r.max_violation = tr.max_violation;
  r.steps = tr.steps;
  r.lcp_solves = tr.lcp_solves;
  r.error_final = r.error_max = kInf;
  if (tr.status != sim::RunStatus::kCompleted) return r;
  if (ref.status != "completed") {
    r.status = "failed: the exact reference (" + law.label() + ") failed: " + ref.run.message;
    return r;
  }
  const sim::Trajectory& grid = refs.on_grid(law, opt.dt_out);
  r.error_final = (tr.final_state - ref.run.final_state).cwiseAbs().maxCoeff();
  r.error_max = grid.status == sim::RunStatus::kCompleted ? max_sample_error(tr, grid, h) : kInf;
  r.error_max = std::max(r.error_max, r.error_final);
  r.energy_drift =
      (tr.energy_final - tr.energy_initial) - (ref.run.energy_final - ref.run.energy_initial);
  r.wall_time_s = timed(integ, model, x0, opt, o.repeat);
  return r;
}

nlohmann::json num(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(); }

nlohmann::json text_or_null(const std::string& s) {
  return s.empty() ? nlohmann::json() : nlohmann::json(s);
}

}  // namespace

std::string ReferenceLaw::label() const {
  if (lcs) return "exact (LCS)";
  return inelastic ? law + ", e = 0" : law;
}

ReferenceLaw reference_law(const std::string& method, const std::string& impact,
                           const mech::Model& model) {
  ReferenceLaw r;
  if (!model.is_mechanical()) {
    r.law = impact;
    r.lcs = true;
    r.reason =
        "LCS model: the exact event-driven run (re-initialisation by projection, no "
        "impact law)";
    return r;
  }
  const bool e = has_restitution(model);
  const std::string inelastic_note =
      e ? "" : " (no restitution in this model: every law is inelastic here)";
  if (method == "event") {
    r.law = impact;
    r.reason = "the exact run itself (impact law " + impact + ")";
  } else if (method == "moreau-jean") {
    r.law = "moreau-restitution";
    r.reason = "Moreau-Jean's own law: restitution inside its step LCP";
    if (impact != r.law) r.reason += " (impact law " + impact + " does not apply to it)";
  } else if (method == "euler") {
    r.law = "moreau";
    r.inelastic = e;
    r.reason =
        "backward Euler ignores restitution: nearest exact law is inelastic" + inelastic_note;
  } else if (method == "bullet") {
    r.law = "moreau";
    r.inelastic = e;
    r.reason =
        "Bullet 3.24's limits do not bounce (rigid-body limits at stop ERP 0.2, multibody "
        "joint limits at all; docs/bullet-comparison.md): nearest exact law is inelastic" +
        inelastic_note;
  } else {
    r.law = impact;
    r.reason = "assumed: the run's impact law";
  }
  return r;
}

sim::Trajectory run_reference(const mech::Model& model, const Eigen::VectorXd& x0,
                              const ReferenceLaw& law, sim::Options opt) {
  const auto event = sim::make_integrator("event");
  opt = sim::keep_used(opt, event->options_used());
  opt.impact = law.law;
  if (!law.inelastic) return event->run(model, x0, opt);
  mech::Model m = model;
  m.mechanical->restitution.setZero();
  return event->run(m, x0, opt);
}

bool SweepResult::reference_failed() const {
  return std::any_of(references.begin(), references.end(),
                     [](const ReferenceRun& r) { return r.status != "completed"; });
}

SweepResult run_sweep(const mech::Model& model, const Eigen::VectorXd& x0, const SweepOptions& o) {
  check_options(o);
  SweepResult out;
  out.model = model.name;
  out.t_end = o.base.t_end.value_or(model.t_end);
  out.impact = o.base.impact;
  References refs(model, x0, o.base);
  const size_t total = o.methods.size() * o.hs.size();
  size_t done = 0;
  for (const auto& method : o.methods) {
    const auto integ = sim::make_integrator(method);
    if (method == "event") {
      const ReferenceRun& ref = refs.get(reference_law("event", o.base.impact, model));
      out.rows.push_back(event_row(*integ, model, x0, o, ref));
      done += o.hs.size();
      if (o.progress)
        o.progress("[" + std::to_string(done) + "/" + std::to_string(total) + "] event done");
      continue;
    }
    for (double h : o.hs) {
      out.rows.push_back(stepping_row(method, *integ, h, model, x0, o, refs));
      ++done;
      const SweepRow& r = out.rows.back();
      if (o.progress)
        o.progress("[" + std::to_string(done) + "/" + std::to_string(total) + "] " + method +
                   " h = " + format_number(h) +
                   (r.status == "completed" ? "" : " (" + r.status + ")"));
    }
  }
  out.references = refs.take();
  return out;
}

nlohmann::json sweep_json(const SweepResult& r) {
  nlohmann::json j;
  j["model"] = r.model;
  j["t_end"] = r.t_end;
  j["impact"] = r.impact;
  j["references"] = nlohmann::json::array();
  for (const auto& ref : r.references)
    j["references"].push_back({{"law", ref.law.law},
                               {"inelastic", ref.law.inelastic},
                               {"label", ref.law.label()},
                               {"status", ref.status},
                               {"warnings", ref.warnings},
                               {"first_warning", text_or_null(ref.first_warning)}});
  j["rows"] = nlohmann::json::array();
  for (const auto& row : r.rows) {
    nlohmann::json o;
    o["method"] = row.method;
    o["h"] = row.method == "event" ? nlohmann::json() : nlohmann::json(row.h);
    o["status"] = row.status;
    o["reference_law"] = row.reference.label();
    o["reference_inelastic"] = row.reference.inelastic;
    o["reference_reason"] = row.reference.reason;
    o["error_final"] = num(row.error_final);
    o["error_max"] = num(row.error_max);
    o["max_violation"] = num(row.max_violation);
    o["energy_drift"] = num(row.energy_drift);
    o["steps"] = row.steps;
    o["lcp_solves"] = row.lcp_solves;
    o["wall_time_s"] = row.wall_time_s;
    o["warnings"] = row.warnings;
    o["first_warning"] = text_or_null(row.first_warning);
    o["reference_warnings"] = row.reference_warnings;
    o["reference_first_warning"] = text_or_null(row.reference_first_warning);
    j["rows"].push_back(std::move(o));
  }
  return j;
}

}  // namespace lcsim::io
