// Forward sensitivities through an impact with planar friction
// (docs/sensitivities.md): the planar Coulomb impact law (impact::
// moreau_friction, the LCP in (lambda_N, lambda_R, xi)) is linear in v at a
// fixed outcome: the contacts with a positive normal impulse A, and for each
// frictional contact on A its post-impact stick or slip sign. With G =
// M^{-1}, the unknowns the normal impulses lambda_A and the stuck contacts'
// tangential impulses lambda_S,
//   E_r v+ = -e_r E_r v   (r in A; e_r = 0 unless approaching, E_r v < 0),
//   t_f v+ = velocity_f   (f stuck),
//   lambda_T,f = -sigma_f mu_f lambda_N   (f sliding along sigma_f t_f),
// so v+ = v + G B lambda with B = [E_A' + T_slip' (-sigma mu), T_S'],
// X G B lambda = c - R v (X = [E_A; T_S], R = [(1 + e) E_A; T_S], c = [0;
// velocity]) and J's velocity block is I - G B (X G B)^{-1} R. The map is
// not differentiable where the outcome is not locally constant: a stuck
// contact at the cone's edge (|lambda_T| = mu lambda_N), a sliding contact
// whose post-impact sliding velocity is zero, an approach rate at zero on a
// contact with restitution (e switches on there), and a closed contact with a
// zero impulse and a zero separation rate, each to sqrt(eps) of its scale.
#include <algorithm>
#include <cmath>

#include "sim/exact/sensitivity.hpp"

