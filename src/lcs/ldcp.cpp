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
#include <lcsim/core/format.hpp>
#include <lcsim/lcs/lcs.hpp>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace lcsim::lcs {

namespace {

// kDependent: an undecided row whose [C_r D_r] lies in the span of the
// active rows' (mark_dependent): undetermined, left out of later levels.
enum class RowState { kUndecided, kActive, kInactive, kDependent };

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

// X 2^e entry by entry (exact, barring overflow and underflow).
MatrixXd ldexp_matrix(const MatrixXd& X, int e) {
  return X.unaryExpr([e](double x) { return std::ldexp(x, e); });
}

// Free response coefficients C A^m x0 and their term scales |C| |A|^m |x0|,
// computed on demand (a selection rarely needs more than a few orders).
class FreeResponse {
 public:
  FreeResponse(const Lcs& sys, const VectorXd& x0) : sys_(sys), Amx_(x0), Amx_abs_(x0.cwiseAbs()) {}
  // Makes order m available; returns m.
  int reach(int m) {
    if (CAx.empty()) {
      Aabs_ = sys_.A.cwiseAbs();
      Cabs_ = sys_.C.cwiseAbs();
    }
    while (static_cast<int>(CAx.size()) <= m) {
      CAx.push_back(sys_.C * Amx_);
      CAx_scale.push_back(Cabs_ * Amx_abs_);
      Amx_ = sys_.A * Amx_;
      Amx_abs_ = Aabs_ * Amx_abs_;
    }
    return m;
  }
  std::vector<VectorXd> CAx, CAx_scale;  // index m: C A^m x0 and its scale
  // True when C A^j x0 and its scale are exactly zero for every j >= m:
  // order m is, and A^{m+1} x0 and |A|^{m+1} |x0| are zero vectors (so is
  // every later power's product).
  bool zero_from(int m) {
    reach(m);
    return CAx[m].isZero(0.0) && CAx_scale[m].isZero(0.0) && Amx_.isZero(0.0) &&
           Amx_abs_.isZero(0.0);
  }

