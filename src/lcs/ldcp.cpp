// Mode selection by the linear dynamic complementarity problem (§3.5.2).
//
// LDCP_kappa(x0) (eq. (3.34)-(3.36)) is solved level by level, as in the proof
// of Theorem 3.6.7: at level p the new coefficient of row r is
//
//   y_r^{rho_r + p} = xi_{p,r} + (script M)_r u^p,                      (3.42)
//   xi_{p,r} = [rho_r + p >= 1] C_r A^{rho_r + p - 1} x0
//              + sum_{j < p} H_r^{rho_r + p - j} u^j,
//
// and rows are classified as active (u_r lexicographically positive so far:
// y_r^. = 0 from now on), inactive (y_r lexicographically positive: u_r^. = 0)
// or undecided (both sequences zero so far). The undecided rows solve the LCP
// with the Schur complement of script M_II (3.49)-(3.50), unique when script M
// is a P-matrix. Levels run from -n+1 (the coefficient of delta^{(n-1)}) up to
// n; levels p <= 0 are the impulsive part, whose coefficients give the jump
// x0 + sum_j A^j B u^{-j} (eq. (3.10)).
#include <algorithm>
#include <cmath>
#include <lcsim/lcs/lcs.hpp>
#include <sstream>

namespace lcsim::lcs {

namespace {

enum class RowState { kUndecided, kActive, kInactive };

std::vector<int> rows_in(const std::vector<RowState>& st, RowState s) {
  std::vector<int> r;
  for (int i = 0; i < static_cast<int>(st.size()); ++i)
    if (st[i] == s) r.push_back(i);
  return r;
}

MatrixXd sub(const MatrixXd& M, const std::vector<int>& r, const std::vector<int>& c) {
  MatrixXd S(r.size(), c.size());
  for (size_t i = 0; i < r.size(); ++i)
    for (size_t j = 0; j < c.size(); ++j) S(i, j) = M(r[i], c[j]);
  return S;
}

VectorXd sub(const VectorXd& v, const std::vector<int>& r) {
  VectorXd s(r.size());
  for (size_t i = 0; i < r.size(); ++i) s(i) = v(r[i]);
  return s;
}

}  // namespace

LdcpData ldcp_data(const Lcs& sys) {
  LdcpData d;
  d.rho = leading_row_indices(sys);
  d.Mlead = leading_row_coefficients(sys);
  d.sys = &sys;
  return d;
}

const MatrixXd& LdcpData::markov(int i) const {
  if (H.empty()) {
    H.push_back(sys->D);
    AiB = sys->B;
  }
  while (static_cast<int>(H.size()) <= i) {
    H.push_back(sys->C * AiB);
    AiB = sys->A * AiB;
  }
  return H[i];
}

ModeSelection select_mode(const Lcs& sys, const VectorXd& x0, const LdcpOptions& opt) {
  ModeSelection out;
  const int n = sys.n();
  const int k = sys.k();
  if (x0.size() != n) {
    out.message = "select_mode: state has size " + std::to_string(x0.size()) + ", expected " +
                  std::to_string(n);
    return out;
  }
  out.x_plus = x0;
  out.impulse.assign(n, VectorXd::Zero(k));
  if (k == 0) {
    out.status = Status::kOk;
    return out;
  }

  LdcpData own_data;
  if (!opt.data) own_data = ldcp_data(sys);
  const LdcpData& data = opt.data ? *opt.data : own_data;
  const std::vector<int>& rho = data.rho;
  for (int r = 0; r < k; ++r) {
    if (rho[r] == kInfiniteIndex) {
      out.message = "constraint " + std::to_string(r) +
                    " has an infinite leading row index: its modes are not autonomous "
                    "(Lemma 3.6.5), the LDCP does not select a mode";
      return out;
    }
  }
  const MatrixXd& Mlead = data.Mlead;
  const int first = -n + 1;
  const int last = n;
  // Free response coefficients C A^m x0 and their term scales, on demand.
  std::vector<VectorXd> CAx, CAx_scale;
  VectorXd Amx = x0, Amx_abs = x0.cwiseAbs();
  MatrixXd Aabs, Cabs;
  auto free_response = [&](int m) -> int {
    if (CAx.empty()) {
      Aabs = sys.A.cwiseAbs();
      Cabs = sys.C.cwiseAbs();
    }
    while (static_cast<int>(CAx.size()) <= m) {
      CAx.push_back(sys.C * Amx);
      CAx_scale.push_back(Cabs * Amx_abs);
      Amx = sys.A * Amx;
      Amx_abs = Aabs * Amx_abs;
    }
    return m;
  };

  std::unique_ptr<lcp::Solver> own_solver;
  const lcp::Solver* solver = opt.solver;
  if (!solver) {
    own_solver = lcp::make_solver("pivot");
    solver = own_solver.get();
  }

  std::vector<RowState> state(k, RowState::kUndecided);
  std::vector<VectorXd> u;          // u^p for p = first..current, index p - first
  std::vector<int> nonzero_levels;  // the j with u^j != 0 (most levels are zero)
  const int start_lcp = opt.regular_only ? 1 : first;

  for (int p = first; p <= last; ++p) {
    if (p > first && !u.back().isZero(0.0)) nonzero_levels.push_back(p - 1);
    // xi and the scale of its terms.
    VectorXd xi = VectorXd::Zero(k), scale = VectorXd::Zero(k);
    for (int r = 0; r < k; ++r) {
      // A row decided inactive keeps its state: its coefficients are not
      // used again (a robot's 64 stops, most open, at up to n levels each).
      if (state[r] == RowState::kInactive) continue;
      const int order = rho[r] + p;
      if (order >= 1) {
        const int m = free_response(order - 1);
        xi(r) += CAx[m](r);
        scale(r) += CAx_scale[m](r);
      }
      for (int j : nonzero_levels) {
        const VectorXd& uj = u[j - first];
        const int h = order - j;
        if (h < 0 || h > 3 * n) continue;
        const MatrixXd& Hh = data.markov(h);
        xi(r) += Hh.row(r).dot(uj);
        scale(r) += Hh.row(r).cwiseAbs().dot(uj.cwiseAbs());
      }
    }
    auto tol_y = [&](int r) { return opt.tol_rel * scale(r) + opt.tol_abs; };

    VectorXd up = VectorXd::Zero(k);
    const auto I = rows_in(state, RowState::kActive);
    const auto K = rows_in(state, RowState::kUndecided);
    if (p < start_lcp) {
      // Below the first level solved, u^p = 0: the coefficients are the free
      // response, and an undecided row must not start negative (regularity).
      if (!I.empty()) {
        out.message = "internal: active rows below the first LCP level";
        return out;
      }
      for (int r : K) {
        if (xi(r) > tol_y(r)) {
          state[r] = RowState::kInactive;
        } else if (xi(r) < -tol_y(r)) {
          std::ostringstream msg;
          msg.precision(6);
          msg << "state is not regular: constraint " << r << " has coefficient y^" << rho[r] + p
              << " = " << xi(r) << " < 0 with no impulse allowed (Theorem 3.6.7, (3.40))";
          out.message = msg.str();
          return out;
        }
      }
      u.push_back(up);
      continue;
    }
    if (K.empty() && I.empty()) {
      u.push_back(up);
      break;  // every row decided inactive: nothing left to compute
    }
    // Eliminate the active rows: u_I = -M_II^{-1} (xi_I + M_IK u_K).
    const MatrixXd MII = sub(Mlead, I, I);
    Eigen::FullPivLU<MatrixXd> luI;
    if (!I.empty()) {
      luI.compute(MII);
      if (!luI.isInvertible()) {
        out.message =
            "leading row coefficient block of the active set is singular "
            "(script M is not a P-matrix); the mode is not autonomous";
        return out;
      }
    }
    VectorXd uK = VectorXd::Zero(K.size());
    if (!K.empty()) {
      MatrixXd S = sub(Mlead, K, K);
      VectorXd qK = sub(xi, K);
      if (!I.empty()) {
        const MatrixXd MKI = sub(Mlead, K, I);
        S -= MKI * luI.solve(sub(Mlead, I, K));
        qK -= MKI * luI.solve(sub(xi, I));
      }
      // Rows whose constant term is zero up to rounding of its terms stay
      // exactly zero: dependent constraints make the Schur complement
      // singular, and a -1e-17 there would make the LCP infeasible.
      const VectorXd cancelled =
          I.empty() ? VectorXd::Zero(K.size())
                    : VectorXd((sub(Mlead, K, I) * luI.solve(sub(xi, I))).cwiseAbs());
      for (size_t i = 0; i < K.size(); ++i)
        if (std::abs(qK(i)) <= opt.tol_rel * (scale(K[i]) + cancelled(i)) + opt.tol_abs)
          qK(i) = 0.0;
      // Dependent constraints give a PSD, not P, matrix whose LCP Lemke
      // still solves (q in its range, Lemma 4.6.1); the motion is unique
      // even where the multipliers are not (Theorem 4.6.5).
      int attempts = 0;
      const lcp::Result res = lcp::solve_with_fallbacks(*solver, S, qK, lcp::Options{}, &attempts);
      out.lcp_solves += attempts;
      if (!res.ok()) {
        out.message = "LCP at LDCP level " + std::to_string(p) +
                      " failed: " + std::string(lcp::to_string(res.status, "solved")) +
                      (res.message.empty() ? "" : " (" + res.message + ")");
        return out;
      }
      uK = res.z;
    }
    for (size_t i = 0; i < K.size(); ++i) up(K[i]) = uK(i);
    if (!I.empty()) {
      VectorXd rhs = sub(xi, I);
      if (!K.empty()) rhs += sub(Mlead, I, K) * uK;
      const VectorXd uI = -luI.solve(rhs);
      for (size_t i = 0; i < I.size(); ++i) up(I[i]) = uI(i);
    }
    // Classify the undecided rows on this level's coefficients.
    const VectorXd y = xi + Mlead * up;
    for (int r : K) {
      const double d = std::max(std::abs(Mlead(r, r)), 1e-300);
      if (up(r) > tol_y(r) / d) {
        state[r] = RowState::kActive;
      } else {
        up(r) = 0.0;  // rounding noise, not an impulse or force
        if (y(r) > tol_y(r)) state[r] = RowState::kInactive;
      }
    }
    u.push_back(up);
    // Once no row is undecided the mode is fixed; the impulsive levels (p <= 0)
    // are still needed for the jump, later levels are not.
    if (p >= 0 && rows_in(state, RowState::kUndecided).empty()) break;
  }

  out.mode = rows_in(state, RowState::kActive);
  out.undetermined = rows_in(state, RowState::kUndecided);
  // Impulsive part: level p <= 0 multiplies delta^{(-p)}.
  VectorXd jump = VectorXd::Zero(n);
  VectorXd AjBu;
  for (int p = first; p <= 0 && p - first < static_cast<int>(u.size()); ++p) {
    const int j = -p;
    out.impulse[j] = u[p - first];
    if (out.impulse[j].isZero(0.0)) continue;
    AjBu = sys.B * out.impulse[j];
    for (int i = 0; i < j; ++i) AjBu = sys.A * AjBu;
    jump += AjBu;
  }
  out.x_plus = x0 + jump;
  out.status = Status::kOk;
  return out;
}

}  // namespace lcsim::lcs
