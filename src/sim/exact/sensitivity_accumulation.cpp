// Forward sensitivities through an accumulation of impacts
// (docs/sensitivities.md): the run takes the limit at the last impact it
// resolves (accumulation.cpp, take_accumulation_limit) by the M-orthogonal
// projection of the state onto E_J q + g_J = 0 and E_J v = 0 over the
// contacts J that take part, then continues in the limit mode. That map is
// linear in the state: with G = M^{-1} and W = E_J G E_J',
//   q+ = q - G E_J' W^+ (E_J q + g_J),   v+ = v - G E_J' W^+ E_J v,
// so its derivative is the projector P = I - G E_J' W^+ E_J on both blocks,
// with the parameters' terms dq+/dg_j = -G E_J' W^+ e_j and, for M, the
// projector's own derivative applied to the residuals (which the limit
// makes small: the gaps are closed to rounding and the rates are the last
// bounce's). The impacts left out (the geometric tail, below
// accumulation_tail) change the exact limit's derivative by the order of
// that tail: this is the derivative of the limit as the run takes it.
#include <algorithm>

#include "sim/exact/sensitivity.hpp"

namespace lcsim::sim::detail {

bool Sensitivity::limit_map(double t, const EventResult& ev, MatrixXd& J, MatrixXd& dR) {
  const mech::MechanicalModel& m = *model_.mechanical;
  const int trigger = ev.limit_rows.empty() ? -1 : ev.limit_rows.front();
  if (!m.gap_inputs.empty()) {
    lose_all(t, trigger,
             "an accumulation on a moving stop: the derivative of its limit is not "
             "computed");
    return false;
  }
  const int nj = static_cast<int>(ev.limit_rows.size());
  J = MatrixXd::Identity(n_, n_);
  dR = MatrixXd::Zero(n_, m_);
  if (nj == 0) return true;  // no contact projected: the identity
  MatrixXd EJ(nj, N_);
  VectorXd gJ(nj);
  for (int i = 0; i < nj; ++i) {
    EJ.row(i) = m.E.row(ev.limit_rows[static_cast<size_t>(i)]);
    gJ(i) = m.g(ev.limit_rows[static_cast<size_t>(i)]);
  }
  const MatrixXd GEt = G_ * EJ.transpose();
  const Eigen::CompleteOrthogonalDecomposition<MatrixXd> W(EJ * GEt);
  const MatrixXd K = GEt * W.pseudoInverse();  // G E_J' W^+
  const MatrixXd P = MatrixXd::Identity(N_, N_) - K * EJ;
  J.topLeftCorner(N_, N_) = P;
  J.block(N_, N_, N_, N_) = P;
  J.block(0, 2 * N_, N_, 1) = -K * gJ;  // the augmented state's constant entry
  const VectorXd rq = EJ * ev.limit_x.head(N_) + gJ, rv = EJ * ev.limit_x.segment(N_, N_);
  for (size_t p = 0; p < cols_.params.size(); ++p) {
    const SensParam& sp = cols_.params[p];
    const Eigen::Index c = nx0_ + static_cast<Eigen::Index>(p);
    if (sp.kind == 'g') {
      const auto it = std::find(ev.limit_rows.begin(), ev.limit_rows.end(), sp.i);
      if (it != ev.limit_rows.end()) dR.block(0, c, N_, 1) = -K.col(it - ev.limit_rows.begin());
    } else if (sp.kind == 'M') {
      if (W.rank() < nj) {
        lose(t, trigger,
             "an accumulation on dependent contacts: the derivative of its limit in M is not "
             "computed",
             {static_cast<int>(c)});
        continue;
      }
      MatrixXd dM = MatrixXd::Zero(N_, N_);
      dM(sp.i, sp.j) = dM(sp.j, sp.i) = 1.0;
      const MatrixXd dG = -G_ * dM * G_;
      // d(G E' W^-1) = dG E' W^-1 - G E' W^-1 (E dG E') W^-1 = P dG E' W^-1
      const MatrixXd dK = P * dG * EJ.transpose() * W.pseudoInverse();
      dR.block(0, c, N_, 1) = -dK * rq;
      dR.block(N_, c, N_, 1) = -dK * rv;
    }
  }
  return true;
}

}  // namespace lcsim::sim::detail
