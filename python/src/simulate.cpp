// lcsim.simulate and lcsim.Trajectory: one run of the library
// (app::run_model, as `lcsim simulate`), its samples streamed into buffers
// that numpy then owns, so a long trajectory is stored once, never copied.
#include <cmath>
#include <cstdint>
#include <exception>
#include <lcsim/app/run.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <optional>
#include <string>

#include "bindings.hpp"

namespace lcsim::python {
namespace {

using Eigen::VectorXd;

constexpr std::int8_t kNoFrictionMode = -1;
constexpr std::int16_t kNoFacet = -1;

// A cone facet as Trajectory.friction_facets holds it: 2i for edge i, 2i + 1
// for the face between edges i and i + 1, -1 for none.
std::int16_t facet_code(impact::ConeFacet f) {
  return f.edge < 0 ? kNoFacet : static_cast<std::int16_t>(2 * f.edge + (f.face ? 1 : 0));
}
impact::ConeFacet facet_of_code(std::int16_t c) {
  return c < 0 ? impact::ConeFacet{} : impact::ConeFacet{c / 2, c % 2 == 1};
}

// Samples as they stream from the run (sim::Options::sample_sink), row
// after row, sized by the model (as the CSV is): a sample without u or y
// (an event-only record; blank cells in the CSV) gives a row of NaN.
struct SampleBuffers {
  std::vector<double> t, x, u, y, u_t;  // u_t: n x frictional contacts
  std::vector<std::uint8_t> active;     // n x k: 1 where the constraint is in the mode
  // n x frictional contacts: sim::FrictionMode's value, kNoFrictionMode where
  // the sample records none.
  std::vector<std::int8_t> friction_mode;
  // Models with 3-D friction (empty otherwise): n x frictional contacts, the
  // multipliers along the second tangents and the facets (facet_code).
  std::vector<double> u_t2;
  std::vector<std::int16_t> facet;
  // Forward sensitivities (Options::sensitivity): n x state x columns, and
  // n x columns with 1 where the column's derivative exists.
  std::vector<double> dx;
  std::vector<std::uint8_t> dx_ok;
  // A switched circuit's configuration per sample (sim::Sample::configuration,
  // for the CSV's outputs); empty for every other model.
  std::vector<int> configuration;
  bool switched = false;
  py::ssize_t nx = 0, k = 0, nf = 0, nc = 0, nf3 = 0;  // nf3: nf with 3-D friction, else 0
  explicit SampleBuffers(const mech::Model& m)
      : nx(m.state_size()),
        k(m.num_constraints()),
        nf(m.is_mechanical() ? static_cast<py::ssize_t>(m.mechanical->friction.size()) : 0),
        nf3(m.is_mechanical() && m.mechanical->has_friction_3d() ? nf : 0) {
    switched = !m.configurations.empty();
  }
  void reserve(std::size_t n) {
    const auto rows = [n](py::ssize_t w) { return n * static_cast<std::size_t>(w); };
    t.reserve(n);
    x.reserve(rows(nx));
    u.reserve(rows(k));
    y.reserve(rows(k));
    active.reserve(rows(k));
  }
  static void append(std::vector<double>& to, const VectorXd& v, py::ssize_t n) {
    if (v.size() == n)
      to.insert(to.end(), v.data(), v.data() + n);
    else
      to.insert(to.end(), static_cast<std::size_t>(n), std::nan(""));
  }
  void add(const sim::Sample& s) {
    t.push_back(s.t);
    if (switched) configuration.push_back(s.configuration);
    append(x, s.x, nx);
    append(u, s.u, k);
    append(y, s.y, k);
    if (nf > 0) {
      append(u_t, s.u_t, nf);
      for (py::ssize_t j = 0; j < nf; ++j)
        friction_mode.push_back(s.friction_mode.size() == static_cast<std::size_t>(nf)
                                    ? static_cast<std::int8_t>(s.friction_mode[j])
                                    : kNoFrictionMode);
    }
    if (nf3 > 0) {
      append(u_t2, s.u_t2, nf3);
      for (py::ssize_t j = 0; j < nf3; ++j)
        facet.push_back(s.friction_facet.size() == static_cast<std::size_t>(nf3)
                            ? facet_code(s.friction_facet[static_cast<std::size_t>(j)])
                            : kNoFacet);
    }
    if (s.dx.size() > 0) {
      nc = s.dx.cols();
      for (Eigen::Index r = 0; r < s.dx.rows(); ++r)
        for (Eigen::Index c = 0; c < s.dx.cols(); ++c) dx.push_back(s.dx(r, c));
      for (char ok : s.dx_exists) dx_ok.push_back(ok ? 1 : 0);
    }
    active.resize(t.size() * static_cast<std::size_t>(k), 0);
    for (int i : s.mode)
      if (i >= 0 && i < k) active[(t.size() - 1) * static_cast<std::size_t>(k) + i] = 1;
  }
};

// A finished run: the library's Trajectory (without samples) and the
// samples as numpy arrays (t: n, x: n x state, u and y: n x constraints).
struct Run {
  ModelHandle model;
  sim::Trajectory traj;
  // A scene's check of its linear model at the recorded states (app::run_model).
  std::optional<scene::LinearisationCheck> linearisation;
  py::array_t<double> t, x, u, y;
  py::array_t<double> u_t;                  // tangential multipliers, n x frictional contacts
  py::array_t<std::int8_t> friction_modes;  // n x frictional contacts (SampleBuffers)
  py::array_t<double> u_t2;                 // n x frictional contacts (3-D), else n x 0
  py::array_t<std::int16_t> facets;         // n x frictional contacts (3-D; facet_code)
  py::array modes;                          // bool, n x k
  py::array_t<double> dx;                   // n x state x columns (SampleBuffers)
  py::array_t<std::uint8_t> dx_ok;          // n x columns
  std::vector<int> configuration;           // SampleBuffers::configuration

