// Scenes: a URDF plus the joints to simulate, springs, extra unilateral
// constraints, the reference configuration, gravity, restitution, the initial
// state and the horizon (docs/model-format.md, "Scenes"). The scene becomes a
// mechanical model linearised about q0 (urdf_model.cpp).
//
// Coordinates are the joint positions themselves (not deviations from q0):
//   M q'' + D q' + K q = f + E' u,   E q + g >= 0,
//   K = K_springs + K_g,  f = tau_g(q0) + K_g q0 + sum_s k_s rest_s c_s,
// from tau_g(q) ~ tau_g(q0) - K_g (q - q0) and a spring force
// -k (c'q - rest) c on the coordinates (c = e_a or e_a - e_b).
#include <urdf_model/model.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <lcsim/io/json.hpp>
#include <lcsim/io/model_file.hpp>
#include <lcsim/io/text.hpp>
#include <lcsim/io/yaml.hpp>
#include <lcsim/scene/linearisation.hpp>
#include <lcsim/scene/scene.hpp>
#include <limits>
#include <set>
#include <sstream>

#include "scene/detail.hpp"

namespace lcsim::scene {

using io::format_number;
using io::is_scene;
using io::load_model_root;
using io::one_line;
using io::read_file;
namespace yaml = io::yaml;

namespace {

using yaml::describe;
using yaml::fail;
using yaml::join;
using yaml::Keys;
using yaml::load;
using yaml::mapping;
using yaml::number;

std::string name_of(const YAML::Node& n, const std::string& source, const std::string& key) {
  if (!n.IsScalar() || n.Scalar().empty())
    fail(source, key, "expected a non-empty name (got " + describe(n) + ")");
  return n.Scalar();
}

// true or false (YAML 1.2's booleans only: yaml-cpp would also read yes,
// on, y, which a typo can produce).
bool boolean(const YAML::Node& n, const std::string& source, const std::string& key) {
  if (n.IsScalar() && (n.Scalar() == "true" || n.Scalar() == "false")) return n.Scalar() == "true";
  fail(source, key, "expected true or false (got " + describe(n) + ")");
}

// {joint: value} with every joint named in `allowed_joints` (a joint of the URDF
// for q0, a simulated joint otherwise); `what` explains the restriction.
std::map<std::string, double> by_joint(
    const YAML::Node& n, const std::string& source, const std::string& key,
    const std::function<std::string(const std::string&)>& check) {
  std::map<std::string, double> out;
  for (const auto& [name, value] : mapping(n, source, key, {})) {
    const std::string why = check(name);
    if (!why.empty()) fail(source, key + "." + name, why);
    out[name] = number(value, source, key + "." + name);
  }
  return out;
}

std::vector<std::string> stop_list(const YAML::Node& s, const std::string& source,
                                   const std::string& key) {
  if (!s.IsSequence())
    fail(source, key, "expected a list of lower/upper (got " + describe(s) + ")");
  std::vector<std::string> st;
  for (std::size_t m = 0; m < s.size(); ++m) {
    const std::string sk = key + "[" + std::to_string(m) + "]";
    const std::string v = name_of(s[m], source, sk);
    if (v != "lower" && v != "upper") fail(source, sk, "expected lower or upper (got '" + v + "')");
    if (std::count(st.begin(), st.end(), v)) fail(source, sk, "duplicate '" + v + "'");
    st.push_back(v);
  }
  return st;
}

// A <limit> with lower > upper used as a stop: the error, naming the URDF,
// the joint and both values, with `hint` (where to write what instead).
[[noreturn]] void refuse_reversed_limit(const std::string& urdf, const urdf::Joint& j,
                                        const std::string& hint) {
  throw InputError(urdf + ": joint '" + j.name + "': <limit>: lower > upper (got lower=" +
                   format_number(j.limits->lower) + ", upper=" + format_number(j.limits->upper) +
                   "), so it cannot be a stop (" + hint + ")");
}

// The stops `st` of simulated joint j (entry `key` of joints:). A continuous
// joint has no limits (URDF ignores lower/upper on it): no stops by
// default, and asking for one is an error. A limit with lower > upper
// (Bullet's data files use it for "no limit") cannot be a stop; it is only
// refused when used, so such a joint can still be frozen or simulated with
// stops: [].
// A <limit> without lower or upper (`missing`, limits_without_bounds) used
// as a stop: URDF's default 0 and 0 would lock the joint at 0, silently.
// Refused (an input error, not a warning: the run would otherwise show a
// joint that never moves), with `hint`.
[[noreturn]] void refuse_unbounded_limit(const std::string& urdf, const urdf::Joint& j,
                                         const std::string& missing, const std::string& hint) {
  throw InputError(urdf + ": joint '" + j.name + "': <limit>: no " + missing +
                   " (URDF reads a missing bound as 0, so as stops lower = upper = 0 would lock "
                   "the joint at 0; " +
                   hint + ", or give lower and upper in the URDF)");
}

// The joint's missing bounds ("" when both are given).
std::string missing_bounds(const std::map<std::string, std::string>& unbounded,
                           const std::string& joint) {
  const auto it = unbounded.find(joint);
  return it == unbounded.end() ? std::string() : it->second;
}

void check_stops(const urdf::Joint& j, bool explicit_stops, std::vector<std::string>& st,
                 const std::string& source, const std::string& key, const std::string& urdf,
                 const std::map<std::string, std::string>& unbounded) {
  if (j.type == urdf::Joint::CONTINUOUS) {
    if (explicit_stops && !st.empty())
      fail(source, key + ".stops",
           "joint '" + j.name + "' is continuous: it has no limits to stop at (write stops: [])");
    st.clear();
    return;
  }
  if (st.empty()) return;
  if (!j.limits)
    fail(source, key, "joint '" + j.name + "' has no <limit> in " + urdf + " (write stops: [])");
  const std::string hint = source + ": " + key + ": write stops: [] to simulate it without stops";
  if (const std::string missing = missing_bounds(unbounded, j.name); !missing.empty())
    refuse_unbounded_limit(urdf, j, missing, hint);
  if (j.limits->lower > j.limits->upper) refuse_reversed_limit(urdf, j, hint);
}

// The limits of each mimic m of simulated joint `leader` (coordinate i) as
// stops on the leader through q_m = a q_i + b: lower <= a q_i + b <= upper
// gives the rows a e_i (gap b - lower) and -a e_i (gap upper - b), named
// m_lower and m_upper. A row and gap equal to one already present (the
// Panda's fingers: multiplier 1, equal limits) says nothing new and is not
// repeated; a mimic with multiplier 0 or no <limit> adds none.
void add_mimic_stops(const urdf::ModelInterface& um, const std::string& urdf,
                     const std::string& key, const std::map<std::string, Mimic>& mimics,
                     const std::string& leader, Eigen::Index i, Eigen::Index n,
                     const std::vector<std::string>& which, std::vector<VectorXd>& rows,
                     std::vector<double>& gaps, std::vector<std::string>& names,
                     const std::map<std::string, std::string>& unbounded) {
  for (const auto& [name, mm] : mimics) {
    const auto j = um.getJoint(name);
    if (mm.leader != leader || !j->limits || j->type == urdf::Joint::CONTINUOUS ||
        mm.multiplier == 0.0 || which.empty())
      continue;
    const std::string hint =
        key + ": write mimic_stops: [] to follow '" + leader + "' without them";
    if (const std::string missing = missing_bounds(unbounded, name); !missing.empty())
      refuse_unbounded_limit(urdf, *j, missing, hint);
    if (j->limits->lower > j->limits->upper) refuse_reversed_limit(urdf, *j, hint);
    for (const auto& s : which) {
      const double sign = s == "lower" ? 1.0 : -1.0;
      VectorXd r = VectorXd::Zero(n);
      r(i) = sign * mm.multiplier;
      const double gap = s == "lower" ? mm.offset - j->limits->lower : j->limits->upper - mm.offset;
      bool repeated = false;
      for (std::size_t k = 0; k < rows.size(); ++k) repeated |= rows[k] == r && gaps[k] == gap;
      if (repeated) continue;
      rows.push_back(r);
      gaps.push_back(gap);
      names.push_back(name + "_" + s);
    }
  }
}
// Tolerance of a mimic's q0 against its leader's (rad or m, relative to
// max(1, |value|)): published reference poses (SRDF, robot descriptions)
// list every joint with 4 to 6 decimals, so a consistent value is off by
// up to 5e-5 of a unit from rounding; an inconsistent one by a real angle.
constexpr double kMimicQ0Tolerance = 1e-4;

// q0 may name a mimic joint m (robots' reference poses list every joint)
// when it agrees with its leader J: q_m = a q_J + b (J's q0, 0 if not
// named). The value then says nothing new and is dropped (m follows J);
// another value is an error naming both joints.
void check_mimic_q0(std::map<std::string, double>& q0, const std::map<std::string, Mimic>& mimics,
                    const std::string& source) {
  for (const auto& [name, mm] : mimics) {
    const auto it = q0.find(name);
    if (it == q0.end()) continue;
    const auto lead = q0.find(mm.leader);
    const double q_leader = lead == q0.end() ? 0.0 : lead->second;
    const double follows = mm.multiplier * q_leader + mm.offset;
    if (std::abs(it->second - follows) > kMimicQ0Tolerance * std::max(1.0, std::abs(follows)))
      fail(source, "q0." + name,
           "joint '" + name + "' mimics '" + mm.leader + "' (q = " + format_number(mm.multiplier) +
               " q_" + mm.leader + " + " + format_number(mm.offset) + " = " +
               format_number(follows) + " at q0." + mm.leader + " = " + format_number(q_leader) +
               "), got " + format_number(it->second) + "; give q0 for '" + mm.leader +
               "' only, or a value that follows it");
    q0.erase(it);
  }
}

}  // namespace

Scene read_scene(const std::string& yaml_text, const std::string& source) {
  const YAML::Node root = load(yaml_text, source);
  const Keys keys = mapping(root, source, "",
                            {"name", "urdf", "joints", "q0", "gravity", "springs", "constraints",
                             "restitution", "initial", "t_end", "balance_inertia"});
  mech::Model model;
  model.source = source;
  model.name = std::filesystem::path(source).stem().string();
  if (keys.count("name")) model.name = name_of(keys.at("name"), source, "name");

  // The URDF, relative to the scene's directory.
  if (!keys.count("urdf")) fail(source, "urdf", "missing (a scene names its URDF file)");
  const std::string urdf_name = name_of(keys.at("urdf"), source, "urdf");
  const std::filesystem::path urdf_path =
      std::filesystem::path(source).parent_path() / std::filesystem::path(urdf_name);
  std::shared_ptr<urdf::ModelInterface> urdf_model;
  std::map<std::string, std::string> unbounded;  // joints whose <limit> lacks a bound
  UrdfRepairs repairs;
  if (keys.count("balance_inertia"))
    repairs.balance_inertia = boolean(keys.at("balance_inertia"), source, "balance_inertia");
  {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(urdf_path, ec))
      fail(source, "urdf",
           "no such file (got '" + urdf_name + "', looked for '" + urdf_path.string() + "')");
    const std::string xml = read_file(urdf_path);
    urdf_model = parse_urdf(xml, urdf_path.string(), repairs);
    unbounded = limits_without_bounds(xml);
  }
  const urdf::ModelInterface& um = *urdf_model;
  const std::string us = urdf_path.string();

