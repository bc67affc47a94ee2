// Model files (YAML, through yaml-cpp), and vectors given on the command
// line. Format: docs/model-format.md. All validation happens here, so
// the layers below may assume well-formed models; every error names the file,
// the key and the offending value.
#include <yaml-cpp/yaml.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <lcsim/io/io.hpp>
#include <lcsim/io/text.hpp>
#include <lcsim/io/yaml.hpp>
#include <map>
#include <set>
#include <sstream>

namespace lcsim::io {

namespace {

using yaml::describe;
using yaml::dims;
using yaml::expect_size;
using yaml::fail;
using yaml::join;
using yaml::Keys;
using yaml::load;
using yaml::mapping;
using yaml::matrix;
using yaml::number;
using yaml::vector;

template <class Mat>
void expect_dims(const Mat& m, Eigen::Index rows, Eigen::Index cols, const std::string& source,
                 const std::string& key, const std::string& why) {
  if (m.rows() != rows || m.cols() != cols)
    fail(source, key,
         "expected " + std::to_string(rows) + " x " + std::to_string(cols) + " " + why + " (got " +
             dims(m) + ")");
}

// A non-negative integer below `bound` (an index or a dimension).
Eigen::Index count(const YAML::Node& n, const std::string& source, const std::string& key,
                   double bound) {
  const double x = number(n, source, key);
  if (x < 0.0 || x != std::floor(x) || x >= bound)
    fail(source, key,
         "expected a whole number in [0, " + format_number(bound) + ") (got '" + n.Scalar() + "')");
  return static_cast<Eigen::Index>(x);
}

// A model matrix, in one of three spellings (docs/model-format.md):
//   a list of rows                        [[1, 0], [0, 2]]
//   its non-zeros                         {rows: 2, cols: 2, entries: [[0, 0, 1], [1, 1, 2]]}
//   a diagonal                            {diagonal: [1, 2]}
// Entries are [row, column, value] with 0-based indices; a position given
// twice is an error (not summed), so a typo cannot silently add up.
mech::SparseMatrix sparse_matrix(const YAML::Node& n, const std::string& source,
                                 const std::string& key, Eigen::Index cols_if_empty) {
  if (n.IsSequence()) return matrix(n, source, key, cols_if_empty).sparseView();
  if (!n.IsMap())
    fail(source, key,
         "expected a matrix: a list of rows, {rows, cols, entries} or {diagonal} (got " +
             describe(n) + ")");
  const Keys keys = mapping(n, source, key, {"rows", "cols", "entries", "diagonal"});
  if (keys.count("diagonal")) {
    if (keys.size() != 1)
      fail(source, key, "a {diagonal: [...]} matrix takes no other keys (rows, cols, entries)");
    const VectorXd d = vector(keys.at("diagonal"), source, key + ".diagonal");
    mech::SparseMatrix m(d.size(), d.size());
    m.reserve(Eigen::VectorXi::Constant(d.size(), 1));
    for (Eigen::Index i = 0; i < d.size(); ++i)
      if (d(i) != 0.0) m.insert(i, i) = d(i);
    m.makeCompressed();
    return m;
  }
  for (const char* k : {"rows", "cols", "entries"})
    if (!keys.count(k))
      fail(source, key + "." + k,
           "missing (a sparse matrix is {rows: R, cols: C, entries: [[row, col, value], ...]})");
  constexpr double kMaxDim = 1e9;
  const Eigen::Index rows = count(keys.at("rows"), source, key + ".rows", kMaxDim);
  const Eigen::Index cols = count(keys.at("cols"), source, key + ".cols", kMaxDim);
  const YAML::Node& e = keys.at("entries");
  if (!e.IsSequence())
    fail(source, key + ".entries",
         "expected a list of [row, col, value] (got " + describe(e) + ")");
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(e.size());
  for (std::size_t i = 0; i < e.size(); ++i) {
    const std::string ekey = key + ".entries[" + std::to_string(i) + "]";
    if (!e[i].IsSequence() || e[i].size() != 3)
      fail(source, ekey, "expected [row, col, value] (got " + describe(e[i]) + ")");
    const Eigen::Index r = count(e[i][0], source, ekey + "[0]", static_cast<double>(rows));
    const Eigen::Index c = count(e[i][1], source, ekey + "[1]", static_cast<double>(cols));
    t.emplace_back(r, c, number(e[i][2], source, ekey + "[2]"));
  }
  mech::SparseMatrix m(rows, cols);
  // Duplicates: count them instead of summing.
  bool repeated = false;
  m.setFromTriplets(t.begin(), t.end(), [&](double a, double) {
    repeated = true;
    return a;
  });
  if (repeated) {
    std::set<std::pair<Eigen::Index, Eigen::Index>> seen;
    for (std::size_t i = 0; i < t.size(); ++i)
      if (!seen.insert({t[i].row(), t[i].col()}).second)
        fail(source, key + ".entries[" + std::to_string(i) + "]",
             "position (" + std::to_string(t[i].row()) + ", " + std::to_string(t[i].col()) +
                 ") given twice");
  }
  m.prune(0.0);
  return m;
}

std::vector<std::string> names(const YAML::Node& n, Eigen::Index size, const std::string& source,
                               const std::string& key, const std::string& why) {
  if (!n.IsSequence()) fail(source, key, "expected a list of names (got " + describe(n) + ")");
  if (static_cast<Eigen::Index>(n.size()) != size)
    fail(source, key,
         "expected " + std::to_string(size) + " names " + why + " (got " +
             std::to_string(n.size()) + ")");
  std::vector<std::string> out;
  std::set<std::string> seen;
  for (std::size_t i = 0; i < n.size(); ++i) {
    const std::string ikey = key + "[" + std::to_string(i) + "]";
    if (!n[i].IsScalar() || n[i].Scalar().empty())
      fail(source, ikey, "expected a non-empty name (got " + describe(n[i]) + ")");
    const std::string name = n[i].Scalar();
    if (!seen.insert(name).second) fail(source, ikey, "duplicate name '" + name + "'");
    out.push_back(name);
  }
  return out;
}

// A cone's d (`friction_d`, an entry's `d`): a whole number in [1, kMaxConeEdges].
constexpr double kMaxConeEdges = 1024;  // 2048 edges: far past any use (docs/friction.md)
int cone_edges(const YAML::Node& n, const std::string& source, const std::string& key) {
  const double x = number(n, source, key);
  if (!(x >= 1.0 && x == std::floor(x) && x <= kMaxConeEdges))
    fail(source, key,
         "must be a whole number >= 1 and <= " + format_number(kMaxConeEdges) + " (got '" +
             n.Scalar() + "')");
  return static_cast<int>(x);
}

// An entry's tangent rows: `tangent: [N numbers]` (planar) or `tangents:
// [[N numbers], [N numbers]]` with optional `d` (three-dimensional), never both.
void parse_tangents(const Keys& keys, const std::string& source, const std::string& ikey,
                    mech::FrictionalContact& c) {
  if (keys.count("tangent") && keys.count("tangents"))
    fail(source, ikey, "has both tangent and tangents (one tangent row is planar, two are 3-D)");
  if (!keys.count("tangent") && !keys.count("tangents"))
    fail(source, ikey + ".tangent", "missing (tangent: one row, or tangents: two rows)");
  if (keys.count("tangent")) {
    if (keys.count("d"))
      fail(source, ikey + ".d", "applies to an entry with tangents: (a planar contact is d = 1)");
    c.tangent = vector(keys.at("tangent"), source, ikey + ".tangent").sparseView();
    return;
  }
  const YAML::Node& tn = keys.at("tangents");
  if (!tn.IsSequence() || tn.size() != 2)
    fail(source, ikey + ".tangents",
         "expected two tangent rows [[...], [...]] (got " + describe(tn) + ")");
  c.tangent = vector(tn[0], source, ikey + ".tangents[0]").sparseView();
  c.tangent2 = vector(tn[1], source, ikey + ".tangents[1]").sparseView();
  // An all-zero second row keeps its length: is_3d() holds and the check names it.
  if (c.tangent2.size() == 0) fail(source, ikey + ".tangents[1]", "empty");
  if (keys.count("d")) c.edges = cone_edges(keys.at("d"), source, ikey + ".d");
}

// An entry's `frame: world`: its rows are a contact frame orthonormal in the
// world, mapped to the model's coordinates (a scene's contact written by
// `analyze --model-out`), so the Euclidean orthogonality test does not apply
// to them (mech::FrictionalContact::world_frame). `frame: model` is the default.
bool world_frame(const YAML::Node& n, const std::string& source, const std::string& key) {
  if (n.IsScalar() && (n.Scalar() == "world" || n.Scalar() == "model"))
    return n.Scalar() == "world";
  fail(source, key, "must be 'world' or 'model' (got " + describe(n) + ")");
}

// `friction: [{contact: <0-based row of E or its name>, tangent: [N numbers],
// mu: <number>, velocity: <number, optional>}]`, or with `tangents: [[N
// numbers], [N numbers]]` and `d: <whole number, optional>` in place of
// `tangent` for a 3-D contact (docs/model-format.md). Names resolve against the
// model's constraint names, so this runs after fill_defaults; the sizes, ranges and duplicates are
// mech::check_mechanical's.
std::vector<mech::FrictionalContact> parse_friction(const YAML::Node& n,
                                                    const mech::MechanicalModel& m,
                                                    const std::string& source) {
  const std::string key = "mechanical.friction";
  if (!n.IsSequence())
    fail(source, key, "expected a list of {contact, tangent, mu} (got " + describe(n) + ")");
  std::vector<mech::FrictionalContact> out;
  for (std::size_t i = 0; i < n.size(); ++i) {
    const std::string ikey = key + "[" + std::to_string(i) + "]";
    const Keys keys = mapping(n[i], source, ikey,
                              {"contact", "tangent", "tangents", "d", "mu", "velocity", "frame"});
    for (const char* k : {"contact", "mu"})
      if (!keys.count(k)) fail(source, ikey + "." + k, "missing");
    mech::FrictionalContact c;
    const YAML::Node& cn = keys.at("contact");
    if (!cn.IsScalar() || cn.Scalar().empty())
      fail(source, ikey + ".contact",
           "expected a 0-based row of E or a constraint name (got " + describe(cn) + ")");
    const std::string& text = cn.Scalar();
    const bool is_index = text.find_first_not_of("0123456789") == std::string::npos;
    if (is_index) {
      c.contact = static_cast<int>(
          count(cn, source, ikey + ".contact", static_cast<double>(m.num_constraints())));
    } else {
      const auto it = std::find(m.constraints.begin(), m.constraints.end(), text);
      if (it == m.constraints.end())
        fail(source, ikey + ".contact",
             "no constraint named '" + text + "' (the constraints: " + join(m.constraints) + ")");
      c.contact = static_cast<int>(it - m.constraints.begin());
    }
    parse_tangents(keys, source, ikey, c);
    c.mu = number(keys.at("mu"), source, ikey + ".mu");
    if (keys.count("velocity"))
      c.velocity = number(keys.at("velocity"), source, ikey + ".velocity");
    if (keys.count("frame")) c.world_frame = world_frame(keys.at("frame"), source, ikey + ".frame");
    out.push_back(std::move(c));
  }
  return out;
}

mech::MechanicalModel parse_mechanical(const YAML::Node& node, const std::string& source,
                                       const std::vector<mech::Input>& inputs) {
  const Keys keys =
      mapping(node, source, "mechanical",
              {"M", "D", "K", "E", "g", "f", "restitution", "coordinates", "constraints",
               "friction", "friction_d", "force_inputs", "gap_inputs"});
  const auto has = [&](const char* k) { return keys.count(k) > 0; };
  mech::MechanicalModel m;
  if (!has("M")) fail(source, "mechanical.M", "missing (the mass matrix is required)");
  m.M = sparse_matrix(keys.at("M"), source, "mechanical.M", 0);
  if (m.M.rows() == 0)
    fail(source, "mechanical.M", "empty (a model needs at least one coordinate)");
  if (m.M.rows() != m.M.cols())
    fail(source, "mechanical.M", "expected a square matrix (got " + dims(m.M) + ")");
  const Eigen::Index N = m.M.rows();
  const std::string nn = "(N = " + std::to_string(N) + " coordinates, from M)";
  if (has("D")) {
    m.D = sparse_matrix(keys.at("D"), source, "mechanical.D", N);
    expect_dims(m.D, N, N, source, "mechanical.D", nn);
  }
  if (has("K")) {
    m.K = sparse_matrix(keys.at("K"), source, "mechanical.K", N);
    expect_dims(m.K, N, N, source, "mechanical.K", nn);
  }
  m.E = mech::SparseMatrix(0, N);
  if (has("E")) {
    m.E = sparse_matrix(keys.at("E"), source, "mechanical.E", N);
    if (m.E.cols() != N)
      fail(source, "mechanical.E",
           "expected " + std::to_string(N) + " columns " + nn + " (got " + dims(m.E) + ")");
  }
  const Eigen::Index k = m.E.rows();
  const std::string kk = "(k = " + std::to_string(k) + " constraints, from the rows of E)";
  if (has("g")) {
    m.g = vector(keys.at("g"), source, "mechanical.g");
    expect_size(m.g, k, source, "mechanical.g", kk);
  }
  if (has("f")) {
    m.f = vector(keys.at("f"), source, "mechanical.f");
    expect_size(m.f, N, source, "mechanical.f", nn);
  }
  if (has("restitution")) {
    m.restitution = vector(keys.at("restitution"), source, "mechanical.restitution");
    expect_size(m.restitution, k, source, "mechanical.restitution", kk);
  }
  if (has("coordinates"))
    m.coordinates = names(keys.at("coordinates"), N, source, "mechanical.coordinates", nn);
  if (has("constraints"))
    m.constraints = names(keys.at("constraints"), k, source, "mechanical.constraints", kk);
  // fill_defaults leaves the zero-row E alone and sizes g and restitution to
  // k, so a model without constraints (E omitted or []) is complete as well.
  mech::fill_defaults(m);
  if (has("friction")) m.friction = parse_friction(keys.at("friction"), m, source);
  if (has("friction_d"))
    m.cone_edges = cone_edges(keys.at("friction_d"), source, "mechanical.friction_d");
  m.inputs = inputs;  // docs/inputs.md
  if (has("force_inputs"))
    m.force_inputs =
        yaml::input_uses(keys.at("force_inputs"), inputs, N, source, "mechanical.force_inputs", nn);
  if (has("gap_inputs"))
    m.gap_inputs =
        yaml::input_uses(keys.at("gap_inputs"), inputs, k, source, "mechanical.gap_inputs", kk);
  // What the file's structure did not already refuse: M symmetric positive
  // definite, restitution in [0, 1], finite entries, no all-zero row of E.
  if (auto p = mech::check_mechanical(m)) fail(source, p->field, p->what);
  return m;
}

lcs::Lcs parse_lcs(const YAML::Node& node, const std::string& source) {
  const Keys keys = mapping(node, source, "lcs", {"A", "B", "C", "D"});
  for (const char* k : {"A", "B", "C"})
    if (!keys.count(k)) fail(source, std::string("lcs.") + k, "missing (A, B and C are required)");
  lcs::Lcs s;
  s.A = matrix(keys.at("A"), source, "lcs.A", 0);
  if (s.A.rows() == 0) fail(source, "lcs.A", "empty (an LCS needs at least one state)");
  if (s.A.rows() != s.A.cols())
    fail(source, "lcs.A", "expected a square matrix (got " + dims(s.A) + ")");
  const Eigen::Index n = s.A.rows();
  s.B = matrix(keys.at("B"), source, "lcs.B", 0);
  if (s.B.rows() != n)
    fail(source, "lcs.B",
         "expected " + std::to_string(n) + " rows (n = " + std::to_string(n) +
             " states, from A) (got " + dims(s.B) + ")");
  const Eigen::Index k = s.B.cols();
  const std::string kk = "(k = " + std::to_string(k) + " complementarity pairs, from B)";
  s.C = matrix(keys.at("C"), source, "lcs.C", n);
  expect_dims(s.C, k, n, source, "lcs.C", kk);
  s.D = MatrixXd::Zero(k, k);
  if (keys.count("D")) {
    s.D = matrix(keys.at("D"), source, "lcs.D", k);
    expect_dims(s.D, k, k, source, "lcs.D", kk);
  }
  return s;
}

}  // namespace

std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, sep)) out.push_back(item);
  return out;
}

