// A phase of the event-driven method with closed frictional contacts (issue
// 17; the thesis's linear relay systems, §4.6.2). In the mode (I, stick /
// slip+ / slip-) the constraint rows H = [E_I; T_S] (the normals and the
// tangents of the sticking contacts) are held at acceleration level,
// H v' = 0, with the force columns G = [E_I - sigma mu T; T_S]: a contact
// slipping in direction sigma has u_T = -sigma mu u_N, so its normal's
// column carries its friction (a non-symmetric constraint matrix). With
// v' = a(x) + M^{-1} G' lambda (a the free acceleration, affine in the
// augmented state x = (q, v, 1)) the multipliers are
//   lambda = -(H M^{-1} G')^{-1} H a(x) = F x,
// and the closed loop is x' = Acl x, as for a frictionless mode.
#include <algorithm>
#include <cmath>
#include <lcsim/lcp/lcp.hpp>
#include <lcsim/lcp/redundant.hpp>
#include <limits>

#include "sim/exact/event_driven_detail.hpp"

namespace lcsim::sim::detail {

namespace {

double sigma_of(FrictionMode f) { return f == FrictionMode::kSlipPositive ? 1.0 : -1.0; }
bool slipping(FrictionMode f) {
  return f == FrictionMode::kSlipPositive || f == FrictionMode::kSlipNegative || cone_slip(f);
}
bool planar_slip(FrictionMode f) {
  return f == FrictionMode::kSlipPositive || f == FrictionMode::kSlipNegative;
}

}  // namespace

void EventDriven::init_friction() {
  const mech::MechanicalModel& m = *model_.mechanical;
  Minv_ = Eigen::LLT<MatrixXd>(MatrixXd(m.M)).solve(MatrixXd::Identity(N_, N_));
  for (const mech::FrictionalContact& fc : m.friction) {
    friction_contacts_.push_back(fc.contact);
    cone_d_.push_back(m.edges_of(fc));
    has_cone_ = has_cone_ || cone_d_.back() >= 2;
  }
  outcome_.assign(static_cast<size_t>(k_), impact::ContactOutcome::kNone);
}

// Painlevé-type phase: the normal forces of I solve E_I M^{-1} G' lambda =
// -E_I a with the sticking tangents eliminated (their Schur complement);
// when that normal matrix is not a P-matrix (for one contact: W_NN - sigma
// mu W_NT <= 0) the contact force is not determined by the phase, and the
// relay system has no solution or several (thesis §4.6.2, Theorem 4.6.7
// needs P-matrices). The message naming the slipping contacts, or "".
std::string EventDriven::painleve_phase(const Phase& ph, const MatrixXd& S, int n_stick) const {
  const Eigen::Index nI = static_cast<Eigen::Index>(ph.mode.size());
  if (std::none_of(ph.friction.begin(), ph.friction.end(), slipping)) return "";
  MatrixXd Ns = S.topLeftCorner(nI, nI);
  if (n_stick > 0) {
    const Eigen::FullPivLU<MatrixXd> lu(S.bottomRightCorner(n_stick, n_stick));
    if (!lu.isInvertible()) return "";  // reported as singular by the caller
    Ns -= S.topRightCorner(nI, n_stick) * lu.solve(S.bottomLeftCorner(n_stick, nI));
  }
  if (lcp::is_p_matrix(Ns)) return "";
  const mech::MechanicalModel& m = *model_.mechanical;
  // Redundant normals (a box's four coplanar corners): a set of dependent
  // rows E_J has a zero minor whatever the friction, so only the sets of
  // independent rows judge Painlevé (lcp/redundant.hpp); the forces'
  // resultant is then checked by friction_feedback.
  if (nI <= 20) {
    MatrixXd EI(nI, N_);
    for (Eigen::Index i = 0; i < nI; ++i) EI.row(i) = m.E.row(ph.mode[static_cast<size_t>(i)]);
    if (lcp::is_p_matrix_on_independent_rows(Ns, EI * Minv_ * EI.transpose())) return "";
  }
  std::string msg = "Painlevé-type phase: with contact";
  for (size_t f = 0; f < ph.friction.size(); ++f) {
    if (!slipping(ph.friction[f])) continue;
    const int r = m.friction[f].contact;
    msg += text(" ", r, " ('", m.constraints[static_cast<size_t>(r)], "', ",
                friction_mode_name(ph.friction[f], cone_d(f)), ")");
  }
  msg += " slipping, the normal matrix E_I M^-1 (E_I - sigma mu T)' is not a P-matrix";
  if (nI == 1) msg += text(" (W_NN - sigma mu W_NT = ", Ns(0, 0), " <= 0)");
  return msg +
         ": the contact force is not determined, the relay LCP may have no solution or several "
         "(not resolved)";
}

// F (normals), Ft (Ft2) and Acl of a mode with closed frictional contacts;
// false (err set) for a Painlevé-type or singular phase. Rows held at
// acceleration level: the planar sticking tangents, and a cone contact's
// (cone_phase.cpp), in the order of mechanical.friction.
bool EventDriven::friction_feedback(Phase& ph, const VectorXd& xa, std::string& err) const {
  const mech::MechanicalModel& m = *model_.mechanical;
  const Eigen::Index nI = static_cast<Eigen::Index>(ph.mode.size());
  std::vector<int> stick;  // planar sticking contacts
  std::vector<RowVectorXd> held, cone_column(ph.friction.size());
  std::vector<Eigen::Index> first(ph.friction.size(), 0);  // a contact's first held row
  for (size_t f = 0; f < ph.friction.size(); ++f) {
    first[f] = nI + static_cast<Eigen::Index>(held.size());
    if (is_cone(f)) {
      cone_rows(f, ph.friction[f], held, cone_column[f]);
    } else if (ph.friction[f] == FrictionMode::kStick) {
      stick.push_back(static_cast<int>(f));
      held.push_back(RowVectorXd(m.friction[f].tangent.transpose()));
    }
  }
  const Eigen::Index ns = static_cast<Eigen::Index>(held.size()), nc = nI + ns;
  MatrixXd H(nc, N_), G(nc, N_);
  for (Eigen::Index i = 0; i < nI; ++i) H.row(i) = m.E.row(ph.mode[static_cast<size_t>(i)]);
  G.topRows(nI) = H.topRows(nI);
  for (size_t f = 0; f < ph.friction.size(); ++f) {
    if (!slipping(ph.friction[f])) continue;
    const auto it = std::find(ph.mode.begin(), ph.mode.end(), m.friction[f].contact);
    if (is_cone(f))
      G.row(it - ph.mode.begin()) += cone_column[f];
    else
      G.row(it - ph.mode.begin()) -=
          sigma_of(ph.friction[f]) * m.friction[f].mu * m.friction[f].tangent.transpose();
  }
  for (Eigen::Index s = 0; s < ns; ++s)
    H.row(nI + s) = G.row(nI + s) = held[static_cast<size_t>(s)];
  const MatrixXd MinvGt = Minv_ * G.transpose();
  const MatrixXd S = H * MinvGt;
  if (err = painleve_phase(ph, S, static_cast<int>(ns)); !err.empty()) return false;
  const MatrixXd Av = sys_.A.middleRows(N_, N_);  // v' = Av x without forces
  MatrixXd F_all;
  if (const Eigen::FullPivLU<MatrixXd> lu(S); lu.isInvertible()) {
    F_all = -lu.solve(H * Av);
    ph.Acl.middleRows(N_, N_) += MinvGt * F_all;
  } else if (std::none_of(ph.friction.begin(), ph.friction.end(), slipping)) {
    // Dependent rows without slip (two corners of a box sticking on one
    // floor): S = H M^-1 H' is symmetric semi-definite and H v' = 0 is
    // consistent, so the forces are determined up to its null space
    // (a statically indeterminate split: indeterminate_split, planar rows
    // only; a cone contact keeps the minimum-norm split).
    F_all = -S.completeOrthogonalDecomposition().solve(H * Av);
    ph.Acl.middleRows(N_, N_) += MinvGt * F_all;
    if (!has_cone_) indeterminate_split(ph, S, stick, xa, F_all);  // forces only: H' Z = 0
  } else if ((has_cone_ || redundant_normals(ph)) &&
             resultant_determined(S, MinvGt, H * Av, F_all)) {
    ph.Acl.middleRows(N_, N_) += MinvGt * F_all;
  } else {
    err =
        "the constraint matrix H M^-1 G' of the mode with slip is singular (dependent "
        "normal and tangent rows): its forces are not determined";
    return false;
  }
  ph.F = F_all.topRows(nI);
  if (has_cone_) ph.Ft2 = MatrixXd::Zero(ph.Ft.rows(), n_);
  for (size_t f = 0; f < ph.friction.size(); ++f) {
    const Eigen::Index fi = static_cast<Eigen::Index>(f);
    if (ph.friction[f] == FrictionMode::kOpen) continue;
    const auto it = std::find(ph.mode.begin(), ph.mode.end(), m.friction[f].contact);
    if (is_cone(f)) {
      cone_forces(ph, f, ph.F.row(it - ph.mode.begin()), F_all, first[f]);
    } else if (ph.friction[f] == FrictionMode::kStick) {
      ph.Ft.row(fi) = F_all.row(first[f]);
    } else if (planar_slip(ph.friction[f])) {
      ph.Ft.row(fi) = -sigma_of(ph.friction[f]) * m.friction[f].mu * ph.F.row(it - ph.mode.begin());
    }
  }
  return true;
}

// Statically indeterminate stick (more independent-looking rows than the
// motion allows: S = H M^-1 H' singular): forces Z c in the null space of S
// act on nothing (H' Z = 0), so any c gives the same motion. The
// minimum-norm split can leave the friction cone where another does not;
// with a one-dimensional null space, c is chosen to maximise the smallest
// margin at the phase start (u_N >= 0, mu u_N -+ u_T >= 0), a 1-D max-min
// of lines solved at their crossings, and held constant through the phase
// (on the augmented state's constant entry). Larger null spaces keep the
// minimum-norm split.
void EventDriven::indeterminate_split(const Phase& ph, const MatrixXd& S,
                                      const std::vector<int>& stick, const VectorXd& xa,
                                      MatrixXd& F_all) const {
  const Eigen::SelfAdjointEigenSolver<MatrixXd> es(S);
  const double tol = 1e-10 * es.eigenvalues().cwiseAbs().maxCoeff();
  if ((es.eigenvalues().array() <= tol).count() != 1) return;
  const VectorXd z = es.eigenvectors().col(0);  // eigenvalues ascend
  const VectorXd lambda = F_all * xa;
  const mech::MechanicalModel& m = *model_.mechanical;
  const Eigen::Index nI = static_cast<Eigen::Index>(ph.mode.size());
  std::vector<double> g0, b;  // margins g0 + b c
  for (Eigen::Index i = 0; i < nI; ++i) g0.push_back(lambda(i)), b.push_back(z(i));
  for (size_t s = 0; s < stick.size(); ++s) {
    const mech::FrictionalContact& fc = m.friction[static_cast<size_t>(stick[s])];
    const Eigen::Index i = std::find(ph.mode.begin(), ph.mode.end(), fc.contact) - ph.mode.begin();
    const Eigen::Index r = nI + static_cast<Eigen::Index>(s);
    for (const double side : {-1.0, 1.0}) {
      g0.push_back(fc.mu * lambda(i) + side * lambda(r));
      b.push_back(fc.mu * z(i) + side * z(r));
    }
  }
  auto worst = [&](double c) {
    double w = std::numeric_limits<double>::infinity();
    for (size_t j = 0; j < g0.size(); ++j) w = std::min(w, g0[j] + b[j] * c);
    return w;
  };
  double best_c = 0.0, best = worst(0.0);
  for (size_t j = 0; j < g0.size(); ++j)
    for (size_t k = 0; k < g0.size(); ++k) {
      if (!(b[j] > 0.0 && b[k] < 0.0)) continue;
      const double c = (g0[k] - g0[j]) / (b[j] - b[k]);
      if (const double w = worst(c); w > best) best = w, best_c = c;
    }
  F_all.col(n_ - 1) += best_c * z;
}

// The monitors of the frictional contacts: sticking, the two edges of the
// cone mu u_N - u_T >= 0 and mu u_N + u_T >= 0; slipping in direction
// sigma, sigma (t'v - velocity) >= 0 (the belt's velocity is the constant
// term, on the augmented state's last entry).
void EventDriven::add_friction_monitors(Phase& ph) const {
  const mech::MechanicalModel& m = *model_.mechanical;
  for (size_t f = 0; f < ph.friction.size(); ++f) {
    const FrictionMode mode = ph.friction[f];
    if (mode == FrictionMode::kOpen) continue;
    if (is_cone(f)) {
      add_cone_monitors(ph, f);
      continue;
    }
    const mech::FrictionalContact& fc = m.friction[f];
    const Eigen::Index fi = static_cast<Eigen::Index>(f);
    Monitor mon;
    mon.constraint = fc.contact;
    mon.friction = static_cast<int>(f);
    if (mode == FrictionMode::kStick) {
      const auto it = std::find(ph.mode.begin(), ph.mode.end(), fc.contact);
      const RowVectorXd uN = ph.F.row(it - ph.mode.begin());
      mon.multiplier = true;
      for (const double side : {-1.0, 1.0}) {
        mon.w = fc.mu * uN + side * ph.Ft.row(fi);
        ph.monitors.push_back(mon);
      }
    } else {
      mon.w = RowVectorXd::Zero(n_);
      mon.w.segment(N_, N_) = fc.tangent.transpose();
      mon.w(n_ - 1) = -fc.velocity;
      mon.w *= sigma_of(mode);
      ph.monitors.push_back(mon);
    }
  }
}

// A sample's stick / slip modes and tangential multipliers (models with
// friction only).
void EventDriven::fill_friction(Sample& s, const Phase& ph, const VectorXd& xa) const {
  if (friction_contacts_.empty()) return;
  s.friction_mode = ph.friction;
  s.friction_mode.resize(friction_contacts_.size(), FrictionMode::kOpen);
  for (FrictionMode& fm : s.friction_mode)
    if (cone_slip(fm)) fm = FrictionMode::kSlip;  // the facet is internal (cone_phase.cpp)
  s.u_t = ph.Ft.rows() == static_cast<Eigen::Index>(friction_contacts_.size())
              ? VectorXd(ph.Ft * xa)
              : VectorXd::Zero(static_cast<Eigen::Index>(friction_contacts_.size()));
  if (!has_cone_) return;
  s.u_t2 = ph.Ft2.rows() == s.u_t.size() ? VectorXd(ph.Ft2 * xa) : VectorXd::Zero(s.u_t.size());
  s.friction_facet.assign(friction_contacts_.size(), impact::ConeFacet{});
  for (size_t f = 0; f < ph.friction.size() && f < friction_contacts_.size(); ++f)
    s.friction_facet[f] = force_facet(ph.friction[f], cone_d(f));
}

void EventDriven::set_friction(Event& e, const EventResult& ev) const {
  const auto nf = static_cast<Eigen::Index>(friction_contacts_.size());
  if (nf == 0) return;
  e.friction_impulse = ev.friction_impulse.size() == nf ? ev.friction_impulse : VectorXd::Zero(nf);
  e.friction_mode_after = ev.friction;
  e.friction_mode_after.resize(friction_contacts_.size(), FrictionMode::kOpen);
  if (has_cone_) {
    e.friction_impulse2 =
        ev.friction_impulse2.size() == nf ? ev.friction_impulse2 : VectorXd::Zero(nf);
    e.friction_facet_after.assign(friction_contacts_.size(), impact::ConeFacet{});
    for (size_t f = 0; f < e.friction_mode_after.size(); ++f)
      e.friction_facet_after[f] = force_facet(e.friction_mode_after[f], cone_d(f));
  }
  for (FrictionMode& fm : e.friction_mode_after)
    if (cone_slip(fm)) fm = FrictionMode::kSlip;
}

}  // namespace lcsim::sim::detail