namespace lcsim::sim::detail {

namespace {

// The rows of one impact round's linear system at its outcome.
struct FrictionImpactRows {
  MatrixXd X, R, B;        // (a + s) x N, (a + s) x N, N x (a + s)
  VectorXd c;              // (a + s)
  std::vector<int> stuck;  // entries of mechanical.friction stuck after the impact
  std::vector<int> sliding;
  std::vector<double> sigma;  // per sliding entry
};

// The friction's part of the rows: a sliding contact's impulse -sigma mu
// lambda_N along its tangent joins its normal's column of B; a stuck one
// adds the unknown lambda_T with the row t_f v+ = velocity_f.
void add_tangent_rows(const mech::MechanicalModel& m, const std::vector<int>& A,
                      FrictionImpactRows& s) {
  const int a = static_cast<int>(A.size());
  for (size_t k = 0; k < s.sliding.size(); ++k) {
    const mech::FrictionalContact& fc = m.friction[static_cast<size_t>(s.sliding[k])];
    const auto i = std::find(A.begin(), A.end(), fc.contact) - A.begin();
    s.B.col(i) -= s.sigma[k] * fc.mu * VectorXd(fc.tangent);
  }
  for (size_t k = 0; k < s.stuck.size(); ++k) {
    const mech::FrictionalContact& fc = m.friction[static_cast<size_t>(s.stuck[k])];
    const Eigen::Index row = a + static_cast<Eigen::Index>(k);
    s.X.row(row) = VectorXd(fc.tangent).transpose();
    s.R.row(row) = s.X.row(row);
    s.B.col(row) = VectorXd(fc.tangent);
    s.c(row) = fc.velocity;
  }
}

// mu[c] of a contact sliding after the impact: its column of B moves by
// dB = -sigma t, so dlambda = -(X G B)^-1 X G dB lambda and dv+ = G (dB
// lambda + B dlambda), into dR's velocity rows of the column.
void mu_impact_columns(const mech::MechanicalModel& m, const std::vector<SensParam>& params,
                       int nx0, const MatrixXd& G, const std::vector<int>& A,
                       const FrictionImpactRows& s, const Eigen::FullPivLU<MatrixXd>& W,
                       const VectorXd& lambda, MatrixXd& dR) {
  const Eigen::Index N = G.rows(), na = s.B.cols();
  for (size_t p = 0; p < params.size(); ++p) {
    const SensParam& sp = params[p];
    const auto k = std::find(s.sliding.begin(), s.sliding.end(), sp.j) - s.sliding.begin();
    if (sp.kind != 'u' || k == static_cast<long>(s.sliding.size())) continue;
    const mech::FrictionalContact& fc = m.friction[static_cast<size_t>(sp.j)];
    const auto i = std::find(A.begin(), A.end(), fc.contact) - A.begin();
    MatrixXd dB = MatrixXd::Zero(N, na);
    dB.col(i) = -s.sigma[static_cast<size_t>(k)] * VectorXd(fc.tangent);
    const VectorXd dlambda = -W.solve(s.X * G * dB * lambda);
    dR.block(N, nx0 + static_cast<Eigen::Index>(p), N, 1) = G * (dB * lambda) + G * s.B * dlambda;
  }
}

}  // namespace

// M[i][j] and e[c] through one impact round at its outcome (the map's
// rows X, R, B, c do not depend on either; G = M^-1 does). M[i][j] (dM the
// unit entries (i, j), (j, i)): dG = -G dM G, so dlambda = -(X G B)^-1 X dG
// B lambda and dv+ = dG B lambda + G B dlambda. e[c] of a contact on A
// whose restitution is on (approaching, a_c = E_c v < 0; `erate` holds a_c
// there, 0 elsewhere and for the inelastic law): R's row moves by E_c, so
// dlambda = -(X G B)^-1 unit_c a_c and dv+ = G B dlambda. Into dR's
// velocity rows of the column. (At e_c = 0 the column is lost where the
// contact is then held: Sensitivity::plastic_restitution.)
void mass_restitution_impact_columns(const std::vector<SensParam>& params, int nx0,
                                     const MatrixXd& G, const MatrixXd& GB, const MatrixXd& X,
                                     const Eigen::FullPivLU<MatrixXd>& W, const VectorXd& lambda,
                                     const std::vector<int>& A, const VectorXd& erate,
                                     MatrixXd& dR) {
  const Eigen::Index N = G.rows(), na = GB.cols();
  for (size_t p = 0; p < params.size(); ++p) {
    const SensParam& sp = params[p];
    VectorXd dv;
    if (sp.kind == 'M') {
      MatrixXd dM = MatrixXd::Zero(N, N);
      dM(sp.i, sp.j) = dM(sp.j, sp.i) = 1.0;
      dv = -G * (dM * (GB * lambda));  // dG B lambda
      if (na > 0) dv += GB * VectorXd(-W.solve(X * dv));
    } else if (sp.kind == 'e') {
      const auto i = std::find(A.begin(), A.end(), sp.i) - A.begin();
      if (i == static_cast<long>(A.size()) || erate(i) == 0.0) continue;
      VectorXd unit = VectorXd::Zero(na);
      unit(i) = erate(i);
      dv = GB * VectorXd(-W.solve(unit));
    } else {
      continue;
    }
    dR.block(N, nx0 + static_cast<Eigen::Index>(p), N, 1) = dv;
  }
}

bool Sensitivity::friction_impact_map(double t, const EventResult::ImpactRound& rd, MatrixXd& J,
                                      MatrixXd& dR) {
  const mech::MechanicalModel& m = *model_.mechanical;
  if (!m.gap_inputs.empty() || rd.outcome.size() != static_cast<size_t>(m.num_constraints())) {
    lose_all(t, rd.closed.empty() ? -1 : rd.closed.front(),
             "an impact with friction on a moving stop: its derivative is not computed");
    return false;
  }
  const MatrixXd E = MatrixXd(m.E);
  const VectorXd& v = rd.v_before;
  const VectorXd e = law_ == 'i' ? VectorXd::Zero(rd.restitution.size()) : rd.restitution;
  const ImpactActive act = impact_active(rd, E);
  const std::vector<int>& A = act.A;
  const double amax = act.amax;
  const int a = static_cast<int>(A.size());
  FrictionImpactRows s;
  for (size_t f = 0; f < m.friction.size(); ++f) {
    const int row = m.friction[f].contact;
    if (std::find(A.begin(), A.end(), row) == A.end()) continue;
    const impact::ContactOutcome o = rd.outcome[static_cast<size_t>(row)];
    if (o == impact::ContactOutcome::kStick) {
      s.stuck.push_back(static_cast<int>(f));
    } else if (o == impact::ContactOutcome::kSlipPositive ||
               o == impact::ContactOutcome::kSlipNegative) {
      s.sliding.push_back(static_cast<int>(f));
      s.sigma.push_back(o == impact::ContactOutcome::kSlipPositive ? 1.0 : -1.0);
    } else {
      lose_all(t, row,
               "an impact with friction whose outcome at this contact is not stick or slip");
      return false;
    }
  }
  const int ns = static_cast<int>(s.stuck.size()), na = a + ns;
  s.X = MatrixXd::Zero(na, N_), s.R = MatrixXd::Zero(na, N_), s.B = MatrixXd::Zero(N_, na);
  s.c = VectorXd::Zero(na);
  VectorXd erate = VectorXd::Zero(na);  // a_r where e_r is on (e[c]'s term)
  for (int i = 0; i < a; ++i) {
    const int r = A[static_cast<size_t>(i)];
    const double ar = E.row(r).dot(v);
    // e switches on with the approach (u_N- < 0): at u_N- = 0 the map has a kink.
    if (e(r) != 0.0 && std::abs(ar) <= kSqrtEps * amax) {
      lose_all(t, r,
               "an impact with friction at a zero approach rate with restitution: not "
               "differentiable");
      return false;
    }
    s.X.row(i) = E.row(r);
    s.R.row(i) = (1.0 + (ar < 0.0 ? e(r) : 0.0)) * E.row(r);
    if (ar < 0.0 && law_ != 'i') erate(i) = ar;
    s.B.col(i) = E.row(r).transpose();
  }
  add_tangent_rows(m, A, s);
  const MatrixXd GB = G_ * s.B;
  const Eigen::FullPivLU<MatrixXd> W(s.X * GB);
  if (na > 0 && !W.isInvertible()) {
    lose_all(t, A.empty() ? -1 : A.front(),
             "an impact with friction whose linear map at its outcome is singular");
    return false;
  }
  const VectorXd lambda = na > 0 ? VectorXd(W.solve(s.c - s.R * v)) : VectorXd();
  const VectorXd vplus = v + GB * lambda;
  if (!friction_impact_regular(t, rd, A, s.stuck, s.sliding, lambda, vplus)) return false;
  J = MatrixXd::Identity(n_, n_);
  if (na > 0) {
    J.block(N_, N_, N_, N_) -= GB * W.solve(s.R);
    J.block(N_, 2 * N_, N_, 1) = GB * W.solve(s.c);
  }
  mu_impact_columns(m, cols_.params, nx0_, G_, A, s, W, lambda, dR);
  mass_restitution_impact_columns(cols_.params, nx0_, G_, GB, s.X, W, lambda, A, erate, dR);
  return true;
}

// The outcome is locally constant: the impulses reproduce the law's (to
// 1e-8 of the largest), no stuck contact at the cone's edge, no sliding one
// at a zero sliding velocity, no closed contact without impulse at a zero
// separation rate.
bool Sensitivity::friction_impact_regular(double t, const EventResult::ImpactRound& rd,
                                          const std::vector<int>& A, const std::vector<int>& stuck,
                                          const std::vector<int>& sliding, const VectorXd& lambda,
                                          const VectorXd& vplus) {
  const mech::MechanicalModel& m = *model_.mechanical;
  const MatrixXd E = MatrixXd(m.E);
  const int a = static_cast<int>(A.size());
  const double pmax = a > 0 ? lambda.head(a).cwiseAbs().maxCoeff() : 0.0;
  const double vmax = rd.v_before.cwiseAbs().maxCoeff() + vplus.cwiseAbs().maxCoeff();
  for (int i = 0; i < a; ++i)
    if (std::abs(lambda(i) - rd.impulse(A[static_cast<size_t>(i)])) > 1e-8 * pmax) {
      lose_all(t, A[static_cast<size_t>(i)],
               "an impact with friction whose impulses the linear map at its outcome does not "
               "reproduce");
      return false;
    }
  for (size_t k = 0; k < stuck.size(); ++k) {
    const mech::FrictionalContact& fc = m.friction[static_cast<size_t>(stuck[k])];
    const auto i = std::find(A.begin(), A.end(), fc.contact) - A.begin();
    const double lt = lambda(a + static_cast<Eigen::Index>(k)), ln = lambda(i);
    if (std::abs(lt) >= (1.0 - kSqrtEps) * fc.mu * ln) {
      lose_all(t, fc.contact,
               "an impact with friction that sticks at the cone's edge (|P_T| = mu P_N): stick "
               "and slip meet there, no derivative");
      return false;
    }
  }
  for (int f : sliding) {
    const mech::FrictionalContact& fc = m.friction[static_cast<size_t>(f)];
    if (std::abs(fc.sliding(vplus)) <=
        kSqrtEps * (vmax * VectorXd(fc.tangent).cwiseAbs().sum() + std::abs(fc.velocity))) {
      lose_all(t, fc.contact,
               "an impact with friction after which the contact slides at zero velocity: stick "
               "and slip meet there, no derivative");
      return false;
    }
  }
  double amax = 0.0;
  for (int r : rd.closed) amax = std::max(amax, std::abs(E.row(r).dot(rd.v_before)));
  for (int r : rd.closed) {
    if (std::find(A.begin(), A.end(), r) != A.end()) continue;
    if (std::abs(E.row(r).dot(vplus)) <= kSqrtEps * amax) {
      lose_all(t, r,
               "degenerate impact: a zero impulse and a zero separation rate (the impact LCP's "
               "active set is not locally constant)");
      return false;
    }
  }
  return true;
}

}  // namespace lcsim::sim::detail