  // Simulated joints and their stops.
  if (!keys.count("joints")) fail(source, "joints", "missing (name the joints to simulate)");
  const YAML::Node& jn = keys.at("joints");
  if (!jn.IsSequence() || jn.size() == 0)
    fail(source, "joints", "expected a non-empty list of joint names (got " + describe(jn) + ")");
  std::vector<std::string> joints;
  std::vector<std::vector<std::string>> stops, mimic_stops;
  for (std::size_t i = 0; i < jn.size(); ++i) {
    const std::string k = "joints[" + std::to_string(i) + "]";
    std::string name;
    std::vector<std::string> st{"lower", "upper"}, mst{"lower", "upper"};
    bool explicit_stops = false;
    if (jn[i].IsMap()) {
      const Keys jk = mapping(jn[i], source, k, {"name", "stops", "mimic_stops"});
      if (!jk.count("name")) fail(source, k + ".name", "missing");
      name = name_of(jk.at("name"), source, k + ".name");
      explicit_stops = jk.count("stops") > 0;
      if (explicit_stops) st = stop_list(jk.at("stops"), source, k + ".stops");
      if (jk.count("mimic_stops"))
        mst = stop_list(jk.at("mimic_stops"), source, k + ".mimic_stops");
    } else {
      name = name_of(jn[i], source, k);
    }
    const auto j = um.getJoint(name);
    if (!j) fail(source, k, "no joint '" + name + "' in " + us);
    if (j->type != urdf::Joint::REVOLUTE && j->type != urdf::Joint::PRISMATIC &&
        j->type != urdf::Joint::CONTINUOUS)
      fail(source, k,
           "joint '" + name +
               "' is not revolute, continuous or prismatic (only those can be simulated; leave "
               "it out to freeze it)");
    if (std::count(joints.begin(), joints.end(), name))
      fail(source, k, "duplicate joint '" + name + "'");
    check_stops(*j, explicit_stops, st, source, k, us, unbounded);
    joints.push_back(name);
    stops.push_back(st);
    mimic_stops.push_back(mst);
  }
  const std::map<std::string, Mimic> mimics = mimic_joints(um, us, joints);
  const auto N = static_cast<Eigen::Index>(joints.size());
  const auto coord = [&](const std::string& n) -> Eigen::Index {
    return std::find(joints.begin(), joints.end(), n) - joints.begin();
  };
  const auto simulated = [&](const std::string& n) -> std::string {
    if (!um.getJoint(n)) return "no joint '" + n + "' in " + us;
    if (mimics.count(n))
      return "joint '" + n + "' mimics '" + mimics.at(n).leader +
             "' (it follows its leader and is not a coordinate)";
    if (coord(n) == N)
      return "joint '" + n +
             "' is frozen (not in joints:); only simulated joints can carry springs, constraints "
             "and initial values";
    return "";
  };

