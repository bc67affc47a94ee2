// URDF models (urdfdom) and their linearisation about a reference
// configuration: the joint-space mass matrix by the composite-rigid-body
// algorithm, the gravity generalised force and the gravity stiffness.
//
// Spatial algebra, all in the URDF root frame (the "world", a fixed base):
// a twist is (omega, v0) with v0 the velocity of the material point at the
// world origin; a wrench is (n0, F) with n0 the moment about the origin, so
// power = twist . wrench. The spatial inertia of a body of mass m, centre of
// mass c and rotational inertia I_c about c (world axes) is
//   I = [ I_c + m [c]x [c]x^T   m [c]x ]
//       [ m [c]x^T              m 1    ]
// and, with S_i the motion subspace (6-vector) of joint i and Ic_i the sum of
// the inertias of every body moved by joint i (the composite body), the mass
// matrix is M_ij = S_j^T Ic_i S_i for j an ancestor of (or equal to) i and 0
// for joints on different branches (Featherstone, Rigid Body Dynamics
// Algorithms, §6.2; expressed in world coordinates no transforms between
// body frames are needed).
#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Geometry>
#include <cmath>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>

#include "io/detail.hpp"
#include "io/io.hpp"

namespace lcsim::io {

namespace {

using Eigen::Isometry3d;
using Eigen::Matrix3d;
using Eigen::Vector3d;
using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

[[noreturn]] void fail(const std::string& source, const std::string& element,
                       const std::string& what) {
  throw InputError(source + ": " + element + ": " + what);
}

std::string num(double x) { return format_number(x); }

Matrix3d skew(const Vector3d& c) {
  Matrix3d s;
  s << 0, -c.z(), c.y(), c.z(), 0, -c.x(), -c.y(), c.x(), 0;
  return s;
}

Vector3d vec(const urdf::Vector3& v) { return {v.x, v.y, v.z}; }

Isometry3d pose(const urdf::Pose& p) {
  Isometry3d X = Isometry3d::Identity();
  X.linear() = Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z)
                   .normalized()
                   .toRotationMatrix();
  X.translation() = vec(p.position);
  return X;
}

bool moves(const urdf::Joint& j) {
  return j.type == urdf::Joint::REVOLUTE || j.type == urdf::Joint::CONTINUOUS ||
         j.type == urdf::Joint::PRISMATIC;
}

// The joint's own motion at position q (child frame relative to the joint
// frame). Frozen floating and planar joints sit at their origin.
Isometry3d motion(const urdf::Joint& j, double q) {
  Isometry3d X = Isometry3d::Identity();
  const Vector3d a = vec(j.axis).normalized();
  if (j.type == urdf::Joint::REVOLUTE || j.type == urdf::Joint::CONTINUOUS)
    X.linear() = Eigen::AngleAxisd(q, a).toRotationMatrix();
  else if (j.type == urdf::Joint::PRISMATIC)
    X.translation() = q * a;
  return X;
}

bool finite_pose(const urdf::Pose& p) {
  return std::isfinite(p.position.x) && std::isfinite(p.position.y) &&
         std::isfinite(p.position.z) && std::isfinite(p.rotation.x) &&
         std::isfinite(p.rotation.y) && std::isfinite(p.rotation.z) && std::isfinite(p.rotation.w);
}

void check_urdf(const urdf::ModelInterface& m, const std::string& source) {
  // urdfdom accepts a joint whose parent is its own child (it only looks for
  // a root): the link then lists itself among its children and every walk
  // down the tree recurses for ever. Refuse it, and any link reached twice.
  for (const auto& [name, joint] : m.joints_)
    if (joint->parent_link_name == joint->child_link_name)
      fail(source, "joint '" + name + "'",
           "parent and child are the same link '" + joint->parent_link_name +
               "' (the joints must form a tree)");
  if (const auto root = m.getRoot()) {
    std::set<const urdf::Link*> seen;
    std::vector<const urdf::Link*> todo{root.get()};
    while (!todo.empty()) {
      const urdf::Link* l = todo.back();
      todo.pop_back();
      if (!seen.insert(l).second)
        fail(source, "link '" + l->name + "'",
             "reached twice from the root (the joints must form a tree)");
      for (const auto& c : l->child_links) todo.push_back(c.get());
    }
  }
  for (const auto& [name, link] : m.links_) {
    if (!link->inertial) continue;
    const urdf::Inertial& in = *link->inertial;
    const std::string el = "link '" + name + "': <inertial>";
    if (!finite_pose(in.origin)) fail(source, el + " <origin>", "not finite");
    if (!std::isfinite(in.mass) || in.mass < 0.0)
      fail(source, el + " <mass value>", "must be finite and >= 0 (got " + num(in.mass) + ")");
    for (double x : {in.ixx, in.ixy, in.ixz, in.iyy, in.iyz, in.izz})
      if (!std::isfinite(x)) fail(source, el + " <inertia>", "not finite (got " + num(x) + ")");
  }
  for (const auto& [name, joint] : m.joints_) {
    const std::string el = "joint '" + name + "'";
    if (!finite_pose(joint->parent_to_joint_origin_transform))
      fail(source, el + ": <origin>", "not finite");
    const Vector3d a = vec(joint->axis);
    if (moves(*joint) && (!a.allFinite() || a.norm() == 0.0))
      fail(source, el + ": <axis xyz>",
           "must be finite and non-zero (got " + num(a.x()) + " " + num(a.y()) + " " + num(a.z()) +
               ")");
    if (joint->limits) {
      const urdf::JointLimits& l = *joint->limits;
      if (!std::isfinite(l.lower) || !std::isfinite(l.upper))
        fail(source, el + ": <limit>",
             "lower and upper must be finite (got lower=" + num(l.lower) +
                 ", upper=" + num(l.upper) + ")");
      if (moves(*joint) && joint->type != urdf::Joint::CONTINUOUS && l.lower > l.upper)
        fail(source, el + ": <limit>",
             "lower > upper (got lower=" + num(l.lower) + ", upper=" + num(l.upper) + ")");
    }
    if (joint->dynamics) {
      const double d = joint->dynamics->damping;
      if (!std::isfinite(d) || d < 0.0)
        fail(source, el + ": <dynamics damping>", "must be finite and >= 0 (got " + num(d) + ")");
    }
  }
}

// The scene's tree: every link, its world pose at a configuration and the
// simulated joint that moves it as a rigid part of its body (-1: the world).
struct Tree {
  const urdf::ModelInterface& model;
  std::vector<std::string> joints;      // simulated, coordinate order
  std::map<std::string, int> index;     // simulated joint -> coordinate
  std::vector<int> parent;              // parent coordinate of each (-1: world)
  std::map<std::string, int> owner;     // link -> coordinate moving it rigidly
  std::vector<std::string> link_order;  // root first (depth first)
};

Tree make_tree(const urdf::ModelInterface& model, const std::vector<std::string>& joints,
               const std::string& source) {
  Tree t{model, joints, {}, {}, {}, {}};
  if (!model.getRoot()) fail(source, "<robot>", "no root link");
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const auto j = model.getJoint(joints[i]);
    if (!j) fail(source, "joint '" + joints[i] + "'", "no such joint in the URDF");
    if (j->type != urdf::Joint::REVOLUTE && j->type != urdf::Joint::PRISMATIC)
      fail(source, "joint '" + joints[i] + "'",
           "unsupported type for a simulated joint (only revolute and prismatic joints can be "
           "simulated; freeze it by leaving it out of the scene)");
    t.index[joints[i]] = static_cast<int>(i);
  }
  t.parent.assign(joints.size(), -1);
  std::function<void(const urdf::Link&, int)> walk = [&](const urdf::Link& link, int owner) {
    t.owner[link.name] = owner;
    t.link_order.push_back(link.name);
    for (const auto& cj : link.child_joints) {
      int child_owner = owner;
      const auto it = t.index.find(cj->name);
      if (it != t.index.end()) {
        t.parent[static_cast<std::size_t>(it->second)] = owner;
        child_owner = it->second;
      }
      walk(*model.getLink(cj->child_link_name), child_owner);
    }
  };
  walk(*model.getRoot(), -1);
  return t;
}

