// A phase of the event-driven method: the closed loop x' = (A + B_.I F_I) x
// of a mode I, balanced, with its spectral bound, its exponential (dense, or
// its action on a vector for large states) and the monitors whose sign
// changes end it (EventDriven::make_phase).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unsupported/Eigen/MatrixFunctions>

#include "sim/exact/event_driven_detail.hpp"

namespace lcsim::sim::detail {

namespace {

// Diagonal balancing by powers of 2 (Parlett–Reinsch): D such that the
// off-diagonal row and column norms of D^{-1} A D are comparable.
// An entry below sqrt(eps) of the largest entries of both its row and its
// column counts as zero: with Rayleigh damping D = alpha M and no spring or
// force, A's velocity block -M^{-1} D is alpha I up to residues of the
// solve (eps cond(M) alpha: 1e-17 ... 1e-10 for cond(M) <= 1e6), and
// balancing those against the identity block scaled the velocities by
// 1e-18, which made the monitors' noise bands 1e4 wide and hid every
// contact (tests/sim/test_golden_coupled.cpp). An entry that matters in
// its row or its column is kept (a stiff spring's 1 against 1e18 in a row).
VectorXd balancing(const MatrixXd& A) {
  const int n = static_cast<int>(A.rows());
  VectorXd d = VectorXd::Ones(n);
  const Eigen::ArrayXXd abs = A.array().abs();
  const Eigen::ArrayXd row_max = abs.rowwise().maxCoeff(), col_max = abs.colwise().maxCoeff();
  MatrixXd B = A;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      if (abs(i, j) <= kSqrtEps * std::min(row_max(i), col_max(j))) B(i, j) = 0.0;
  for (int sweep = 0; sweep < 50; ++sweep) {
    bool changed = false;
    for (int i = 0; i < n; ++i) {
      double c = 0.0, r = 0.0;
      for (int j = 0; j < n; ++j) {
        if (j == i) continue;
        c += std::abs(B(j, i));
        r += std::abs(B(i, j));
      }
      if (c == 0.0 || r == 0.0) continue;
      double f = 1.0;
      const double s = c + r;
      while (c < r / 2.0) {
        c *= 2.0;
        r /= 2.0;
        f *= 2.0;
      }
      while (c >= r * 2.0) {
        c /= 2.0;
        r *= 2.0;
        f /= 2.0;
      }
      if (c + r < 0.95 * s) {
        changed = true;
        d(i) *= f;
        B.col(i) *= f;
        B.row(i) /= f;
      }
    }
    if (!changed) break;
  }
  return d;
}

}  // namespace

// The rows that start a path of k edges, for k = 1, 2, ..., until none is
// left (k is the index) or the set stops shrinking (a cycle: 0); the set
// only shrinks, so at most n + 1 lengths. Up to 64 rows as bit masks (O(n^2)
// once, O(n) per length), else O(n^2) per length. No products.
int nilpotency_index(const MatrixXd& A) {
  const Eigen::Index n = A.rows();
  if (n <= 64) {
    std::vector<std::uint64_t> reads(static_cast<size_t>(n), 0);  // row i's nonzero columns
    for (Eigen::Index j = 0; j < n; ++j)
      for (Eigen::Index i = 0; i < n; ++i)
        if (A(i, j) != 0.0) reads[static_cast<size_t>(i)] |= std::uint64_t{1} << j;
    std::uint64_t starts = n == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << n) - 1;
    for (int k = 1;; ++k) {
      std::uint64_t next = 0;
      for (Eigen::Index i = 0; i < n; ++i)
        if (reads[static_cast<size_t>(i)] & starts) next |= std::uint64_t{1} << i;
      if (next == 0) return k;
      if (next == starts) return 0;
      starts = next;
    }
  }
  std::vector<char> starts(static_cast<size_t>(n), 1), next(static_cast<size_t>(n));
  Eigen::Index count = n;
  for (int k = 1;; ++k) {
    Eigen::Index c = 0;
    for (Eigen::Index i = 0; i < n; ++i) {
      char s = 0;
      for (Eigen::Index j = 0; j < n && !s; ++j)
        s = starts[static_cast<size_t>(j)] && A(i, j) != 0.0;
      next[static_cast<size_t>(i)] = s;
      c += s;
    }
    if (c == 0) return k;
    if (c == count) return 0;
    starts.swap(next);
    count = c;
  }
}

bool no_path_of(const MatrixXd& A, int len) {
  const int k = nilpotency_index(A);
  return k != 0 && k <= len;
}

