// Stops: a simulated joint's <limit> as unilateral constraints (the
// `stops:` and `mimic_stops:` of an entry of `joints:`), and the limits of
// the joints that mimic it, as stops on it.
#include <urdf_model/model.h>

#include <algorithm>
#include <lcsim/io/text.hpp>
#include <lcsim/io/yaml.hpp>

#include "scene/detail.hpp"

namespace lcsim::scene {

using io::format_number;
using io::yaml::describe;
using io::yaml::fail;

namespace {

// A <limit> with lower > upper used as a stop: the error, naming the URDF,
// the joint and both values, with `hint` (where to write what instead).
[[noreturn]] void refuse_reversed_limit(const std::string& urdf, const urdf::Joint& j,
                                        const std::string& hint) {
  throw InputError(urdf + ": joint '" + j.name + "': <limit>: lower > upper (got lower=" +
                   format_number(j.limits->lower) + ", upper=" + format_number(j.limits->upper) +
                   "), so it cannot be a stop (" + hint + ")");
}

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

// The limits of each mimic m of simulated joint `leader` (coordinate i) as
// stops on the leader through q_m = a q_i + b: lower <= a q_i + b <= upper
// gives the rows a e_i (gap b - lower) and -a e_i (gap upper - b), named
// m_lower and m_upper. A row and gap equal to one already present (the
// Panda's fingers: multiplier 1, equal limits) says nothing new and is not
// repeated; a mimic with multiplier 0 or no <limit> adds none.
void add_mimic_stops(const SceneUrdf& urdf, const std::string& key,
                     const std::map<std::string, Mimic>& mimics, const std::string& leader,
                     Eigen::Index i, Eigen::Index n, const std::vector<std::string>& which,
                     SceneConstraints& out) {
  for (const auto& [name, mm] : mimics) {
    const auto j = urdf.model->getJoint(name);
    if (mm.leader != leader || !j->limits || j->type == urdf::Joint::CONTINUOUS ||
        mm.multiplier == 0.0 || which.empty())
      continue;
    const std::string hint =
        key + ": write mimic_stops: [] to follow '" + leader + "' without them";
    if (const std::string missing = missing_bounds(urdf.unbounded, name); !missing.empty())
      refuse_unbounded_limit(urdf.path, *j, missing, hint);
    if (j->limits->lower > j->limits->upper) refuse_reversed_limit(urdf.path, *j, hint);
    for (const auto& s : which) {
      const double sign = s == "lower" ? 1.0 : -1.0;
      VectorXd r = VectorXd::Zero(n);
      r(i) = sign * mm.multiplier;
      const double gap = s == "lower" ? mm.offset - j->limits->lower : j->limits->upper - mm.offset;
      bool repeated = false;
      for (std::size_t k = 0; k < out.rows.size(); ++k)
        repeated |= out.rows[k] == r && out.gaps[k] == gap;
      if (repeated) continue;
      out.add(r, gap, name + "_" + s);
    }
  }
}

}  // namespace

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

// A continuous joint has no limits (URDF ignores lower/upper on it): no
// stops by default, and asking for one is an error. A limit with lower >
// upper (Bullet's data files use it for "no limit") cannot be a stop; it is
// only refused when used, so such a joint can still be frozen or simulated
// with stops: [].
void check_stops(const urdf::Joint& j, bool explicit_stops, std::vector<std::string>& st,
                 const std::string& source, const std::string& key, const SceneUrdf& urdf) {
  if (j.type == urdf::Joint::CONTINUOUS) {
    if (explicit_stops && !st.empty())
      fail(source, key + ".stops",
           "joint '" + j.name + "' is continuous: it has no limits to stop at (write stops: [])");
    st.clear();
    return;
  }
  if (st.empty()) return;
  if (!j.limits)
    fail(source, key,
         "joint '" + j.name + "' has no <limit> in " + urdf.path + " (write stops: [])");
  const std::string hint = source + ": " + key + ": write stops: [] to simulate it without stops";
  if (const std::string missing = missing_bounds(urdf.unbounded, j.name); !missing.empty())
    refuse_unbounded_limit(urdf.path, j, missing, hint);
  if (j.limits->lower > j.limits->upper) refuse_reversed_limit(urdf.path, j, hint);
}

SceneConstraints joint_stops(const std::string& source, const SceneUrdf& urdf,
                             const SceneJoints& joints) {
  SceneConstraints out;
  const Eigen::Index N = joints.size();
  for (std::size_t i = 0; i < joints.names.size(); ++i) {
    const auto j = urdf.model->getJoint(joints.names[i]);
    for (const auto& s : joints.stops[i]) {
      VectorXd r = VectorXd::Zero(N);
      if (s == "lower") {
        r(static_cast<Eigen::Index>(i)) = 1.0;  // q - lower >= 0
        out.add(r, -j->limits->lower, joints.names[i] + "_" + s);
      } else {
        r(static_cast<Eigen::Index>(i)) = -1.0;  // upper - q >= 0
        out.add(r, j->limits->upper, joints.names[i] + "_" + s);
      }
    }
    add_mimic_stops(urdf, source + ": joints[" + std::to_string(i) + "]", joints.mimics,
                    joints.names[i], static_cast<Eigen::Index>(i), N, joints.mimic_stops[i], out);
  }
  return out;
}

}  // namespace lcsim::scene
