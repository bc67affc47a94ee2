// lcsim.impacts, lcsim.impact_map, lcsim.solve_lcp, lcsim.analyze and
// lcsim.sweep: the library's impact laws, LCP solvers, model analysis and
// work-precision sweep, called as the CLI calls them.
#include <lcsim/app/analysis.hpp>
#include <lcsim/app/impact_map.hpp>
#include <lcsim/app/impacts.hpp>
#include <lcsim/app/sweep.hpp>
#include <lcsim/impact/impact.hpp>
#include <lcsim/lcp/lcp.hpp>
#include <lcsim/mech/mech.hpp>
#include <lcsim/scene/scene.hpp>
#include <map>
#include <optional>
#include <string>

#include "bindings.hpp"

namespace lcsim::python {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

const mech::MechanicalModel& mechanical(const ModelHandle& m, const std::string& what) {
  if (!m->model.is_mechanical())
    throw io::InputError("model '" + m->model.name + "': " + what +
                         " need a mechanical model (M, E), not `lcs:`");
  return *m->model.mechanical;
}

// app::impacts_at_state, keyed by each law's own name (sorted).
std::map<std::string, impact::ImpactResult> impacts(const ModelHandle& model,
                                                    std::optional<VectorXd> x0,
                                                    std::optional<std::vector<std::string>> rules,
                                                    std::optional<VectorXd> restitution) {
  app::ImpactsRequest request;
  if (x0) request.x0 = *x0;
  if (rules) request.rules = *rules;
  if (restitution) request.restitution = *restitution;
  app::ImpactsAtState r;
  {
    py::gil_scoped_release release;
    r = app::impacts_at_state(model->model, request);
  }
  return {r.results.begin(), r.results.end()};
}

lcp::Result solve_lcp(const MatrixXd& M, const VectorXd& q, const std::string& solver) {
  const auto s = lcp::make_solver(solver);
  lcp::Result r;
  {
    py::gil_scoped_release release;
    r = s->solve(M, q, lcp::Options{});
  }
  if (r.status == lcp::Status::kInvalidInput) throw io::InputError("LCP: " + r.message);
  return r;
}

// app::analysis_report's JSON, as `lcsim analyze --json` prints it, as a dict.
py::object analyze(const ModelHandle& model, bool full, double linearisation_threshold) {
  app::AnalysisOptions o;
  o.full = full;
  o.linearisation_threshold = linearisation_threshold;
  std::string json;
  {
    py::gil_scoped_release release;
    json = app::analysis_report(*model, o).json.dump();
  }
  return py::module_::import("json").attr("loads")(json);
}

std::string sweep(const ModelHandle& model, std::vector<std::string> methods,
                  std::vector<double> hs, std::optional<VectorXd> x0, std::optional<double> t_end,
                  std::optional<std::string> impact, std::optional<double> theta, int repeat,
                  std::vector<std::string> sensitivity) {
  app::SweepOptions o;
  o.base.sensitivity = std::move(sensitivity);
  o.methods = std::move(methods);
  o.hs = std::move(hs);
  o.repeat = repeat;
  o.base.t_end = t_end;
  if (!t_end && !std::isnan(model->model.t_end)) o.base.t_end = model->model.t_end;
  if (impact) o.base.impact = *impact;
  if (theta) o.base.theta = *theta;
  app::SweepResult r;
  {
    py::gil_scoped_release release;
    r = app::run_sweep(model->model, x0.value_or(model->model.initial), o);
  }
  return app::sweep_json(r).dump(2);
}

std::string impact_map_csv(const ModelHandle& model, std::pair<double, double> v1,
                           std::pair<double, double> v2, int n, std::optional<VectorXd> x0,
                           std::string law) {
  const mech::MechanicalModel& m = mechanical(model, "impact maps");
  app::ImpactMapSpec spec;
  const VectorXd x = x0.value_or(VectorXd::Zero(2 * m.dofs()));
  if (x.size() != 2 * m.dofs())
    throw io::InputError("x0: expected " + std::to_string(2 * m.dofs()) + " entries (got " +
                         std::to_string(x.size()) + ")");
  spec.q = x.head(m.dofs());
  spec.v0 = x.tail(m.dofs());
  spec.axis1 = {v1.first, v1.second, n};
  spec.axis2 = {v2.first, v2.second, n};
  spec.law = std::move(law);
  app::ImpactMap map;
  {
    py::gil_scoped_release release;
    map = app::impact_map(m, spec);
  }
  if (!map.failure.empty()) throw std::runtime_error("impact map: " + map.failure);
  return app::impact_map_csv(m, map);
}

void bind_results(py::module_& m) {
  py::class_<impact::ImpactResult> ir(m, "ImpactResult", "The outcome of one impact law.");
  ir.def_property_readonly("ok", &impact::ImpactResult::ok, "True when the law computed a result.");
  ir.def_property_readonly(
      "status",
      [](const impact::ImpactResult& r) { return std::string(lcsim::to_string(r.status)); },
      "'ok', 'invalid input' (the law refused its input) or 'numerical failure'.");
  ir.def_readonly("message", &impact::ImpactResult::message, "Why it failed, or a note.");
  ir.def_readonly("v_after", &impact::ImpactResult::v_after, "Post-impact velocity.");
  ir.def_readonly("impulse", &impact::ImpactResult::impulse, "Impulse per constraint.");
  ir.def_readonly("mode", &impact::ImpactResult::mode, "Constraints with positive impulse.");
  ir.def_readonly("energy_before", &impact::ImpactResult::energy_before, "Kinetic energy (J).");
  ir.def_readonly("energy_after", &impact::ImpactResult::energy_after, "Kinetic energy (J).");
  ir.def_readonly("worst_rate", &impact::ImpactResult::worst_rate,
                  "Most negative E_J v+ (0 if none).");
  ir.def_readonly("admissible", &impact::ImpactResult::admissible,
                  "False when the result is not an admissible impact.");
  ir.def_readonly("friction_impulse", &impact::ImpactResult::friction_impulse,
                  "Friction impulse per constraint along its (first) tangent (N s); empty "
                  "without friction.");
  ir.def_readonly("friction_impulse2", &impact::ImpactResult::friction_impulse2,
                  "Friction impulse per constraint along the second tangent of a 3-D contact "
                  "(N s); empty unless the model has one.");
  ir.def_property_readonly(
      "friction_outcome",
      [](const impact::ImpactResult& r) {
        std::vector<std::string> out;
        for (const auto o : r.outcome) out.emplace_back(impact::to_string(o));
        return out;
      },
      "Per constraint: 'none', 'no-impulse', 'stick', 'slip+', 'slip-' or 'slip' (3-D).");
  ir.def_property_readonly(
      "friction_mode",
      [](const impact::ImpactResult& r) {
        std::vector<std::string> out;
        for (size_t i = 0; i < r.facet.size(); ++i)
          out.push_back(impact::cone_mode_text(r.outcome[i], r.facet[i]));
        return out;
      },
      "Models with a 3-D contact, per constraint: 'open', 'stick', 'slip-edge-<i>' or "
      "'slip-face-<i>' (the cone's facet that holds the friction impulse); empty otherwise.");
  py::class_<lcp::Result> lr(m, "LcpResult", "The solution of an LCP w = M z + q.");
  lr.def_property_readonly(
      "status",
      [](const lcp::Result& r) { return std::string(lcp::to_string(r.status, "solved")); },
      "'solved', 'ray termination', 'iteration limit', 'numerical failure'.");
  lr.def_property_readonly("ok", &lcp::Result::ok, "True when solved.");
  lr.def_readonly("z", &lcp::Result::z, "The solution z.");
  lr.def_readonly("w", &lcp::Result::w, "w = M z + q.");
  lr.def_readonly("residual", &lcp::Result::residual, "||min(z, w)||_inf.");
  lr.def_readonly("pivots", &lcp::Result::pivots, "Pivots (pivoting solvers).");
  lr.def_readonly("iterations", &lcp::Result::iterations, "Sweeps (iterative solvers).");
  lr.def_readonly("message", &lcp::Result::message, "Detail, or ''.");
}

}  // namespace