double spectral_radius_bound(const MatrixXd& A) {
  const double a = A.cwiseAbs().rowwise().sum().maxCoeff();
  if (a == 0.0) return 0.0;
  // A pattern without a path of 16 edges (the free dynamics and the sliding
  // phases of a body without springs: x' = v, v' = const) has B^16 exactly
  // zero below: each entry of a computed power is a sum of products along
  // paths, every one with a factor exactly zero (B's entries are finite and
  // at most 1 in size, so no product is NaN), so the bound is 0 * a = 0, as
  // the squarings would return, without them.
  if (std::isfinite(a) && no_path_of(A, 16)) return 0.0;
  MatrixXd B = A / a;
  for (int i = 0; i < 4; ++i) B = (B * B).eval();
  return std::pow(B.cwiseAbs().rowwise().sum().maxCoeff(), 1.0 / 16.0) * a;
}

// e^{Ab tau} z in balanced coordinates. A nilpotent pattern (nil > 0): the
// finite series, nil - 1 products with Ab. Above kDenseExpMax: the Taylor
// series of the action in s = ceil(||Ab tau||_1) substeps, so each substep
// has ||Ab tau/s||_1 <= 1 and its series, truncated once two consecutive
// terms are below eps/4 of the partial sum, converges like 1/k! (at most
// ~20 terms); the error is that of the dense exponential's (both are
// backward stable for ||Ab tau/s|| <= 1; Al-Mohy & Higham 2011 choose s
// and the degree more finely).
VectorXd Phase::expv(double tau, const VectorXd& z) const {
  if (nil > 0) {
    VectorXd sum = z, term = z;
    for (int j = 1; j < nil; ++j) {
      term = times(term);
      term *= tau / static_cast<double>(j);
      sum += term;
    }
    return sum;
  }
  if (dense_exp()) return expm(tau) * z;
  const double a = Ab_norm1 * std::abs(tau);
  const long steps = std::max(1L, static_cast<long>(std::ceil(a)));
  const double dt = tau / static_cast<double>(steps);
  VectorXd y = z, term(z.size());
  for (long st = 0; st < steps; ++st) {
    term = y;
    VectorXd sum = y;
    double prev = term.cwiseAbs().maxCoeff();
    for (int k = 1; k <= 60; ++k) {
      term = times(term);
      term *= dt / static_cast<double>(k);
      sum += term;
      const double cur = term.cwiseAbs().maxCoeff();
      const double bound = 0.25 * kEps * sum.cwiseAbs().maxCoeff();
      if (cur <= bound && prev <= bound) break;
      prev = cur;
    }
    y = sum;
  }
  return y;
}

MatrixXd Phase::expm(double tau) const {
  if (nil == 0) return (Ab * tau).exp();
  const Eigen::Index n = Ab.rows();
  MatrixXd sum = MatrixXd::Identity(n, n);
  if (nil == 1) return sum;
  const MatrixXd X = Ab * tau;
  MatrixXd term = X;
  sum += term;
  for (int j = 2; j < nil; ++j) {
    term = (term * X) / static_cast<double>(j);
    sum += term;
  }
  return sum;
}

const Phase& EventDriven::make_phase(const lcs::IndexSet& mode,
                                     const std::vector<FrictionMode>& friction,
                                     const lcs::IndexSet& undetermined, const VectorXd& xa,
                                     std::string& err) const {
  // The state compared exactly (NaN never matches): a phase's monitors are
  // scaled by it, so only the very same state gives the very same phase.
  const PhaseMemo* m = phase_memo_ ? &*phase_memo_ : nullptr;
  // A memo whose phase the run has taken (adopt_phase, event_driven.cpp)
  // has none left (an empty D): built again.
  if (m && m->phase.D.size() == xa.size() && m->mode == mode && m->friction == friction &&
      m->undetermined == undetermined && m->xa.size() == xa.size() &&
      (m->xa.array() == xa.array()).all())
    return m->phase;
  Phase ph = build_phase(mode, friction, undetermined, xa, err);
  if (!err.empty()) {
    phase_memo_.reset();
    failed_phase_ = std::move(ph);
    return failed_phase_;
  }
  phase_memo_ = PhaseMemo{mode, undetermined, friction, xa, std::move(ph), std::nullopt, 0.0};
  return phase_memo_->phase;
}

const EventDriven::MonitorStart& EventDriven::selection_start(const Phase& ph, const VectorXd& xa,
                                                              double t) const {
  PhaseMemo* m = phase_memo_ ? &*phase_memo_ : nullptr;
  const bool memo =
      m && &m->phase == &ph && m->xa.size() == xa.size() && (m->xa.array() == xa.array()).all();
  if (memo && m->start && m->start_t == t) return *m->start;
  MonitorStart st = monitor_start(ph, xa.cwiseQuotient(ph.D), t, 1.0);
  if (!memo) return scratch_start_ = std::move(st);
  m->start = std::move(st);
  m->start_t = t;
  return *m->start;
}

