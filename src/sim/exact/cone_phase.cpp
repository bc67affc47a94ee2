// A 3-D frictional contact on a polyhedral cone in a phase of the exact
// method (issue 27; docs/friction.md, "The exact method in three
// dimensions"). The cone's 2d edges D_i = cos(phi_i) t + sin(phi_i) t2,
// phi_i = pi i/d, span the polygon mu u_N conv{D_i}; its face j joins edges j
// and j+1 and has the outward normal n_j at theta_j = (j + 1/2) pi/d, at
// distance c = cos(pi/(2d)) (in units of mu u_N) from the centre, half-length
// s = sin(pi/(2d)). With the sliding velocity s_T = (t'v, t2'v), maximal
// dissipation puts the force F (along t, t2) at
//   stick:       s_T = 0 held (rows t, t2), F the rows' multipliers, inside
//                the polygon: mu c u_N - n_j.F >= 0 for every face j;
//   edge i:      s_T strictly within pi/(2d) of phi_i, F = -mu u_N D_i: a
//                fixed column -mu D_i on the normal (as planar slip);
//   face j:      s_T along +n_j (the row n_j^perp = -sin t + cos t2 held),
//                F = -mu c u_N n_j + w n_j^perp with |w| <= mu s u_N (w the
//                held row's multiplier): the force on the opposite face.
// Each is linear, so the phase is the planar machinery's (friction_phase.cpp)
// with these rows and columns; the monitors are the conditions above.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "sim/exact/event_driven_detail.hpp"

