// Free pairs: modes whose multipliers are not unique although their motion is
// (issue 29; docs/circuits.md, "All four diodes blocking").
//
// In mode I (undetermined rows U held too, S = I ∪ U) the multipliers solve
// y_S = 0. A pair c of S with B_c = 0 (u_c moves no state, at any order:
// H^i_{.c} = C A^{i-1} B_c = 0 for i >= 1) and D_{Sc} = 0 (it moves no held
// output) has a u_c that the mode does not fix: Ker [B_.S; D_SS] != {0}, the
// half of Lemma 3.3.3 (3) that makes such a mode "not autonomous" in the
// thesis's sense, although the state's trajectory is unique (as for dependent
// contacts, §4.6.1, Theorem 4.6.5). Its own output must vanish identically
// there (y_c = (C_c + D_{c,I'} F_{I'}) x with I' = I less its free pairs);
// then u_c is free in the set the complementarity inequalities leave:
//
//   u_c >= 0,  y_j = a_j x + g_j u_c >= 0 for every other pair j (g_j = D_jc),
//
// an interval [max(0, l x), min(h x)] (l = -a_j / g_j where g_j > 0, h =
// a_j / -g_j where g_j < 0). The mode continues while that interval is not
// empty, which is exactly when every difference h x - l x (and h x - 0) is
// >= 0 (Fourier–Motzkin elimination of the one variable u_c is exact): those
// differences are the phase's monitors, Bohl functions of the closed loop
// like any other, and their roots are the mode's exits judged on every
// admissible choice of u_c, never on one arbitrary choice. A sample records
// the least admissible u_c, max(0, l x). An output that moves with two free
// pairs (a multi-dimensional interval) is refused.
//
// Mode selection (select_by_enumeration): the LDCP of §3.5.2 solved level
// by level assumes a P-matrix script M; the bridge's is skew (D + D' = 0),
// and where a capacitor meets the tank through two diodes the level-0
// currents are fixed only at level 1, which no level-by-level solution sees.
// When the levels fail, every mode I is tried as the thesis defines a
// smooth continuation: its phase (the free pairs as above) must keep y_I = 0
// from the state (every derivative of y_I vanishes at x0: held_outputs_vanish)
// and start with every monitor lexicographically >= 0 (all_consistent). The
// modes that pass must all give one motion (x0 and A_I^j x0, j <= n, equal):
// then the one holding the fewest pairs is taken; otherwise the state's
// continuation is not unique and the run is refused naming two of them.
#include <algorithm>
#include <cmath>
#include <lcsim/core/format.hpp>
#include <string>

#include "sim/exact/event_driven_detail.hpp"

