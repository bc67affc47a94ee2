// Mode selection at an event for models with 3-D contacts on a polyhedral
// cone (issue 27; docs/friction.md, "The exact method in three dimensions").
// Each closed frictional contact gets its candidates from its sliding
// velocity s_T = (t'v, t2'v):
//   - zero (to the rounding of its terms, or the impact law said stick):
//     stick, then slip on each edge, then slip on each face; s_T is set
//     exactly to zero first;
//   - on the bisector of face j (its component across n_j zero to rounding):
//     slip on face j, or on edge j or j+1 (where a face slip ends: its force
//     reached an end of the face); the component across is set to zero;
//   - otherwise: slip on the edge whose region holds s_T (the only one).
// Planar contacts (d = 1) take stick, slip+, slip- when their sliding is
// zero, else the slip their velocity gives. The combinations are tried in
// order and the first whose phase is consistent (each friction monitor
// starts positive or leaves zero upwards: its first nonzero derivative) is
// taken; this is the planar method's check (friction_modes.cpp), here the
// selection itself. At an isolated contact exactly one candidate passes:
// stick needs the stick force strictly inside the polygon, an edge the
// sliding acceleration strictly inside its region, a face the acceleration
// along n_j with the face force strictly inside the face. Above 4096
// combinations only the first are tried, after the cone LCP's guess
// (cone_guess.cpp) and, when that fails, the combinations over the contacts
// whose stick forces reach their polygons (cone_boundary.cpp).
#include <algorithm>
#include <cmath>
#include <lcsim/impact/impact.hpp>
#include <numbers>

#include "sim/exact/event_driven_detail.hpp"