namespace lcsim::sim::detail {

namespace {

// Unit vector at angle a, as a combination of the tangents t, t2.
RowVectorXd along(const mech::FrictionalContact& fc, double a) {
  return std::cos(a) * RowVectorXd(fc.tangent.transpose()) +
         std::sin(a) * RowVectorXd(fc.tangent2.transpose());
}

}  // namespace

impact::ConeFacet force_facet(FrictionMode m, int d) {
  if (!cone_slip(m) || d < 1) return {};
  return {(cone_index(m) + d) % (2 * d), cone_on_face(m)};
}

std::string friction_mode_name(FrictionMode m, int d) {
  if (!cone_slip(m)) return std::string(to_string(m));
  const impact::ConeFacet facet = force_facet(m, d);
  return text(facet.face ? "slip-face-" : "slip-edge-", facet.edge);
}

void EventDriven::cone_rows(size_t f, FrictionMode mode, std::vector<RowVectorXd>& held,
                            RowVectorXd& column) const {
  const mech::FrictionalContact& fc = model_.mechanical->friction[f];
  const int d = cone_d_[f];
  const double step = std::numbers::pi / d;
  column.resize(0);
  if (mode == FrictionMode::kStick) {
    held.push_back(RowVectorXd(fc.tangent.transpose()));
    held.push_back(RowVectorXd(fc.tangent2.transpose()));
  } else if (cone_slip(mode)) {
    if (!cone_on_face(mode)) {
      column = -fc.mu * along(fc, cone_index(mode) * step);
    } else {
      const double theta = (cone_index(mode) + 0.5) * step;
      column = -fc.mu * std::cos(step / 2) * along(fc, theta);
      held.push_back(along(fc, theta + std::numbers::pi / 2));
    }
  }
}

void EventDriven::cone_forces(Phase& ph, size_t f, const RowVectorXd& uN, const MatrixXd& F_all,
                              Eigen::Index first) const {
  const FrictionMode mode = ph.friction[f];
  const Eigen::Index fi = static_cast<Eigen::Index>(f);
  const double mu = model_.mechanical->friction[f].mu;
  const int d = cone_d_[f];
  const double step = std::numbers::pi / d;
  if (mode == FrictionMode::kStick) {
    ph.Ft.row(fi) = F_all.row(first);
    ph.Ft2.row(fi) = F_all.row(first + 1);
  } else if (cone_slip(mode) && !cone_on_face(mode)) {
    const double phi = cone_index(mode) * step;
    ph.Ft.row(fi) = -mu * std::cos(phi) * uN;
    ph.Ft2.row(fi) = -mu * std::sin(phi) * uN;
  } else if (cone_slip(mode)) {
    const double theta = (cone_index(mode) + 0.5) * step, c = std::cos(step / 2);
    ph.Ft.row(fi) = -mu * c * std::cos(theta) * uN - std::sin(theta) * F_all.row(first);
    ph.Ft2.row(fi) = -mu * c * std::sin(theta) * uN + std::cos(theta) * F_all.row(first);
  }
}

std::pair<RowVectorXd, RowVectorXd> EventDriven::cone_sliding_rows(size_t f) const {
  const mech::FrictionalContact& fc = model_.mechanical->friction[f];
  std::pair<RowVectorXd, RowVectorXd> s{RowVectorXd::Zero(n_), RowVectorXd::Zero(n_)};
  s.first.segment(N_, N_) = fc.tangent.transpose();
  s.second.segment(N_, N_) = fc.tangent2.transpose();
  return s;
}

// The monitors of entry f (a cone contact in `ph`): stick, the polygon's 2d
// faces; edge i, the two bisectors bounding its region (the velocity's cross
// products with them); face j, the speed along n_j and the two ends of the
// face.
void EventDriven::add_cone_monitors(Phase& ph, size_t f) const {
  const FrictionMode mode = ph.friction[f];
  const mech::FrictionalContact& fc = model_.mechanical->friction[f];
  const Eigen::Index fi = static_cast<Eigen::Index>(f);
  const int d = cone_d_[f];
  const double step = std::numbers::pi / d;
  const auto it = std::find(ph.mode.begin(), ph.mode.end(), fc.contact);
  const RowVectorXd uN = ph.F.row(it - ph.mode.begin());
  Monitor mon;
  mon.constraint = fc.contact;
  mon.friction = static_cast<int>(f);
  if (mode == FrictionMode::kStick) {
    mon.multiplier = true;
    for (int j = 0; j < 2 * d; ++j) {
      const double theta = (j + 0.5) * step;
      mon.w = fc.mu * std::cos(step / 2) * uN - std::cos(theta) * ph.Ft.row(fi) -
              std::sin(theta) * ph.Ft2.row(fi);
      ph.monitors.push_back(mon);
    }
    return;
  }
  const auto [s1, s2] = cone_sliding_rows(f);
  if (!cone_on_face(mode)) {
    const double lo = (cone_index(mode) - 0.5) * step, hi = (cone_index(mode) + 0.5) * step;
    mon.w = std::cos(lo) * s2 - std::sin(lo) * s1;  // s_T left of the lower bisector
    ph.monitors.push_back(mon);
    mon.w = std::sin(hi) * s1 - std::cos(hi) * s2;  // s_T right of the upper bisector
    ph.monitors.push_back(mon);
    return;
  }
  const double theta = (cone_index(mode) + 0.5) * step;
  mon.w = std::cos(theta) * s1 + std::sin(theta) * s2;  // speed along n_j
  ph.monitors.push_back(mon);
  const RowVectorXd w = -std::sin(theta) * ph.Ft.row(fi) + std::cos(theta) * ph.Ft2.row(fi);
  mon.multiplier = true;
  for (const double side : {-1.0, 1.0}) {
    mon.w = fc.mu * std::sin(step / 2) * uN + side * w;
    ph.monitors.push_back(mon);
  }
}

bool EventDriven::resultant_determined(const MatrixXd& S, const MatrixXd& MinvGt,
                                       const MatrixXd& HAv, MatrixXd& F_all) {
  const Eigen::JacobiSVD<MatrixXd> svd(S, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const VectorXd& sv = svd.singularValues();
  const double tol = 1e-10 * sv(0);  // rank: the stick rows' duplicates are exact
  Eigen::Index rank = 0;
  while (rank < sv.size() && sv(rank) > tol) ++rank;
  F_all = -S.completeOrthogonalDecomposition().solve(HAv);
  const double scale =
      S.cwiseAbs().maxCoeff() * F_all.cwiseAbs().maxCoeff() + HAv.cwiseAbs().maxCoeff();
  if (!((S * F_all + HAv).cwiseAbs().maxCoeff() <= 1e-10 * scale)) return false;
  const MatrixXd Z = svd.matrixV().rightCols(sv.size() - rank);  // null space of S
  return (MinvGt * Z).cwiseAbs().maxCoeff() <= 1e-10 * MinvGt.cwiseAbs().maxCoeff();
}

}  // namespace lcsim::sim::detail
