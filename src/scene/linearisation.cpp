// How far a scene's linear model holds: the exact mass matrix and forces of
// its URDF at visited or probed configurations against the linear model
// (definitions in io.hpp, "How far the linear model holds", and
// docs/model-format.md, "Where the linear model holds").
#include <urdf_model/model.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <lcsim/core/format.hpp>
#include <lcsim/io/json.hpp>
#include <lcsim/io/text.hpp>
#include <lcsim/scene/linearisation.hpp>
#include <limits>
#include <stdexcept>

#include "scene/detail.hpp"

namespace lcsim::scene {

using io::format_number;
using io::one_line;
using io::to_json;

namespace {

// e_M, e_F and e_C at q for the linear model (M0, f, K, the contacts' rows)
// and the exact dynamics and geometry.
struct Errors {
  double mass = 0.0, force = 0.0, contact = 0.0;
  std::size_t worst_contact = 0;  // where e_C is largest
  double max() const { return std::max({mass, force, contact}); }
};

// Each contact's plane (nullptr against a body) and point at q0, for e_C.
struct ContactsAtStart {
  std::vector<const Plane*> planes;
  std::vector<Eigen::Vector3d> seen;
};
ContactsAtStart contacts_at_start(const Scene& s, const Bodies& dyn, const VectorXd& q0) {
  ContactsAtStart c;
  for (const ContactFrame& f : s.contacts) {
    c.planes.push_back(plane_of(f, s.planes));
    c.seen.push_back(probe_contact(dyn, f, c.planes.back(), q0).seen);
  }
  return c;
}

struct Evaluator {
  const Scene& scene;
  Bodies dyn;
  MatrixXd M0, K;
  VectorXd f, q0;

  explicit Evaluator(const Scene& s)
      : scene(s),
        dyn(scene_bodies(s)),
        M0(s.model.mechanical->M.toDense()),
        K(s.model.mechanical->K.toDense()),
        f(s.model.mechanical->f),
        q0(dyn.reference()),
        start(contacts_at_start(s, dyn, q0)) {}

  ContactsAtStart start;

  // e_M and e_F at q, and e_C when `contacts` (the run's check; the joints'
  // linear ranges leave the contacts to their own ranges, contact_ranges).
  Errors at(const VectorXd& q, bool contacts) const {
    Errors e;
    e.mass = (dyn.mass_matrix(q) - M0).norm() / M0.norm();
    const VectorXd L = f - K * q;
    const VectorXd d = dyn.gravity_force(q) - scene.lin.tau_g + scene.lin.K_g * (q - q0);
    const double scale = std::max({(L + d).norm(), L.norm(), (K * (q - q0)).norm()});
    e.force = scale > 0.0 ? d.norm() / scale : 0.0;
    if (contacts) contact_errors(q, e);
    return e;
  }