 private:
  const Lcs& sys_;
  VectorXd Amx_, Amx_abs_;  // A^m x0 and |A|^m |x0| for the next order
  MatrixXd Aabs_, Cabs_;
};

// LDCP_kappa(x0) being solved: the system, its data, the options, and what the
// levels solved so far have found.
struct Ldcp {
  const Lcs& sys;
  const LdcpData& data;
  const LdcpOptions& opt;
  const lcp::Solver& solver;
  const int first;  // the level of delta^{(n-1)}: -n + 1
  FreeResponse free;
  std::vector<RowState> state;
  std::vector<VectorXd> u;          // u^p for p = first..current, index p - first
  std::vector<int> nonzero_levels;  // the j with u^j != 0 (most levels are zero)
  // mark_dependent's last active set and the undecided rows it found
  // independent of it (the test is a function of the set and the row only:
  // not made again while the set is the same).
  std::vector<int> dep_active, dep_independent;
};

// Level p: the known part xi_p of the new coefficients y^{rho_r + p} (3.42),
// the scale of its terms, and the rows active (I) and undecided (K) on entry.
struct Level {
  int p = 0;
  VectorXd xi, scale;
  IndexSet I, K;
  double tol_y(int r, const LdcpOptions& opt) const { return opt.tol_rel * scale(r) + opt.tol_abs; }
};

std::string infinite_index_refusal(const std::vector<int>& rho) {
  for (int r = 0; r < static_cast<int>(rho.size()); ++r) {
    if (rho[r] == kInfiniteIndex)
      return "constraint " + std::to_string(r) +
             " has an infinite leading row index: its modes are not autonomous "
             "(Lemma 3.6.5), the LDCP does not select a mode";
  }
  return "";
}

// xi_{p,r} = [rho_r + p >= 1] C_r A^{rho_r + p - 1} x0
//            + sum_{j < p} H_r^{rho_r + p - j} u^j                      (3.42)
Level level_coefficients(Ldcp& s, int p) {
  const int k = s.sys.k();
  const int n = s.sys.n();
  Level l;
  l.p = p;
  l.xi = VectorXd::Zero(k);
  l.scale = VectorXd::Zero(k);
  for (int r = 0; r < k; ++r) {
    // A row decided inactive keeps its state: its coefficients are not
    // used again (a robot's 64 stops, most open, at up to n levels each).
    if (s.state[r] == RowState::kInactive || s.state[r] == RowState::kDependent) continue;
    const int order = s.data.rho[r] + p;
    if (order >= 1) {
      const int m = s.free.reach(order - 1);
      l.xi(r) += s.free.CAx[m](r);
      l.scale(r) += s.free.CAx_scale[m](r);
    }
    for (int j : s.nonzero_levels) {
      const VectorXd& uj = s.u[j - s.first];
      const int h = order - j;
      if (h < 0 || h > 3 * n) continue;
      const MatrixXd& Hh = s.data.markov(h);
      l.xi(r) += Hh.row(r).dot(uj);
      l.scale(r) += Hh.row(r).cwiseAbs().dot(uj.cwiseAbs());
    }
  }
  return l;
}

// Below the first level solved, u^p = 0: the coefficients are the free
// response, and an undecided row must not start negative (regularity,
// Theorem 3.6.7, (3.40)). "" or why the state is refused.
std::string free_level(Ldcp& s, const Level& l) {
  if (!l.I.empty()) return "internal: active rows below the first LCP level";
  for (int r : l.K) {
    if (l.xi(r) > l.tol_y(r, s.opt)) {
      s.state[r] = RowState::kInactive;
    } else if (l.xi(r) < -l.tol_y(r, s.opt)) {
      return text("state is not regular: constraint ", r, " has coefficient y^",
                  s.data.rho[r] + l.p, " = ", l.xi(r),
                  " < 0 with no impulse allowed (Theorem 3.6.7, (3.40))");
    }
  }
  return "";
}

// Rows whose constant term is zero up to rounding of its terms stay exactly
// zero: dependent constraints make the Schur complement singular, and a
// -1e-17 there would make the LCP infeasible.
void zero_cancelled(const Ldcp& s, const Level& l, const Eigen::FullPivLU<MatrixXd>& luI,
                    VectorXd& qK) {
  const MatrixXd& Mlead = s.data.Mlead;
  const VectorXd cancelled =
      l.I.empty() ? VectorXd::Zero(l.K.size())
                  : VectorXd((sub(Mlead, l.K, l.I) * luI.solve(sub(l.xi, l.I))).cwiseAbs());
  for (size_t i = 0; i < l.K.size(); ++i)
    if (std::abs(qK(i)) <= s.opt.tol_rel * (l.scale(l.K[i]) + cancelled(i)) + s.opt.tol_abs)
      qK(i) = 0.0;
}

// Lemma 4.6.1 needs q in the range of a singular S, and rounding leaves it
// just outside: the NAO's two feet on four coplanar points each gave an S of
// rank 1 whose rows for three corners of a foot were equal and whose q
// differed in the 15th digit, so no complementary basis solved it. When the
// LCP fails and q's part outside S's range is rounding of the terms that
// formed q (as zero_cancelled judges each entry), the LCP is solved again on
// q's part in the range. A solvable LCP never gets here, so its result is
// unchanged. True when q_range is set.
bool range_part(const Ldcp& s, const Level& l, const MatrixXd& S, const VectorXd& qK,
                VectorXd& q_range) {
  const Eigen::JacobiSVD<MatrixXd> svd(S, Eigen::ComputeThinU);
  const double tol = rank_tolerance(S);
  const Eigen::Index rank = (svd.singularValues().array() > tol).count();
  if (rank == S.rows()) return false;  // regular S: its failure is not rounding
  const MatrixXd U = svd.matrixU().leftCols(rank);
  q_range = U * (U.transpose() * qK);
  for (size_t i = 0; i < l.K.size(); ++i) {
    const double rounding = s.opt.tol_rel * (l.scale(l.K[i]) + std::abs(qK(i))) + s.opt.tol_abs;
    if (std::abs(q_range(i) - qK(i)) > rounding) return false;
  }
  return true;
}

// u_K from the LCP of the Schur complement of script M_II (3.49)-(3.50).
// "" or why the LCP failed.
std::string schur_lcp(const Ldcp& s, const Level& l, const Eigen::FullPivLU<MatrixXd>& luI,
                      VectorXd& uK, int& lcp_solves) {
  const MatrixXd& Mlead = s.data.Mlead;
  MatrixXd S = sub(Mlead, l.K, l.K);
  VectorXd qK = sub(l.xi, l.K);
  if (!l.I.empty()) {
    const MatrixXd MKI = sub(Mlead, l.K, l.I);
    S -= MKI * luI.solve(sub(Mlead, l.I, l.K));
    qK -= MKI * luI.solve(sub(l.xi, l.I));
  }
  zero_cancelled(s, l, luI, qK);
  // Dependent constraints give a PSD, not P, matrix whose LCP Lemke still
  // solves (q in its range, Lemma 4.6.1); the motion is unique even where the
  // multipliers are not (Theorem 4.6.5).
  int attempts = 0;
  lcp::Result res = lcp::solve_with_fallbacks(s.solver, S, qK, lcp::Options{}, &attempts);
  lcp_solves += attempts;
  if (!res.ok()) {
    VectorXd q_range;
    if (range_part(s, l, S, qK, q_range)) {
      res = lcp::solve_with_fallbacks(s.solver, S, q_range, lcp::Options{}, &attempts);
      lcp_solves += attempts;
    }
  }
  if (!res.ok())
    return "LCP at LDCP level " + std::to_string(l.p) +
           " failed: " + std::string(lcp::to_string(res.status, "solved")) +
           (res.message.empty() ? "" : " (" + res.message + ")");
  uK = res.z;
  return "";
}

// u^p: the active rows eliminated, u_I = -M_II^{-1} (xi_I + M_IK u_K), and
// u_K from the Schur complement LCP (§3.5.2). "" or why u^p does not exist.
std::string solve_level(const Ldcp& s, const Level& l, VectorXd& up, int& lcp_solves) {
  const MatrixXd& Mlead = s.data.Mlead;
  Eigen::FullPivLU<MatrixXd> luI;
  if (!l.I.empty()) {
    luI.compute(sub(Mlead, l.I, l.I));
    if (!luI.isInvertible())
      return "leading row coefficient block of the active set is singular "
             "(script M is not a P-matrix); the mode is not autonomous";
  }
  VectorXd uK = VectorXd::Zero(l.K.size());
  if (!l.K.empty()) {
    std::string failed = schur_lcp(s, l, luI, uK, lcp_solves);
    if (!failed.empty()) return failed;
  }
  for (size_t i = 0; i < l.K.size(); ++i) up(l.K[i]) = uK(i);
  if (!l.I.empty()) {
    VectorXd rhs = sub(l.xi, l.I);
    if (!l.K.empty()) rhs += sub(Mlead, l.I, l.K) * uK;
    const VectorXd uI = -luI.solve(rhs);
    for (size_t i = 0; i < l.I.size(); ++i) up(l.I[i]) = uI(i);
  }
  return "";
}

// The rounding of u_r^p: the u_r whose term in the coefficients y^p is within
// their rounding. Through the diagonal, tol_y(r) / |M_rr|, as long as the
// diagonal is not negligible in its column. A zero diagonal (a skew coupling,
// as between a diode in voltage form and one in current form: a passive LCS
// has D + D' >= 0, not a P-matrix D; or one left at 1e-17 by the rounding of
// a circuit's reduction) says nothing of u_r's size, and dividing by it would
// discard a u_r that is not rounding: then the smallest tol_y(i) / |M_ir|
// over the rows i that u_r moves. A zero column leaves u_r out of y^p.
double u_tolerance(const Ldcp& s, const Level& l, int r) {
  const MatrixXd& Mlead = s.data.Mlead;
  const double diagonal = std::abs(Mlead(r, r));
  const double column = Mlead.col(r).cwiseAbs().maxCoeff();
  constexpr double kNegligible = 1e-12;  // relative to the column: rounding of the reduction
  if (diagonal > kNegligible * column) return l.tol_y(r, s.opt) / std::max(diagonal, 1e-300);
  double tol = l.tol_y(r, s.opt) / std::max(diagonal, 1e-300);
  for (int i = 0; i < static_cast<int>(Mlead.rows()); ++i)
    if (std::abs(Mlead(i, r)) > kNegligible * column)
      tol = std::min(tol, l.tol_y(i, s.opt) / std::abs(Mlead(i, r)));
  return tol;
}

// Dependent constraints (a box flat on its four coplanar corners: rows of
// rank 3) let the LCP end on a solution that loads every row of a dependent
// set (Lemke and the pivoting solvers may stop on a degenerate point that is
// not a vertex: bullet3's cube_small.urdf dropped flat got four positive
// multipliers). Those rows would all become active, script M_II would be
// singular, and the mode's feedback could not be built. A direction z over
// the loaded rows P and the active rows I with B z = 0 and D z = 0 moves no
// state, no coefficient y of any level and no jump (every one is linear in
// B u and D u, (3.42), (3.10)), so u^p - t z solves the same level: t is
// taken to zero one multiplier of P and keep the others >= 0
// (Caratheodory), until the columns of [B; D] over P and I are independent,
// as a vertex's are. Multipliers on dependent rows are not unique anyway
// (thesis §4.6.1); the motion is. A level whose columns are independent is
// left exactly as it was.
void drop_dependent_multipliers(const Ldcp& s, const Level& l, VectorXd& up) {
  const int n = s.sys.n();
  for (int round = 0; round < static_cast<int>(l.K.size()); ++round) {
    std::vector<int> cols = l.I;
    const size_t first_p = cols.size();
    for (int r : l.K)
      if (up(r) > u_tolerance(s, l, r)) cols.push_back(r);
    if (cols.size() == first_p) return;
    const auto m = static_cast<Eigen::Index>(cols.size());
    MatrixXd G(n + s.sys.k(), m);
    VectorXd scale(m);
    for (Eigen::Index c = 0; c < m; ++c) {
      G.col(c) << s.sys.B.col(cols[static_cast<size_t>(c)]),
          s.sys.D.col(cols[static_cast<size_t>(c)]);
      scale(c) = std::max(G.col(c).cwiseAbs().maxCoeff(), 1e-300);
      G.col(c) /= scale(c);  // column units differ; a scaling keeps the null space's support
    }
    const Eigen::JacobiSVD<MatrixXd> svd(G, Eigen::ComputeFullV);
    if (svd.singularValues()(m - 1) > rank_tolerance(G)) return;
    VectorXd z = svd.matrixV().col(m - 1).cwiseQuotient(scale);
    const auto pz = z.tail(m - static_cast<Eigen::Index>(first_p));
    const double tiny = 1e-12 * z.cwiseAbs().maxCoeff();
    if (pz.size() == 0 || pz.cwiseAbs().maxCoeff() <= tiny) return;
    if (pz.maxCoeff() <= tiny) z = -z;  // then some entry of P is above tiny
    double t = -1.0;
    Eigen::Index zeroed = -1;
    for (Eigen::Index c = static_cast<Eigen::Index>(first_p); c < m; ++c) {
      if (z(c) <= tiny) continue;
      const double ratio = up(cols[static_cast<size_t>(c)]) / z(c);
      if (zeroed < 0 || ratio < t) t = ratio, zeroed = c;
    }
    if (zeroed < 0) return;  // not reached (above); never index with -1
    for (Eigen::Index c = 0; c < m; ++c) {
      double& u = up(cols[static_cast<size_t>(c)]);
      u -= t * z(c);
      if (c >= static_cast<Eigen::Index>(first_p)) u = std::max(u, 0.0);  // rounding of t z
    }
    up(cols[static_cast<size_t>(zeroed)]) = 0.0;
  }
}

// An undecided row becomes active when u_r^p > 0, inactive when y_r^p > 0
// (the lexicographic signs of §3.5.2); u_r^p within rounding is set to 0.
void classify_undecided(Ldcp& s, const Level& l, VectorXd& up) {
  const MatrixXd& Mlead = s.data.Mlead;
  const VectorXd y = l.xi + Mlead * up;
  for (int r : l.K) {
    if (up(r) > u_tolerance(s, l, r)) {
      s.state[r] = RowState::kActive;
    } else {
      up(r) = 0.0;  // rounding noise, not an impulse or force
      if (y(r) > l.tol_y(r, s.opt)) s.state[r] = RowState::kInactive;
    }
  }
}

// An undecided row r whose [C_r D_r] is a combination of the active rows'
// (a fourth coplanar corner of a box whose three others are active: E_r =
// E_1 + E_2 - E_3, and so its gap offset in the augmented C) has y_r = sum
// alpha_i y_i identically, zero in the mode; any u_r >= 0 that the active
// rows absorb gives the same motion, and u_r = 0 is one. Carried on as
// undecided it met rounding at every later level: a q of 1e-10 from the
// active block's solve (not in its scale) classified the KUKA's box corner
// inactive, monitored on a gap that is rounding of zero (events that
// changed nothing until the livelock guard refused), and the 80-link chain's
// 54 dependent contacts overflowed the levels' scale before level n. Such a
// row is undetermined from this level on (u_r = 0, as the rows left
// undecided at the end). The test is relative, 1e-9 of the row, far above
// the rounding of a geometric dependence (4.4e-16 on the KUKA's corners)
// and far below any independent row.
void mark_dependent(Ldcp& s) {
  const std::vector<int> I = rows_in(s.state, RowState::kActive);
  std::vector<int> K = rows_in(s.state, RowState::kUndecided);
  if (I.empty() || K.empty()) return;
  if (I == s.dep_active) {
    std::erase_if(K, [&](int r) {
      return std::find(s.dep_independent.begin(), s.dep_independent.end(), r) !=
             s.dep_independent.end();
    });
    if (K.empty()) return;
  } else {
    s.dep_active = I;
    s.dep_independent.clear();
  }
  const int n = s.sys.n(), k = s.sys.k();
  MatrixXd rows(n + k, static_cast<Eigen::Index>(I.size()));
  for (size_t i = 0; i < I.size(); ++i)
    rows.col(static_cast<Eigen::Index>(i)) << s.sys.C.row(I[i]).transpose(),
        s.sys.D.row(I[i]).transpose();
  const Eigen::CompleteOrthogonalDecomposition<MatrixXd> cod(rows);
  constexpr double kDependence = 1e-9;
  for (int r : K) {
    VectorXd row(n + k);
    row << s.sys.C.row(r).transpose(), s.sys.D.row(r).transpose();
    const double size = row.norm();
    if (!(size > 0.0)) continue;
    if ((rows * cod.solve(row) - row).norm() <= kDependence * size)
      s.state[static_cast<size_t>(r)] = RowState::kDependent;
    else
      s.dep_independent.push_back(r);
  }
}

// True when every level after l repeats l exactly, so that solving them
// would change nothing: l (a force level, p >= 1) had no known part (xi and
// its scale exactly zero), found u^p = 0 and decided no row (`before`: the
// states on entry), and every later level's known part is exactly zero too
// (the free response C A^m x0 from the orders later levels read, and the
// Markov parameters H^h that the nonzero levels u^j meet there: zero, and
// zero for every higher power). Each later level then has the same rows,
// the same coefficients (zero) and the same script M as l: the same LCP and
// the same result, level after level. A box resting on its four coplanar
// corners with no spring keeps two corners undecided (dependent rows, u and
// y identically zero) and otherwise solved the same zero level up to n.
bool later_levels_repeat(Ldcp& s, const Level& l, const VectorXd& up,
                         const std::vector<RowState>& before) {
  if (l.p < 1 || !l.xi.isZero(0.0) || !l.scale.isZero(0.0) || !up.isZero(0.0) || s.state != before)
    return false;
  int rho_min = std::numeric_limits<int>::max();
  for (int r = 0; r < s.sys.k(); ++r)
    if (s.state[r] != RowState::kInactive) rho_min = std::min(rho_min, s.data.rho[r]);
  if (rho_min == std::numeric_limits<int>::max()) return true;  // every row inactive
  // Level p + 1 reads the orders rho_r + p + 1 >= rho_min + p + 1 of the
  // free response, C A^{order - 1} x0.
  if (!s.free.zero_from(std::max(0, rho_min + l.p))) return false;
  const int h_max = 3 * s.sys.n();  // level_coefficients' cap on h
  for (int j : s.nonzero_levels) {
    for (int h = std::max(0, rho_min + l.p + 1 - j); h <= h_max; ++h) {
      if (!s.data.markov(h).isZero(0.0)) return false;
      // markov(h) leaves A^h B in AiB when H ends at h: zero, then every
      // later H = C A^{h'} B is zero.
      if (static_cast<int>(s.data.H.size()) == h + 1 && s.data.AiB.isZero(0.0)) break;
    }
  }
  return true;
}

// The levels' terms grow as |C| |A|^m |x0| (an 80-link chain lying on the
// floor: ~200-fold per level, past 1e308 at level 133 of 171); a level whose
// coefficients or scale are not finite (inf, or NaN from inf - inf or 0 *
// inf) decides nothing. select_mode then solves the LDCP again with time
// scaled (select_mode_time_scaled). The message starts with
// kLevelsOverflow, which select_mode recognises.
constexpr const char* kLevelsOverflow = "the LDCP's levels overflow";

std::string levels_overflow(const Level& l) {
  Eigen::Index r = 0;
  for (; r < l.xi.size(); ++r)
    if (!std::isfinite(l.xi(r)) || !std::isfinite(l.scale(r))) break;
  return text(kLevelsOverflow, ": at level ", l.p, " constraint ", static_cast<int>(r),
              "'s coefficient is ", l.xi(r), " with terms of size ", l.scale(r),
              " (|C| |A|^m |x0| and the Markov parameters' terms past the double range)");
}

// Levels -n+1 .. n, as in the proof of Theorem 3.6.7, until the mode is
// fixed. "" or why the LDCP has no (autonomous) solution.
std::string solve_levels(Ldcp& s, int& lcp_solves) {
  const int start_lcp = s.opt.regular_only ? 1 : s.first;
  // A free level whose rows all read orders rho_r + p < 1 with no nonzero
  // level before it has xi = 0 and scale = 0: free_level decides nothing
  // there (0 is within +-tol_abs), so only its u^p = 0 is kept.
  int rho_max = std::numeric_limits<int>::min();
  for (int r = 0; r < s.sys.k(); ++r) rho_max = std::max(rho_max, s.data.rho[r]);
  const bool quiet_free = s.opt.tol_abs >= 0.0 && std::isfinite(s.opt.tol_rel);
  for (int p = s.first; p <= s.sys.n(); ++p) {
    if (p > s.first && !s.u.back().isZero(0.0)) s.nonzero_levels.push_back(p - 1);
    if (p < start_lcp && quiet_free && s.nonzero_levels.empty() && rho_max + p < 1) {
      s.u.emplace_back(VectorXd::Zero(s.sys.k()));
      continue;
    }
    Level l = level_coefficients(s, p);
    if (!l.xi.allFinite() || !l.scale.allFinite()) return levels_overflow(l);
    l.I = rows_in(s.state, RowState::kActive);
    l.K = rows_in(s.state, RowState::kUndecided);
    VectorXd& up = s.u.emplace_back(VectorXd::Zero(s.sys.k()));  // u^p, 0 until solved
    if (p < start_lcp) {
      const std::string refused = free_level(s, l);
      if (!refused.empty()) return refused;
      continue;
    }
    if (l.K.empty() && l.I.empty()) break;  // every row decided inactive
    const std::vector<RowState> before = s.state;
    const std::string failed = solve_level(s, l, up, lcp_solves);
    if (!failed.empty()) return failed;
    drop_dependent_multipliers(s, l, up);
    classify_undecided(s, l, up);
    mark_dependent(s);
    // Once no row is undecided the mode is fixed; the impulsive levels (p <= 0)
    // are still needed for the jump, later levels are not.
    if (p >= 0 && rows_in(s.state, RowState::kUndecided).empty()) break;
    if (later_levels_repeat(s, l, up, before)) break;
  }
  return "";
}

// The impulsive part: level p <= 0 multiplies delta^{(-p)}; fills impulse and
// returns the jump sum_j A^j B u^{-j} of the state (eq. (3.10)).
VectorXd impulsive_jump(const Ldcp& s, std::vector<VectorXd>& impulse) {
  VectorXd jump = VectorXd::Zero(s.sys.n());
  VectorXd AjBu;
  for (int p = s.first; p <= 0 && p - s.first < static_cast<int>(s.u.size()); ++p) {
    const int j = -p;
    impulse[j] = s.u[p - s.first];
    if (impulse[j].isZero(0.0)) continue;
    AjBu = s.sys.B * impulse[j];
    for (int i = 0; i < j; ++i) AjBu = s.sys.A * AjBu;
    jump += AjBu;
  }
  return jump;
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

// The rows left undecided and those found dependent, in order.
std::vector<int> undetermined_rows(const Ldcp& s) {
  std::vector<int> out;
  for (int r = 0; r < static_cast<int>(s.state.size()); ++r)
    if (s.state[static_cast<size_t>(r)] == RowState::kUndecided ||
        s.state[static_cast<size_t>(r)] == RowState::kDependent)
      out.push_back(r);
  return out;
}

namespace {

// The driver: refusals, then the levels, then the mode and the jump.
ModeSelection select_mode_once(const Lcs& sys, const VectorXd& x0, const LdcpOptions& opt) {
  ModeSelection out;
  const int n = sys.n();
  if (x0.size() != n) {
    out.message = "select_mode: state has size " + std::to_string(x0.size()) + ", expected " +
                  std::to_string(n);
    return out;
  }
  out.x_plus = x0;
  out.impulse.assign(n, VectorXd::Zero(sys.k()));
  if (sys.k() == 0) {
    out.status = Status::kOk;
    return out;
  }
  LdcpData own_data;
  const LdcpData& data = opt.data ? *opt.data : (own_data = ldcp_data(sys));
  out.message = infinite_index_refusal(data.rho);
  if (!out.message.empty()) return out;
  std::unique_ptr<lcp::Solver> own_solver;
  const lcp::Solver& solver = opt.solver ? *opt.solver : *(own_solver = lcp::make_solver("pivot"));
  Ldcp s{sys, data, opt, solver, -n + 1, FreeResponse(sys, x0), {}, {}, {}, {}, {}};
  s.state.assign(sys.k(), RowState::kUndecided);
  out.message = solve_levels(s, out.lcp_solves);
  if (!out.message.empty()) {
    // A failure says where: the rows active and undecided when it failed
    // (the caller names them; status stays a failure).
    out.mode = rows_in(s.state, RowState::kActive);
    out.undetermined = undetermined_rows(s);
    return out;
  }
  out.mode = rows_in(s.state, RowState::kActive);
  out.undetermined = undetermined_rows(s);
  out.x_plus = x0 + impulsive_jump(s, out.impulse);
  out.status = Status::kOk;
  return out;
}

// log2 of the growth per order of |A|^m: the geometric mean over 2n + 1
// orders (the most the levels read, rho_r + n <= 2n) of the factors by
// which |A| multiplies a vector of ones, renormalised each time, so that
// |A|^(2n+1) 1 <= 2^((2n+1) g) for the g returned (Perron–Frobenius: it is
// at least the spectral radius of |A|). -inf when |A| is nilpotent.
double log2_growth(const MatrixXd& A) {
  const MatrixXd Aabs = A.cwiseAbs();
  VectorXd v = VectorXd::Ones(A.rows());
  const int orders = 2 * static_cast<int>(A.rows()) + 1;
  double sum = 0.0;
  for (int i = 0; i < orders; ++i) {
    v = Aabs * v;
    const double r = v.maxCoeff();
    if (!(r > 0.0)) return -std::numeric_limits<double>::infinity();
    sum += std::log2(r);
    v /= r;
  }
  return sum / orders;
}

// Issue 27 (the 80-link chain): the LDCP in time tau = 2^e t, its system
// (A, B) 2^-e (A, B) with 2^e the growth per order of |A|^m rounded up to a
// power of two (log2_growth), so |A'|^m |x0| no longer grows with m. The
// levels' signs and relative zero tests are those of the unscaled problem
// (level p's coefficients of row r are multiplied by 2^(-e (rho_r + p)),
// exactly, without rounding); tol_abs (an absolute tolerance) is taken in
// the scaled units. The mode, the undetermined rows and the state after the
// jump (x0 + B times the total impulse) are the system's; the impulse of
// delta^(j) is 2^(-e (j + 1)) times the scaled one's (delta^(j)(t) =
// 2^(e (j + 1)) delta^(j)(tau)), mapped back. Only ever run when the
// unscaled levels overflowed (`first`), so every model whose levels stay
// finite keeps its numbers byte for byte.
ModeSelection select_mode_time_scaled(const Lcs& sys, const VectorXd& x0, const LdcpOptions& opt,
                                      const ModeSelection& first) {
  const double g = log2_growth(sys.A);
  if (!std::isfinite(g) || g <= 0.0) return first;  // no growth to take out
  const int e = static_cast<int>(std::ceil(g));
  const Lcs scaled{ldexp_matrix(sys.A, -e), ldexp_matrix(sys.B, -e), sys.C, sys.D};
  LdcpOptions o = opt;
  o.data = nullptr;  // the scaled system's own Markov parameters
  ModeSelection out = select_mode_once(scaled, x0, o);
  out.lcp_solves += first.lcp_solves;
  if (!out.ok()) {
    out.message = text(first.message, "; solved again with time scaled by 2^", e,
                       " (the growth per order of |A|^m): ", out.message);
    return out;
  }
  for (size_t j = 0; j < out.impulse.size(); ++j)
    out.impulse[j] = ldexp_matrix(out.impulse[j], -e * static_cast<int>(j + 1));
  return out;
}

}  // namespace

ModeSelection select_mode(const Lcs& sys, const VectorXd& x0, const LdcpOptions& opt) {
  ModeSelection out = select_mode_once(sys, x0, opt);
  if (out.ok() || out.message.rfind(kLevelsOverflow, 0) != 0) return out;
  return select_mode_time_scaled(sys, x0, opt, out);
}

}  // namespace lcsim::lcs
