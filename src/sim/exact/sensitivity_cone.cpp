// Forward sensitivities through 3-D friction on a polyhedral cone in the
// exact method (docs/sensitivities.md, "3-D friction"; the phases are
// cone_phase.cpp's). A phase in the mode (I, per contact stick / edge i /
// face j) is the planar machinery's with other rows and columns: with the
// held rows H = [E_I; stick: t, t2; face j: n_j^perp] and the force
// columns Gc = H with the sliding contacts' normal rows carrying their
// friction (edge i: -mu D_i; face j: -mu c n_j, c = cos(pi/(2d))), the
// forces are lambda = F x = -S^-1 H Av x, S = H M^-1 Gc', and for a
// parameter of the free acceleration dF = -S^-1 H dAv, dAcl = dAv + M^-1
// Gc' dF; for mu[c] of a sliding contact its column moves by dGc = the
// column / mu; M[i][j] moves G = M^-1 (dG = -G dM G: S, Av and the loop);
// an input's own parameter its dAv as f[i] (the planar derivations,
// sensitivity_friction.cpp). Its
// monitors (cone_phase.cpp's add_cone_monitors) move with dF: stick, the
// polygon's face j: mu c u_N - cos(theta_j) u_T - sin(theta_j) u_T2; a
// face's ends: mu s u_N -+ w (s = sin(pi/(2d)), w the cross row's
// multiplier); the sliding velocity's rows have no parameter term.
//
// At the start (t = 0) mode selection sets the rows it finds zero exactly
// to zero (cone_modes.cpp's project_rows: a contact at rest that sticks, a
// velocity on a face's bisector). A perturbed start slides off them and
// returns to them in a time O(|perturbation|) (stick: the stick force is
// strictly inside the polygon, so the slip decelerates; face: both edges'
// regions turn the velocity back to the bisector), by forces in the span
// of the held rows: the velocity's derivative is the M-orthogonal
// projection onto H v = 0 (the saltation of the slip -> stick or edge ->
// face event as its time goes to 0), the positions' is unchanged (they
// move by O(perturbation^2)). The same holds for a planar contact sticking
// at the start (its row t), so the projection is applied on every model
// with friction (before it, a planar stick at t = 0 gave dv(T)/dv0 = 1 and
// dx(T)/dv0 = T where both are 0).
//
// Impacts with a 3-D contact: sensitivity_cone_impact.cpp.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "sim/exact/sensitivity.hpp"