  // The run as the library gives it, samples included (for the writers).
  sim::Sample sample(py::ssize_t i) const {
    sim::Sample s;
    s.t = t.at(i);
    auto row = [i](const py::array_t<double>& a) {
      const py::ssize_t n = a.shape(1);
      return VectorXd(Eigen::Map<const VectorXd>(a.data() + i * n, n));
    };
    // A row of NaN in u or y: the sample recorded none (blank cells).
    auto recorded = [](VectorXd v) { return v.array().isNaN().all() ? VectorXd() : v; };
    s.x = row(x), s.u = recorded(row(u)), s.y = recorded(row(y));
    if (static_cast<std::size_t>(i) < configuration.size())
      s.configuration = configuration[static_cast<std::size_t>(i)];
    if (u_t.shape(1) > 0) s.u_t = recorded(row(u_t));
    const py::ssize_t nf = friction_modes.shape(1);
    if (nf > 0 && friction_modes.at(i, 0) != kNoFrictionMode)
      for (py::ssize_t j = 0; j < nf; ++j)
        s.friction_mode.push_back(static_cast<sim::FrictionMode>(friction_modes.at(i, j)));
    if (u_t2.shape(1) > 0) {
      s.u_t2 = recorded(row(u_t2));
      for (py::ssize_t j = 0; j < facets.shape(1); ++j)
        s.friction_facet.push_back(facet_of_code(facets.at(i, j)));
    }
    const py::ssize_t k = modes.shape(1);
    const auto* on = static_cast<const std::uint8_t*>(modes.data()) + i * k;
    for (py::ssize_t j = 0; j < k; ++j)
      if (on[j]) s.mode.push_back(static_cast<int>(j));
    return s;
  }
  sim::Trajectory with_samples() const {
    sim::Trajectory tr = traj;
    for (py::ssize_t i = 0; i < t.shape(0); ++i) tr.samples.push_back(sample(i));
    return tr;
  }
  // What the CLI's `simulate --json` prints (app::run_json).
  std::string json_text() const {
    return app::run_json(model->model, traj, linearisation).dump(2) + "\n";
  }
};

std::shared_ptr<Run> simulate(const ModelHandle& model, const std::optional<VectorXd>& x0,
                              std::optional<double> t_end, const std::string& method,
                              std::optional<double> h, std::optional<double> theta,
                              std::optional<std::string> impact, double dt_out,
                              std::optional<std::string> lcp_solver, bool force,
                              std::optional<double> max_output, const py::object& progress,
                              const std::vector<std::string>& sensitivity) {
  app::RunRequest req;
  req.method = method;
  req.x0 = x0;                                    // unset: the model's
  if (x0) req.x0 = model->model.full_state(*x0);  // a circuit's sources are the model's
  sim::Options& opt = req.options;
  opt.t_end = t_end;
  opt.dt_out = dt_out;
  if (h) opt.h = *h;
  if (theta) opt.theta = *theta;
  if (impact) opt.impact = *impact;
  if (lcp_solver) opt.lcp_solver = *lcp_solver;
  if (max_output) opt.max_output_bytes = *max_output;
  opt.force = force;
  opt.sensitivity = sensitivity;
  SampleBuffers buf(model->model);
  // Room for the output grid's samples (plus a few for events), so that a
  // run's buffers are allocated once rather than grown: up to 64 MB, beyond
  // that they grow (the run itself refuses output above max_output_bytes).
  const double horizon = t_end.value_or(model->model.t_end);
  const double row_bytes =
      8.0 * (1 + model->model.state_size() + 2 * model->model.num_constraints());
  if (dt_out > 0.0 && horizon > 0.0 && horizon / dt_out * row_bytes < 64e6)
    buf.reserve(static_cast<std::size_t>(horizon / dt_out) + 16);
  req.sample_sink = [&buf](const sim::Sample& s) { buf.add(s); };
  std::exception_ptr progress_error;
  if (!progress.is_none())
    opt.progress = [&progress, &progress_error](double t) {
      if (progress_error) return;
      py::gil_scoped_acquire gil;
      try {
        progress(t);
      } catch (...) {
        progress_error = std::current_exception();
      }
    };
  auto run = std::make_shared<Run>();
  run->model = model;
  {
    py::gil_scoped_release release;
    app::ModelRun r = app::run_model(*model, req);
    run->traj = std::move(r.trajectory);
    run->linearisation = std::move(r.linearisation);
  }
  if (progress_error) std::rethrow_exception(progress_error);
  if (run->traj.status == sim::RunStatus::kInvalidInput) throw io::InputError(run->traj.message);
  const auto n = static_cast<py::ssize_t>(buf.t.size());
  run->t = numpy_owning(std::move(buf.t), {n});
  run->x = numpy_owning(std::move(buf.x), {n, buf.nx});
  run->u = numpy_owning(std::move(buf.u), {n, buf.k});
  run->y = numpy_owning(std::move(buf.y), {n, buf.k});
  run->u_t = numpy_owning(std::move(buf.u_t), {n, buf.nf});
  run->friction_modes = numpy_owning(std::move(buf.friction_mode), {n, buf.nf});
  run->u_t2 = numpy_owning(std::move(buf.u_t2), {n, buf.nf3});
  run->facets = numpy_owning(std::move(buf.facet), {n, buf.nf3});
  run->configuration = std::move(buf.configuration);
  run->modes =
      numpy_owning(std::move(buf.active), {n, buf.k}).attr("view")("bool").cast<py::array>();
  const py::ssize_t nc = static_cast<py::ssize_t>(run->traj.sensitivity_columns.size());
  // Every sample carries dx when sensitivities were computed (else none).
  const bool have = nc > 0 && buf.dx.size() == static_cast<std::size_t>(n * buf.nx * nc) &&
                    buf.dx_ok.size() == static_cast<std::size_t>(n * nc);
  if (!have) buf.dx.clear(), buf.dx_ok.clear();
  const py::ssize_t rows = have ? n : 0;
  run->dx = numpy_owning(std::move(buf.dx), {rows, buf.nx, nc});
  run->dx_ok = numpy_owning(std::move(buf.dx_ok), {rows, nc});
  return run;
}

void bind_event(py::module_& m) {
  py::class_<sim::Event> e(
      m, "Event", "An event of a run: an impact, a contact, a release, a stick, a slip, ...");
  e.def_readonly("t", &sim::Event::t, "Time (s).");
  e.def_property_readonly(
      "type", [](const sim::Event& ev) { return std::string(sim::to_string(ev.type)); },
      "'impact', 'release', 'contact', 'accumulation', 'start', 'stick' or 'slip'.");
  e.def_readonly("state_before", &sim::Event::state_before, "State before the event.");
  e.def_readonly("state_after", &sim::Event::state_after, "State after the event.");
  e.def_readonly("impulse", &sim::Event::impulse, "Impulse per constraint (zero if no jump).");
  e.def_readonly("mode", &sim::Event::mode_after, "Active constraints after (0-based).");
  e.def_readonly("note", &sim::Event::note, "How the event was resolved when not plain.");
  e.def_readonly("friction_impulse", &sim::Event::friction_impulse,
                 "Tangential impulse per frictional contact (model order; empty without "
                 "friction).");
  e.def_readonly("friction_impulse2", &sim::Event::friction_impulse2,
                 "Impulse along the second tangent per frictional contact (model order, N s; "
                 "empty without 3-D friction).");
  e.def_property_readonly(
      "friction_modes",
      [](const sim::Event& ev) {
        std::vector<std::string> out;
        const auto& fa = ev.friction_facet_after;
        for (std::size_t j = 0; j < ev.friction_mode_after.size(); ++j)
          out.push_back(fa.size() == ev.friction_mode_after.size()
                            ? sim::friction_mode_text(ev.friction_mode_after[j], fa[j])
                            : std::string(sim::to_string(ev.friction_mode_after[j])));
        return out;
      },
      "Mode per frictional contact after the event: 'open', 'stick', 'slip+', 'slip-', or for "
      "a 3-D contact 'slip-edge-<i>' / 'slip-face-<i>' ('slip' where the facet is unknown).");
  e.def_property_readonly(
      "dt",
      [](const sim::Event& ev) {
        py::list out;
        for (Eigen::Index c = 0; c < ev.dt.size(); ++c)
          out.append(ev.dt_exists[static_cast<std::size_t>(c)] ? py::cast(ev.dt(c)) : py::none());
        return out;
      },
      "d t_event / d column of Trajectory.sensitivity_columns (s per unit), None where it "
      "does not exist; empty without sensitivities.");
  e.def("__repr__", [](const sim::Event& ev) {
    return "<lcsim.Event " + std::string(sim::to_string(ev.type)) +
           " at t = " + std::to_string(ev.t) + ">";
  });
}

using RunClass = py::class_<Run, std::shared_ptr<Run>>;

// Trajectory's samples: numpy arrays, one row per sample.
void bind_samples(RunClass& r) {
  r.def_readonly("t", &Run::t, "Sample times (s), shape (n,).");
  r.def_readonly("u_t", &Run::u_t,
                 "Tangential multipliers of the frictional contacts (model order), shape "
                 "(n, contacts); NaN where a sample records none.");
  r.def_readonly(
      "friction_modes", &Run::friction_modes,
      "Modes of the frictional contacts (model order), shape (n, contacts), int8: 0 "
      "open, 1 stick, 2 slip+, 3 slip-, 4 slip (3-D) (lcsim.FRICTION_MODES); -1 where the method "
      "does not determine them.");
  r.def_readonly("u_t2", &Run::u_t2,
                 "Multipliers along the second tangents (N, model order), shape (n, contacts) "
                 "for a model with 3-D friction (0 for a planar entry), (n, 0) otherwise; NaN "
                 "where a sample records none.");
  r.def_readonly("friction_facets", &Run::facets,
                 "The cone facet of each sliding 3-D contact, shape as u_t2, int16: 2i for "
                 "edge i, 2i + 1 for the face between edges i and i + 1, -1 for none.");
  r.def_property_readonly(
      "friction_mode_names",
      [](const Run& run) {
        py::list rows;
        const py::ssize_t n = run.friction_modes.shape(0), nf = run.friction_modes.shape(1);
        const bool cone = run.facets.shape(1) == nf && nf > 0;
        for (py::ssize_t i = 0; i < n; ++i) {
          py::list row;
          for (py::ssize_t j = 0; j < nf; ++j) {
            const std::int8_t m = run.friction_modes.at(i, j);
            if (m == kNoFrictionMode) {
              row.append(py::none());
              continue;
            }
            const impact::ConeFacet f =
                cone ? facet_of_code(run.facets.at(i, j)) : impact::ConeFacet{};
            row.append(sim::friction_mode_text(static_cast<sim::FrictionMode>(m), f));
          }
          rows.append(std::move(row));
        }
        return rows;
      },
      "The modes as the CSV's fm_ columns write them, one list per sample: 'open', 'stick', "
      "'slip+', 'slip-', 'slip-edge-<i>', 'slip-face-<i>' (None where not determined).");
  r.def_readonly("x", &Run::x, "States, shape (n, state size): q then v for mechanical models.");
  r.def_readonly("u", &Run::u,
                 "Multipliers (regular part), shape (n, constraints); NaN where not recorded.");
  r.def_readonly("y", &Run::y, "Gaps / outputs, shape (n, constraints); NaN where not recorded.");
  r.def_readonly("modes", &Run::modes,
                 "Modes, shape (n, constraints), bool: True where a constraint is active.");
}

// Column c of the sensitivities as a masked array (masked where it does not
// exist): shape (n, state) for one column, (n, state, count) for `count`.
py::object masked_columns(const Run& run, py::ssize_t c, py::ssize_t count, bool squeeze) {
  py::object np = py::module_::import("numpy");
  py::slice cols(c, c + count, 1);
  py::object data = run.dx[py::make_tuple(py::ellipsis(), cols)];
  py::object ok = run.dx_ok[py::make_tuple(py::slice(0, run.dx_ok.shape(0), 1), py::none(), cols)];
  py::object mask = np.attr("broadcast_to")(np.attr("logical_not")(ok), data.attr("shape"));
  py::object out = py::module_::import("numpy.ma")
                       .attr("masked_array")(data, py::arg("mask") = mask.attr("copy")());
  return squeeze ? out[py::make_tuple(py::ellipsis(), 0)] : out;
}

// Forward sensitivities (simulate(..., sensitivity=[...])).
void bind_sensitivities(RunClass& r) {
  r.def_property_readonly(
      "sensitivity_columns", [](const Run& run) { return run.traj.sensitivity_columns; },
      "The sensitivity columns: x0[i] per initial-state entry, then the parameters asked.");
  r.def_property_readonly(
      "dx_dx0",
      [](const Run& run) -> py::object {
        const auto& cols = run.traj.sensitivity_columns;
        if (cols.empty() || cols.front() != "x0[0]") return py::none();
        return masked_columns(run, 0, run.x.shape(1), false);
      },
      "dx(t)/dx0 at each sample, numpy.ma masked array of shape (n, state, state) "
      "(sample, entry of x, entry of x0), masked where the derivative does not exist; "
      "None unless 'x0' was asked.");
  r.def_property_readonly(
      "dx_dp",
      [](const Run& run) {
        py::dict out;
        const auto& cols = run.traj.sensitivity_columns;
        for (std::size_t c = 0; c < cols.size(); ++c)
          if (cols[c].rfind("x0[", 0) != 0)
            out[py::str(cols[c])] = masked_columns(run, static_cast<py::ssize_t>(c), 1, true);
        return out;
      },
      "dx(t)/dp per parameter asked (its name as asked, 'e[stop]'): numpy.ma masked arrays "
      "of shape (n, state), masked where the derivative does not exist.");
  r.def_property_readonly(
      "sensitivity_losses",
      [](const Run& run) {
        py::list out;
        for (const auto& l : run.traj.sensitivity_losses) {
          py::list cols;
          for (int c : l.columns)
            cols.append(run.traj.sensitivity_columns[static_cast<std::size_t>(c)]);
          out.append(py::dict(py::arg("t") = l.t, py::arg("contact") = l.contact,
                              py::arg("reason") = l.reason, py::arg("columns") = cols));
        }
        return out;
      },
      "Where derivatives stop existing: dicts with t, contact, reason and the columns ended.");
}

// Trajectory's events, status and diagnostics: the library's sim::Trajectory.
void bind_summary(RunClass& r) {
  r.def_property_readonly(
      "events", [](const Run& run) { return run.traj.events; }, "The recorded events.");
  r.def_property_readonly(
      "final_state", [](const Run& run) { return run.traj.final_state; }, "State at t_end.");
  r.def_property_readonly(
      "status",
      [](const Run& run) { return std::string(lcsim::to_string(run.traj.status, "completed")); },
      "'completed', 'numerical failure', 'event limit' or 'interrupted'.");
  r.def_property_readonly(
      "ok", [](const Run& run) { return run.traj.status == sim::RunStatus::kCompleted; },
      "True when the run completed.");
  r.def_property_readonly(
      "message", [](const Run& run) { return run.traj.message; }, "Why the run failed, or ''.");
  r.def_property_readonly(
      "method", [](const Run& run) { return run.traj.method; }, "The integrator.");
  r.def_property_readonly(
      "impact_law", [](const Run& run) { return run.traj.impact_law; }, "The impact law applied.");
  r.def_property_readonly(
      "t_end", [](const Run& run) { return run.traj.t_end; }, "The time reached (s).");
  r.def_property_readonly(
      "energy_initial", [](const Run& run) { return run.traj.energy_initial; },
      "Total energy at the start (J, mechanical models).");
  r.def_property_readonly(
      "energy_final", [](const Run& run) { return run.traj.energy_final; },
      "Total energy at the end (J, mechanical models).");
  r.def_property_readonly(
      "max_violation", [](const Run& run) { return run.traj.max_violation; },
      "Most negative gap over the run (0 if none).");
  r.def_property_readonly(
      "lcp_solves", [](const Run& run) { return run.traj.lcp_solves; }, "LCPs solved.");
  r.def_property_readonly(
      "steps", [](const Run& run) { return run.traj.steps; }, "Steps or continuous phases.");
  r.def_property_readonly(
      "warnings",
      [](const Run& run) {
        py::list out;
        for (const auto& w : run.traj.warnings)
          out.append(py::dict(py::arg("kind") = w.kind, py::arg("count") = w.count,
                              py::arg("first_t") = w.first_t, py::arg("message") = w.message));
        return out;
      },
      "The warnings, one dict per kind in order of first appearance: kind, count, "
      "first_t (time of the first) and message (the first one's).");
  r.def_property_readonly(
      "warning_count", [](const Run& run) { return run.traj.warning_count(); },
      "Warnings counted, all kinds.");
  r.def_property_readonly(
      "events_not_recorded", [](const Run& run) { return run.traj.events_not_recorded; },
      "Events past the recording cap (counted, not kept).");
  r.def_property_readonly(
      "wall_time_s", [](const Run& run) { return run.traj.wall_time_s; }, "Wall time (s).");
  r.def_property_readonly(
      "model", [](const Run& run) { return run.model; }, "The model that was run.");
}

// Trajectory's writers: what the CLI's `simulate --out` and `--json` write.
void bind_writers(RunClass& r) {
  r.def(
      "to_csv",
      [](const Run& run, std::optional<std::filesystem::path> path) -> std::optional<std::string> {
        if (!path) return io::trajectory_csv(run.model->model, run.with_samples());
        io::TrajectoryCsvWriter w(*path, run.model->model);  // what `simulate --out` writes
        for (py::ssize_t i = 0; i < run.t.shape(0); ++i) w.write(run.sample(i));
        w.commit();
        return std::nullopt;
      },
      py::arg("path") = py::none(),
      "The samples as the CLI's `simulate --out` writes them (io layer): to `path` "
      "(atomically), or returned as text when no path is given.");
  r.def(
      "to_json",
      [](const Run& run, std::optional<std::filesystem::path> path) -> std::optional<std::string> {
        if (!path) return run.json_text();
        io::write_file_atomic(*path, run.json_text());
        return std::nullopt;
      },
      py::arg("path") = py::none(),
      "The run summary as the CLI's `simulate --json` prints it (io::trajectory_json): "
      "written to `path`, or returned as text.");
}

}  // namespace

void bind_simulate(py::module_& m) {
  bind_event(m);
  RunClass r(m, "Trajectory", R"(The result of lcsim.simulate.
Samples as numpy arrays (t, x, u, y; q and v are views of x for mechanical models;
at a jump two samples share t), events, status and diagnostics. A numerical failure
is a status ('numerical failure', 'event limit', ...) with a message, not an exception.)");
  bind_samples(r);
  bind_summary(r);
  bind_writers(r);
  bind_sensitivities(r);
  m.def("simulate", &simulate, py::arg("model"), py::arg("x0") = py::none(),
        py::arg("t_end") = py::none(), py::arg("method") = "event", py::arg("h") = py::none(),
        py::arg("theta") = py::none(), py::arg("impact") = py::none(), py::arg("dt_out") = 0.0,
        py::arg("lcp_solver") = py::none(), py::arg("force") = false,
        py::arg("max_output") = py::none(), py::arg("progress") = py::none(),
        py::arg("sensitivity") = std::vector<std::string>{},
        R"(Simulates `model` from x0 (default: the model's initial state) to t_end (default:
the model's) with `method` (lcsim.integrator_names()). Unset options keep the library's
defaults; an option the method does not read is refused. dt_out is the output grid (0:
events, start and end only). `progress(t)` is called as the run goes. The GIL is
released during the run. Raises InputError for invalid input; numerical trouble is
the returned trajectory's status. `sensitivity` (method 'event'): 'x0' and parameter
names ('f[1]', 'e[stop]', docs/sensitivities.md) give run.dx_dx0 and run.dx_dp.)");
}

}  // namespace lcsim::python
