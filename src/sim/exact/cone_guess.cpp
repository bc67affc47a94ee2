// The cone's first guess at an event (issue 27): where several 3-D contacts
// may each stick or start to slip (their sliding velocities zero), the
// combinations of their modes are many ((1 + 4d)^k: 83 521 for four feet at
// d = 4) and select_cone_friction tries at most 4096 of them. The
// acceleration-level LCP of Stewart and Trinkle's form answers in one solve
// which contacts stick and in which direction the others start to slide, as
// the planar method's friction_lcp_modes does for planar contacts:
//   0 <= E_I v'                  ⟂ lambda_N >= 0
//   0 <= D_i v' + xi             ⟂ beta_i >= 0     (each edge of each contact)
//   0 <= mu lambda_N - sum beta_i ⟂ xi >= 0,
// v' = a_free + M^-1 (G_I' lambda_N + sum D_i' beta_i), G_I the normal rows
// with the contacts that keep sliding adding their friction (-mu D of their
// edge, or of their face's midpoint direction times cos(pi/2d): a guess).
// Each contact's guess is read from its sliding acceleration s' = (t v', t2
// v'): zero -> stick; else the edge or face whose region holds it, as
// cone_candidates reads a sliding velocity. The guess is moved to the front
// of the contact's candidates; the enumeration still judges every
// combination by its phase's monitors, so a wrong guess costs order only.
#include <algorithm>
#include <cmath>
#include <lcsim/impact/impact.hpp>
#include <numbers>

#include "sim/exact/event_driven_detail.hpp"

namespace lcsim::sim::detail {

namespace {

// The mode a sliding direction (s1, s2) along (t, t2) selects on a cone of
// 2d edges (tol: zero to rounding): stick, the face whose bisector holds it,
// or the edge whose region does.
FrictionMode cone_mode_of(double s1, double s2, int d, double tol) {
  if (std::hypot(s1, s2) <= tol) return FrictionMode::kStick;
  const double step = std::numbers::pi / d, phi = std::atan2(s2, s1);
  const long sector = static_cast<long>(std::floor(phi / step));
  const int j = static_cast<int>(((sector % (2 * d)) + 2 * d) % (2 * d));
  const double theta = (j + 0.5) * step;
  if (std::abs(std::cos(theta) * s2 - std::sin(theta) * s1) <= tol) return cone_face(j);
  const long i = std::lround(phi / step);
  return cone_edge(static_cast<int>(((i % (2 * d)) + 2 * d) % (2 * d)));
}

// The friction force direction (per unit mu lambda_N, along -) of a contact
// that keeps sliding in mode `fm`, as a row over v.
RowVectorXd sliding_force_row(const mech::FrictionalContact& fc, FrictionMode fm, int d) {
  const RowVectorXd t(fc.tangent.transpose()), t2(fc.tangent2.transpose());
  if (!cone_slip(fm)) return (fm == FrictionMode::kSlipPositive ? 1.0 : -1.0) * t;
  const double step = std::numbers::pi / d;
  const double a = (cone_index(fm) + (cone_on_face(fm) ? 0.5 : 0.0)) * step;
  const double c = cone_on_face(fm) ? std::cos(step / 2) : 1.0;
  return c * (std::cos(a) * t + std::sin(a) * t2);
}

}  // namespace

// `cand` reordered: each 3-D contact with a choice gets the LCP's guess
// first. Nothing changes when the LCP has no solution.
void EventDriven::cone_lcp_guess(const lcs::IndexSet& mode, const VectorXd& xa,
                                 std::vector<std::vector<FrictionMode>>& cand, long& solves) const {
  const mech::MechanicalModel& m = *model_.mechanical;
  const Eigen::Index nI = static_cast<Eigen::Index>(mode.size());
  std::vector<int> choice, normal_of, first, dd;
  VectorXd mu(0);
  Eigen::Index nE = 0;
  for (size_t f = 0; f < cand.size(); ++f) {
    if (cand[f].size() < 2 || !is_cone(f)) continue;
    choice.push_back(static_cast<int>(f));
    normal_of.push_back(static_cast<int>(
        std::find(mode.begin(), mode.end(), m.friction[f].contact) - mode.begin()));
    first.push_back(static_cast<int>(nE));
    dd.push_back(cone_d_[f]);
    nE += 2 * cone_d_[f];
  }
  if (choice.empty()) return;
  mu.resize(static_cast<Eigen::Index>(choice.size()));
  MatrixXd H(nI + nE, N_), G(nI + nE, N_);
  for (Eigen::Index i = 0; i < nI; ++i) H.row(i) = m.E.row(mode[static_cast<size_t>(i)]);
  G.topRows(nI) = H.topRows(nI);
  for (size_t f = 0; f < cand.size(); ++f) {  // the contacts that keep sliding
    const FrictionMode fm = cand[f].front();
    if (cand[f].size() > 1 || fm == FrictionMode::kOpen || fm == FrictionMode::kStick) continue;
    const auto it = std::find(mode.begin(), mode.end(), m.friction[f].contact);
    if (it == mode.end()) continue;
    G.row(it - mode.begin()) -= m.friction[f].mu * sliding_force_row(m.friction[f], fm, cone_d(f));
  }
  for (size_t k = 0; k < choice.size(); ++k) {
    const mech::FrictionalContact& fc = m.friction[static_cast<size_t>(choice[k])];
    mu(static_cast<Eigen::Index>(k)) = fc.mu;
    for (int i = 0; i < 2 * dd[k]; ++i) {
      const double a = i * std::numbers::pi / dd[k];
      H.row(nI + first[k] + i) = G.row(nI + first[k] + i) =
          std::cos(a) * RowVectorXd(fc.tangent.transpose()) +
          std::sin(a) * RowVectorXd(fc.tangent2.transpose());
    }
  }
  const VectorXd acc = sys_.A.middleRows(N_, N_) * xa;  // the free accelerations
  const VectorXd rates = H * acc;
  const impact::FrictionLcp p = impact::friction_cone_lcp(H * Minv_ * G.transpose(), rates.head(nI),
                                                          rates.tail(nE), normal_of, first, dd, mu);
  int n_solves = 0;
  const lcp::Result res = impact::solve_friction_cone_lcp(p, *solver_, &n_solves, nullptr);
  solves += n_solves;
  if (!res.ok()) return;
  const VectorXd forces = G.transpose() * res.z.head(nI + nE);
  const VectorXd vdot = acc + Minv_ * forces;
  const VectorXd terms = acc.cwiseAbs() + Minv_.cwiseAbs() * forces.cwiseAbs();
  for (size_t k = 0; k < choice.size(); ++k) {
    const size_t f = static_cast<size_t>(choice[k]);
    const mech::FrictionalContact& fc = m.friction[f];
    const double s1 = fc.tangent.dot(vdot), s2 = fc.tangent2.dot(vdot);
    // Zero to the rounding of its terms (the zero test of cone_candidates).
    const double tol = mech::zero_tolerance(
        fc.tangent.cwiseAbs().dot(terms) + fc.tangent2.cwiseAbs().dot(terms), ldcp_);
    const FrictionMode guess = cone_mode_of(s1, s2, dd[k], tol);
    auto& c = cand[f];
    const auto it = std::find(c.begin(), c.end(), guess);
    if (it != c.end()) std::rotate(c.begin(), it, it + 1);
  }
}

}  // namespace lcsim::sim::detail