std::string read_file(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    throw InputError(path.string() + ": cannot open: no such file");
  if (std::filesystem::is_directory(path, ec))
    throw InputError(path.string() + ": cannot open: is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open: permission denied or unreadable");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw InputError(path.string() + ": read error");
  return ss.str();
}

YAML::Node load_model_root(const std::string& yaml_text, const std::string& source) {
  YAML::Node root = load(yaml_text, source);
  if (root.IsNull() || !root.IsDefined())
    throw InputError(source +
                     ": empty file (expected a model: `name` and a `mechanical:` or `lcs:` "
                     "section, or a scene: `urdf:` and `joints:`)");
  return root;
}

bool is_scene(const YAML::Node& root) {
  return root.IsMap() && (root["urdf"] || root["bodies"]);  // one URDF, or several
}

mech::Model parse_matrix_model(const YAML::Node& root, const std::string& source) {
  // `inputs:` (docs/inputs.md) is taken out first, so that the message for
  // an unknown key lists the keys every model has, as it always did.
  YAML::Node body = root, inputs_node;
  const bool has_inputs = root.IsMap() && root["inputs"];
  if (has_inputs) {
    inputs_node = root["inputs"];
    body = YAML::Clone(root);
    body.remove("inputs");
  }
  const Keys keys = mapping(body, source, "", {"name", "mechanical", "lcs", "initial", "t_end"});
  mech::Model model;
  model.source = source;
  if (keys.count("name")) {
    const YAML::Node& n = keys.at("name");
    if (!n.IsScalar() || n.Scalar().empty())
      fail(source, "name", "expected a non-empty name (got " + describe(n) + ")");
    model.name = n.Scalar();
  } else {
    model.name = std::filesystem::path(source).stem().string();
  }
  const bool has_mech = keys.count("mechanical") > 0;
  const bool has_lcs = keys.count("lcs") > 0;
  if (has_mech && has_lcs)
    fail(source, "mechanical, lcs", "a model is one or the other; give only one of the sections");
  if (!has_mech && !has_lcs)
    fail(source, "mechanical", "missing (expected a `mechanical:` or an `lcs:` section)");
  std::vector<mech::Input> inputs;
  if (has_inputs) {
    if (has_lcs)
      fail(source, "inputs",
           "inputs are for mechanical models (an `lcs:` model's sources are its own states)");
    inputs = yaml::inputs(inputs_node, source);
  }
  if (has_mech) model.mechanical = parse_mechanical(keys.at("mechanical"), source, inputs);
  if (has_lcs) model.lcs = parse_lcs(keys.at("lcs"), source);
  if (keys.count("initial")) {
    model.initial = vector(keys.at("initial"), source, "initial");
    const std::string why = model.is_mechanical()
                                ? "(the state: " + std::to_string(model.mechanical->dofs()) +
                                      " positions q then " +
                                      std::to_string(model.mechanical->dofs()) + " velocities v)"
                                : "(the state x, n = " + std::to_string(model.state_size()) + ")";
    expect_size(model.initial, model.state_size(), source, "initial", why);
  }
  if (keys.count("t_end")) {
    model.t_end = number(keys.at("t_end"), source, "t_end");
    if (!(model.t_end > 0.0))
      fail(source, "t_end", "must be > 0 (got " + format_number(model.t_end) + ")");
  }
  return model;
}

