// The one check of a run's input (sim::check_run): whatever calls an
// integrator — the CLI, the Python module, a study, a user's program — goes
// through Integrator::run and so through this.
#include <algorithm>
#include <cmath>
#include <lcsim/core/format.hpp>
#include <lcsim/impact/impact.hpp>
#include <lcsim/lcp/lcp.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>

namespace lcsim::sim {

namespace {

// Calls f(used, &Options::member, "member") for every option that some
// method does not read (the groups of OptionsUsed).
template <class F>
void visit_method_options(const OptionsUsed& u, F&& f) {
  f(u.h, &Options::h, "h");
  f(u.theta, &Options::theta, "theta");
  f(u.impact, &Options::impact, "impact");
  f(u.lcp_solver, &Options::lcp_solver, "lcp_solver");
  f(u.event_search, &Options::event_time_tol, "event_time_tol");
  f(u.event_search, &Options::max_events_per_unit_time, "max_events_per_unit_time");
  f(u.event_search, &Options::max_events, "max_events");
  f(u.event_search, &Options::livelock_events, "livelock_events");
  f(u.event_search, &Options::accumulation_dt, "accumulation_dt");
  f(u.event_search, &Options::accumulation_tail, "accumulation_tail");
  f(u.force, &Options::force, "force");
  f(u.linear_algebra, &Options::sparse_dofs_threshold, "sparse_dofs_threshold");
  f(u.linear_algebra, &Options::pivot_max_active, "pivot_max_active");
}

// "" when every option the method does not read is at its default.
std::string ignored_options(const Options& opt, std::string_view method, const OptionsUsed& u) {
  const Options defaults{};
  std::string message;
  visit_method_options(u, [&](bool used, auto member, const char* name) {
    if (used || !message.empty() || opt.*member == defaults.*member) return;
    message = "method '" + std::string(method) + "' does not use Options::" + name + " (got " +
              to_text(opt.*member) + "); leave it at its default (" + to_text(defaults.*member) +
              ")";
  });
  return message;
}

bool finite_positive(double x) { return std::isfinite(x) && x > 0.0; }

std::string check_values(const Options& opt, const OptionsUsed& u) {
  const auto f = short_number;
  const double T = *opt.t_end;
  if (!finite_positive(T)) return "t_end must be a finite number > 0 (got " + f(T) + ")";
  if (!(std::isfinite(opt.dt_out) && opt.dt_out >= 0.0))
    return "dt_out must be a finite number >= 0 (got " + f(opt.dt_out) + ")";
  if (!(opt.max_output_bytes > 0.0))
    return "max_output_bytes must be > 0 (got " + f(opt.max_output_bytes) + ")";
  if (u.h) {
    if (!finite_positive(opt.h)) return "step h must be a finite number > 0 (got " + f(opt.h) + ")";
    if (opt.h > T) return "step h = " + f(opt.h) + " exceeds t_end = " + f(T);
    if (T / opt.h > 1e9) return "t_end / h = " + f(T / opt.h) + " steps is more than 1e9 (raise h)";
  }
  if (u.theta && !(opt.theta > 0.0 && opt.theta <= 1.0))
    return "theta must lie in (0, 1] (got " + f(opt.theta) + ")";
  if (u.impact && !impact::laws().contains(opt.impact))
    return impact::laws().unknown_message(opt.impact);
  if (u.lcp_solver && !lcp::solvers().contains(opt.lcp_solver))
    return lcp::solvers().unknown_message(opt.lcp_solver);
  if (u.event_search) {
    if (!(std::isfinite(opt.event_time_tol) && opt.event_time_tol >= 0.0))
      return "event_time_tol must be a finite number >= 0 (got " + f(opt.event_time_tol) + ")";
    if (!(opt.max_events_per_unit_time > 0.0))
      return "max_events_per_unit_time must be > 0 (got " + f(opt.max_events_per_unit_time) + ")";
    if (opt.max_events < 1) return "max_events must be >= 1 (got " + f(opt.max_events) + ")";
    if (opt.max_recorded_events < 0)
      return "max_recorded_events must be >= 0 (got " + f(opt.max_recorded_events) + ")";
    if (opt.livelock_events < 2)
      return "livelock_events must be >= 2 (got " + std::to_string(opt.livelock_events) + ")";
    if (!(std::isfinite(opt.accumulation_dt) && opt.accumulation_dt >= 0.0))
      return "accumulation_dt must be a finite number >= 0 (got " + f(opt.accumulation_dt) + ")";
    if (!(std::isfinite(opt.accumulation_tail) && opt.accumulation_tail >= 0.0))
      return "accumulation_tail must be a finite number >= 0 (got " + f(opt.accumulation_tail) +
             ")";
  }
  if (u.linear_algebra && (opt.sparse_dofs_threshold < 0 || opt.pivot_max_active < 0))
    return "sparse_dofs_threshold and pivot_max_active must be >= 0 (got " +
           std::to_string(opt.sparse_dofs_threshold) + ", " + std::to_string(opt.pivot_max_active) +
           ")";
  return "";
}

// Samples a run records: on the dt_out grid, else every step of h; the
// event-driven method without a grid records events only, bounded by
// max_recorded_events. Each is costed as its CSV row, about 25 bytes per
// number (17 significant digits, sign, exponent, separator), which is more
// than the 8 bytes per number it takes in memory.
std::string check_output_size(const mech::Model& model, const Options& opt, const OptionsUsed& u) {
  if (!opt.record_samples && !opt.sample_sink) return "";
  double samples = 0.0;
  const char* knob = "dt_out";
  if (opt.dt_out > 0.0)
    samples = *opt.t_end / opt.dt_out + 2.0;
  else if (u.h) {
    samples = *opt.t_end / opt.h + 1.0;
    knob = "dt_out (or h)";
  } else
    return "";
  const double numbers =
      1.0 + model.state_size() + 2.0 * model.num_constraints() +
      (model.is_mechanical() ? static_cast<double>(model.mechanical->friction.size()) : 0.0);
  const double bytes = samples * numbers * 25.0;
  if (bytes <= opt.max_output_bytes) return "";
  return "the recorded output would be about " + short_number(bytes) + " bytes (" +
         short_number(samples) + " samples of " + short_number(numbers) +
         " numbers), more than max_output_bytes = " + short_number(opt.max_output_bytes) +
         ": raise " + knob + ", or max_output_bytes";
}

// The methods that would take this model and state in a run of default
// options (their own checks and refusal included: Bullet and MuJoCo take
// friction at a URDF scene's contacts only), quoted and joined, those with
// `takes` in their OptionsUsed.
std::string methods_taking(const mech::Model& model, const VectorXd& x0, bool OptionsUsed::*takes) {
  Options probe;
  probe.t_end = std::isfinite(model.t_end) ? model.t_end : 1.0;
  std::string with;
  for (const std::string& name : integrators().names())
    if (auto integ = integrators().make(name);
        integ && integ->options_used().*takes && !integ->refuse(model, x0, probe))
      with += (with.empty() ? "'" : ", '") + name + "'";
  return with;
}

// A model with friction and a method that would ignore it: refused, naming
// the methods that would take it (methods_taking).
std::string refuse_friction(const mech::Model& model, const VectorXd& x0, std::string_view method,
                            const OptionsUsed& used) {
  if (used.friction || !model.is_mechanical() || !model.mechanical->has_friction()) return "";
  const std::string with = methods_taking(model, x0, &OptionsUsed::friction);
  return "method '" + std::string(method) + "' does not support friction (model '" + model.name +
         "' has " + std::to_string(model.mechanical->friction.size()) + " frictional contact" +
         (model.mechanical->friction.size() == 1 ? "" : "s") + " in mechanical.friction); " +
         (with.empty() ? std::string("no other method takes this model and state")
                       : "use method " + with);
}

// A model with 3-D friction (two tangents) and a method that handles planar
// friction only: refused, naming the methods that would take it.
std::string refuse_friction_3d(const mech::Model& model, const VectorXd& x0,
                               std::string_view method, const OptionsUsed& used) {
  if (used.friction_3d || !model.is_mechanical() || !model.mechanical->has_friction_3d()) return "";
  const auto& fr = model.mechanical->friction;
  const auto it = std::find_if(fr.begin(), fr.end(),
                               [](const mech::FrictionalContact& c) { return c.is_3d(); });
  const std::string with = methods_taking(model, x0, &OptionsUsed::friction_3d);
  return "method '" + std::string(method) + "' does not yet handle 3-D friction (model '" +
         model.name + "' has two tangents at mechanical.friction[" +
         std::to_string(it - fr.begin()) + "]); " +
         (with.empty() ? std::string("no other method takes this model and state")
                       : "method " + with + " does");
}

// A method that needs D and K symmetric (OptionsUsed::symmetric_dk) and a
// model whose D or K is not (gyroscopic damping, a follower force).
std::string refuse_asymmetric(const mech::Model& model, std::string_view method,
                              const OptionsUsed& used) {
  if (!used.symmetric_dk || !model.is_mechanical()) return "";
  std::string why = mech::asymmetry(model.mechanical->D, "D");
  if (why.empty()) why = mech::asymmetry(model.mechanical->K, "K");
  if (why.empty()) return "";
  return "method '" + std::string(method) +
         "' needs symmetric D and K (it factors M + h theta D + " +
         "h^2 theta^2 K by Cholesky), and model '" + model.name + "' has " + why +
         "; methods 'event' and 'euler' take it";
}

// A method that applies an impact law to a model with friction: the law must
// handle friction, else the run would fail at its first impact.
std::string refuse_friction_law(const mech::Model& model, const Options& opt,
                                const OptionsUsed& used) {
  if (!used.impact || !model.is_mechanical() || !model.mechanical->has_friction()) return "";
  if (impact::make_impact_law(opt.impact)->handles_friction()) return "";
  std::string with;
  for (const std::string& name : impact::laws().names())
    if (auto law = impact::laws().make(name); law && law->handles_friction())
      with += (with.empty() ? "'" : ", '") + name + "'";
  return "impact law '" + opt.impact + "' does not handle friction (model '" + model.name +
         "' has mechanical.friction); use impact law " + with;
}

// A switched model's schedule as mech::Model states it, or what is wrong
// (a caller may build one by hand): one configuration index per interval,
// each in range and of the model's dimensions, times increasing, one note
// per time.
std::string switched_structure(const mech::Model& model) {
  const std::size_t n = model.switch_times.size();
  const auto where = [&] { return text("model '", model.name, "': "); };
  if (model.switch_config.size() != n + 1 || model.switch_notes.size() != n)
    return text(where(), "switch_config has ", model.switch_config.size(),
                " entries and switch_notes ", model.switch_notes.size(), " for ", n,
                " switch_times (one more, and as many, are needed)");
  if (!model.lcs) return text(where(), "switch_times on a model without an LCS (`lcs:`)");
  const lcs::Lcs& base = *model.lcs;
  for (std::size_t i = 0; i <= n; ++i) {
    const int c = model.switch_config[i];
    if (c < 0 || static_cast<std::size_t>(c) >= model.configurations.size())
      return text(where(), "switch_config[", i, "] = ", c, " is not one of the ",
                  model.configurations.size(), " configurations");
    const lcs::Lcs& l = model.configurations[static_cast<std::size_t>(c)].lcs;
    if (l.A.rows() != base.A.rows() || l.B.cols() != base.B.cols())
      return text(where(), "configuration ", c, " has ", l.A.rows(), " states and ", l.B.cols(),
                  " pairs, the model ", base.A.rows(), " and ", base.B.cols());
    if (i > 0 && i < n && !(model.switch_times[i] > model.switch_times[i - 1]))
      return text(where(), "switch_times[", i, "] = ", model.switch_times[i],
                  " does not follow switch_times[", i - 1, "] = ", model.switch_times[i - 1]);
  }
  return "";
}

}  // namespace

// A model with inputs (docs/inputs.md) needs a method that evaluates them;
// a moving stop (gap_inputs) is the exact method's only.
std::string refuse_inputs(const mech::Model& model, const Options& opt, std::string_view method,
                          const OptionsUsed& used) {
  // A switched circuit (mech::Model::configurations): the exact method swaps
  // its matrices at the switch times, known up to switch_horizon; the
  // time-stepping methods and the sensitivities do not follow the swaps.
  if (model.is_switched()) {
    if (std::string why = switched_structure(model); !why.empty()) return why;
    if (!used.event_search)
      return text("method '", method, "' does not simulate switched circuits (model '", model.name,
                  "' has ideal switches); method 'event' does");
    if (!opt.sensitivity.empty())
      return text("sensitivities are not supported through switch times (model '", model.name,
                  "' has ideal switches)");
    if (*opt.t_end > model.switch_horizon)
      return text("t_end = ", *opt.t_end, " s is beyond the switch schedule of model '", model.name,
                  "', known up to .tran's tstop = ", model.switch_horizon, " s");
  }
  // An `lcs:` model's inputs (a circuit's PULSE, PWL or delayed SIN sources):
  // their exosystems are re-initialised at the breakpoints by the exact
  // method's scheduled events; the time-stepping methods would integrate the
  // exosystem across a breakpoint, so they refuse.
  if (!model.is_mechanical() && !model.inputs.empty()) {
    if (!used.inputs || !used.event_search)
      return text("method '", method, "' does not simulate inputs with breakpoints (model '",
                  model.name, "' has ", model.inputs.size(),
                  ": PULSE, PWL or delayed SIN sources); method 'event' does");
    return "";
  }
  if (!model.is_mechanical() || !model.mechanical->has_inputs()) return "";
  const mech::MechanicalModel& m = *model.mechanical;
  if (!used.inputs)
    return text("method '", method, "' does not evaluate inputs (model '", model.name, "' has ",
                m.inputs.size(), " in `inputs:`); methods 'event', 'euler' and 'moreau-jean' do");
  // Moving stops: the exact method only (the one method that searches
  // events: it locates each impact on the moving stop), without friction.
  if (!m.gap_inputs.empty() && !used.event_search)
    return text("method '", method, "' does not simulate mechanical.gap_inputs (a moving stop; ",
                "model '", model.name, "'); method 'event' does");
  if (!m.gap_inputs.empty() && m.has_friction())
    return text("model '", model.name,
                "': mechanical.gap_inputs (a moving stop) with friction is not simulated yet");
  // Sensitivities: the schemes' step maps take force inputs as the step's
  // known forcing (step_sensitivity.cpp); the exact method's go through the
  // scheduled events (docs/sensitivities.md).
  return "";
}

Options keep_used(const Options& opt, const OptionsUsed& used) {
  Options out = opt;
  const Options defaults{};
  visit_method_options(used, [&](bool u, auto member, const char*) {
    if (!u) out.*member = defaults.*member;
  });
  if (!used.sensitivity) out.sensitivity.clear();
  return out;
}

std::string check_run(const mech::Model& model, const VectorXd& x0, const Options& opt,
                      std::string_view method, const OptionsUsed& used) {
  if (auto p = mech::check_model(model))
    return "model '" + model.name + "': " + p->field + ": " + p->what;
  const long n = model.state_size();
  if (x0.size() != n)
    return "initial state: expected " + std::to_string(n) + " entries (the model's state size) " +
           "(got " + std::to_string(x0.size()) + ")";
  for (Eigen::Index i = 0; i < x0.size(); ++i)
    if (!std::isfinite(x0(i)))
      return "initial state[" + std::to_string(i) + "]: not finite (got " + short_number(x0(i)) +
             ")";
  if (used.needs_mechanical && !model.is_mechanical())
    return "method '" + std::string(method) + "' needs a mechanical model ('" + model.name +
           "' is a general LCS; the methods 'event' and 'euler' take one)";
  // 3-D first: a planar refusal would name methods that refuse 3-D friction too.
  if (std::string m = refuse_friction_3d(model, x0, method, used); !m.empty()) return m;
  if (std::string m = refuse_friction(model, x0, method, used); !m.empty()) return m;
  if (std::string m = refuse_asymmetric(model, method, used); !m.empty()) return m;
  if (used.dense_lcs && model.lcs_state_size() > mech::kMaxDenseLcsState)
    return "method '" + std::string(method) +
           "' works on the dense LCS (matrix exponentials and LCPs of size n = 2N + 1), and " +
           "model '" + model.name + "' has size " + std::to_string(model.lcs_state_size()) +
           ", more than the " + std::to_string(mech::kMaxDenseLcsState) +
           " it allows; method 'moreau-jean' works on the sparse model";
  if (!opt.t_end) return "no horizon: set Options::t_end, or t_end in the model";
  if (std::string m = check_values(opt, used); !m.empty()) return m;
  if (std::string m = refuse_friction_law(model, opt, used); !m.empty()) return m;
  if (std::string m = refuse_inputs(model, opt, method, used); !m.empty()) return m;
  if (std::string m = ignored_options(opt, method, used); !m.empty()) return m;
  if (std::string m = check_sensitivity(model, opt, method, used); !m.empty()) return m;
  if (std::string m = infeasible_start(model, x0); !m.empty()) return m;
  return check_output_size(model, opt, used);
}

}  // namespace lcsim::sim