namespace lcsim::sim::detail {

namespace {

// An entry of B or D below this fraction of the matrix's largest entry is
// rounding of the circuit's reduction (an LU of the MNA equations), not a
// coupling: the same threshold as the LDCP's u_tolerance.
constexpr double kNegligible = 1e-12;
// The circuits' and the LDCP's zero test of a coefficient: relative to the
// magnitudes of its terms (LdcpOptions::tol_rel), plus tol_abs.
constexpr int kMaxEnumerated = 12;  // 4096 candidate modes

bool contains(const lcs::IndexSet& s, int r) { return std::find(s.begin(), s.end(), r) != s.end(); }

lcs::IndexSet merged(lcs::IndexSet a, const lcs::IndexSet& b) {
  a.insert(a.end(), b.begin(), b.end());
  std::sort(a.begin(), a.end());
  a.erase(std::unique(a.begin(), a.end()), a.end());
  return a;
}

std::string set_text(const lcs::IndexSet& s) {
  std::string t = "{";
  for (size_t i = 0; i < s.size(); ++i) t += (i ? ", " : "") + std::to_string(s[i]);
  return t + "}";
}

}  // namespace

bool EventDriven::free_shape(int c, const lcs::IndexSet& held) const {
  if (model_.is_mechanical()) return false;
  const double dmax = sys_.D.cwiseAbs().maxCoeff();
  if (dmax == 0.0) return false;
  if (n_ > 0 && sys_.B.col(c).cwiseAbs().maxCoeff() > kNegligible * sys_.B.cwiseAbs().maxCoeff())
    return false;
  bool moves_other = false;
  for (int r = 0; r < k_; ++r) {
    const bool coupled = std::abs(sys_.D(r, c)) > kNegligible * dmax;
    if (coupled && contains(held, r)) return false;
    if (coupled) moves_other = true;
  }
  return moves_other;
}

lcs::IndexSet EventDriven::free_columns(const lcs::IndexSet& mode,
                                        const lcs::IndexSet& undetermined) const {
  lcs::IndexSet free;
  if (model_.is_mechanical() || mode.empty()) return free;
  const lcs::IndexSet held = merged(mode, undetermined);
  for (int c : mode)
    if (free_shape(c, held)) free.push_back(c);
  return free;
}

bool EventDriven::free_feedback(Phase& ph, const lcs::IndexSet& free, std::string& err) const {
  if (!opt_.sensitivity.empty()) {
    err = text("mode ", set_text(ph.mode), ": pair(s) ", set_text(free),
               " have multipliers that are not unique (docs/circuits.md); their sensitivities "
               "are not computed");
    return false;
  }
  lcs::IndexSet held;
  for (int r : ph.mode)
    if (!contains(free, r)) held.push_back(r);
  MatrixXd Fh = MatrixXd::Zero(0, n_);
  if (!held.empty()) {
    auto it = feedback_cache_.find(held);
    if (it == feedback_cache_.end())
      it = feedback_cache_.emplace(held, lcs::mode_feedback(sys_, held)).first;
    if (!it->second.ok()) {
      err = "mode feedback F_I unavailable: " + it->second.message;
      return false;
    }
    Fh = it->second.F;
    MatrixXd BI(n_, held.size());
    for (size_t i = 0; i < held.size(); ++i) BI.col(i) = sys_.B.col(held[i]);
    ph.Acl += BI * Fh;
  }
  for (size_t i = 0, h = 0; i < ph.mode.size(); ++i)
    if (!contains(free, ph.mode[i])) ph.F.row(i) = Fh.row(h++);
  for (int c : free) {  // y_c = (C_c + D_{c,I'} F_{I'}) x must vanish identically
    RowVectorXd w = sys_.C.row(c);
    double scale = sys_.C.row(c).cwiseAbs().sum();
    for (size_t h = 0; h < held.size(); ++h) {
      w += sys_.D(c, held[h]) * Fh.row(h);
      scale += std::abs(sys_.D(c, held[h])) * Fh.row(h).cwiseAbs().sum();
    }
    if (w.cwiseAbs().maxCoeff() > ldcp_.tol_rel * scale) {
      err = text("mode ", set_text(ph.mode), ": pair ", c,
                 " moves no state and no held output, but its own output does not vanish in "
                 "the mode (its multiplier is not determined)");
      return false;
    }
  }
  return true;
}

bool EventDriven::add_free_monitors(Phase& ph, const lcs::IndexSet& free,
                                    const lcs::IndexSet& undetermined, std::string& err) const {
  const double dmax = sys_.D.cwiseAbs().maxCoeff();
  ph.free.assign(free.size(), FreePair{});
  std::vector<std::vector<int>> upper_rows(free.size());
  for (size_t f = 0; f < free.size(); ++f) ph.free[f].column = free[f];
  for (int r = 0; r < k_; ++r) {
    if (contains(free, r)) continue;
    const auto in_mode = std::find(ph.mode.begin(), ph.mode.end(), r);
    Monitor mon;
    mon.constraint = r;
    if (in_mode != ph.mode.end()) {
      mon.multiplier = true;
      mon.w = ph.F.row(in_mode - ph.mode.begin());
      ph.monitors.push_back(std::move(mon));
      continue;
    }
    if (contains(undetermined, r)) continue;  // y_r and u_r vanish identically
    RowVectorXd w = sys_.C.row(r);
    for (size_t i = 0; i < ph.mode.size(); ++i) w += sys_.D(r, ph.mode[i]) * ph.F.row(i);
    int coupled = -1;
    for (size_t f = 0; f < free.size(); ++f) {
      if (std::abs(sys_.D(r, free[f])) <= kNegligible * dmax) continue;
      if (coupled >= 0) {
        err = text("mode ", set_text(ph.mode), ": the output of pair ", r,
                   " moves with two free multipliers (pairs ", free[static_cast<size_t>(coupled)],
                   " and ", free[f], "); lcsim selects one at a time");
        return false;
      }
      coupled = static_cast<int>(f);
    }
    if (coupled < 0) {
      mon.w = w;
      ph.monitors.push_back(std::move(mon));
      continue;
    }
    FreePair& fp = ph.free[static_cast<size_t>(coupled)];
    const double g = sys_.D(r, fp.column);
    if (g > 0.0) {
      fp.lower.push_back(-w / g);
    } else {
      fp.upper.push_back(w / -g);
      upper_rows[static_cast<size_t>(coupled)].push_back(r);
    }
  }
  // Fourier–Motzkin: the interval [max(0, l x), min(h x)] is not empty.
  for (size_t f = 0; f < free.size(); ++f) {
    const FreePair& fp = ph.free[f];
    for (size_t u = 0; u < fp.upper.size(); ++u) {
      Monitor mon;
      mon.constraint = upper_rows[f][u];
      mon.w = fp.upper[u];  // h x - 0
      ph.monitors.push_back(mon);
      for (const RowVectorXd& l : fp.lower) {
        mon.w = fp.upper[u] - l;
        ph.monitors.push_back(mon);
      }
    }
  }
  return true;
}

void EventDriven::normalise_free(lcs::IndexSet& mode, lcs::IndexSet& undetermined) const {
  if (model_.is_mechanical() || undetermined.empty()) return;
  const lcs::IndexSet held = merged(mode, undetermined);
  lcs::IndexSet keep;
  for (int c : undetermined) {
    if (free_shape(c, held))
      mode.push_back(c);
    else
      keep.push_back(c);
  }
  std::sort(mode.begin(), mode.end());
  undetermined = keep;
}

bool EventDriven::held_outputs_vanish(const Phase& ph, const VectorXd& xa) const {
  const MatrixXd Aabs = ph.Acl.cwiseAbs();
  for (size_t i = 0; i < ph.mode.size(); ++i) {
    const int r = ph.mode[i];
    RowVectorXd w = sys_.C.row(r);
    RowVectorXd wabs = w.cwiseAbs();
    for (size_t j = 0; j < ph.mode.size(); ++j) {
      w += sys_.D(r, ph.mode[j]) * ph.F.row(j);
      wabs += std::abs(sys_.D(r, ph.mode[j])) * ph.F.row(j).cwiseAbs();
    }
    VectorXd x = xa, xs = xa.cwiseAbs();
    for (int j = 0; j < n_; ++j) {  // y_r^(j)(0) = w Acl^j x0 (Cayley–Hamilton: j < n)
      if (std::abs(w.dot(x)) > ldcp_.tol_rel * wabs.dot(xs) + ldcp_.tol_abs) return false;
      x = ph.Acl * x;
      xs = Aabs * xs;
    }
  }
  return true;
}

namespace {

// x0 and A^j x0 (j = 1..n) agree for the two closed loops, to the LDCP's
// relative tolerance of their terms.
bool same_motion(const MatrixXd& A1, const MatrixXd& A2, const VectorXd& x0) {
  constexpr double kRel = 1e-9, kAbs = 1e-13;  // LdcpOptions' defaults
  VectorXd x1 = x0, x2 = x0, s1 = x0.cwiseAbs(), s2 = s1;
  const MatrixXd A1abs = A1.cwiseAbs(), A2abs = A2.cwiseAbs();
  for (Eigen::Index j = 0; j < x0.size(); ++j) {
    x1 = A1 * x1, x2 = A2 * x2, s1 = A1abs * s1, s2 = A2abs * s2;
    if (((x1 - x2).cwiseAbs().array() > kRel * (s1 + s2).array() + kAbs).any()) return false;
  }
  return true;
}

}  // namespace

std::string EventDriven::pair_list(const lcs::IndexSet& s) const {
  std::string t;
  for (size_t i = 0; i < s.size(); ++i) {
    const auto r = static_cast<size_t>(s[i]);
    t += (i ? ", " : "") +
         (r < model_.pair_names.size() ? model_.pair_names[r] : "pair " + std::to_string(r));
  }
  return t.empty() ? std::string("none") : t;
}

std::string EventDriven::pair_sets(const lcs::IndexSet& active,
                                   const lcs::IndexSet& undecided) const {
  if (active.empty() && undecided.empty()) return "";
  return " (active: " + pair_list(active) + "; undecided: " + pair_list(undecided) + ")";
}

bool EventDriven::select_by_enumeration(double t, const VectorXd& xa, EventResult& out,
                                        std::string& why) {
  if (model_.is_mechanical() || k_ > kMaxEnumerated) return false;
  std::vector<std::pair<lcs::IndexSet, MatrixXd>> passed;  // mode, closed loop
  for (long mask = 0; mask < (1L << k_); ++mask) {
    lcs::IndexSet I;
    for (int r = 0; r < k_; ++r)
      if (mask >> r & 1L) I.push_back(r);
    // One mode per motion: an inactive pair that would be free in I with its
    // output vanishing identically is the same phase as I with it.
    bool canonical = true;
    for (int c = 0; c < k_ && canonical; ++c)
      if (!contains(I, c) && free_shape(c, merged(I, {c}))) canonical = false;
    std::string err;
    const Phase ph = build_phase(I, {}, {}, xa, err);
    if (!err.empty() || !held_outputs_vanish(ph, xa) || !all_consistent(ph, xa, t)) continue;
    if (!canonical) {
      // Canonical unless its free candidate's output does not vanish (then I
      // with that pair would be refused, and I is the phase).
      bool vanish = true;
      for (int c = 0; c < k_; ++c) {
        if (contains(I, c) || !free_shape(c, merged(I, {c}))) continue;
        RowVectorXd w = sys_.C.row(c);
        for (size_t i = 0; i < I.size(); ++i) w += sys_.D(c, I[i]) * ph.F.row(i);
        if (w.cwiseAbs().maxCoeff() > ldcp_.tol_rel * sys_.C.row(c).cwiseAbs().sum())
          vanish = false;
      }
      if (vanish) continue;
    }
    passed.emplace_back(I, ph.Acl);
  }
  if (passed.empty()) return false;
  for (size_t i = 1; i < passed.size(); ++i) {
    if (same_motion(passed[0].second, passed[i].second, xa)) continue;
    why = "modes {" + pair_list(passed[0].first) + "} and {" + pair_list(passed[i].first) +
          "} (active pairs) both continue the state with different motions (the LDCP's levels "
          "failed and the continuation is not unique)";
    return false;
  }
  // The fewest pairs held (the first such mask): a pair held at an
  // identically zero multiplier would pin a free one and judge the exits on
  // that one choice.
  size_t best = 0;
  for (size_t i = 1; i < passed.size(); ++i)
    if (passed[i].first.size() < passed[best].first.size()) best = i;
  out.mode = passed[best].first;
  out.x_plus = xa;
  out.status = Status::kOk;
  ldcp_undetermined_.clear();
  return true;
}

}  // namespace lcsim::sim::detail