mech::Model parse_matrix_model(const std::string& yaml_text, const std::string& source) {
  const YAML::Node root = load_model_root(yaml_text, source);
  if (is_scene(root))
    throw InputError(source +
                     ": a scene (a top-level `urdf:` key), not a matrix model: scene::load_model "
                     "reads both kinds");
  return parse_matrix_model(root, source);
}

mech::Model load_matrix_model(const std::filesystem::path& path) {
  return parse_matrix_model(read_file(path), path.string());
}

namespace {

// What the rank of E says: dependent constraints, or rows that cannot be
// active together (the two limits of one joint), or both, told apart when
// there are few rows (k > 0).
void add_rank_notes(const mech::MechanicalModel& m, std::vector<std::string>& notes) {
  const int k = m.num_constraints();
  const int rank = mech::constraint_rank(m);
  // Rows that can never be active together (the two limits of one joint)
  // lower the rank of E without being dependent constraints: checked on
  // the sets that can be active together when there are few rows.
  const bool deficit = rank < k;
  // Beyond the enumeration bound (or an enumeration cut short without a
  // dependent set found) the two causes are not told apart: said so,
  // not called dependent.
  bool judged = k <= mech::kMaxCoactiveConstraints, dependent = false;
  if (deficit && judged) {
    const mech::CoactiveSets sets = mech::coactive_sets(m);
    const Eigen::MatrixXd E(m.E);
    dependent = std::any_of(sets.maximal.begin(), sets.maximal.end(), [&](const auto& J) {
      Eigen::MatrixXd EJ(J.size(), E.cols());
      for (size_t i = 0; i < J.size(); ++i) EJ.row(i) = E.row(J[i]);
      return lcs::numerical_rank(EJ) < static_cast<int>(J.size());
    });
    judged = sets.complete || dependent;
    if (!dependent && judged)
      notes.push_back("E (" + std::to_string(k) + " x " + std::to_string(m.dofs()) + ") has rank " +
                      std::to_string(rank) + " < " + std::to_string(k) +
                      " only through rows that cannot be active together (e.g. both limits "
                      "of one joint): every set that can be active together has "
                      "independent rows, so no constraints are dependent");
  }
  if (deficit && !judged)
    notes.push_back("E (" + std::to_string(k) + " x " + std::to_string(m.dofs()) + ") has rank " +
                    std::to_string(rank) + " < " + std::to_string(k) +
                    ": dependent constraints or rows that cannot be active together (e.g. "
                    "both limits of one joint), not told apart (" +
                    (k > mech::kMaxCoactiveConstraints
                         ? "the sets that can be active together are enumerated for k <= " +
                               std::to_string(mech::kMaxCoactiveConstraints) + " only"
                         : std::string("their enumeration was cut short")) +
                    "); dependent constraints are legal (thesis §4.6.1): post-impact "
                    "velocities are unique, impulses need not be");
  else if (dependent)
    notes.push_back("dependent constraints: E (" + std::to_string(k) + " x " +
                    std::to_string(m.dofs()) + ") has rank " + std::to_string(rank) + " < " +
                    std::to_string(k) +
                    "; legal (thesis §4.6.1): post-impact velocities are unique, impulses "
                    "need not be");
}

}  // namespace