  std::map<std::string, double> q0;
  if (keys.count("q0"))
    q0 = by_joint(keys.at("q0"), source, "q0", [&](const std::string& n) -> std::string {
      const auto j = um.getJoint(n);
      if (!j) return "no joint '" + n + "' in " + us;
      if (j->type != urdf::Joint::REVOLUTE && j->type != urdf::Joint::PRISMATIC &&
          j->type != urdf::Joint::CONTINUOUS)
        return "joint '" + n + "' has no position (not revolute, continuous or prismatic)";
      return "";
    });
  check_mimic_q0(q0, mimics, source);

  Eigen::Vector3d gravity(0.0, 0.0, -9.81);
  if (keys.count("gravity")) {
    const YAML::Node& g = keys.at("gravity");
    if (!g.IsSequence() || g.size() != 3)
      fail(source, "gravity", "expected a vector of 3 numbers in m/s^2 (got " + describe(g) + ")");
    for (std::size_t i = 0; i < 3; ++i)
      gravity(static_cast<Eigen::Index>(i)) =
          number(g[i], source, "gravity[" + std::to_string(i) + "]");
  }

  const UrdfLinearisation lin = linearise_urdf(um, joints, q0, gravity, us);
  VectorXd q0v = VectorXd::Zero(N);
  for (Eigen::Index i = 0; i < N; ++i)
    if (q0.count(joints[static_cast<std::size_t>(i)]))
      q0v(i) = q0.at(joints[static_cast<std::size_t>(i)]);