namespace lcsim::sim::detail {

namespace {

// Combinations tried at most (33 for one contact with d = 8; all stick,
// the most common outcome when several contacts stop together, is the first).
constexpr size_t kMaxCombinations = 4096;

}  // namespace

std::vector<std::vector<FrictionMode>> EventDriven::cone_candidates(
    const lcs::IndexSet& mode, const VectorXd& xa, std::vector<RowVectorXd>& zero_rows,
    std::vector<double>& zero_target) const {
  const mech::MechanicalModel& m = *model_.mechanical;
  const VectorXd q = xa.head(N_), v = xa.segment(N_, N_);
  std::vector<std::vector<FrictionMode>> cand(m.friction.size());
  for (size_t f = 0; f < m.friction.size(); ++f) {
    const mech::FrictionalContact& fc = m.friction[f];
    if (std::find(mode.begin(), mode.end(), fc.contact) == mode.end()) {
      cand[f] = {FrictionMode::kOpen};
      continue;
    }
    // The zero test of zero_sliding (friction_modes.cpp), over both tangents.
    double terms = fc.tangent.cwiseAbs().dot(v.cwiseAbs()) + std::abs(fc.velocity);
    double size = fc.tangent.cwiseAbs().sum();
    if (is_cone(f)) {
      terms += fc.tangent2.cwiseAbs().dot(v.cwiseAbs());
      size += fc.tangent2.cwiseAbs().sum();
    }
    const double tol =
        mech::zero_tolerance(terms, ldcp_) +
        64.0 * kEps * size * (v.cwiseAbs().maxCoeff() + rho_A_ * q.cwiseAbs().maxCoeff());
    const bool stuck = outcome_[static_cast<size_t>(fc.contact)] == impact::ContactOutcome::kStick;
    const double s1 = fc.sliding(v);
    if (!is_cone(f)) {
      if (std::abs(s1) <= tol || stuck) {
        cand[f] = {FrictionMode::kStick, FrictionMode::kSlipPositive, FrictionMode::kSlipNegative};
        zero_rows.push_back(RowVectorXd(fc.tangent.transpose()));
        zero_target.push_back(fc.velocity);
      } else {
        cand[f] = {s1 > 0.0 ? FrictionMode::kSlipPositive : FrictionMode::kSlipNegative};
      }
      continue;
    }
    const int d = cone_d_[f];
    const double step = std::numbers::pi / d, s2 = fc.tangent2.dot(v);
    if (std::hypot(s1, s2) <= tol || stuck) {
      cand[f].push_back(FrictionMode::kStick);
      for (int i = 0; i < 2 * d; ++i) cand[f].push_back(cone_edge(i));
      for (int j = 0; j < 2 * d; ++j) cand[f].push_back(cone_face(j));
      zero_rows.push_back(RowVectorXd(fc.tangent.transpose()));
      zero_rows.push_back(RowVectorXd(fc.tangent2.transpose()));
      zero_target.insert(zero_target.end(), {0.0, 0.0});
      continue;
    }
    const double phi = std::atan2(s2, s1);
    const int j = static_cast<int>(((static_cast<long>(std::floor(phi / step)) % (2 * d)) + 2 * d) %
                                   (2 * d));  // the sector between edges j and j+1
    const double theta = (j + 0.5) * step;
    if (std::abs(std::cos(theta) * s2 - std::sin(theta) * s1) <= tol) {
      cand[f] = {cone_face(j), cone_edge(j), cone_edge((j + 1) % (2 * d))};
      zero_rows.push_back(-std::sin(theta) * RowVectorXd(fc.tangent.transpose()) +
                          std::cos(theta) * RowVectorXd(fc.tangent2.transpose()));
      zero_target.push_back(0.0);
    } else {
      const long i = std::lround(phi / step);
      cand[f] = {cone_edge(static_cast<int>(((i % (2 * d)) + 2 * d) % (2 * d)))};
    }
  }
  return cand;
}

// Sets the rows' velocities exactly to their targets keeping E_I v = 0: the
// M-orthogonal projection (they are there up to rounding).
void EventDriven::project_rows(const lcs::IndexSet& mode, const std::vector<RowVectorXd>& rows,
                               const std::vector<double>& target, VectorXd& xa) const {
  const mech::MechanicalModel& m = *model_.mechanical;
  const Eigen::Index nI = static_cast<Eigen::Index>(mode.size());
  const Eigen::Index nr = nI + static_cast<Eigen::Index>(rows.size());
  MatrixXd G(nr, N_);
  VectorXd r(nr);
  const VectorXd v = xa.segment(N_, N_);
  for (Eigen::Index i = 0; i < nI; ++i) {
    G.row(i) = m.E.row(mode[static_cast<size_t>(i)]);
    r(i) = G.row(i).dot(v);
  }
  for (size_t z = 0; z < rows.size(); ++z) {
    G.row(nI + static_cast<Eigen::Index>(z)) = rows[z];
    r(nI + static_cast<Eigen::Index>(z)) = rows[z].dot(v) - target[z];
  }
  const MatrixXd MinvGt = Minv_ * G.transpose();
  const VectorXd lambda = (G * MinvGt).completeOrthogonalDecomposition().solve(r);
  xa.segment(N_, N_) -= MinvGt * lambda;
}

// Selects out.friction for out.mode at xa (models with a cone contact).
std::string EventDriven::select_cone_friction(double t, const lcs::IndexSet& undetermined,
                                              VectorXd& xa, EventResult& out) {
  std::vector<RowVectorXd> rows;
  std::vector<double> target;
  std::vector<std::vector<FrictionMode>> cand = cone_candidates(out.mode, xa, rows, target);
  out.friction.clear();
  double total = 1.0;  // combinations (may be many: only kMaxCombinations are tried)
  for (const auto& c : cand) {
    out.friction.push_back(c.front());
    total *= static_cast<double>(c.size());
  }
  if (total == 1.0) return "";  // every contact's mode follows from its velocity
  if (!rows.empty()) project_rows(out.mode, rows, target, xa);
  // Beyond the bound the enumeration would see a few of them: the cone
  // LCP's guess first (cone_guess.cpp).
  if (total > static_cast<double>(kMaxCombinations))
    cone_lcp_guess(out.mode, xa, cand, out.lcp_solves);
  const size_t tries =
      total > static_cast<double>(kMaxCombinations) ? kMaxCombinations : static_cast<size_t>(total);
  std::string painleve;
  std::vector<FrictionMode> fm(cand.size());
  for (size_t code = 0; code < tries; ++code) {
    size_t c = code;
    for (size_t f = 0; f < cand.size(); ++f) {
      fm[f] = cand[f][c % cand[f].size()];
      c /= cand[f].size();
    }
    std::string err;
    const Phase& ph = make_phase(out.mode, fm, undetermined, xa, err);
    if (!err.empty()) {
      if (painleve.empty() && err.find("Painlev") != std::string::npos) painleve = err;
    } else if (consistent(ph, xa, t)) {
      out.friction = fm;
      return "";
    }
    // Beyond the bound, before the enumeration goes on: the contacts whose
    // stick forces reach their polygons (cone_boundary.cpp).
    if (code == 0 && tries < total) {
      bool found = false;
      std::vector<FrictionMode> fb = fm;
      if (std::string why = select_cone_boundary(t, out.mode, undetermined, cand, xa, fb, found);
          !why.empty() || found) {
        out.friction = fb;
        return why;
      }
    }
  }
  if (!painleve.empty()) return painleve;
  // The contacts with a choice, named only when none is consistent.
  const mech::MechanicalModel& m = *model_.mechanical;
  std::string names;
  for (size_t f = 0; f < cand.size(); ++f)
    if (cand[f].size() > 1)
      names += text(names.empty() ? "'" : ", '",
                    m.constraints[static_cast<size_t>(m.friction[f].contact)], "'");
  if (tries < total)
    return text("stick / slip selection at t = ", t, ": none of the first ", tries, " of ", total,
                " combinations of stick and slip on the cone's edges and faces of the contacts ",
                names, " is consistent (not enumerated further)");
  return text("stick / slip selection at t = ", t, ": no mode of the contacts ", names,
              " is consistent (each of stick and slip on the cone's edges and faces leaves a "
              "friction monitor negative)");
}

}  // namespace lcsim::sim::detail