  // e_C (linearisation.hpp): only where the gap's error is at least its
  // distance from contact in one of the two models, and above the rounding
  // of the positions it comes from (16 eps of their size: a state 1e-18 m
  // from q0 moves the point by rounding, and the ratio of two roundings
  // is no error of the model).
  void contact_errors(const VectorXd& q, Errors& e) const {
    constexpr double kRounding = 16.0 * std::numeric_limits<double>::epsilon();
    const VectorXd dq = q - q0;
    for (std::size_t k = 0; k < scene.contacts.size(); ++k) {
      const ContactFrame& c = scene.contacts[k];
      const ContactProbe at = probe_contact(dyn, c, start.planes[k], q);
      const double moved = (at.seen - start.seen[k]).norm();
      const double linear = c.gap + c.normal_row.dot(dq);
      const double off = std::abs(at.gap - linear);
      const double size = at.seen.norm() + start.seen[k].norm() + std::abs(at.gap) +
                          std::abs(c.gap) + std::abs(linear);
      // A point back where it started (moved = 0) has no relative error, as
      // in the contact ranges; the ratio would be infinite.
      if (!(moved > 0.0) || off <= kRounding * size ||
          off < std::min(std::abs(at.gap), std::abs(linear)))
        continue;
      if (off / moved > e.contact) e.contact = off / moved, e.worst_contact = k;
    }
  }
};

}  // namespace

Reach first_crossing(const std::function<bool(double)>& exceeds, double end) {
  constexpr int kSteps = 64, kBisections = 50;
  double ok = 0.0, bad = -1.0;
  for (int k = 1; k <= kSteps && bad < 0.0; ++k) {
    const double s = k == kSteps ? end : end * k / kSteps;
    (exceeds(s) ? bad : ok) = s;
  }
  for (int k = 0; k < kBisections && bad > 0.0; ++k) {
    const double mid = 0.5 * (ok + bad);
    (exceeds(mid) ? bad : ok) = mid;
  }
  return {ok, bad > 0.0};
}

void check_linearisation_threshold(double threshold) {
  if (!(threshold > 0.0) || !std::isfinite(threshold))
    throw InputError("linearisation_threshold must be a finite number > 0 (got " +
                     format_number(threshold) + ")");
}

LinearisationCheck check_linearisation(const Scene& scene, const std::vector<VectorXd>& states) {
  const Evaluator ev(scene);
  const Eigen::Index n = ev.q0.size();
  LinearisationCheck c;
  c.worst_q = ev.q0;
  const std::size_t count = std::min(states.size(), kLinearisationStates);
  for (std::size_t k = 0; k < count; ++k) {
    // Evenly spread indices, the first and the last included.
    const std::size_t i =
        count < 2 ? 0
                  : static_cast<std::size_t>(std::llround(static_cast<double>(k) *
                                                          static_cast<double>(states.size() - 1) /
                                                          static_cast<double>(count - 1)));
    const VectorXd& x = states[i];
    if (x.size() < n)
      throw std::invalid_argument("scene::check_linearisation: state " + std::to_string(i) +
                                  " has " + std::to_string(x.size()) + " entries, the scene has " +
                                  std::to_string(n) + " coordinates");
    const Errors e = ev.at(x.head(n), true);
    c.mass_error = std::max(c.mass_error, e.mass);
    c.force_error = std::max(c.force_error, e.force);
    if (e.contact > c.contact_error) {
      c.contact_error = e.contact;
      c.contact = scene.contacts[e.worst_contact].point.name;
    }
    if (e.max() > c.error) {
      c.error = e.max();
      c.worst_q = x.head(n);
    }
  }
  c.states = count;
  return c;
}

std::string linearisation_warning(const LinearisationCheck& check, double threshold) {
  check_linearisation_threshold(threshold);
  if (!(check.error > threshold)) return "";
  const auto g3 = [](double x) { return format_number(x, 3); };
  const std::string q = number_list(check.worst_q, 3);
  return "the linear model is off by " + g3(100.0 * check.error) + " % (mass " +
         g3(100.0 * check.mass_error) + " %, forces " + g3(100.0 * check.force_error) +
         (check.contact_error > threshold
              ? " %, contact '" + check.contact + "' " + g3(100.0 * check.contact_error)
              : std::string()) +
         " %) at q = (" + q + "), above the threshold " + g3(100.0 * threshold) +
         " %: the run left the region where the linearisation about q0 holds";
}

std::vector<LinearRange> linear_ranges(const Scene& scene, double threshold) {
  check_linearisation_threshold(threshold);
  const Evaluator ev(scene);
  std::vector<LinearRange> out;
  for (std::size_t i = 0; i < scene.lin.joints.size(); ++i) {
    const auto ii = static_cast<Eigen::Index>(i);
    // A floating base's coordinates are no URDF joint: its position (m)
    // and rotation vector (rad) have no limits.
    const auto j = ev.dyn.joint_of(ii);
    const double q0 = ev.q0(ii);
    LinearRange r;
    r.joint = scene.lin.joints[i];
    const bool metres = ev.dyn.in_metres(ii);
    r.unit = metres ? "m" : "rad";
    r.q0 = q0;
    for (const double dir : {-1.0, 1.0}) {
      double end = metres ? 1.0 : M_PI;
      std::string why = "search";
      // No limit on a continuous joint (URDF ignores it there) nor where
      // lower > upper (Bullet's "no limit"; scene.cpp refuses it as a stop).
      if (j && j->limits && j->type != urdf::Joint::CONTINUOUS &&
          j->limits->lower <= j->limits->upper) {
        const double lim = dir < 0 ? q0 - j->limits->lower : j->limits->upper - q0;
        if (lim >= 0.0) {
          end = lim;
          why = "limit";
        }
      }
      const auto exceeds = [&](double s) {
        VectorXd q = ev.q0;
        q(ii) += dir * s;
        return ev.at(q, false).max() > threshold;
      };
      const Reach got = first_crossing(exceeds, end);
      const double ok = got.ok;
      if (got.crossed) why = "threshold";
      // At the limit itself, the URDF's number (q0 - (q0 - lower) may round).
      const double at =
          why == "limit" ? (dir < 0 ? j->limits->lower : j->limits->upper) : q0 + dir * ok;
      (dir < 0 ? r.lower : r.upper) = at;
      (dir < 0 ? r.lower_end : r.upper_end) = why;
    }
    out.push_back(r);
  }
  return out;
}

nlohmann::json to_json(const LinearisationCheck& check) {
  return {{"error", check.error},
          {"mass_error", check.mass_error},
          {"force_error", check.force_error},
          {"contact_error", check.contact_error},
          {"contact", check.contact},
          {"worst_q", to_json(check.worst_q)},
          {"states", check.states}};
}

nlohmann::json to_json(const std::vector<LinearRange>& ranges) {
  nlohmann::json a = nlohmann::json::array();
  for (const LinearRange& r : ranges)
    a.push_back({{"joint", r.joint},
                 {"unit", r.unit},
                 {"q0", r.q0},
                 {"lower", r.lower},
                 {"upper", r.upper},
                 {"lower_end", r.lower_end},
                 {"upper_end", r.upper_end}});
  return a;
}

void LinearisationStates::add(const VectorXd& x) {
  if (seen_++ % stride_ == 0) kept_.push_back(x);
  last_ = x;
  if (kept_.size() < 2 * kLinearisationStates) return;
  std::vector<VectorXd> half;
  for (std::size_t i = 0; i < kept_.size(); i += 2) half.push_back(std::move(kept_[i]));
  kept_ = std::move(half);
  stride_ *= 2;
}

std::vector<VectorXd> LinearisationStates::states() const {
  std::vector<VectorXd> s = kept_;
  if (seen_ > 0 && (seen_ - 1) % stride_ != 0) s.push_back(last_);
  return s;
}

}  // namespace lcsim::scene