// The selection's start (with the memo) serves the march when `ph` is the
// memo's phase: built from the same mode, friction modes, undetermined set
// (the run's phases are made with ldcp_undetermined_) and state, bit for
// bit, started at the same t. Its h_first is min(1, T), T the monitors'
// shortest time scale; for h_max <= 1, min(h_max, min(1, T)) is
// min(h_max, T), the march's own, exactly.
EventDriven::MonitorStart EventDriven::march_start(const Phase& ph, const VectorXd& xa,
                                                   const VectorXd& xstart, double t,
                                                   double h_max) const {
  const PhaseMemo* m = phase_memo_ ? &*phase_memo_ : nullptr;
  if (h_max <= 1.0 && m && m->start && m->start_t == t && m->mode == ph.mode &&
      m->friction == ph.friction && m->undetermined == ldcp_undetermined_ &&
      m->xa.size() == xa.size() && (m->xa.array() == xa.array()).all()) {
    MonitorStart st = *m->start;
    st.h_first = std::min(h_max, st.h_first);
    return st;
  }
  return monitor_start(ph, xstart, t, h_max);
}

Phase EventDriven::build_phase(const lcs::IndexSet& mode, const std::vector<FrictionMode>& friction,
                               const lcs::IndexSet& undetermined, const VectorXd& xa,
                               std::string& err) const {
  Phase ph;
  ph.mode = mode;
  ph.friction = friction;
  ph.Acl = sys_.A;
  ph.F = MatrixXd::Zero(mode.size(), n_);
  ph.Ft = MatrixXd::Zero(static_cast<Eigen::Index>(friction.size()), n_);
  const bool frictional = std::any_of(friction.begin(), friction.end(),
                                      [](FrictionMode f) { return f != FrictionMode::kOpen; });
  const lcs::IndexSet free = free_columns(mode, undetermined);  // empty but for circuits
  if (frictional) {
    if (!friction_feedback(ph, xa, err)) return ph;
  } else if (!free.empty()) {
    if (!free_feedback(ph, free, err) || !add_free_monitors(ph, free, undetermined, err)) return ph;
  } else if (!mode.empty()) {
    auto it = feedback_cache_.find(mode);
    if (it == feedback_cache_.end())
      it = feedback_cache_.emplace(mode, lcs::mode_feedback(sys_, mode)).first;
    const lcs::ModeFeedback& fb = it->second;
    if (!fb.ok()) {
      err = "mode feedback F_I unavailable: " + fb.message;
      return ph;
    }
    ph.F = fb.F;
    MatrixXd BI(n_, mode.size());
    for (size_t i = 0; i < mode.size(); ++i) BI.col(i) = sys_.B.col(mode[i]);
    ph.Acl += BI * ph.F;
  }
  for (int r = 0; free.empty() && r < k_; ++r) {
    const auto in_mode = std::find(mode.begin(), mode.end(), r);
    Monitor mon;
    mon.constraint = r;
    if (in_mode != mode.end()) {
      mon.multiplier = true;
      mon.w = ph.F.row(in_mode - mode.begin());
    } else {
      if (std::find(undetermined.begin(), undetermined.end(), r) != undetermined.end())
        continue;  // y_r and u_r vanish identically in this mode (Remark 3.4.8)
      mon.multiplier = false;
      RowVectorXd w = sys_.C.row(r);
      for (size_t i = 0; i < mode.size(); ++i) w += sys_.D(r, mode[i]) * ph.F.row(i);
      mon.w = w;
    }
    ph.monitors.push_back(std::move(mon));
  }
  if (frictional) add_friction_monitors(ph);
  ph.D = balancing(ph.Acl);
  ph.Ab = ph.D.cwiseInverse().asDiagonal() * ph.Acl * ph.D.asDiagonal();
  ph.Ab_norm1 = ph.Ab.cwiseAbs().colwise().sum().maxCoeff();
  // A NaN or infinite entry times an exact zero is no zero: such a phase
  // keeps Pade's exponential, whose result is not finite either.
  ph.nil = ph.Ab.allFinite() ? nilpotency_index(ph.Ab) : 0;
  if (!ph.dense_exp()) {
    ph.Ab_sparse = ph.Ab.sparseView();
    ph.use_sparse = ph.Ab_sparse.nonZeros() * 10 <= ph.Ab.size();
  }
  // Ab depends on the mode only: its bound (four n x n squarings) is kept.
  const auto key = std::make_pair(mode, friction);
  auto rit = rho_cache_.find(key);
  if (rit == rho_cache_.end()) rit = rho_cache_.emplace(key, spectral_radius_bound(ph.Ab)).first;
  ph.rho = rit->second;
  const VectorXd z = xa.cwiseQuotient(ph.D);
  for (Monitor& mon : ph.monitors) {
    mon.w = mon.w.cwiseProduct(ph.D.transpose());
    mon.wA = ph.row_times(mon.w);
    mon.scale = mon.w.cwiseAbs().dot(z.cwiseAbs());
  }
  return ph;
}

}  // namespace lcsim::sim::detail
