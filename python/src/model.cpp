// lcsim.Model: a loaded model file or scene, or a model built from matrices.
#include <algorithm>
#include <cmath>
#include <lcsim/mech/mech.hpp>
#include <lcsim/scene/scene.hpp>
#include <limits>
#include <optional>
#include <string>

#include "bindings.hpp"

namespace lcsim::python {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using OptVector = std::optional<VectorXd>;

// A numpy array (dense) or a scipy.sparse matrix as the model's sparse storage.
mech::SparseMatrix to_sparse(const py::object& a) {
  const py::object issparse = py::module_::import("scipy.sparse").attr("issparse");
  if (issparse(a).cast<bool>()) return a.cast<mech::SparseMatrix>();
  return a.cast<MatrixXd>().sparseView();
}

// The library's check of a model built in code; InputError with its message.
ModelHandle checked(mech::Model model, const OptVector& initial, std::optional<double> t_end) {
  if (initial) model.initial = *initial;
  if (t_end) model.t_end = *t_end;
  if (auto p = mech::check_model(model))
    throw io::InputError("model '" + model.name + "': " + p->field + ": " + p->what);
  return std::make_shared<scene::LoadedModel>(
      scene::LoadedModel{std::move(model), std::nullopt, nullptr});
}

// One entry of Model.mechanical's `friction`: {contact: index or name,
// tangent, mu, velocity (optional)}; sizes, ranges and mu are checked by
// mech::check_model with the other fields.
mech::FrictionalContact frictional_contact(const py::handle& entry, std::size_t i,
                                           const mech::MechanicalModel& mm) {
  const std::string at = "friction[" + std::to_string(i) + "]";
  if (!py::isinstance<py::dict>(entry))
    throw io::InputError(at + ": expected a dict {contact, tangent, mu[, velocity]}");
  const auto d = py::reinterpret_borrow<py::dict>(entry);
  for (const char* key : {"contact", "mu"})
    if (!d.contains(key)) throw io::InputError(at + "." + key + ": missing");
  if (d.contains("tangent") == d.contains("tangents"))
    throw io::InputError(at + ": expected one of tangent (planar) or tangents (two rows, 3-D)");
  for (const auto& item : d) {
    const std::string key = py::str(item.first);
    if (key != "contact" && key != "tangent" && key != "tangents" && key != "d" && key != "mu" &&
        key != "velocity")
      throw io::InputError(
          at + "." + key +
          ": unknown key (expected contact, tangent or tangents, d, mu, velocity)");
  }
  if (d.contains("d") && !d.contains("tangents"))
    throw io::InputError(at + ".d: applies to an entry with tangents (a planar contact is d = 1)");
  mech::FrictionalContact c;
  const py::object contact = d["contact"];
  if (py::isinstance<py::str>(contact)) {
    const std::string name = contact.cast<std::string>();
    const auto it = std::find(mm.constraints.begin(), mm.constraints.end(), name);
    if (it == mm.constraints.end())
      throw io::InputError(at + ".contact: no constraint named '" + name + "'");
    c.contact = static_cast<int>(it - mm.constraints.begin());
  } else {
    c.contact = contact.cast<int>();
  }
  if (d.contains("tangent")) {
    c.tangent = d["tangent"].cast<VectorXd>().sparseView();
  } else {  // the two rows of a 3-D contact (issue 27), checked by mech::check_model
    const auto rows = d["tangents"].cast<std::vector<VectorXd>>();
    if (rows.size() != 2)
      throw io::InputError(at + ".tangents: expected two tangent rows (got " +
                           std::to_string(rows.size()) + ")");
    if (rows[1].size() == 0) throw io::InputError(at + ".tangents[1]: empty");
    c.tangent = rows[0].sparseView();
    c.tangent2 = rows[1].sparseView();
    if (d.contains("d")) {
      c.edges = d["d"].cast<int>();
      if (c.edges < 1)
        throw io::InputError(at + ".d: must be >= 1 (got " + std::to_string(c.edges) + ")");
    }
  }
  c.mu = d["mu"].cast<double>();
  if (d.contains("velocity")) c.velocity = d["velocity"].cast<double>();
  return c;
}

ModelHandle make_mechanical(const py::object& M, const py::object& K, const py::object& E,
                            const py::object& D, const OptVector& f, const OptVector& g,
                            const OptVector& restitution, std::vector<std::string> names,
                            std::vector<std::string> constraint_names, const std::string& name,
                            const OptVector& initial, std::optional<double> t_end,
                            const py::object& friction) {
  mech::MechanicalModel mm;
  mm.M = to_sparse(M);
  if (!K.is_none()) mm.K = to_sparse(K);
  if (!E.is_none()) mm.E = to_sparse(E);
  if (!D.is_none()) mm.D = to_sparse(D);
  if (f) mm.f = *f;
  if (g) mm.g = *g;
  if (restitution) mm.restitution = *restitution;
  mm.coordinates = std::move(names);
  mm.constraints = std::move(constraint_names);
  mech::fill_defaults(mm);
  if (!friction.is_none()) {
    std::size_t i = 0;
    for (const py::handle& entry : friction)
      mm.friction.push_back(frictional_contact(entry, i++, mm));
  }
  mech::Model model = mech::model_of(std::move(mm), name);
  return checked(std::move(model), initial, t_end);
}

ModelHandle make_lcs(const MatrixXd& A, const MatrixXd& B, const MatrixXd& C, const MatrixXd& D,
                     const std::string& name, const OptVector& initial,
                     std::optional<double> t_end) {
  mech::Model model;
  model.name = name;
  model.lcs = lcs::Lcs{A, B, C, D};
  return checked(std::move(model), initial, t_end);
}

ModelHandle load(const std::filesystem::path& path) {
  return std::make_shared<scene::LoadedModel>(scene::load_model_and_scene(path));
}

const mech::MechanicalModel& mechanical(const scene::LoadedModel& m) {
  if (!m.model.is_mechanical())
    throw io::InputError("model '" + m.model.name + "': not a mechanical model (an `lcs:` model)");
  return *m.model.mechanical;
}

using ModelClass = py::class_<scene::LoadedModel, ModelHandle>;

// Model.mechanical and Model.lcs: models from matrices.
void def_constructors(ModelClass& c) {
  c.def_static("mechanical", &make_mechanical, py::arg("M"), py::arg("K") = py::none(),
               py::arg("E") = py::none(), py::arg("D") = py::none(), py::arg("f") = py::none(),
               py::arg("g") = py::none(), py::arg("restitution") = py::none(),
               py::arg("names") = std::vector<std::string>{},
               py::arg("constraint_names") = std::vector<std::string>{}, py::arg("name") = "model",
               py::arg("initial") = py::none(), py::arg("t_end") = py::none(),
               py::arg("friction") = py::none(),
               R"(A mechanical model from matrices (numpy arrays or scipy.sparse matrices).
Omitted D, K, f, g and restitution are zero; names default to q1.., constraint names to c1...
`initial` is a default state (q then v), `t_end` a default horizon (s).
`friction` lists frictional contacts as dicts {contact: 0-based row of E or its name,
tangent: N numbers, mu: >= 0, velocity: the surface's velocity along the tangent
(optional, 0)}, or for a 3-D contact {contact, tangents: [t, t2], mu, d (optional, 4)},
as the YAML `friction:` list (docs/model-format.md).
Raises InputError (the library's message) when sizes disagree, M is not symmetric
positive definite, a restitution lies outside [0, 1], ...)");
  c.def_static("lcs", &make_lcs, py::arg("A"), py::arg("B"), py::arg("C"), py::arg("D"),
               py::arg("name") = "lcs", py::arg("initial") = py::none(),
               py::arg("t_end") = py::none(),
               "A general LCS x' = A x + B u, y = C x + D u, 0 <= y _|_ u >= 0 (numpy arrays). "
               "Raises InputError when the library refuses it.");
}

// What every model has: name, source, kind, sizes, defaults.
void def_properties(ModelClass& c) {
  c.def_property_readonly(
      "name", [](const scene::LoadedModel& l) { return l.model.name; }, "The model's name.");
  c.def_property_readonly(
      "source", [](const scene::LoadedModel& l) { return l.model.source; },
      "The file it was loaded from ('' if built in code).");
  c.def_property_readonly(
      "is_mechanical", [](const scene::LoadedModel& l) { return l.model.is_mechanical(); },
      "True for a mechanical model, False for a general LCS.");
  c.def_property_readonly(
      "is_scene", [](const scene::LoadedModel& l) { return l.scene.has_value(); },
      "True when loaded from a URDF scene.");
  c.def_property_readonly(
      "state_size", [](const scene::LoadedModel& l) { return l.model.state_size(); },
      "Size of the state: 2N (q then v) for a mechanical model, n for an LCS.");
  c.def_property_readonly(
      "num_constraints", [](const scene::LoadedModel& l) { return l.model.num_constraints(); },
      "Number of complementarity pairs (constraints).");
  c.def_property_readonly(
      "dofs", [](const scene::LoadedModel& l) { return mechanical(l).dofs(); },
      "Number of coordinates N (mechanical models).");
  c.def_property_readonly(
      "initial",
      [](const scene::LoadedModel& l) -> std::optional<VectorXd> {
        if (l.model.initial.size() == 0) return std::nullopt;
        return l.model.initial;
      },
      "The default initial state, or None.");
  c.def_property_readonly(
      "t_end",
      [](const scene::LoadedModel& l) -> std::optional<double> {
        if (std::isnan(l.model.t_end)) return std::nullopt;
        return l.model.t_end;
      },
      "The default horizon (s), or None.");
}

// The matrices and names of a mechanical model.
void def_mechanical_fields(ModelClass& c) {
#define LCSIM_MECH_FIELD(field, doc) \
  c.def_property_readonly(           \
      #field, [](const scene::LoadedModel& l) { return mechanical(l).field; }, doc)
  LCSIM_MECH_FIELD(M, "Mass matrix (scipy.sparse).");
  LCSIM_MECH_FIELD(D, "Damping matrix (scipy.sparse).");
  LCSIM_MECH_FIELD(K, "Stiffness matrix (scipy.sparse).");
  LCSIM_MECH_FIELD(E, "Constraint rows, E q + g >= 0 (scipy.sparse).");
  LCSIM_MECH_FIELD(g, "Gaps at q = 0.");
  LCSIM_MECH_FIELD(f, "Constant generalised force.");
  LCSIM_MECH_FIELD(restitution, "Newton restitution coefficient per constraint.");
  LCSIM_MECH_FIELD(coordinates, "Coordinate names.");
  LCSIM_MECH_FIELD(constraints, "Constraint names.");
#undef LCSIM_MECH_FIELD
  c.def("__repr__", [](const scene::LoadedModel& l) {
    return "<lcsim.Model '" + l.model.name + "': " +
           (l.model.is_mechanical() ? std::to_string(l.model.mechanical->dofs()) + " coordinates"
                                    : std::to_string(l.model.state_size()) + " states (LCS)") +
           ", " + std::to_string(l.model.num_constraints()) + " constraints>";
  });
}

}  // namespace

void bind_model(py::module_& m) {
  ModelClass c(m, "Model", R"(A model: a mechanical model
M q'' + D q' + K q = f + E' u, 0 <= E q + g _|_ u >= 0 (with restitution per contact),
or a general LCS x' = A x + B u, y = C x + D u, 0 <= y _|_ u >= 0. Built by lcsim.load
(a YAML model or a URDF scene), Model.mechanical or Model.lcs; checked by the library.)");
  def_constructors(c);
  def_properties(c);
  def_mechanical_fields(c);
  m.def("load", &load, py::arg("path"),
        "Reads a YAML model file, a URDF scene or a SPICE netlist (.cir, .sp, .net; "
        "scene::load_model_and_scene). Raises InputError "
        "naming the file, the key and the value when it is invalid.");
}

}  // namespace lcsim::python
