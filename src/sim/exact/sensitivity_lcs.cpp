// Forward sensitivities of a general LCS x' = A x + B u, y = C x + D u
// (docs/sensitivities.md): the derivatives of a mode's closed loop in the
// entries of A, B, C, D, and the derivative of a jump x+ = P_I x.
//
// Mode I with the leading row indices rho_i and coefficients script M_II of
// its own system (A, B_.I, C_I., D_II) (lcs::mode_feedback): u_I = F x with
// F = -(script M_II)^{-1} R, R_i = C_i A^{rho_i}, script M_i = D_iI
// (rho_i = 0) or C_i A^{rho_i - 1} B_.I. So, with one entry of A, B, C or D
// moving (a unit dA, dB, dC or dD),
//   dF = -(script M_II)^{-1} (dR + d(script M) F),
//   dAcl = dA + dB_.I F + B_.I dF,
// and a free output's monitor C_r + D_rI F moves by dC_r + dD_rI F + D_rI dF.
// The rho_i are integers: an entry that changes one (a zero feedthrough made
// nonzero turns an index-2 diode into a resistor) is a singular perturbation
// with no derivative there.
//
// A jump of mode I (thesis §3.4.2) is x+ = P_I x, the projection onto the
// consistent subspace V_I = {x : C_i A^m x = 0, m < rho_i, i in I} along the
// jump space T_I. With L the rows C_i A^m (m < rho_i) and T the columns
// A^m B_j (m < rho_j), P = I - T (L T)^{-1} L whenever L T is square and
// invertible; that form is checked against lcs::projection before its
// derivative dP = -(dT K L + T dK L + T K dL), dK = -K (dL T + L dT) K
// (K = (L T)^{-1}) is used.
#include <cmath>

#include "sim/exact/sensitivity.hpp"