// World pose of every link with simulated and frozen joints at q (by name).
std::map<std::string, Isometry3d> link_poses(const Tree& t,
                                             const std::map<std::string, double>& q) {
  std::map<std::string, Isometry3d> X;
  X[t.model.getRoot()->name] = Isometry3d::Identity();
  for (const auto& name : t.link_order) {
    const auto link = t.model.getLink(name);
    for (const auto& cj : link->child_joints) {
      const auto qi = q.find(cj->name);
      X[cj->child_link_name] = X[name] * pose(cj->parent_to_joint_origin_transform) *
                               motion(*cj, qi == q.end() ? 0.0 : qi->second);
    }
  }
  return X;
}

// Motion subspace of simulated joint `name` in world coordinates.
Vector6d subspace(const Tree& t, const std::string& name,
                  const std::map<std::string, Isometry3d>& X) {
  const auto j = t.model.getJoint(name);
  const Isometry3d& Xc = X.at(j->child_link_name);  // joint frame after its motion
  const Vector3d a = Xc.linear() * vec(j->axis).normalized();
  Vector6d S;
  if (j->type == urdf::Joint::PRISMATIC)
    S << Vector3d::Zero(), a;
  else
    S << a, Xc.translation().cross(a);
  return S;
}

struct LinkInertia {
  double m;
  Vector3d c;   // world centre of mass
  Matrix3d Ic;  // about c, world axes
};