  // Scenes are small (one coordinate per simulated joint): assembled dense,
  // stored sparse (mech::MechanicalModel) at the end.
  mech::MechanicalModel m;
  MatrixXd D = MatrixXd(lin.damping.asDiagonal());
  MatrixXd K = lin.K_g;
  m.f = lin.tau_g + lin.K_g * q0v;
  m.coordinates = joints;

  if (keys.count("springs")) {
    const YAML::Node& sn = keys.at("springs");
    if (!sn.IsSequence()) fail(source, "springs", "expected a list (got " + describe(sn) + ")");
    for (std::size_t i = 0; i < sn.size(); ++i) {
      const std::string k = "springs[" + std::to_string(i) + "]";
      const Keys sk =
          mapping(sn[i], source, k, {"name", "joint", "other", "stiffness", "damping", "rest"});
      if (!sk.count("joint")) fail(source, k + ".joint", "missing");
      VectorXd c = VectorXd::Zero(N);
      for (const char* role : {"joint", "other"}) {
        if (!sk.count(role)) continue;
        const std::string rk = k + "." + role;
        const std::string jn2 = name_of(sk.at(role), source, rk);
        const std::string why = simulated(jn2);
        if (!why.empty()) fail(source, rk, why);
        c(coord(jn2)) += std::string(role) == "joint" ? 1.0 : -1.0;
      }
      if (c.isZero()) fail(source, k + ".other", "a spring between a joint and itself");
      double stiffness = 0.0, damping = 0.0, rest = 0.0;
      if (sk.count("stiffness")) stiffness = number(sk.at("stiffness"), source, k + ".stiffness");
      if (sk.count("damping")) damping = number(sk.at("damping"), source, k + ".damping");
      if (sk.count("rest")) rest = number(sk.at("rest"), source, k + ".rest");
      if (stiffness < 0.0)
        fail(source, k + ".stiffness", "must be >= 0 (got " + format_number(stiffness) + ")");
      if (damping < 0.0)
        fail(source, k + ".damping", "must be >= 0 (got " + format_number(damping) + ")");
      K += stiffness * c * c.transpose();
      D += damping * c * c.transpose();
      m.f += stiffness * rest * c;
    }
  }