void bind_tools(py::module_& m) {
  bind_results(m);
  m.def("impacts", &impacts, py::arg("model"), py::arg("x0") = py::none(),
        py::arg("rules") = py::none(), py::arg("restitution") = py::none(),
        "Applies each impact rule (default: all, lcsim.impact_law_names(); with friction, those "
        "that handle it) at the state x0 = (q, v) (default: the model's initial state); the "
        "closed contacts are those with zero gap at q (app::impacts_at_state, as `lcsim "
        "impacts`). Returns {rule: ImpactResult}, keyed by each law's own name (the alias "
        "'moreau' gives 'newton'). `restitution`: one coefficient per constraint "
        "(default: the model's).");
  m.def("solve_lcp", &solve_lcp, py::arg("M"), py::arg("q"), py::arg("solver") = "lemke",
        "Solves 0 <= z _|_ w = M z + q >= 0 with a solver of lcsim.solver_names(). Raises "
        "InputError for a malformed problem; a failure is the result's status.");
  m.def("analyze", &analyze, py::arg("model"), py::arg("full") = false,
        py::arg("linearisation_threshold") = scene::kLinearisationThreshold,
        "What the theory says of a model (app::analysis_report): sizes, M's eigenvalues, "
        "rank of E, the Delassus matrix and its P-property, the sets of constraints active "
        "together, the leading indices and Theorem 3.6.3, passivity, notes, a scene's linear "
        "ranges, what was not judged. The dict `lcsim analyze --json` prints, field for field; "
        "`full`: every matrix and set (default: a summary, naming what it left out in "
        "'left_out').");
  m.def("_sweep_json", &sweep, py::arg("model"), py::arg("methods"), py::arg("hs"),
        py::arg("x0") = py::none(), py::arg("t_end") = py::none(), py::arg("impact") = py::none(),
        py::arg("theta") = py::none(), py::arg("repeat") = 3,
        py::arg("sensitivity") = std::vector<std::string>{},
        "The work-precision sweep (app::run_sweep) as the JSON text `lcsim sweep --json` prints; "
        "`sensitivity` (as `--sensitivity`) adds each row's error_gradient.");
  m.def("_impact_map_csv", &impact_map_csv, py::arg("model"), py::arg("v1"), py::arg("v2"),
        py::arg("n") = 41, py::arg("x0") = py::none(), py::arg("law") = "newton",
        "The impact map of thesis Figure 3.5 (app::impact_map) as the CSV `lcsim impacts --map` "
        "prints.");
}

}  // namespace lcsim::python