LinkInertia link_inertia(const urdf::Link& link, const Isometry3d& X) {
  const urdf::Inertial& in = *link.inertial;
  const Isometry3d Xi = X * pose(in.origin);
  Matrix3d I;
  I << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
  return {in.mass, Xi.translation(), Xi.linear() * I * Xi.linear().transpose()};
}

Matrix6d spatial(const LinkInertia& b) {
  const Matrix3d C = skew(b.c);
  Matrix6d I;
  I << b.Ic + b.m * C * C.transpose(), b.m * C, b.m * C.transpose(), b.m * Matrix3d::Identity();
  return I;
}

// Calls f(i) for coordinate `o` and each of its ancestors.
template <class F>
void up(const Tree& t, int o, F f) {
  for (int b = o; b >= 0; b = t.parent[static_cast<std::size_t>(b)]) f(b);
}

MatrixXd crba(const Tree& t, const std::map<std::string, double>& q) {
  const auto X = link_poses(t, q);
  const auto n = static_cast<Eigen::Index>(t.joints.size());
  std::vector<Matrix6d> Ic(t.joints.size(), Matrix6d::Zero());
  for (const auto& name : t.link_order) {
    const auto link = t.model.getLink(name);
    const int o = t.owner.at(name);
    if (o < 0 || !link->inertial) continue;
    const Matrix6d I = spatial(link_inertia(*link, X.at(name)));
    up(t, o, [&](int b) { Ic[static_cast<std::size_t>(b)] += I; });
  }
  std::vector<Vector6d> S;
  for (const auto& j : t.joints) S.push_back(subspace(t, j, X));
  MatrixXd M = MatrixXd::Zero(n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    const Vector6d F = Ic[ui] * S[ui];
    up(t, static_cast<int>(i),
       [&](int j) { M(i, j) = M(j, i) = S[static_cast<std::size_t>(j)].dot(F); });
  }
  return M;
}

// tau_g,i = S_i . (sum of the gravity wrenches (c x m g, m g) of the bodies
// joint i moves).
VectorXd gravity_force(const Tree& t, const std::map<std::string, double>& q,
                       const Vector3d& gravity) {
  const auto X = link_poses(t, q);
  std::vector<Vector6d> F(t.joints.size(), Vector6d::Zero());
  for (const auto& name : t.link_order) {
    const auto link = t.model.getLink(name);
    const int o = t.owner.at(name);
    if (o < 0 || !link->inertial) continue;
    const LinkInertia b = link_inertia(*link, X.at(name));
    Vector6d w;
    w << b.c.cross(b.m * gravity), b.m * gravity;
    up(t, o, [&](int k) { F[static_cast<std::size_t>(k)] += w; });
  }
  VectorXd tau(static_cast<Eigen::Index>(t.joints.size()));
  for (std::size_t i = 0; i < t.joints.size(); ++i)
    tau(static_cast<Eigen::Index>(i)) = subspace(t, t.joints[i], X).dot(F[i]);
  return tau;
}

// Collects urdfdom's messages (sent through console_bridge) while it
// parses, so that the InputError can quote its errors: they name the element.
// Installed for the duration of one parse; console_bridge's handler is
// process-global, so parsing is not thread-safe (neither is urdfdom's log).
class CapturedLog : public console_bridge::OutputHandler {
 public:
  CapturedLog() { console_bridge::useOutputHandler(this); }
  ~CapturedLog() override { console_bridge::restorePreviousOutputHandler(); }
  CapturedLog(const CapturedLog&) = delete;
  CapturedLog& operator=(const CapturedLog&) = delete;
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level < console_bridge::CONSOLE_BRIDGE_LOG_ERROR) return;
    std::string t = text;
    while (!t.empty() && (t.back() == '\n' || t.back() == ' ' || t.back() == '.')) t.pop_back();
    if (!t.empty()) text_ += (text_.empty() ? "" : "; ") + t;
  }
  const std::string& text() const { return text_; }

 private:
  std::string text_;
};

}  // namespace