  // Constraints: joint stops first (joint order, lower before upper), then
  // the scene's constraints in file order.
  std::vector<VectorXd> rows;
  std::vector<double> gaps;
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const auto j = um.getJoint(joints[i]);
    for (const auto& s : stops[i]) {
      VectorXd r = VectorXd::Zero(N);
      if (s == "lower") {
        r(static_cast<Eigen::Index>(i)) = 1.0;  // q - lower >= 0
        gaps.push_back(-j->limits->lower);
      } else {
        r(static_cast<Eigen::Index>(i)) = -1.0;  // upper - q >= 0
        gaps.push_back(j->limits->upper);
      }
      rows.push_back(r);
      m.constraints.push_back(joints[i] + "_" + s);
    }
    add_mimic_stops(um, us, source + ": joints[" + std::to_string(i) + "]", mimics, joints[i],
                    static_cast<Eigen::Index>(i), N, mimic_stops[i], rows, gaps, m.constraints,
                    unbounded);
  }
  if (keys.count("constraints")) {
    const YAML::Node& cn = keys.at("constraints");
    if (!cn.IsSequence()) fail(source, "constraints", "expected a list (got " + describe(cn) + ")");
    for (std::size_t i = 0; i < cn.size(); ++i) {
      const std::string k = "constraints[" + std::to_string(i) + "]";
      const Keys ck = mapping(cn[i], source, k, {"name", "coefficients", "g"});
      if (!ck.count("name")) fail(source, k + ".name", "missing");
      if (!ck.count("coefficients")) fail(source, k + ".coefficients", "missing");
      const std::string name = name_of(ck.at("name"), source, k + ".name");
      VectorXd r = VectorXd::Zero(N);
      for (const auto& [jname, c] :
           by_joint(ck.at("coefficients"), source, k + ".coefficients", simulated))
        r(coord(jname)) = c;
      if (r.isZero()) fail(source, k + ".coefficients", "all zero (the constraint says nothing)");
      rows.push_back(r);
      gaps.push_back(ck.count("g") ? number(ck.at("g"), source, k + ".g") : 0.0);
      m.constraints.push_back(name);
    }
  }
  {
    std::set<std::string> seen;
    for (const auto& c : m.constraints)
      if (!seen.insert(c).second)
        fail(source, "constraints", "duplicate constraint name '" + c + "'");
  }
  const auto k = static_cast<Eigen::Index>(rows.size());
  MatrixXd E = MatrixXd::Zero(k, N);
  m.g = VectorXd::Zero(k);
  for (Eigen::Index i = 0; i < k; ++i) {
    E.row(i) = rows[static_cast<std::size_t>(i)].transpose();
    m.g(i) = gaps[static_cast<std::size_t>(i)];
  }
  m.M = lin.M.sparseView();
  m.D = D.sparseView();
  m.K = K.sparseView();
  m.E = E.sparseView();
  m.restitution = VectorXd::Zero(k);
  if (keys.count("restitution")) {
    for (const auto& [name, e] :
         by_joint(keys.at("restitution"), source, "restitution",
                  [&](const std::string& n) -> std::string {
                    if (!std::count(m.constraints.begin(), m.constraints.end(), n))
                      return "no constraint '" + n + "' (the constraints are " +
                             join(m.constraints) + ")";
                    return "";
                  })) {
      if (e < 0.0 || e > 1.0)
        fail(source, "restitution." + name, "outside [0, 1] (got " + format_number(e) + ")");
      m.restitution(std::find(m.constraints.begin(), m.constraints.end(), name) -
                    m.constraints.begin()) = e;
    }
  }

  // M must be symmetric positive definite (the CRBA makes it symmetric by
  // construction; a massless subtree makes it singular).
  {
    const Eigen::SelfAdjointEigenSolver<MatrixXd> es(lin.M);
    const double eps = std::numeric_limits<double>::epsilon();
    if (es.eigenvalues().minCoeff() <=
        static_cast<double>(N) * eps * std::abs(es.eigenvalues().maxCoeff())) {
      // The joints that move along the null direction (its largest
      // components: a unit vector has one of at least 1/sqrt(N)).
      const VectorXd v = es.eigenvectors().col(0).cwiseAbs();
      std::vector<std::string> which;
      for (Eigen::Index i = 0; i < N; ++i)
        if (v(i) >= 0.5 * v.maxCoeff())
          which.push_back("'" + joints[static_cast<std::size_t>(i)] + "'");
      fail(source, "joints",
           "the mass matrix at q0 is not positive definite (smallest eigenvalue " +
               format_number(es.eigenvalues().minCoeff()) + ", along joint " + join(which) +
               "): the joint moves no inertia about its axis (a point mass or massless links on "
               "the axis)");
    }
  }

  // The initial state: q0 at rest, except the positions and velocities that
  // `initial` names; a scene without `initial` starts at q0 at rest.
  {
    VectorXd x(2 * N);
    x << q0v, VectorXd::Zero(N);
    const Keys ik =
        keys.count("initial") ? mapping(keys.at("initial"), source, "initial", {"q", "v"}) : Keys{};
    for (const char* part : {"q", "v"}) {
      if (!ik.count(part)) continue;
      for (const auto& [jname, val] :
           by_joint(ik.at(part), source, std::string("initial.") + part, simulated))
        x(coord(jname) + (std::string(part) == "v" ? N : 0)) = val;
    }
    model.initial = x;
  }
  if (keys.count("t_end")) {
    model.t_end = number(keys.at("t_end"), source, "t_end");
    if (!(model.t_end > 0.0))
      fail(source, "t_end", "must be > 0 (got " + format_number(model.t_end) + ")");
  }
  mech::fill_defaults(m);
  model.mechanical = m;
  Scene scene{std::move(model), urdf_model, us, q0, gravity, lin, std::move(repairs.notes)};
  return scene;
}

