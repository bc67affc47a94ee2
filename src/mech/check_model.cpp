// The one check of a model built in code or read from a file: sizes that
// agree, finite entries, M symmetric positive definite, restitution in
// [0, 1], no all-zero constraint row. The loaders (src/io) report a problem
// with the file's name in front; a run (sim::check_run) with the model's.
#include <Eigen/SparseCholesky>
#include <cmath>
#include <cstdio>
#include <lcsim/core/format.hpp>
#include <lcsim/mech/mech.hpp>
#include <limits>
#include <string>
#include <vector>

namespace lcsim::mech {

namespace {

std::string dims(Eigen::Index r, Eigen::Index c) {
  return std::to_string(r) + " x " + std::to_string(c);
}

// The first non-finite entry of a sparse or dense matrix, as "[i][j] = v".
template <class Mat>
std::optional<std::string> non_finite(const Mat& A) {
  if constexpr (std::is_same_v<Mat, SparseMatrix>) {
    for (Eigen::Index j = 0; j < A.outerSize(); ++j)
      for (SparseMatrix::InnerIterator it(A, j); it; ++it)
        if (!std::isfinite(it.value()))
          return "[" + std::to_string(it.row()) + "][" + std::to_string(it.col()) +
                 "] = " + short_number(it.value());
  } else {
    for (Eigen::Index i = 0; i < A.rows(); ++i)
      for (Eigen::Index j = 0; j < A.cols(); ++j)
        if (!std::isfinite(A(i, j)))
          return "[" + std::to_string(i) + "][" + std::to_string(j) +
                 "] = " + short_number(A(i, j));
  }
  return std::nullopt;
}

std::optional<std::string> non_finite_vector(const VectorXd& v) {
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (!std::isfinite(v(i))) return "[" + std::to_string(i) + "] = " + short_number(v(i));
  return std::nullopt;
}

// Up to this many coordinates M is checked densely, with its eigenvalues in
// the message; above it by a sparse LDL' factorisation (O(nnz) for banded M),
// cheap enough for every run to repeat (Integrator::run checks the model).
constexpr Eigen::Index kDenseMassCheckMax = 64;

// A tangent row: length N, finite, not all zero. `key` is "tangent" or
// "tangents[1]" (the second tangent of a 3-D contact).
std::optional<ModelProblem> check_tangent(const Eigen::SparseVector<double>& t, Eigen::Index N,
                                          const std::string& at) {
  if (t.size() != N)
    return ModelProblem{at, "expected " + std::to_string(N) + " entries (N = " + std::to_string(N) +
                                " coordinates, from M) (got " + std::to_string(t.size()) + ")"};
  double largest = 0.0;
  for (Eigen::SparseVector<double>::InnerIterator it(t); it; ++it) {
    if (!std::isfinite(it.value()))
      return ModelProblem{at + "[" + std::to_string(it.index()) + "] = " + short_number(it.value()),
                          "not finite"};
    largest = std::max(largest, std::abs(it.value()));
  }
  if (!(largest > 0.0)) return ModelProblem{at, "all zero (it measures no sliding)"};
  return std::nullopt;
}

// The cosine of the angle between a and b (Euclidean); both non-zero.
double cosine(const Eigen::SparseVector<double>& a, const Eigen::SparseVector<double>& b) {
  return a.dot(b) / (a.norm() * b.norm());
}

// A three-dimensional contact (FrictionalContact::is_3d): t2 checked as t,
// d >= 0 (0: the model's default), no moving surface, and the normal row n,
// t and t2 pairwise orthogonal with |t| = |t2| (Euclidean, to
// kTangentOrthogonality): the cone's edges are at the angles pi i/d from t
// in the plane of t and t2, which are angles only in an orthonormal frame
// (up to a common scale, which scales mu as for a planar tangent). The
// Euclidean metric, not M^-1's: W_NT = n M^-1 t' = 0 would forbid the
// coupled contacts planar friction accepts (a rod's corner: sliding turns
// the rod and moves the normal), and it depends on the masses, not on the
// contact's geometry; for a matrix model in the contact point's Cartesian
// coordinates the Euclidean test is the geometric one.
// E_rows: E by rows (E's row c.contact as a sparse vector in O(its entries);
// m.E.row() of the column-major E scans every column, O(N) per contact and
// O(N^2) over a model's contacts: seconds at N = 10^4).
std::optional<ModelProblem> check_friction_3d(
    const MechanicalModel& m, const Eigen::SparseMatrix<double, Eigen::RowMajor>& E_rows,
    const FrictionalContact& c, const std::string& at) {
  const Eigen::Index N = m.M.rows();
  if (auto p = check_tangent(c.tangent2, N, at + ".tangents[1]")) return p;
  if (c.edges < 0)
    return ModelProblem{at + ".d", "must be >= 1 (got " + std::to_string(c.edges) + ")"};
  if (c.velocity != 0.0)
    return ModelProblem{at + ".velocity", "a moving surface is planar only (got " +
                                              short_number(c.velocity) + " with two tangents)"};
  if (c.world_frame) return std::nullopt;  // orthonormal in the world (FrictionalContact)
  const Eigen::SparseVector<double> n = E_rows.row(c.contact).transpose();
  const std::string row = "the normal row E[" + std::to_string(c.contact) + "]";
  const std::pair<std::string, double> pairs[] = {
      {"tangents[0] and " + row, cosine(n, c.tangent)},
      {"tangents[1] and " + row, cosine(n, c.tangent2)},
      {"tangents[0] and tangents[1]", cosine(c.tangent, c.tangent2)}};
  for (const auto& [which, cos] : pairs)
    if (!(std::abs(cos) <= kTangentOrthogonality))
      return ModelProblem{at + ".tangents", which + " are not orthogonal: cosine " +
                                                short_number(cos) + ", more than " +
                                                short_number(kTangentOrthogonality) +
                                                " (Euclidean, in the model's coordinates)"};
  const double n1 = c.tangent.norm(), n2 = c.tangent2.norm();
  if (!(std::abs(n1 - n2) <= kTangentOrthogonality * n1))
    return ModelProblem{at + ".tangents",
                        "tangents[0] and tangents[1] must have equal lengths (got " +
                            short_number(n1) + " and " + short_number(n2) +
                            "): the cone's edges are at angles pi i/d"};
  return std::nullopt;
}

// Frictional contacts: a row of E each, at most one per row, a finite
// tangent row of length N, a finite mu >= 0; 3-D ones check_friction_3d.
std::optional<ModelProblem> check_friction(const MechanicalModel& m) {
  const Eigen::Index N = m.M.rows(), k = m.E.rows();
  std::vector<int> owner(static_cast<size_t>(k), -1);
  Eigen::SparseMatrix<double, Eigen::RowMajor> E_rows;  // E by rows, made at the first 3-D contact
  for (size_t f = 0; f < m.friction.size(); ++f) {
    const FrictionalContact& c = m.friction[f];
    const std::string at = "mechanical.friction[" + std::to_string(f) + "]";
    if (c.contact < 0 || c.contact >= k)
      return ModelProblem{at + ".contact", "contact " + std::to_string(c.contact) +
                                               " out of range (k = " + std::to_string(k) +
                                               " constraints, 0-based)"};
    if (owner[static_cast<size_t>(c.contact)] >= 0)
      return ModelProblem{at + ".contact",
                          "contact " + std::to_string(c.contact) + " ('" +
                              m.constraints[static_cast<size_t>(c.contact)] +
                              "') already has friction (mechanical.friction[" +
                              std::to_string(owner[static_cast<size_t>(c.contact)]) + "])"};
    owner[static_cast<size_t>(c.contact)] = static_cast<int>(f);
    if (auto p = check_tangent(c.tangent, N, at + (c.is_3d() ? ".tangents[0]" : ".tangent")))
      return p;
    if (!std::isfinite(c.mu))
      return ModelProblem{at + ".mu", "not finite (got " + short_number(c.mu) + ")"};
    if (c.mu < 0.0)
      return ModelProblem{at + ".mu", "must be >= 0 (got " + short_number(c.mu) + ")"};
    if (!std::isfinite(c.velocity))
      return ModelProblem{at + ".velocity", "not finite (got " + short_number(c.velocity) + ")"};
    if (c.is_3d()) {
      if (E_rows.rows() == 0 && !c.world_frame) E_rows = m.E;
      if (auto p = check_friction_3d(m, E_rows, c, at)) return p;
    }
  }
  if (m.cone_edges < 1)
    return ModelProblem{"mechanical.friction_d",
                        "must be >= 1 (got " + std::to_string(m.cone_edges) + ")"};
  return std::nullopt;
}

}  // namespace

std::string asymmetry(const SparseMatrix& A, std::string_view name) {
  double scale = 0.0;
  for (Eigen::Index j = 0; j < A.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(A, j); it; ++it)
      scale = std::max(scale, std::abs(it.value()));
  const auto entry = [&](Eigen::Index a, Eigen::Index b) {
    return std::string(name) + "[" + std::to_string(a) + "][" + std::to_string(b) +
           "] = " + short_number(A.coeff(a, b));
  };
  for (Eigen::Index j = 0; j < A.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(A, j); it; ++it) {
      const Eigen::Index i = it.row();
      if (std::abs(it.value() - A.coeff(j, i)) > 1e-12 * scale) {
        const Eigen::Index a = std::min(i, j), b = std::max(i, j);
        return entry(a, b) + " but " + entry(b, a);
      }
    }
  return "";
}

std::optional<ModelProblem> check_mass_matrix(const SparseMatrix& M) {
  if (const std::string why = asymmetry(M, "M"); !why.empty())
    return ModelProblem{"mechanical.M", "not symmetric (" + why + ")"};
  const double rel = static_cast<double>(M.rows()) * std::numeric_limits<double>::epsilon();
  if (M.rows() <= kDenseMassCheckMax) {
    const MatrixXd Md = M.toDense();
    const MatrixXd S = 0.5 * (Md + Md.transpose());
    const Eigen::LLT<MatrixXd> llt(S);
    const VectorXd ev = Eigen::SelfAdjointEigenSolver<MatrixXd>(S).eigenvalues();
    if (llt.info() != Eigen::Success || ev.minCoeff() <= rel * std::abs(ev.maxCoeff()))
      return ModelProblem{"mechanical.M", "not positive definite (smallest eigenvalue " +
                                              short_number(ev.minCoeff()) + ", largest " +
                                              short_number(ev.maxCoeff()) + ")"};
    return std::nullopt;
  }
  const Eigen::SimplicialLDLT<SparseMatrix> ldlt(M);
  const VectorXd d = ldlt.info() == Eigen::Success ? ldlt.vectorD() : VectorXd();
  if (d.size() == 0 || !d.allFinite() || d.minCoeff() <= rel * d.cwiseAbs().maxCoeff())
    return ModelProblem{"mechanical.M",
                        d.size() == 0 ? "not positive definite (its LDL' factorisation failed)"
                                      : "not positive definite (smallest LDL' pivot " +
                                            short_number(d.minCoeff()) + ", largest " +
                                            short_number(d.maxCoeff()) + ")"};
  return std::nullopt;
}

namespace {

// The sizes of every matrix, vector and name list against N (the rows of M)
// and k (the rows of E).
std::optional<ModelProblem> check_dimensions(const MechanicalModel& m) {
  const Eigen::Index N = m.M.rows(), k = m.E.rows();
  if (N == 0) return ModelProblem{"mechanical.M", "empty (a model needs at least one coordinate)"};
  if (m.M.cols() != N)
    return ModelProblem{"mechanical.M",
                        "expected a square matrix (got " + dims(N, m.M.cols()) + ")"};
  const std::string nn = " (N = " + std::to_string(N) + " coordinates, from M)";
  const std::string kk = " (k = " + std::to_string(k) + " constraints, from the rows of E)";
  auto square = [&](const SparseMatrix& A, const char* field) -> std::optional<ModelProblem> {
    if (A.rows() != N || A.cols() != N)
      return ModelProblem{
          field, "expected " + dims(N, N) + nn + " (got " + dims(A.rows(), A.cols()) + ")"};
    return std::nullopt;
  };
  if (auto p = square(m.D, "mechanical.D")) return p;
  if (auto p = square(m.K, "mechanical.K")) return p;
  if (m.E.cols() != N)
    return ModelProblem{"mechanical.E", "expected " + std::to_string(N) + " columns" + nn +
                                            " (got " + dims(k, m.E.cols()) + ")"};
  auto sized = [&](const VectorXd& v, Eigen::Index n, const char* field,
                   const std::string& why) -> std::optional<ModelProblem> {
    if (v.size() != n)
      return ModelProblem{field, "expected " + std::to_string(n) + " entries" + why + " (got " +
                                     std::to_string(v.size()) + ")"};
    return std::nullopt;
  };
  if (auto p = sized(m.g, k, "mechanical.g", kk)) return p;
  if (auto p = sized(m.f, N, "mechanical.f", nn)) return p;
  if (auto p = sized(m.restitution, k, "mechanical.restitution", kk)) return p;
  if (static_cast<Eigen::Index>(m.coordinates.size()) != N)
    return ModelProblem{"mechanical.coordinates", "expected " + std::to_string(N) + " names" + nn +
                                                      " (got " +
                                                      std::to_string(m.coordinates.size()) + ")"};
  if (static_cast<Eigen::Index>(m.constraints.size()) != k)
    return ModelProblem{"mechanical.constraints", "expected " + std::to_string(k) + " names" + kk +
                                                      " (got " +
                                                      std::to_string(m.constraints.size()) + ")"};
  return std::nullopt;
}

// Every entry finite, the matrices then the vectors.
std::optional<ModelProblem> check_finite(const MechanicalModel& m) {
  const std::pair<const SparseMatrix*, const char*> mats[] = {{&m.M, "mechanical.M"},
                                                              {&m.D, "mechanical.D"},
                                                              {&m.K, "mechanical.K"},
                                                              {&m.E, "mechanical.E"}};
  for (const auto& [A, field] : mats)
    if (auto at = non_finite(*A)) return ModelProblem{field + *at, "not finite"};
  const std::pair<const VectorXd*, const char*> vecs[] = {
      {&m.g, "mechanical.g"}, {&m.f, "mechanical.f"}, {&m.restitution, "mechanical.restitution"}};
  for (const auto& [v, field] : vecs)
    if (auto at = non_finite_vector(*v)) return ModelProblem{field + *at, "not finite"};
  return std::nullopt;
}

// M symmetric positive definite, restitution in [0, 1], no all-zero row of E.
std::optional<ModelProblem> check_values(const MechanicalModel& m) {
  const Eigen::Index N = m.M.rows(), k = m.E.rows();
  if (auto p = check_mass_matrix(m.M)) return p;
  for (Eigen::Index i = 0; i < k; ++i)
    if (m.restitution(i) < 0.0 || m.restitution(i) > 1.0)
      return ModelProblem{"mechanical.restitution[" + std::to_string(i) + "]",
                          "outside [0, 1] (got " + short_number(m.restitution(i)) + ")"};
  // A zero row of E is the constraint 0 q + g >= 0: it never acts (g >= 0) or
  // is never satisfiable (g < 0), and its multiplier has no leading index.
  if (k > 0) {
    const VectorXd row_norms = m.E.cwiseAbs() * VectorXd::Ones(N);
    for (Eigen::Index i = 0; i < k; ++i)
      if (!(row_norms(i) > 0.0))
        return ModelProblem{"mechanical.E[" + std::to_string(i) + "]",
                            "constraint '" + m.constraints[i] +
                                "' has an all-zero row (it constrains no coordinate)"};
  }
  return std::nullopt;
}

// The inputs (docs/inputs.md): named once each, usable signals, and uses
// that name an input with a finite gain of the right size.
std::optional<ModelProblem> check_inputs(const MechanicalModel& m) {
  for (std::size_t j = 0; j < m.inputs.size(); ++j) {
    const Input& in = m.inputs[j];
    const std::string field = "inputs[" + std::to_string(j) + "]";
    if (in.name.empty()) return ModelProblem{field, "an input needs a name"};
    for (std::size_t i = 0; i < j; ++i)
      if (m.inputs[i].name == in.name)
        return ModelProblem{field, "input '" + in.name + "' is named twice"};
    if (std::string why = check_input(in); !why.empty())
      return ModelProblem{field, "input '" + in.name + "': " + why};
  }
  const auto check_uses = [&](const std::vector<InputUse>& uses, const char* key,
                              Eigen::Index size) -> std::optional<ModelProblem> {
    for (std::size_t i = 0; i < uses.size(); ++i) {
      const std::string field = std::string("mechanical.") + key + "[" + std::to_string(i) + "]";
      if (uses[i].input < 0 || static_cast<std::size_t>(uses[i].input) >= m.inputs.size())
        return ModelProblem{field, "names no input (got index " + std::to_string(uses[i].input) +
                                       " of " + std::to_string(m.inputs.size()) + ")"};
      if (uses[i].gain.size() != size)
        return ModelProblem{field + ".gain", "expected " + std::to_string(size) + " entries (got " +
                                                 std::to_string(uses[i].gain.size()) + ")"};
      if (auto at = non_finite_vector(uses[i].gain))
        return ModelProblem{field + ".gain" + *at, "not finite"};
    }
    return std::nullopt;
  };
  if (auto p = check_uses(m.force_inputs, "force_inputs", m.M.rows())) return p;
  return check_uses(m.gap_inputs, "gap_inputs", m.E.rows());
}

}  // namespace

std::optional<ModelProblem> check_mechanical(const MechanicalModel& m) {
  if (auto p = check_dimensions(m)) return p;
  if (auto p = check_finite(m)) return p;
  if (auto p = check_values(m)) return p;
  if (auto p = check_inputs(m)) return p;
  return check_friction(m);
}

std::optional<ModelProblem> check_lcs(const lcs::Lcs& s) {
  const Eigen::Index n = s.A.rows(), k = s.B.cols();
  if (n == 0) return ModelProblem{"lcs.A", "empty (an LCS needs at least one state)"};
  if (s.A.cols() != n)
    return ModelProblem{"lcs.A", "expected a square matrix (got " + dims(n, s.A.cols()) + ")"};
  if (s.B.rows() != n)
    return ModelProblem{
        "lcs.B", "expected " + std::to_string(n) + " rows (got " + dims(s.B.rows(), k) + ")"};
  if (s.C.rows() != k || s.C.cols() != n)
    return ModelProblem{"lcs.C",
                        "expected " + dims(k, n) + " (got " + dims(s.C.rows(), s.C.cols()) + ")"};
  if (s.D.rows() != k || s.D.cols() != k)
    return ModelProblem{"lcs.D",
                        "expected " + dims(k, k) + " (got " + dims(s.D.rows(), s.D.cols()) + ")"};
  const std::pair<const MatrixXd*, const char*> mats[] = {
      {&s.A, "lcs.A"}, {&s.B, "lcs.B"}, {&s.C, "lcs.C"}, {&s.D, "lcs.D"}};
  for (const auto& [A, field] : mats)
    if (auto at = non_finite(*A)) return ModelProblem{field + *at, "not finite"};
  return std::nullopt;
}

namespace {
// An `lcs:` model's inputs (Model::inputs): each usable, their exosystems the
// last states of the exosystem block, each block S and initial state its own.
std::optional<ModelProblem> check_lcs_inputs(const Model& model) {
  const int n = model.lcs->n(), e = model.exo_states;
  int at = e;
  for (const Input& in : model.inputs) at -= in.exo_size();
  if (at < 0)
    return ModelProblem{
        "lcs.inputs", text("their exosystems need more states than the ", e, " of the exosystem")};
  for (std::size_t i = 0; i < model.inputs.size(); ++i) {
    const Input& in = model.inputs[i];
    const std::string field = text("lcs.inputs[", i, "]");
    if (std::string what = check_input(in); !what.empty())
      return ModelProblem{field, "input '" + in.name + "': " + what};
    const int s = in.exo_size(), row = n - e + at;
    if (!(model.lcs->A.block(row, row, s, s) - in.exo_matrix()).isZero(0.0) ||
        !(model.exo_initial.segment(at, s) - in.exo_state(0.0)).isZero(0.0))
      return ModelProblem{
          field, "input '" + in.name + "': its exosystem block and initial state are not its own"};
    at += s;
  }
  return std::nullopt;
}

// The names, exosystem and outputs of an `lcs:` model (all empty for any
// other): sizes that agree, finite entries, an exosystem driven by itself.
std::optional<ModelProblem> check_lcs_labels(const Model& model) {
  const bool labelled = !model.state_names.empty() || !model.pair_names.empty() ||
                        model.exo_states != 0 || !model.output_names.empty() ||
                        !model.inputs.empty();
  if (!labelled) return std::nullopt;
  if (!model.lcs)
    return ModelProblem{"model", "state names, exosystem, inputs and outputs are for LCS models"};
  const int n = model.lcs->n(), k = model.lcs->k(), e = model.exo_states;
  const auto size_problem = [](const char* field, std::size_t want, std::size_t got) {
    return ModelProblem{
        field, "expected " + std::to_string(want) + " entries (got " + std::to_string(got) + ")"};
  };
  if (!model.state_names.empty() && model.state_names.size() != static_cast<std::size_t>(n))
    return size_problem("lcs.states", n, model.state_names.size());
  if (!model.pair_names.empty() && model.pair_names.size() != static_cast<std::size_t>(k))
    return size_problem("lcs.pairs", k, model.pair_names.size());
  if (e < 0 || e > n || model.exo_initial.size() != e)
    return ModelProblem{"lcs.exosystem", "expected at most " + std::to_string(n) +
                                             " states with as many initial values"};
  // (No view of an empty block: Eigen's offsets a null pointer.)
  if (e > 0 && ((n > e && model.lcs->A.bottomLeftCorner(e, n - e).cwiseAbs().sum() != 0.0) ||
                (k > 0 && model.lcs->B.bottomRows(e).cwiseAbs().sum() != 0.0)))
    return ModelProblem{"lcs.exosystem", "its states must be driven by themselves only"};
  if (auto at = non_finite_vector(model.exo_initial))
    return ModelProblem{"lcs.exosystem" + *at, "not finite"};
  if (auto p = check_lcs_inputs(model)) return p;
  const auto m = static_cast<Eigen::Index>(model.output_names.size());
  if (model.output_x.rows() != m || model.output_u.rows() != m ||
      (m > 0 && (model.output_x.cols() != n || model.output_u.cols() != k)))
    return ModelProblem{"lcs.outputs", "expected " + std::to_string(m) + " rows of " +
                                           std::to_string(n) + " and " + std::to_string(k) +
                                           " entries"};
  if (auto at = non_finite(model.output_x)) return ModelProblem{"lcs.outputs" + *at, "not finite"};
  if (auto at = non_finite(model.output_u)) return ModelProblem{"lcs.outputs" + *at, "not finite"};
  return std::nullopt;
}
}  // namespace

std::optional<ModelProblem> check_model(const Model& model) {
  if (model.mechanical.has_value() == model.lcs.has_value())
    return ModelProblem{"model", model.mechanical ? "holds both a mechanical model and an LCS"
                                                  : "holds neither a mechanical model nor an LCS"};
  auto p = model.mechanical ? check_mechanical(*model.mechanical) : check_lcs(*model.lcs);
  if (p) return p;
  if (auto q = check_lcs_labels(model)) return q;
  if (model.initial.size() > 0) {
    if (model.initial.size() != model.state_size())
      return ModelProblem{"initial", "expected " + std::to_string(model.state_size()) +
                                         " entries (got " + std::to_string(model.initial.size()) +
                                         ")"};
    if (auto at = non_finite_vector(model.initial))
      return ModelProblem{"initial" + *at, "not finite"};
  }
  if (!std::isnan(model.t_end) && !(model.t_end > 0.0 && std::isfinite(model.t_end)))
    return ModelProblem{"t_end",
                        "must be a finite number > 0 (got " + short_number(model.t_end) + ")"};
  return std::nullopt;
}

}  // namespace lcsim::mech