namespace lcsim::sim::detail {

namespace {

// One entry of (A, B, C, D) moved by one: the unit perturbation of a
// parameter of a general LCS.
struct Delta {
  MatrixXd A, B, C, D;
};

Delta unit_delta(const lcs::Lcs& sys, const SensParam& p) {
  Delta d{MatrixXd::Zero(sys.n(), sys.n()), MatrixXd::Zero(sys.n(), sys.k()),
          MatrixXd::Zero(sys.k(), sys.n()), MatrixXd::Zero(sys.k(), sys.k())};
  MatrixXd& m = p.kind == 'A' ? d.A : p.kind == 'B' ? d.B : p.kind == 'C' ? d.C : d.D;
  m(p.i, p.j) = 1.0;
  return d;
}

MatrixXd cols_of(const MatrixXd& M, const lcs::IndexSet& I) {
  MatrixXd out(M.rows(), static_cast<Eigen::Index>(I.size()));
  for (size_t a = 0; a < I.size(); ++a) out.col(static_cast<Eigen::Index>(a)) = M.col(I[a]);
  return out;
}
MatrixXd rows_of(const MatrixXd& M, const lcs::IndexSet& I) {
  MatrixXd out(static_cast<Eigen::Index>(I.size()), M.cols());
  for (size_t a = 0; a < I.size(); ++a) out.row(static_cast<Eigen::Index>(a)) = M.row(I[a]);
  return out;
}

// The mode's own system (A, B_.I, C_I., D_II), perturbed by s times d.
lcs::Lcs mode_system(const lcs::Lcs& sys, const lcs::IndexSet& I, const Delta* d, double s) {
  lcs::Lcs out{sys.A, cols_of(sys.B, I), rows_of(sys.C, I), cols_of(rows_of(sys.D, I), I)};
  if (d != nullptr) {
    out.A += s * d->A;
    out.B += s * cols_of(d->B, I);
    out.C += s * rows_of(d->C, I);
    out.D += s * cols_of(rows_of(d->D, I), I);
  }
  return out;
}

// The moved entries of the mode's system: (dA, dB_.I, dC_I., dD_II).
lcs::Lcs mode_delta(const Delta& d, const lcs::IndexSet& I) {
  return lcs::Lcs{d.A, cols_of(d.B, I), rows_of(d.C, I), cols_of(rows_of(d.D, I), I)};
}

// c A^m and its derivative for m = 0..count-1, from c and dc (rows).
void row_powers(const RowVectorXd& c, const RowVectorXd& dc, const MatrixXd& A, const MatrixXd& dA,
                int count, std::vector<RowVectorXd>& r, std::vector<RowVectorXd>& dr) {
  r.assign(1, c);
  dr.assign(1, dc);
  for (int m = 1; m < count; ++m) {
    dr.push_back(dr.back() * A + r.back() * dA);
    r.push_back(r.back() * A);
  }
}

// The leading rows of the mode's system and their derivatives: R, d R and
// script M, d(script M) (rows in mode order).
struct LeadingRows {
  MatrixXd R, dR, Mc, dMc;
};

LeadingRows leading_rows(const lcs::Lcs& sub, const lcs::Lcs& dsub, const std::vector<int>& rho) {
  const Eigen::Index kI = sub.C.rows(), n = sub.A.rows();
  LeadingRows out{MatrixXd(kI, n), MatrixXd(kI, n), MatrixXd(kI, kI), MatrixXd(kI, kI)};
  std::vector<RowVectorXd> r, dr;
  for (Eigen::Index a = 0; a < kI; ++a) {
    const int ra = rho[static_cast<size_t>(a)];
    row_powers(sub.C.row(a), dsub.C.row(a), sub.A, dsub.A, ra + 1, r, dr);
    out.R.row(a) = r.back();
    out.dR.row(a) = dr.back();
    if (ra == 0) {
      out.Mc.row(a) = sub.D.row(a);
      out.dMc.row(a) = dsub.D.row(a);
    } else {
      const size_t m = static_cast<size_t>(ra - 1);
      out.Mc.row(a) = r[m] * sub.B;
      out.dMc.row(a) = dr[m] * sub.B + r[m] * dsub.B;
    }
  }
  return out;
}

}  // namespace

void Sensitivity::lcs_mode_derivatives(const lcs::IndexSet& mode, double t) {
  const lcs::Lcs sub = mode_system(sys_, mode, nullptr, 0.0);
  const std::vector<int> rho = lcs::leading_row_indices(sub);
  const Eigen::Index kI = static_cast<Eigen::Index>(mode.size());
  const MatrixXd BI = sub.B, DrI = cols_of(sys_.D, mode);
  std::vector<int> singular;  // columns whose entry changes a leading row index
  std::string names;
  for (size_t p = 0; p < cols_.params.size(); ++p) {
    const int col = nx0_ + static_cast<int>(p);
    dAb_[p] = MatrixXd::Zero(n_, n_);  // carried as zero when absent
    if (!exists_[static_cast<size_t>(col)]) continue;
    const Delta d = unit_delta(sys_, cols_.params[p]);
    // The entry must leave the mode's leading row indices as they are (two
    // steps, so that a cancellation at one cannot hide a change).
    bool same = true;
    for (double s : {1.0, -0.6180339887})
      same = same && lcs::leading_row_indices(mode_system(sys_, mode, &d, s)) == rho;
    if (!same) {
      singular.push_back(col);
      names += (names.empty() ? "" : ", ") + cols_.params[p].name;
      continue;
    }
    MatrixXd F = MatrixXd::Zero(kI, n_), dF = MatrixXd::Zero(kI, n_);
    if (kI > 0) {
      const lcs::Lcs dsub = mode_delta(d, mode);
      const LeadingRows lr = leading_rows(sub, dsub, rho);
      const Eigen::PartialPivLU<MatrixXd> Mf(lr.Mc);
      F = -Mf.solve(lr.R);
      dF = -Mf.solve(lr.dR + lr.dMc * F);
    }
    const MatrixXd dAcl = d.A + cols_of(d.B, mode) * F + BI * dF;
    dAb_[p] = D_.cwiseInverse().asDiagonal() * dAcl * D_.asDiagonal();
    dF_[p] = dF;
    MatrixXd dW = d.C + cols_of(d.D, mode) * F + DrI * dF;
    for (int r : mode) dW.row(r).setZero();  // the mode's rows are multiplier monitors (dF)
    dW_[p] = dW;
  }
  if (!singular.empty())
    lose(t, mode.front(),
         (singular.size() == 1 ? "the entry " + names + " changes"
                               : "the entries " + names + " change") +
             " a leading row index of this mode: a singular perturbation (for example a zero "
             "feedthrough made nonzero), where no derivative exists",
         singular, true);
}

bool Sensitivity::lcs_jump(double t, const EventResult::LcsJump& jump, MatrixXd& J, MatrixXd& dR) {
  const lcs::IndexSet& I = jump.mode;
  const int trig = I.empty() ? -1 : I.front();
  const lcs::Projection pr = lcs::projection(sys_, I);
  if (!pr.ok()) {
    lose_all(t, trig, "a jump of a general LCS whose projection P_I is unavailable: " + pr.message);
    return false;
  }
  J = pr.P;
  dR = MatrixXd::Zero(n_, m_);
  std::vector<int> params;
  for (int c = nx0_; c < m_; ++c)
    if (exists_[static_cast<size_t>(c)]) params.push_back(c);
  if (params.empty()) return true;
  const lcs::Lcs sub = mode_system(sys_, I, nullptr, 0.0);
  const std::vector<int> rho = lcs::leading_row_indices(sub);
  int dim = 0;
  for (int r : rho) dim += std::max(r, 0);
  // L (dim x n), T (n x dim) and their derivatives per parameter.
  auto build = [&](const Delta& d, MatrixXd& L, MatrixXd& T, MatrixXd& dL, MatrixXd& dT) {
    L.resize(dim, n_), dL.resize(dim, n_), T.resize(n_, dim), dT.resize(n_, dim);
    const lcs::Lcs ds = mode_delta(d, I);
    std::vector<RowVectorXd> r, dr, c, dc;
    int at = 0;
    for (size_t a = 0; a < I.size(); ++a) {
      row_powers(sub.C.row(static_cast<Eigen::Index>(a)), ds.C.row(static_cast<Eigen::Index>(a)),
                 sub.A, ds.A, rho[a], r, dr);
      // Columns A^m B_j as rows of B_j' (A')^m.
      row_powers(sub.B.col(static_cast<Eigen::Index>(a)).transpose(),
                 ds.B.col(static_cast<Eigen::Index>(a)).transpose(), sub.A.transpose(),
                 ds.A.transpose(), rho[a], c, dc);
      for (int m = 0; m < rho[a]; ++m, ++at) {
        L.row(at) = r[static_cast<size_t>(m)];
        dL.row(at) = dr[static_cast<size_t>(m)];
        T.col(at) = c[static_cast<size_t>(m)].transpose();
        dT.col(at) = dc[static_cast<size_t>(m)].transpose();
      }
    }
  };
  MatrixXd L, T, dL, dT;
  build(unit_delta(sys_, cols_.params[static_cast<size_t>(params[0] - nx0_)]), L, T, dL, dT);
  const Eigen::FullPivLU<MatrixXd> LT(L * T);
  const MatrixXd K = dim > 0 && LT.isInvertible() ? MatrixXd(LT.inverse()) : MatrixXd();
  const MatrixXd P = MatrixXd::Identity(n_, n_) - (K.size() > 0 ? MatrixXd(T * K * L) : MatrixXd());
  if (dim == 0 || K.size() == 0 ||
      (P - J).cwiseAbs().maxCoeff() > 1e-9 * (1.0 + J.cwiseAbs().maxCoeff())) {
    lose(t, trig,
         "a jump of a general LCS whose projection is not I - T (L T)^-1 L: its derivative in the "
         "system's entries is not computed",
         params, true);
    return true;
  }
  for (int col : params) {
    const Delta d = unit_delta(sys_, cols_.params[static_cast<size_t>(col - nx0_)]);
    build(d, L, T, dL, dT);
    const MatrixXd dK = -K * (dL * T + L * dT) * K;
    const MatrixXd dP = -(dT * K * L + T * dK * L + T * K * dL);
    dR.col(col) = dP * jump.x_before;
  }
  return true;
}

}  // namespace lcsim::sim::detail