mech::Model parse_scene(const std::string& yaml_text, const std::string& source) {
  return read_scene(yaml_text, source).model;
}

mech::Model parse_model(const std::string& yaml_text, const std::string& source) {
  const YAML::Node root = io::load_model_root(yaml_text, source);
  // A top-level `urdf:` key makes the file a scene.
  if (io::is_scene(root)) {
    try {
      return parse_scene(yaml_text, source);
    } catch (const InputError& e) {
      throw InputError(io::one_line(e.what()));  // URDF names and values may hold newlines
    }
  }
  return io::parse_matrix_model(root, source);
}

mech::Model load_model(const std::filesystem::path& path) {
  return parse_model(io::read_file(path), path.string());
}

LoadedModel load_model_and_scene(const std::filesystem::path& path) {
  const std::string text = read_file(path);
  const YAML::Node root = load_model_root(text, path.string());
  if (!is_scene(root)) return {io::parse_matrix_model(root, path.string()), std::nullopt};
  try {
    Scene scene = read_scene(text, path.string());
    mech::Model model = scene.model;
    return {std::move(model), std::move(scene)};
  } catch (const InputError& e) {
    throw InputError(one_line(e.what()));  // as load_model: URDF names may hold newlines
  }
}

std::vector<std::string> model_notes(const LoadedModel& loaded) {
  std::vector<std::string> notes = loaded.scene ? loaded.scene->notes : std::vector<std::string>{};
  for (std::string& n : io::model_notes(loaded.model)) notes.push_back(std::move(n));
  return notes;
}

