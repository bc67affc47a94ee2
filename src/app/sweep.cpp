// The work-precision sweep: reference laws, reference runs, rows (sweep.hpp).
#include <algorithm>
#include <cmath>
#include <deque>
#include <lcsim/app/run.hpp>
#include <lcsim/app/sweep.hpp>
#include <lcsim/impact/impact.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/io/text.hpp>
#include <lcsim/sim/reference.hpp>
#include <limits>
#include <map>
#include <memory>
#include <optional>

namespace lcsim::app {

using io::format_number;
using io::InputError;
using io::one_line;
using io::split;
using sim::reference_law;
using sim::ReferenceLaw;
using sim::run_reference;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Largest max-abs state error of the run's samples against the reference's
// samples on the same grid (both sorted by time).
double max_sample_error(const std::vector<sim::Sample>& run, const sim::Trajectory& exact,
                        double h) {
  double worst = 0.0;
  size_t e = 0;
  for (const auto& s : run) {
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
// refused: ...", src/sim/stepping/time_stepping.cpp) is told apart from a failure.
std::string status_of(const sim::Trajectory& t) {
  if (t.status == sim::RunStatus::kCompleted) return "completed";
  const bool refused = t.status == sim::RunStatus::kInvalidInput ||
                       t.message.find(": refused:") != std::string::npos;
  return (refused ? "refused: " : "failed: ") + t.message;
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

// The median wall time of `repeat` runs as a user runs them: with their
// output, the samples on the comparison grid opt.dt_out kept in memory
// (issue 24: a row timed without its samples showed 0.09 s for a run whose
// samples took 16 s).
double timed(const sim::Integrator& integ, const mech::Model& model, const Eigen::VectorXd& x0,
             const sim::Options& opt, int repeat) {
  std::vector<double> times;
  for (int r = 0; r < repeat; ++r) times.push_back(integ.run(model, x0, opt).wall_time_s);
  return median(times);
}

// A stepping run compared as it goes (Options::sample_sink, every step):
// its samples on the comparison grid are kept (for max_sample_error), and
// at each event of the exact run the run's state at the end of the step
// that holds it is compared with the exact state just before and just after
// the event, the nearer counting. That state is one step from the event, so
// the figure includes the O(h) localisation error of a step-h method: the
// method's own error at the event.
class StreamComparison {
 public:
  StreamComparison(const sim::Trajectory& exact, double dt_cmp, double h, double t_end)
      : exact_(exact), sampler_(dt_cmp), h_(h), t_end_(t_end) {}
  void operator()(const sim::Sample& s) {
    if (sampler_.want(s.t, h_, s.t >= t_end_)) grid_.push_back(s);
    const auto& ev = exact_.events;
    for (; next_ < ev.size() && ev[next_].t <= s.t; ++next_) {
      const sim::Event& e = ev[next_];
      if (e.state_before.size() != s.x.size() || e.state_after.size() != s.x.size()) continue;
      at_events_ = std::max(at_events_, std::min((s.x - e.state_before).cwiseAbs().maxCoeff(),
                                                 (s.x - e.state_after).cwiseAbs().maxCoeff()));
    }
  }
  const std::vector<sim::Sample>& grid() const { return grid_; }
  double at_events() const { return at_events_; }

 private:
  const sim::Trajectory& exact_;
  sim::OutputSampler sampler_;
  double h_, t_end_;
  std::vector<sim::Sample> grid_;
  std::size_t next_ = 0;
  double at_events_ = 0.0;
};

// Max-abs difference of the run's dx(T)/dtheta to the reference's: +inf
// when a column is absent in either (or the run computed none).
double gradient_error(const sim::Trajectory& run, const sim::Trajectory& ref) {
  if (run.dx_final.size() == 0 || run.dx_final.rows() != ref.dx_final.rows() ||
      run.dx_final.cols() != ref.dx_final.cols())
    return kInf;
  for (size_t c = 0; c < run.dx_final_exists.size(); ++c)
    if (!run.dx_final_exists[c] || !ref.dx_final_exists[c]) return kInf;
  return (run.dx_final - ref.dx_final).cwiseAbs().maxCoeff();
}

void fill_reference(SweepRow& row, const ReferenceRun& ref) {
  row.reference = ref.law;
  row.reference_warnings = ref.warnings;
  row.reference_first_warning = ref.first_warning;
}

SweepRow event_row(const sim::Integrator& integ, const mech::Model& model,
                   const Eigen::VectorXd& x0, const SweepOptions& o, const sim::Options& timing,
                   const ReferenceRun& ref) {
  SweepRow r;
  r.method = "event";
  fill_reference(r, ref);
  r.status = ref.status;
  r.warnings = ref.warnings;
  r.first_warning = ref.first_warning;
  r.max_violation = ref.run.max_violation;
  r.steps = ref.run.steps;
  r.lcp_solves = ref.run.lcp_solves;
  if (!o.base.sensitivity.empty()) r.error_gradient = gradient_error(ref.run, ref.run);  // 0 or inf
  if (ref.status == "completed")
    r.wall_time_s = timed(integ, model, x0, timing, o.repeat);
  else
    r.error_final = r.error_max = r.error_events = r.error_gradient = kInf;
  return r;
}

// What a row's error floor is when the run integrates other dynamics than
// the model (Trajectory::dynamics): "" when it integrates the model.
std::string error_floor(const sim::Trajectory& tr) {
  if (tr.dynamics.empty()) return "";
  return "the linearisation gap: this method integrates " + tr.dynamics +
         ", the exact run the model (its linearisation about q0), so the error does not fall "
         "below their difference as h shrinks";
}

SweepRow stepping_row(const std::string& method, const sim::Integrator& integ,
                      const sim::Options& timing, const mech::Model& model,
                      const Eigen::VectorXd& x0, const SweepOptions& o, References& refs) {
  SweepRow r;
  r.method = method;
  r.h = timing.h;
  const ReferenceLaw law = reference_law(method, o.base.impact, model);
  const ReferenceRun& ref = refs.get(law);
  fill_reference(r, ref);
  r.reference = law;  // the run may be shared with a method of another reason
  // The compared run: every step through the comparison, nothing kept but
  // the grid (so no output cap applies to it).
  StreamComparison cmp(ref.run, timing.dt_out, timing.h, *timing.t_end);
  sim::Options opt = timing;
  opt.dt_out = 0.0;
  opt.max_output_bytes = kInf;
  opt.sample_sink = [&cmp](const sim::Sample& s) { cmp(s); };
  const sim::Trajectory tr = integ.run(model, x0, opt);
  r.status = status_of(tr);
  r.warnings = tr.warning_count();
  r.first_warning = tr.first_warning();
  r.max_violation = tr.max_violation;
  r.steps = tr.steps;
  r.lcp_solves = tr.lcp_solves;
  r.error_floor = error_floor(tr);
  r.error_final = r.error_max = r.error_events = r.error_gradient = kInf;
  if (tr.status != sim::RunStatus::kCompleted) return r;
  if (ref.status != "completed") {
    r.status = "failed: the exact reference (" + law.label() + ") failed: " + ref.run.message;
    return r;
  }
  const sim::Trajectory& grid = refs.on_grid(law, timing.dt_out);
  r.error_final = (tr.final_state - ref.run.final_state).cwiseAbs().maxCoeff();
  r.error_events = cmp.at_events();
  r.error_max = grid.status == sim::RunStatus::kCompleted
                    ? max_sample_error(cmp.grid(), grid, timing.h)
                    : kInf;
  r.error_max = std::max({r.error_max, r.error_final, r.error_events});
  if (!o.base.sensitivity.empty()) r.error_gradient = gradient_error(tr, ref.run);
  r.energy_drift =
      (tr.energy_final - tr.energy_initial) - (ref.run.energy_final - ref.run.energy_initial);
  r.wall_time_s = timed(integ, model, x0, timing, o.repeat);
  return r;
}

// A row refused before anything ran (Integrator::refuse).
SweepRow refused_row(const std::string& method, double h, const sim::Trajectory& why,
                     const mech::Model& model, const SweepOptions& o) {
  SweepRow r;
  r.method = method;
  r.h = h;
  r.reference = reference_law(method, o.base.impact, model);
  r.status = status_of(why);
  r.error_final = r.error_max = r.error_events = r.error_gradient = kInf;
  return r;
}

// One row to run: its method, options (h and the comparison grid set, the
// options the method does not read at their defaults) and, when the method
// refuses them, why.
struct PlannedRow {
  std::string method;
  std::shared_ptr<const sim::Integrator> integ;
  sim::Options timing;
  std::optional<sim::Trajectory> refused;
};

// Every row of the sweep, each checked by its method before any runs
// (issue 24: a sweep that computed nine rows then stopped at a refused
// tenth left nothing). The event row is timed with samples on the finest
// comparison grid of the sweep, as the stepping rows are on theirs.
std::vector<PlannedRow> plan_rows(const mech::Model& model, const Eigen::VectorXd& x0,
                                  const SweepOptions& o, double t_end) {
  double finest = kInf;
  for (double h : o.hs) finest = std::min(finest, comparison_grid(t_end, h));
  std::vector<PlannedRow> rows;
  for (const auto& method : o.methods) {
    std::shared_ptr<const sim::Integrator> integ = sim::make_integrator(method);
    auto add = [&](double h, double dt_out) {
      PlannedRow p{method, integ, o.base, std::nullopt};
      p.timing.h = h;
      p.timing.dt_out = dt_out;
      p.timing.progress = nullptr;
      p.timing = sim::keep_used(p.timing, integ->options_used());
      p.refused = integ->refuse(model, x0, p.timing);
      if (!p.timing.t_end) p.timing.t_end = t_end;
      rows.push_back(std::move(p));
    };
    if (method == "event")
      add(sim::Options{}.h, finest);
    else
      for (double h : o.hs) add(h, comparison_grid(t_end, h));
  }
  return rows;
}

nlohmann::json text_or_null(const std::string& s) {
  return s.empty() ? nlohmann::json() : nlohmann::json(s);
}

}  // namespace

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
  out.sensitivity = o.base.sensitivity;
  const std::vector<PlannedRow> plan = plan_rows(model, x0, o, out.t_end);
  // Nothing to measure: the first refusal is the sweep's input error.
  if (std::all_of(plan.begin(), plan.end(), [](const PlannedRow& p) { return p.refused; }))
    throw InputError(plan.front().refused->message);
  References refs(model, x0, o.base);
  const std::string total = std::to_string(plan.size());
  for (std::size_t i = 0; i < plan.size(); ++i) {
    const PlannedRow& p = plan[i];
    const bool event = p.method == "event";
    if (p.refused)
      out.rows.push_back(refused_row(p.method, event ? 0.0 : p.timing.h, *p.refused, model, o));
    else if (event)
      out.rows.push_back(event_row(*p.integ, model, x0, o, p.timing,
                                   refs.get(reference_law("event", o.base.impact, model))));
    else
      out.rows.push_back(stepping_row(p.method, *p.integ, p.timing, model, x0, o, refs));
    const SweepRow& r = out.rows.back();
    if (o.progress)
      o.progress("[" + std::to_string(i + 1) + "/" + total + "] " + p.method +
                 (event ? "" : " h = " + format_number(p.timing.h)) +
                 (r.status == "completed" ? "" : " (" + r.status + ")"));
  }
  out.references = refs.take();
  return out;
}

nlohmann::json sweep_json(const SweepResult& r) {
  nlohmann::json j;
  j["model"] = r.model;
  j["t_end"] = r.t_end;
  j["impact"] = r.impact;
  j["error_measures"] = kErrorMeasures;
  if (!r.sensitivity.empty()) j["sensitivity"] = r.sensitivity;
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
    o["error_final"] = io::finite_or_null(row.error_final);
    o["error_max"] = io::finite_or_null(row.error_max);
    o["error_events"] = io::finite_or_null(row.error_events);
    if (!r.sensitivity.empty()) o["error_gradient"] = io::finite_or_null(row.error_gradient);
    o["error_floor"] = text_or_null(row.error_floor);
    o["max_violation"] = io::finite_or_null(row.max_violation);
    o["energy_drift"] = io::finite_or_null(row.energy_drift);
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

}  // namespace lcsim::app