std::vector<std::string> model_notes(const mech::Model& model) {
  std::vector<std::string> notes;
  if (model.is_mechanical()) {
    const mech::MechanicalModel& m = *model.mechanical;
    const int k = m.num_constraints();
    if (k == 0)
      notes.push_back("no unilateral constraints: the model is a free linear system");
    else
      add_rank_notes(m, notes);
    if (model.initial.size() == model.state_size() && k > 0) {
      const VectorXd y = mech::gaps(m, model.initial.head(m.dofs()));
      for (int i = 0; i < k; ++i)
        if (y(i) < 0.0)
          notes.push_back("initial state violates constraint " + m.constraints[i] + " (gap " +
                          format_number(y(i)) +
                          " < 0); an impact changes velocities only and cannot repair it");
    }
  }
  if (model.initial.size() == 0) notes.push_back("no initial state in the file");
  if (std::isnan(model.t_end)) notes.push_back("no t_end in the file");
  return notes;
}

VectorXd parse_vector(const std::string& text, const std::string& what) {
  std::vector<double> out;
  std::size_t start = 0;
  int index = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    const std::size_t end = comma == std::string::npos ? text.size() : comma;
    std::size_t b = start, e = end;
    while (b < e && std::isspace(static_cast<unsigned char>(text[b]))) ++b;
    while (e > b && std::isspace(static_cast<unsigned char>(text[e - 1]))) --e;
    const std::string token = text.substr(b, e - b);
    const std::string where = what + ": entry " + std::to_string(index) + " of '" + text + "'";
    if (token.empty()) throw InputError(where + ": empty (expected comma-separated numbers)");
    double x = 0.0;
    const char* first = token.data();
    const char* last = token.data() + token.size();
    if (*first == '+') ++first;  // from_chars refuses a leading '+'
    const auto [ptr, ec] = std::from_chars(first, last, x);
    if (ec != std::errc() || ptr != last)
      throw InputError(one_line(where + ": not a number (got '" + token + "')"));
    if (!std::isfinite(x)) throw InputError(where + ": not finite (got '" + token + "')");
    out.push_back(x);
    ++index;
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return Eigen::Map<const VectorXd>(out.data(), static_cast<Eigen::Index>(out.size()));
}

}  // namespace lcsim::io
