// How far a scene's linear model holds: the error of the linearisation at
// given states, its check on a run, and the range of each joint where it holds.
#pragma once

#include <Eigen/Dense>
#include <cstddef>
#include <functional>
#include <lcsim/scene/scene.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace lcsim::scene {

using Eigen::VectorXd;

// At coordinates q the exact model has the mass matrix M(q) and the force
// F(q) = tau_g(q) + springs(q) (springs are linear in q, so exact in the
// model); the linear model has M0 = M(q0) and L(q) = f - K q. Velocity
// terms (Coriolis and centrifugal forces, quadratic in v) are not measured.
//   mass error   e_M(q) = ||M(q) - M0||_F / ||M0||_F
//   force error  e_F(q) = ||F(q) - L(q)||_2 / max(||F(q)||_2, ||L(q)||_2, ||K (q - q0)||_2)
//                (0 where all vanish), F(q) - L(q) = tau_g(q) - tau_g(q0) + K_g (q - q0);
//                the last term of the scale, the linear model's change of force
//                since q0, keeps rounding noise from counting where both forces
//                vanish (a spring at its rest length, gravity along no joint)
//   contact error e_C(q) = max over the scene's contacts c of
//                |phi_c(q) - gap_c(q)| / |p_c(q) - p_c(q0)|, the exact gap
//                phi against the linear one gap = phi(q0) + (d phi/dq)(q0) (q - q0),
//                relative to the contact point's displacement (the measure of
//                the contact ranges below), counted where the difference could
//                decide whether the contact is open: |phi - gap| >= min(|phi|,
//                |gap|), for a point that moved (a rolling wheel's rim point
//                the linear model keeps at the bottom, a foot swinging near
//                the floor), not for a point far from its plane in both models
//   error        e(q) = max(e_M(q), e_F(q), e_C(q))
// For a pendulum about its hanging equilibrium, e_F = |theta - sin theta| / |theta| ~ theta^2/6.
struct LinearisationCheck {
  double error = 0.0;          // max over the states of e(q)
  double mass_error = 0.0;     // max of e_M
  double force_error = 0.0;    // max of e_F
  double contact_error = 0.0;  // max of e_C
  std::string contact;         // the contact where e_C was largest ("" when e_C = 0)
  VectorXd worst_q;            // the state where e(q) was largest
  std::size_t states = 0;      // how many states were evaluated
};
constexpr std::size_t kLinearisationStates = 200;  // states evaluated at most
constexpr double kLinearisationThreshold = 0.01;   // default warning threshold (1 %)

// e(q) at the given coordinates (size N each; the first N entries of a full
// state are used, so trajectory states (q, v) may be passed as they are).
// More than kLinearisationStates states are subsampled evenly, first and last
// kept. std::invalid_argument for a wrong size.
LinearisationCheck check_linearisation(const Scene& scene, const std::vector<VectorXd>& states);

// The states of a run as they stream by (sim::Options::sample_sink), thinned
// so that at most 2 * kLinearisationStates are kept, evenly spaced, plus the
// last: what check_linearisation evaluates, in bounded memory however long
// the run. app::run_model checks a scene's run with it, for the command
// line and the Python module alike.
class LinearisationStates {
 public:
  void add(const VectorXd& x);
  std::vector<VectorXd> states() const;

 private:
  std::vector<VectorXd> kept_;
  VectorXd last_;
  long seen_ = 0, stride_ = 1;
};

// "" when check.error <= threshold, else the warning line. InputError
// ("linearisation_threshold must be ...", naming the field, as the options'
// messages do) unless threshold is finite and > 0.
std::string linearisation_warning(const LinearisationCheck& check, double threshold);
void check_linearisation_threshold(double threshold);

// The scan both ranges below use along one coordinate, from 0 outwards to
// `end` (> 0): exceeds(s) at s = end k / 64, k = 1..64, until the first s
// where it holds, then 50 bisections between that s and the last one where
// it did not. `ok` is the farthest s before the first crossing (end when
// none), `crossed` whether there was one. exceeds need not be monotone: a
// crossing the 64 steps skip over is not seen.
struct Reach {
  double ok = 0.0;
  bool crossed = false;
};
Reach first_crossing(const std::function<bool(double)>& exceeds, double end);

// Per simulated joint, the interval of q about q0 (other joints at q0) in
// which e(q) <= threshold: from q0 outwards in 64 steps to the joint's limit
// (or pi rad / 1 m when it has none), then 50 bisections where e first
// exceeds the threshold (each coordinate alone; e need not be monotone, the
// scan stops at the first crossing it sees). A floating base's coordinates
// come first, each named as a joint here ("box.z": m, "box.rx": rad), with
// no limits.
struct LinearRange {
  std::string joint;
  std::string unit;  // "rad" (revolute) or "m" (prismatic)
  double q0 = 0.0;
  double lower = 0.0, upper = 0.0;  // rad or m, absolute joint positions
  // What ends each side: "threshold" (e crosses it there), "limit" (the
  // joint's limit, no crossing before it) or "search" (no limit on that
  // side: the scan stopped at pi rad or 1 m without a crossing).
  std::string lower_end, upper_end;
};
std::vector<LinearRange> linear_ranges(const Scene& scene, double threshold);

// Per contact of the scene (Scene::contacts, in row order): its gap at q0
// (the model's E q0 + g, m), whether it is closed there
// (mech::gap_is_zero), and how far the configuration can move before the
// linear gap is off by more than `threshold` of the contact point's own
// displacement. Along each coordinate alone (others at q0) the error is
//   e = |phi(q) - gap_lin(q)| / |p(q) - p(q0)|,
// p the contact point (the link point, the sphere's centre for a sphere)
// seen from what it touches: in the world for a plane, in the frame of
// the other body's link for a body's shape. The scale does not vanish where
// the gap's row does not depend on the coordinate (a toe straight below its
// hip: e = |sin(th/2)|, 1 % at th = 2 asin(0.01) ~ 0.0200 rad); a
// coordinate that does not move p (|p(q) - p(q0)| = 0: another leg's joint,
// a sphere turning about its centre) never ends a range. It is scanned by
// first_crossing (64 steps to pi rad, 1 m or the joint's limit, then 50
// bisections), both ways, and `range` is the smaller distance reached,
// `coordinate` the coordinate whose range is the smallest among those in
// rad (rotations bend the gap; a translation or prismatic joint along
// which the point moves straight never does), or among all if none is a
// rotation. `end`: "threshold" or "search"/"limit" (no crossing).
struct ContactRange {
  std::string contact, plane;
  double gap = 0.0;  // m, at q0
  bool closed = false;
  std::string coordinate, unit;
  double range = 0.0;  // rad or m
  std::string end;
};
std::vector<ContactRange> contact_ranges(const Scene& scene, double threshold);
nlohmann::json to_json(const std::vector<ContactRange>& ranges);

// JSON of the two: {error, mass_error, force_error, worst_q, states} and
// [{joint, unit, q0, lower, upper, lower_end, upper_end}, ...].
nlohmann::json to_json(const LinearisationCheck& check);
nlohmann::json to_json(const std::vector<LinearRange>& ranges);

}  // namespace lcsim::scene