namespace lcsim::sim::detail {

namespace {

RowVectorXd row_of(const Eigen::SparseVector<double>& v) { return RowVectorXd(VectorXd(v)); }

// Unit vector at angle a in the tangent plane (t, t2).
RowVectorXd along(const mech::FrictionalContact& fc, double a) {
  return std::cos(a) * row_of(fc.tangent) + std::sin(a) * row_of(fc.tangent2);
}

bool planar_slip(FrictionMode m) {
  return m == FrictionMode::kSlipPositive || m == FrictionMode::kSlipNegative;
}

// Entry f's rows in mode `mode` with d edge pairs: the held rows it adds,
// and its friction column per unit of mu on its normal (empty if none).
void entry_rows(const mech::FrictionalContact& fc, FrictionMode mode, int d,
                std::vector<RowVectorXd>& held, RowVectorXd& unit_column) {
  unit_column.resize(0);
  if (d < 2) {  // planar (a 3-D contact with d = 1 too: friction along t only)
    if (mode == FrictionMode::kStick) held.push_back(row_of(fc.tangent));
    if (planar_slip(mode))
      unit_column = -(mode == FrictionMode::kSlipPositive ? 1.0 : -1.0) * row_of(fc.tangent);
    return;
  }
  const double step = std::numbers::pi / d;
  if (mode == FrictionMode::kStick) {
    held.push_back(row_of(fc.tangent));
    held.push_back(row_of(fc.tangent2));
  } else if (cone_slip(mode) && !cone_on_face(mode)) {
    unit_column = -along(fc, cone_index(mode) * step);
  } else if (cone_slip(mode)) {
    const double theta = (cone_index(mode) + 0.5) * step;
    unit_column = -std::cos(step / 2) * along(fc, theta);
    held.push_back(along(fc, theta + std::numbers::pi / 2));
  }
}

}  // namespace

// The phase's H, Gc, forces and each parameter's dAcl, dF (see the header).
void Sensitivity::cone_mode_derivatives(const Phase& ph, double t) {
  const mech::MechanicalModel& m = *model_.mechanical;
  const size_t P = cols_.params.size(), nf = ph.friction.size();
  dAb_.assign(P, MatrixXd::Zero(n_, n_));
  dF_.assign(P, MatrixXd());
  dW_.assign(P, MatrixXd());
  const Eigen::Index nI = static_cast<Eigen::Index>(ph.mode.size());
  std::vector<RowVectorXd> held, unit(nf);
  cone_first_.assign(nf, -1);
  stick_row_.assign(nf, -1);  // friction_monitor_dh's, for the planar entries
  cone_modes_ = ph.friction;
  for (size_t f = 0; f < nf; ++f) {
    const Eigen::Index first = nI + static_cast<Eigen::Index>(held.size());
    entry_rows(m.friction[f], ph.friction[f], cone_d_[f], held, unit[f]);
    if (nI + static_cast<Eigen::Index>(held.size()) > first) cone_first_[f] = first;
    if (cone_d_[f] < 2) stick_row_[f] = cone_first_[f];
  }
  const Eigen::Index nc = nI + static_cast<Eigen::Index>(held.size());
  MatrixXd H(nc, N_);
  const MatrixXd E = MatrixXd(m.E);
  for (Eigen::Index i = 0; i < nI; ++i) H.row(i) = E.row(ph.mode[static_cast<size_t>(i)]);
  for (Eigen::Index s = nI; s < nc; ++s) H.row(s) = held[static_cast<size_t>(s - nI)];
  MatrixXd Gc = H;
  std::vector<Eigen::Index> normal(nf, -1);
  for (size_t f = 0; f < nf; ++f) {
    const auto it = std::find(ph.mode.begin(), ph.mode.end(), m.friction[f].contact);
    if (it != ph.mode.end()) normal[f] = it - ph.mode.begin();
    if (unit[f].size() > 0 && normal[f] >= 0) Gc.row(normal[f]) += m.friction[f].mu * unit[f];
  }
  const MatrixXd GGt = G_ * Gc.transpose();
  Eigen::FullPivLU<MatrixXd> lu;  // no held row (every contact open): nothing to factor
  if (nc > 0) lu.compute(H * GGt);
  friction_F_ = MatrixXd::Zero(nc, n_);
  if (nc > 0 && !lu.isInvertible()) {
    std::vector<int> cols;
    for (size_t p = 0; p < P; ++p) cols.push_back(nx0_ + static_cast<int>(p));
    lose(t, ph.mode.empty() ? -1 : ph.mode.front(),
         "a statically indeterminate stick or slip with a 3-D contact (H M^-1 G' singular): the "
         "forces' split is the phase's choice, its parameter derivative is not computed",
         cols, true);
    return;
  }
  const MatrixXd Av = sys_.A.middleRows(N_, N_);
  if (nc > 0) friction_F_ = -lu.solve(H * Av);
  for (size_t p = 0; p < P; ++p) {
    const SensParam& sp = cols_.params[p];
    if (std::string("fKDugeM").find(sp.kind) == std::string::npos && !input_param_kind(sp.kind)) {
      // Not derived here (never a silent zero).
      lose(t, -1, "'" + sp.name + "' is not computed through 3-D friction",
           {nx0_ + static_cast<int>(p)});
      continue;
    }
    MatrixXd dAv = MatrixXd::Zero(N_, n_), dF = MatrixXd::Zero(nc, n_);
    if (sp.kind == 'f') dAv.col(2 * N_) = G_.col(sp.i);
    if (sp.kind == 'K') dAv.col(sp.j) = -G_.col(sp.i);
    if (sp.kind == 'D') dAv.col(N_ + sp.j) = -G_.col(sp.i);
    MatrixXd dA = MatrixXd::Zero(n_, n_);
    // An input's own parameter (a force input's): its exosystem rows as
    // they are, its velocity rows dAv through the forces as f[i]'s.
    if (input_param_kind(sp.kind)) dA = input_param_dA(m, sys_, sp), dAv = dA.middleRows(N_, N_);
    if (sp.kind == 'M') {
      // G = M^-1 moves S, the free acceleration and the closed loop (the
      // planar derivation: sensitivity_friction.cpp's mass_phase_rows).
      dA.middleRows(N_, N_) = mass_phase_rows(sp, G_, Av, H, Gc, friction_F_, lu, dF);
    } else if (sp.kind == 'u') {
      // mu of a sliding contact: its normal's column moves by its unit
      // column; a sticking contact's mu enters its monitors only.
      const size_t f = static_cast<size_t>(sp.j);
      if (unit[f].size() > 0 && normal[f] >= 0) {
        MatrixXd dGc = MatrixXd::Zero(nc, N_);
        dGc.row(normal[f]) = unit[f];
        dF = -lu.solve(H * G_ * dGc.transpose() * friction_F_);
        dA.middleRows(N_, N_) = G_ * dGc.transpose() * friction_F_ + GGt * dF;
      }
    } else {
      if (nc > 0) dF = -lu.solve(H * dAv);
      dA.middleRows(N_, N_) = dAv + GGt * dF;
    }
    dAb_[p] = D_.cwiseInverse().asDiagonal() * dA * D_.asDiagonal();
    dF_[p] = dF;
  }
}

// A monitor's parameter term in a model with a 3-D contact: a planar
// entry's as friction_monitor_dh; a cone entry's stick or face-end monitor
// by its position k among the entry's monitors (add_cone_monitors: stick,
// faces j = k; face, the speed then the ends -1, +1).
double Sensitivity::cone_monitor_dh(size_t p, size_t monitor, const VectorXd& x) const {
  const Monitor& mon = monitors_[monitor];
  if (!is_cone_entry(mon.friction)) return friction_monitor_dh(p, monitor, x);
  if (!mon.multiplier) return 0.0;
  const size_t f = static_cast<size_t>(mon.friction);
  const mech::FrictionalContact& fc = model_.mechanical->friction[f];
  const auto it = std::find(mode_.begin(), mode_.end(), fc.contact);
  const Eigen::Index row = cone_first_[f];
  if (row < 0 || it == mode_.end()) return 0.0;
  const Eigen::Index normal = it - mode_.begin();
  int k = 0;
  for (size_t j = 0; j < monitor; ++j) k += monitors_[j].friction == mon.friction ? 1 : 0;
  const double step = std::numbers::pi / cone_d_[f];
  const SensParam& sp = cols_.params[p];
  const bool own = sp.kind == 'u' && sp.j == mon.friction;
  const MatrixXd& dF = dF_[p];
  const double uN = friction_F_.row(normal).dot(x), duN = dF.row(normal).dot(x);
  if (cone_modes_[f] == FrictionMode::kStick) {
    const double theta = (k + 0.5) * step, c = std::cos(step / 2);
    return c * (fc.mu * duN + (own ? uN : 0.0)) - std::cos(theta) * dF.row(row).dot(x) -
           std::sin(theta) * dF.row(row + 1).dot(x);
  }
  const double side = k == 1 ? -1.0 : 1.0, s = std::sin(step / 2);
  return s * (fc.mu * duN + (own ? uN : 0.0)) + side * dF.row(row).dot(x);
}

// A cone monitor starting at zero (order m0 of its first nonzero
// derivative). Generic: a sliding velocity's monitor of the contact whose
// stick force or face force just reached the polygon's boundary (m0 = 2:
// the force is continuous there), the velocity not at rest on an edge (a
// stick force leaving the polygon at a vertex: both of the edge's bisector
// monitors at zero); the bisector just crossed by a moving velocity from
// one edge's region into the next (m0 = 1: a face whose force would leave
// the face, so the velocity crosses its bisector transversally); a sliding
// velocity that passed through zero (a face slide's speed reaching zero
// under a pull beyond the polygon, as a planar slip reverses: the new
// slip starts from rest along the acceleration, m0 = 1). At t = 0, slip from rest (a push
// beyond the polygon): the x0 entries that move the sliding velocity are one-sided, the others
// kept. Anything else (a stick force on the polygon's boundary, a face
// force at an end of the face, a velocity on the boundary of an edge's
// region at the start) has several stick / slip selections nearby.
void Sensitivity::check_cone_start(const Monitor& mon, FrictionMode mode, double t, int m0,
                                   int trigger, bool stuck) {
  const size_t f = static_cast<size_t>(mon.friction);
  const mech::FrictionalContact& fc = model_.mechanical->friction[f];
  const VectorXd v = x0_.segment(N_, N_);
  const double s1 = VectorXd(fc.tangent).dot(v), s2 = VectorXd(fc.tangent2).dot(v);
  const double scale =
      (VectorXd(fc.tangent).cwiseAbs() + VectorXd(fc.tangent2).cwiseAbs()).dot(v.cwiseAbs());
  const bool at_rest = std::hypot(s1, s2) <= kSqrtEps * scale;
  const bool edge = cone_slip(mode) && !cone_on_face(mode);
  if (!mon.multiplier && mon.constraint == trigger &&
      ((m0 == 1 && !stuck) || (m0 == 2 && stuck && !(edge && at_rest))))
    return;
  if (t == 0.0 && trigger < 0 && !mon.multiplier && at_rest && m0 == 1) {
    std::vector<int> cols;
    for (int c = N_; c < 2 * N_ && c < nx0_; ++c)
      if (fc.tangent.coeff(c - N_) != 0.0 || fc.tangent2.coeff(c - N_) != 0.0) cols.push_back(c);
    lose(t, mon.constraint,
         "slip from rest at the start on a 3-D contact: the sliding velocity is zero, so only "
         "one-sided derivatives exist in the entries that move it",
         cols, true);
    return;
  }
  lose_all(t, mon.constraint,
           edge && at_rest
               ? "degenerate stick / slip on a 3-D contact: slip from rest on an edge of the "
                 "cone (the stick force left the polygon at a vertex), no derivative"
           : mon.multiplier
               ? "degenerate stick / slip on a 3-D contact: the stick force on the polygon's "
                 "boundary, or the face force at an end of the face (stick and slip meet), no "
                 "derivative"
           : at_rest
               ? "degenerate stick / slip on a 3-D contact: at rest with the force on the "
                 "polygon's boundary (slip from rest without acceleration: stick and slip meet), "
                 "no derivative"
               : "degenerate stick / slip on a 3-D contact: the sliding velocity on the boundary "
                 "between an edge's region and a face's, no derivative");
}

// Other friction monitors at zero with the trigger (to sqrt(eps) of their
// terms): several contacts turning or stopping together (a box's four
// corners, by symmetry), a slide stopping on an edge of the cone (its two
// bisector monitors: the turn onto a face and the stop coincide), a stick
// force reaching the polygon at a vertex. The event time is then the
// earliest of several roots: a column keeps its derivative where every
// root moves alike (dtau from each monitor equal to 1e-8 relative: a
// perturbation that keeps the contacts together, as the box's along its
// slide), and is lost where they part (nearby runs have other events).
void Sensitivity::check_cone_event(double tau, const VectorXd& x_minus, size_t monitor) {
  const Monitor& mon = monitors_[monitor];
  if (mon.friction < 0) return;
  std::vector<char> part(static_cast<size_t>(m_), 0);
  int parting_contact = -1;
  bool edge_stop = false;
  for (size_t j = 0; j < monitors_.size(); ++j) {
    const Monitor& o = monitors_[j];
    if (j == monitor || o.friction < 0 ||
        std::abs(o.w.dot(x_minus)) >
            kSqrtEps * o.w.cwiseAbs().sum() * x_minus.cwiseAbs().maxCoeff())
      continue;
    const double rate = o.w.dot(xdot_minus_);
    RowVectorXd dh = o.w * S_minus_;
    for (size_t p = 0; p < cols_.params.size(); ++p)
      if (p < dF_.size() && dF_[p].size() > 0)
        dh(nx0_ + static_cast<Eigen::Index>(p)) += cone_monitor_dh(p, j, x_minus);
    const bool flat = std::abs(rate) <= kSqrtEps * o.w.cwiseAbs().dot(xdot_minus_.cwiseAbs());
    for (int c = 0; c < m_; ++c) {
      const double d = flat ? 0.0 : -dh(c) / rate, d0 = dtau_(c);
      if (flat || std::abs(d - d0) > 1e-8 * (std::abs(d) + std::abs(d0)) + 1e-14) {
        part[static_cast<size_t>(c)] = 1;
        if (parting_contact < 0) parting_contact = o.constraint;
        edge_stop = edge_stop || (o.friction == mon.friction && !o.multiplier && !mon.multiplier);
      }
    }
  }
  std::vector<int> cols;
  for (int c = 0; c < m_; ++c)
    if (part[static_cast<size_t>(c)]) cols.push_back(c);
  if (cols.empty()) return;
  lose(tau, parting_contact,
       edge_stop ? "a 3-D slide that stops on an edge of the cone: the turn onto a face and the "
                   "stop coincide, no derivative in the entries that part them"
                 : "coinciding stick / slip events (another friction monitor reaches zero with "
                   "this one: contacts turning or stopping together, a stick force at the "
                   "polygon's vertex), no derivative in the entries that part them",
       cols);
}

// At t = 0: the velocity rows of S projected M-orthogonally onto H v = 0
// (the phase's normals and the rows mode selection set to zero: stick's t,
// t2, a face's cross row), see the header.
void Sensitivity::project_friction_start(const Phase& ph, MatrixXd& S) const {
  const mech::MechanicalModel& m = *model_.mechanical;
  std::vector<RowVectorXd> held;
  for (size_t f = 0; f < ph.friction.size(); ++f) {
    const FrictionMode fm = ph.friction[f];
    if (fm != FrictionMode::kStick && !(cone_slip(fm) && cone_on_face(fm))) continue;
    RowVectorXd unused;
    entry_rows(m.friction[f], fm, cone_d_[f], held, unused);
  }
  if (held.empty()) return;
  const Eigen::Index nI = static_cast<Eigen::Index>(ph.mode.size());
  MatrixXd H(nI + static_cast<Eigen::Index>(held.size()), N_);
  for (Eigen::Index i = 0; i < nI; ++i) H.row(i) = m.E.row(ph.mode[static_cast<size_t>(i)]);
  for (size_t s = 0; s < held.size(); ++s) H.row(nI + static_cast<Eigen::Index>(s)) = held[s];
  const MatrixXd GHt = G_ * H.transpose();
  // Dependent rows (a box's four corners on one floor): the least-squares
  // multipliers still give the projection onto H v = 0.
  const MatrixXd V = S.middleRows(N_, N_);
  S.middleRows(N_, N_) = V - GHt * (H * GHt).completeOrthogonalDecomposition().solve(H * V);
}

}  // namespace lcsim::sim::detail