std::optional<Scene> load_scene_details(const std::filesystem::path& path) {
  return load_model_and_scene(path).scene;
}

namespace {

bool same_matrix(const mech::SparseMatrix& a, const mech::SparseMatrix& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() && MatrixXd(a) == MatrixXd(b);
}

bool same_vector(const VectorXd& a, const VectorXd& b) { return a.size() == b.size() && a == b; }

// The same model up to the restitution: a restitution is a parameter of the
// constraints, not of the scene's bodies (the URDF has none; a study's
// restitution axis changes it, issue 24), so a scene with another one is
// still that scene.
bool same_model(const mech::MechanicalModel& a, const mech::MechanicalModel& b) {
  return same_matrix(a.M, b.M) && same_matrix(a.D, b.D) && same_matrix(a.K, b.K) &&
         same_matrix(a.E, b.E) && same_vector(a.g, b.g) && same_vector(a.f, b.f) &&
         a.restitution.size() == b.restitution.size() && a.coordinates == b.coordinates &&
         a.constraints == b.constraints;
}

}  // namespace

std::optional<Scene> scene_setup(const mech::Model& model) {
  if (!model.is_mechanical()) return std::nullopt;
  try {
    std::optional<Scene> scene = load_scene_details(model.source);
    if (!scene || !same_model(*scene->model.mechanical, *model.mechanical)) return std::nullopt;
    scene->model.mechanical->restitution = model.mechanical->restitution;  // the model's own
    return scene;
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

mech::Model load_scene(const std::filesystem::path& path) {
  return parse_scene(read_file(path), path.string());
}

}  // namespace lcsim::scene