namespace {
// Every error of the URDF path is one line: names and values in a URDF may
// hold newlines (found by fuzz_scene), so the public entry points fold them.
template <class F>
auto one_line_errors(F&& f) {
  try {
    return f();
  } catch (const InputError& e) {
    throw InputError(one_line(e.what()));
  }
}
}  // namespace

static std::shared_ptr<urdf::ModelInterface> parse_urdf_unfolded(const std::string& xml,
                                                                 const std::string& source) {
  urdf::ModelInterfaceSharedPtr m;
  std::string log;
  try {
    const CapturedLog capture;
    try {
      m = urdf::parseURDF(xml);
    } catch (const std::exception& e) {
      throw InputError(source + ": not a valid URDF: " + one_line(e.what()));
    }
    log = capture.text();
  } catch (const InputError&) {
    throw;
  }
  // urdfdom reports some bad elements (e.g. a non-numeric <mass value>) as
  // errors but goes on without them: refuse those as well.
  if (!m || !log.empty())
    throw InputError(source + ": not a valid URDF: " +
                     one_line(log.empty() ? std::string("urdfdom refused it") : log));
  check_urdf(*m, source);
  return m;
}

std::shared_ptr<urdf::ModelInterface> load_urdf(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw InputError(path.string() + ": cannot open URDF: no such file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open URDF: unreadable");
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_urdf(ss.str(), path.string());
}

std::shared_ptr<urdf::ModelInterface> parse_urdf(const std::string& xml,
                                                 const std::string& source) {
  return one_line_errors([&] { return parse_urdf_unfolded(xml, source); });
}

static UrdfLinearisation linearise_urdf_unfolded(const urdf::ModelInterface& model,
                                                 const std::vector<std::string>& joints,
                                                 const std::map<std::string, double>& q0,
                                                 const Eigen::Vector3d& gravity,
                                                 const std::string& source) {
  const Tree t = make_tree(model, joints, source);
  // A simulated joint must move some mass: its body (its child link and the
  // links frozen to it) needs an <inertial> with mass > 0.
  for (std::size_t i = 0; i < joints.size(); ++i) {
    double mass = 0.0;
    for (const auto& [name, o] : t.owner)
      if (o == static_cast<int>(i) && model.getLink(name)->inertial)
        mass += model.getLink(name)->inertial->mass;
    if (!(mass > 0.0))
      fail(source, "link '" + model.getJoint(joints[i])->child_link_name + "'",
           "moved by joint '" + joints[i] +
               "' but it (with the links fixed or frozen to it) has no <inertial> mass "
               "(got total mass " +
               num(mass) + ")");
  }
  UrdfLinearisation lin;
  lin.joints = joints;
  lin.M = crba(t, q0);
  lin.tau_g = gravity_force(t, q0, gravity);
  // Gravity stiffness by central differences: tau_g is a sum of products of
  // sines and cosines (revolute) and polynomials of degree <= 1 (prismatic)
  // of q, so the error is h^2/6 |tau'''| (truncation) + eps |tau| / h
  // (rounding). h = 6e-6 ~ eps^(1/3) balances them: both are about 1e-11
  // relative to the scale of tau_g (|tau'''| ~ |tau| for lever arms ~1 m;
  // h is absolute, in rad or m). The result is symmetrised (it is minus the
  // Hessian of the potential energy), which does not increase that error.
  const double h = 6e-6;
  const auto n = static_cast<Eigen::Index>(joints.size());
  lin.K_g = MatrixXd::Zero(n, n);
  for (Eigen::Index j = 0; j < n; ++j) {
    auto qp = q0, qm = q0;
    const std::string& name = joints[static_cast<std::size_t>(j)];
    qp[name] = (q0.count(name) ? q0.at(name) : 0.0) + h;
    qm[name] = (q0.count(name) ? q0.at(name) : 0.0) - h;
    lin.K_g.col(j) = -(gravity_force(t, qp, gravity) - gravity_force(t, qm, gravity)) / (2 * h);
  }
  lin.K_g = (0.5 * (lin.K_g + lin.K_g.transpose())).eval();
  lin.damping = VectorXd::Zero(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto j = model.getJoint(joints[static_cast<std::size_t>(i)]);
    if (j->dynamics) lin.damping(i) = j->dynamics->damping;
  }
  return lin;
}

UrdfLinearisation linearise_urdf(const urdf::ModelInterface& model,
                                 const std::vector<std::string>& joints,
                                 const std::map<std::string, double>& q0,
                                 const Eigen::Vector3d& gravity, const std::string& source) {
  return one_line_errors(
      [&] { return linearise_urdf_unfolded(model, joints, q0, gravity, source); });
}

}  // namespace lcsim::io