namespace lcsim::sim::detail {

// A phase with planar friction in the mode (I, stick / slip): with the held
// rows H = [E_I; T_S] and the force columns G = [E_I - sigma mu T; T_S]
// (friction_phase.cpp), the forces are lambda = F x = -S^-1 H Av x with
// S = H M^-1 G' and Av the free acceleration's rows (-M^-1 K, -M^-1 D,
// M^-1 f), and Acl's velocity rows are Av + M^-1 G' F. A parameter of the
// free acceleration (f[i], K[i][j], D[i][j]: dAv = M^-1 dH, one column)
// leaves H, G and S as they are: dF = -S^-1 H dAv and dAcl = dAv + M^-1 G'
// dF; so does a force input's own parameter (its dA's velocity rows; its
// exosystem rows as they are). M[i][j] moves G = M^-1 and with it Av and S
// (mass_phase_rows). A gap offset g[c] and a restitution e[c] move no phase
// (g[c]'s term is the gap monitor's, dh = 1). A singular S (a statically
// indeterminate stick, whose split the phase chooses) loses the columns.

// M[i][j] (dM the unit entries (i, j) and (j, i)) in a friction phase: G =
// M^-1 moves by dG = -G dM G, so the free acceleration Av = G [-K -D f ...]
// by dAv = -G dM Av, S = H G Gc' by dS = H dG Gc', the forces F = -S^-1 H
// Av by dF = -S^-1 (dS F + H dAv), and Acl's velocity rows Av + G Gc' F by
// dAv + dG Gc' F + G Gc' dF. Returns those rows (N x n); dF is set (rows of
// F; none when every contact is open). Shared with the 3-D phases
// (sensitivity_cone.cpp), whose H and Gc are other rows of the same form.
MatrixXd mass_phase_rows(const SensParam& sp, const MatrixXd& G, const MatrixXd& Av,
                         const MatrixXd& H, const MatrixXd& Gc, const MatrixXd& F,
                         const Eigen::FullPivLU<MatrixXd>& lu, MatrixXd& dF) {
  const Eigen::Index N = G.rows();
  MatrixXd dM = MatrixXd::Zero(N, N);
  dM(sp.i, sp.j) = dM(sp.j, sp.i) = 1.0;
  const MatrixXd dG = -G * dM * G;
  const MatrixXd dAv = -G * (dM * Av);
  dF = MatrixXd::Zero(H.rows(), Av.cols());
  if (H.rows() == 0) return dAv;
  const MatrixXd dGGt = dG * Gc.transpose();
  dF = -lu.solve(H * dGGt * F + H * dAv);
  return dAv + dGGt * F + G * Gc.transpose() * dF;
}

void Sensitivity::friction_mode_derivatives(const Phase& ph, double t) {
  const mech::MechanicalModel& m = *model_.mechanical;
  const size_t P = cols_.params.size();
  dAb_.assign(P, MatrixXd::Zero(n_, n_));
  dF_.assign(P, MatrixXd());
  dW_.assign(P, MatrixXd());
  const Eigen::Index nI = static_cast<Eigen::Index>(ph.mode.size());
  std::vector<Eigen::Index> stick(ph.friction.size(), -1);
  Eigen::Index ns = 0;
  for (size_t f = 0; f < ph.friction.size(); ++f)
    if (ph.friction[f] == FrictionMode::kStick) stick[f] = nI + ns++;
  stick_row_ = stick;
  MatrixXd H(nI + ns, N_), Gc(nI + ns, N_);
  const MatrixXd E = MatrixXd(m.E);
  for (Eigen::Index i = 0; i < nI; ++i) H.row(i) = E.row(ph.mode[static_cast<size_t>(i)]);
  Gc.topRows(nI) = H.topRows(nI);
  for (size_t f = 0; f < ph.friction.size(); ++f) {
    const mech::FrictionalContact& fc = m.friction[f];
    if (stick[f] >= 0) H.row(stick[f]) = Gc.row(stick[f]) = VectorXd(fc.tangent).transpose();
    const FrictionMode fm = ph.friction[f];
    if (fm != FrictionMode::kSlipPositive && fm != FrictionMode::kSlipNegative) continue;
    const auto it = std::find(ph.mode.begin(), ph.mode.end(), fc.contact);
    Gc.row(it - ph.mode.begin()) -=
        (fm == FrictionMode::kSlipPositive ? 1.0 : -1.0) * fc.mu * VectorXd(fc.tangent).transpose();
  }
  const MatrixXd GGt = G_ * Gc.transpose();
  Eigen::FullPivLU<MatrixXd> lu;  // no held row (every contact open): nothing to factor
  if (nI + ns > 0) lu.compute(H * GGt);
  friction_F_ = MatrixXd::Zero(nI + ns, n_);
  if (nI + ns > 0 && !lu.isInvertible()) {
    std::vector<int> cols;
    for (size_t p = 0; p < P; ++p) cols.push_back(nx0_ + static_cast<int>(p));
    lose(t, ph.mode.empty() ? -1 : ph.mode.front(),
         "a statically indeterminate stick (H M^-1 G' singular): the forces' split is the "
         "phase's choice, its parameter derivative is not computed",
         cols, true);
    return;
  }
  const MatrixXd Av = sys_.A.middleRows(N_, N_);
  if (nI + ns > 0) friction_F_ = -lu.solve(H * Av);
  for (size_t p = 0; p < P; ++p) {
    const SensParam& sp = cols_.params[p];
    MatrixXd dAv = MatrixXd::Zero(N_, n_), dF = MatrixXd::Zero(nI + ns, n_);
    if (sp.kind == 'f') dAv.col(2 * N_) = G_.col(sp.i);
    if (sp.kind == 'K') dAv.col(sp.j) = -G_.col(sp.i);
    if (sp.kind == 'D') dAv.col(N_ + sp.j) = -G_.col(sp.i);
    MatrixXd dA = MatrixXd::Zero(n_, n_);
    if (sp.kind == 'M') {
      dA.middleRows(N_, N_) = mass_phase_rows(sp, G_, Av, H, Gc, friction_F_, lu, dF);
    } else if (sp.kind == 'u') {
      // mu of a sliding contact: its normal's force column -sigma mu t
      // moves by dGc = -sigma t, so dF = -S^-1 H M^-1 dGc' F and dAcl's
      // velocity rows M^-1 (dGc' F + G' dF). Sticking: no phase term.
      const FrictionMode fm = ph.friction[static_cast<size_t>(sp.j)];
      if (fm == FrictionMode::kSlipPositive || fm == FrictionMode::kSlipNegative) {
        const mech::FrictionalContact& fc = m.friction[static_cast<size_t>(sp.j)];
        MatrixXd dGc = MatrixXd::Zero(nI + ns, N_);
        dGc.row(std::find(ph.mode.begin(), ph.mode.end(), fc.contact) - ph.mode.begin()) =
            -(fm == FrictionMode::kSlipPositive ? 1.0 : -1.0) * VectorXd(fc.tangent).transpose();
        dF = -lu.solve(H * G_ * dGc.transpose() * friction_F_);
        dA.middleRows(N_, N_) = G_ * dGc.transpose() * friction_F_ + GGt * dF;
      }
    } else {
      // An input's own parameter (a force input's; moving stops are not
      // simulated with friction): its dA's velocity rows are dAv, its
      // exosystem rows stay as they are.
      if (input_param_kind(sp.kind)) dA = input_param_dA(m, sys_, sp), dAv = dA.middleRows(N_, N_);
      if (nI + ns > 0) dF = -lu.solve(H * dAv);
      dA.middleRows(N_, N_) = dAv + GGt * dF;
    }
    dAb_[p] = D_.cwiseInverse().asDiagonal() * dA * D_.asDiagonal();
    dF_[p] = dF;
  }
}

// A friction monitor's parameter term: a sliding velocity sigma (t'v -
// velocity) has none; a stick force mu u_N + side u_T (add_friction_monitors
// pushes side -1, then +1) moves by (mu dF_N + side dF_T) x.
double Sensitivity::friction_monitor_dh(size_t p, size_t monitor, const VectorXd& x) const {
  const Monitor& mon = monitors_[monitor];
  if (!mon.multiplier) return 0.0;
  const mech::FrictionalContact& fc =
      model_.mechanical->friction[static_cast<size_t>(mon.friction)];
  const Eigen::Index row = stick_row_[static_cast<size_t>(mon.friction)];
  const auto it = std::find(mode_.begin(), mode_.end(), fc.contact);
  if (row < 0 || it == mode_.end()) return 0.0;
  const Monitor* prev = monitor > 0 ? &monitors_[monitor - 1] : nullptr;
  const double side =
      prev != nullptr && prev->multiplier && prev->friction == mon.friction ? 1.0 : -1.0;
  const MatrixXd& dF = dF_[p];
  const Eigen::Index normal = it - mode_.begin();
  const SensParam& sp = cols_.params[p];
  // mu[c] of this contact: d(mu) u_N.
  const double own = sp.kind == 'u' && sp.j == mon.friction ? friction_F_.row(normal).dot(x) : 0.0;
  return own + (fc.mu * dF.row(normal) + side * dF.row(row)).dot(x);
}

}  // namespace lcsim::sim::detail
