// Event-driven integration: Algorithm 3.7.1 of the thesis.
//
// Step one/three (mode selection and re-initialisation): for mechanical
// models the impact law on the closed contacts (Moreau's LCP (3.69)-(3.70),
// with Newton restitution, §8.2.2), then the LDCP on the regular part
// (contact forces at acceleration level and, where those vanish, higher
// derivatives: Theorem 3.6.7). For general LCS the full LDCP_n including the
// impulsive levels, whose jump equals P_I x0 (eq. (3.10)).
// Step four: in mode I the dynamics are x' = (A + B_.I F_I) x, integrated
// exactly with the matrix exponential; output samples are exact too.
// Step five: the next event is the first time a free output y_i (i not in I)
// or an active multiplier u_i (i in I) turns negative: a root of a Bohl
// function, bracketed on a sampling grid fine enough for its frequencies and
// refined by Brent's method; grazing minima between samples are checked.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <lcsim/sim/sim.hpp>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <unsupported/Eigen/MatrixFunctions>

namespace lcsim::sim {

namespace {

using Eigen::MatrixXd;
using Eigen::RowVectorXd;

constexpr double kEps = std::numeric_limits<double>::epsilon();

// Brent's method (Dekker–Brent zeroin) for a root of f in [a, b] with
// f(a) f(b) <= 0. Returns the bracket end at which |f| is smallest once the
// bracket is shorter than tol.
template <class F>
double brent_root(F&& f, double a, double b, double fa, double fb, double tol) {
  if (fa == 0.0) return a;
  if (fb == 0.0) return b;
  double c = a, fc = fa, d = b - a, e = d;
  for (int iter = 0; iter < 200; ++iter) {
    if ((fb > 0) == (fc > 0)) {
      c = a;
      fc = fa;
      d = e = b - a;
    }
    if (std::abs(fc) < std::abs(fb)) {
      a = b;
      b = c;
      c = a;
      fa = fb;
      fb = fc;
      fc = fa;
    }
    const double tol1 = 2.0 * kEps * std::abs(b) + 0.5 * tol;
    const double xm = 0.5 * (c - b);
    if (std::abs(xm) <= tol1 || fb == 0.0) return b;
    if (std::abs(e) >= tol1 && std::abs(fa) > std::abs(fb)) {
      double p, q, r;
      const double s = fb / fa;
      if (a == c) {
        p = 2.0 * xm * s;
        q = 1.0 - s;
      } else {
        q = fa / fc;
        r = fb / fc;
        p = s * (2.0 * xm * q * (q - r) - (b - a) * (r - 1.0));
        q = (q - 1.0) * (r - 1.0) * (s - 1.0);
      }
      if (p > 0) q = -q;
      p = std::abs(p);
      if (2.0 * p < std::min(3.0 * xm * q - std::abs(tol1 * q), std::abs(e * q))) {
        e = d;
        d = p / q;
      } else {
        d = xm;
        e = d;
      }
    } else {
      d = xm;
      e = d;
    }
    a = b;
    fa = fb;
    b += std::abs(d) > tol1 ? d : (xm > 0 ? tol1 : -tol1);
    fb = f(b);
  }
  return b;
}

// The return to zero of phi on (a, b] when phi leaves zero upwards at a and
// phi(b) = fb < 0: a positive point is searched for by halving towards a,
// then the root is bracketed between it and b. If none is found down to
// 2^-60 of the interval the opening is below resolution and a is returned.
template <class F>
double return_after_opening(F&& phi, double a, double b, double fb, double tol) {
  for (int k = 1; k <= 60; ++k) {
    const double tp = a + std::ldexp(b - a, -k);
    if (!(tp > a)) break;
    const double fp = phi(tp);
    if (fp > 0.0) return brent_root(phi, tp, b, fp, fb, tol);
  }
  return a;
}

// An upper bound on the spectral radius, ||B^16||^(1/16) ||A|| with
// B = A/||A|| (Gelfand's formula; 4 squarings, no eigen-decomposition).
double spectral_radius_bound(const MatrixXd& A) {
  const double a = A.cwiseAbs().rowwise().sum().maxCoeff();
  if (a == 0.0) return 0.0;
  MatrixXd B = A / a;
  for (int i = 0; i < 4; ++i) B = (B * B).eval();
  return std::pow(B.cwiseAbs().rowwise().sum().maxCoeff(), 1.0 / 16.0) * a;
}

struct Monitor {
  RowVectorXd w;            // phi(t) = w x(t)
  RowVectorXd wA;           // phi'(t) = w Acl x(t)
  double scale = 0.0;       // |w| |x| scale for tolerances
  int constraint = -1;      // which constraint
  bool multiplier = false;  // true: u_i of an active constraint; false: free output y_i
};

struct Phase {
  lcs::IndexSet mode;
  MatrixXd Acl;  // closed-loop matrix
  MatrixXd F;    // u_I = F x (|I| x n)
  // Balanced coordinates z = x ./ D with Ab = D^{-1} Acl D (powers of 2):
  // a stiff spring k makes Acl's entries span k and 1 while its frequencies
  // are sqrt(k); exponentials of the balanced matrix keep the relative
  // accuracy that the unbalanced one loses (gap errors of 1e-8 at k = 1e9).
  VectorXd D;
  MatrixXd Ab;
  std::vector<Monitor> monitors;  // w, wA in balanced coordinates
  double Ab_norm1 = 0.0;          // ||Ab||_1
  // Above kDenseExpMax states, Ab by rows when at most a tenth of it is
  // non-zero (a chain's closed loop is banded): products with vectors then
  // cost O(nnz), not O(n^2).
  Eigen::SparseMatrix<double, Eigen::RowMajor> Ab_sparse;
  bool use_sparse = false;
  VectorXd times(const VectorXd& x) const {
    return use_sparse ? VectorXd(Ab_sparse * x) : VectorXd(Ab * x);
  }
  RowVectorXd row_times(const RowVectorXd& w) const {
    return use_sparse ? RowVectorXd(w * Ab_sparse) : RowVectorXd(w * Ab);
  }
  double rho = 0.0;  // spectral_radius_bound(Ab)

  // Up to this many states e^{Ab tau} is formed (Padé with scaling and
  // squaring, O(n^3)) and, on a sampling grid, reused; above it only its
  // action on a vector is computed (O(n^2) per term): a chain of 100 carts
  // (n = 201) spent 70% of its run in dense exponentials.
  static constexpr int kDenseExpMax = 64;
  bool dense_exp() const { return Ab.rows() <= kDenseExpMax; }

  // e^{Ab tau} z in balanced coordinates. Above kDenseExpMax: the Taylor
  // series of the action in s = ceil(||Ab tau||_1) substeps, so each substep
  // has ||Ab tau/s||_1 <= 1 and its series, truncated once two consecutive
  // terms are below eps/4 of the partial sum, converges like 1/k! (at most
  // ~20 terms); the error is that of the dense exponential's (both are
  // backward stable for ||Ab tau/s|| <= 1; Al-Mohy & Higham 2011 choose s
  // and the degree more finely).
  VectorXd expv(double tau, const VectorXd& z) const {
    if (dense_exp()) return (Ab * tau).exp() * z;
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
  VectorXd exp_apply(double tau, const VectorXd& x) const {
    return D.cwiseProduct(expv(tau, x.cwiseQuotient(D)));
  }
};

// Diagonal balancing by powers of 2 (Parlett–Reinsch): D such that the
// off-diagonal row and column norms of D^{-1} A D are comparable.
VectorXd balancing(const MatrixXd& A) {
  const int n = static_cast<int>(A.rows());
  VectorXd d = VectorXd::Ones(n);
  MatrixXd B = A;
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

struct EventResult {
  bool ok = false;
  std::string message;
  VectorXd x_plus;
  lcs::IndexSet mode;
  VectorXd impulse;  // sum of the impulses applied (size k)
  bool jumped = false;
  bool accumulation = false;
  double t_star = 0.0;  // extrapolated accumulation time (accumulation only)
  std::string note;     // how an accumulation's limit was taken (Event::note)
  long lcp_solves = 0;
  std::vector<std::string> warnings;
};

// Ends a run that cannot make progress: `limit` consecutive events, each
// less than 1e-4 of the fastest time scale (1/rho) after the one before and
// each changing the state by less than 1e-6 of its size, are a livelock, not
// physics: modes that alternate with impulses at the level of the gaps'
// rounding (on the NAO legs before accumulations were taken: every 2e-9 s,
// jumps of 8e-8 in a state of size 1.5, for ever). A real accumulation has
// geometrically shrinking intervals and is taken as a limit long before.
constexpr double kIdleJump = 1e-6;

class LivelockGuard {
 public:
  LivelockGuard(int limit, double rho, std::vector<std::string> names)
      : limit_(limit), rho_(rho), names_(std::move(names)) {}
  // "" while the run makes progress, else the failure message.
  std::string after_event(double t, const VectorXd& x_minus, const VectorXd& x_plus,
                          const lcs::IndexSet& old_mode, const EventResult& ev) {
    const double dt = t - last_t_;
    last_t_ = t;
    const double quick = rho_ > 0.0 ? 1e-4 / rho_ : 1e-4 * std::max(1.0, std::abs(t));
    const double jump = (x_plus - x_minus).cwiseAbs().maxCoeff();
    const bool idle = dt <= quick && jump <= kIdleJump * x_minus.cwiseAbs().maxCoeff();
    if (!idle) {
      streak_ = 0;
      involved_.clear();
      return "";
    }
    if (streak_++ == 0) since_ = t;
    for (int r : ev.mode)
      if (std::find(old_mode.begin(), old_mode.end(), r) == old_mode.end()) involved_.insert(r);
    for (int r : old_mode)
      if (std::find(ev.mode.begin(), ev.mode.end(), r) == ev.mode.end()) involved_.insert(r);
    for (int r = 0; r < static_cast<int>(ev.impulse.size()); ++r)
      if (ev.impulse(r) != 0.0) involved_.insert(r);
    if (streak_ < limit_) return "";
    std::ostringstream msg;
    msg.precision(6);
    msg << "no progress at t = " << t << ": " << streak_ << " events in " << (t - since_)
        << " s each changed the state by less than rounding, at contacts ";
    bool first = true;
    for (int r : involved_) {
      msg << (first ? "" : ", ")
          << (r < static_cast<int>(names_.size()) ? "'" + names_[r] + "'" : std::to_string(r));
      first = false;
    }
    if (involved_.empty()) msg << "(none)";
    msg << " (their modes alternate with impulses below rounding): the event-driven method "
           "cannot resolve this contact configuration; a time-stepping method (Moreau–Jean) can";
    return msg.str();
  }

 private:
  int limit_;
  double rho_;
  std::vector<std::string> names_;
  int streak_ = 0;
  double since_ = 0.0, last_t_ = -std::numeric_limits<double>::infinity();
  std::set<int> involved_;
};

class EventDriven {
 public:
  // `model` fits the dense LCS (Integrator::run checks).
  EventDriven(const mech::Model& model, const Options& opt)
      : model_(model), opt_(opt), sys_(model.as_lcs()) {
    n_ = sys_.n();
    k_ = sys_.k();
    if (model.is_mechanical()) {
      N_ = model.mechanical->dofs();
      restitution_ = model.mechanical->restitution;
    }
    solver_ = lcp::make_solver(opt.lcp_solver);
    impact_ = impact::make_impact_law(opt.impact);
    impact_times_.assign(k_, {});
    ldcp_.solver = solver_.get();
    ldcp_data_ = lcs::ldcp_data(sys_);
    rho_A_ = spectral_radius_bound(sys_.A);
    ldcp_.data = &ldcp_data_;
  }

  Trajectory run(const VectorXd& x0_user);

 private:
  VectorXd augment(const VectorXd& x) const {
    if (!model_.is_mechanical()) return x;
    VectorXd xa(n_);
    xa << x, 1.0;
    return xa;
  }
  VectorXd user(const VectorXd& xa) const {
    return model_.is_mechanical() ? VectorXd(xa.head(2 * N_)) : xa;
  }
  bool is_zero(double value, double scale) const {
    return std::abs(value) <= ldcp_.tol_rel * scale + ldcp_.tol_abs;
  }

  Phase make_phase(const lcs::IndexSet& mode, const lcs::IndexSet& undetermined, const VectorXd& xa,
                   std::string& err) const;
  EventResult process_event(double t, const VectorXd& xa);
  double accumulation_time(int r, double t, double* ratio) const;
  void project_onto(const std::vector<int>& rows, VectorXd& xa, bool positions) const;
  EventResult process_mechanical(double t, const VectorXd& xa);
  std::string take_accumulation_limit(int r, double t, double ratio, double t_star,
                                      const VectorXd& gap, const VectorXd& gap_scale,
                                      VectorXd& xa) const;
  EventResult process_lcs(const VectorXd& xa);
  void record(Trajectory& tr, double t, const VectorXd& xa, const Phase& ph) const;
  VectorXd multipliers(const Phase& ph, const VectorXd& xa) const {
    VectorXd u = VectorXd::Zero(k_);
    if (!ph.mode.empty()) {
      const VectorXd uI = ph.F * xa;
      for (size_t i = 0; i < ph.mode.size(); ++i) u(ph.mode[i]) = uI(i);
    }
    return u;
  }
  double violation(const VectorXd& xa) const {
    if (k_ == 0) return 0.0;
    const VectorXd y = sys_.C * xa;  // D u is zero for mechanical models
    return std::min(0.0, y.minCoeff());
  }
  double energy(const VectorXd& xa) const {
    if (!model_.is_mechanical()) return 0.0;
    return mech::total_energy(*model_.mechanical, xa.head(N_), xa.segment(N_, N_));
  }

  const mech::Model& model_;
  const Options& opt_;
  lcs::Lcs sys_;
  int n_ = 0, k_ = 0, N_ = 0;
  VectorXd restitution_;
  std::unique_ptr<lcp::Solver> solver_;
  std::unique_ptr<impact::ImpactLaw> impact_;
  lcs::LdcpOptions ldcp_;
  std::vector<std::vector<double>> impact_times_;  // last few impacts per contact
  lcs::IndexSet ldcp_undetermined_;                // K of the last mode selection
  lcs::LdcpData ldcp_data_;
  double rho_A_ = 0.0;  // bound on the spectral radius of the free dynamics
  mutable std::map<lcs::IndexSet, lcs::ModeFeedback> feedback_cache_;
  mutable std::map<lcs::IndexSet, double> rho_cache_;
};

Phase EventDriven::make_phase(const lcs::IndexSet& mode, const lcs::IndexSet& undetermined,
                              const VectorXd& xa, std::string& err) const {
  Phase ph;
  ph.mode = mode;
  ph.Acl = sys_.A;
  ph.F = MatrixXd::Zero(mode.size(), n_);
  if (!mode.empty()) {
    auto it = feedback_cache_.find(mode);
    if (it == feedback_cache_.end())
      it = feedback_cache_.emplace(mode, lcs::mode_feedback(sys_, mode)).first;
    const lcs::ModeFeedback& fb = it->second;
    if (!fb.ok) {
      err = "mode feedback F_I unavailable: " + fb.message;
      return ph;
    }
    ph.F = fb.F;
    MatrixXd BI(n_, mode.size());
    for (size_t i = 0; i < mode.size(); ++i) BI.col(i) = sys_.B.col(mode[i]);
    ph.Acl += BI * ph.F;
  }
  for (int r = 0; r < k_; ++r) {
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
  ph.D = balancing(ph.Acl);
  ph.Ab = ph.D.cwiseInverse().asDiagonal() * ph.Acl * ph.D.asDiagonal();
  ph.Ab_norm1 = ph.Ab.cwiseAbs().colwise().sum().maxCoeff();
  if (!ph.dense_exp()) {
    ph.Ab_sparse = ph.Ab.sparseView();
    ph.use_sparse = ph.Ab_sparse.nonZeros() * 10 <= ph.Ab.size();
  }
  // Ab depends on the mode only: its bound (four n x n squarings) is kept.
  auto rit = rho_cache_.find(mode);
  if (rit == rho_cache_.end()) rit = rho_cache_.emplace(mode, spectral_radius_bound(ph.Ab)).first;
  ph.rho = rit->second;
  const VectorXd z = xa.cwiseQuotient(ph.D);
  for (Monitor& mon : ph.monitors) {
    mon.w = mon.w.cwiseProduct(ph.D.transpose());
    mon.wA = ph.row_times(mon.w);
    mon.scale = mon.w.cwiseAbs().dot(z.cwiseAbs());
  }
  return ph;
}

// Impacts of contact r at t_{k-3}, t_{k-2}, t_{k-1} and now t, whatever the
// restitution (inelastic impacts accumulate too when they alternate between
// coupled contacts): when the intervals shrink geometrically (two successive
// ratios agree to kRatioAgreement) the remaining impacts sum to d r/(1-r) (d the last
// interval, r the ratio); when that tail is below accumulation_tail max(1, t)
// s, or the last interval is below accumulation_dt, the limit is taken.
// Returns the accumulation time (and the ratio, 0 for the interval test),
// or -1.
// A ball's ratios agree exactly; impacts that alternate through a coupling
// reach a constant ratio only as their intervals shrink (the rest of the
// system drifts between impacts: 0.061, 0.060, 0.056 on the NAO legs' knee
// and ankle), and they must be caught before the rounding of the gaps drives
// them (there below 1e-8 s). 10 % agreement with a tail below 1e-6 s: the
// limit then misses only motion within the tail, in which every contact
// involved stays within its bounce amplitude of the limit.
constexpr double kRatioAgreement = 0.1;

double EventDriven::accumulation_time(int r, double t, double* ratio_out) const {
  const auto& h = impact_times_[r];
  *ratio_out = 0.0;
  // A further round of the impact law at the same event is not an impact of
  // a sequence (it repairs a jump that left a contact approaching).
  if (h.empty() || h.back() >= t) return -1.0;
  const double d2 = t - h.back();
  if (d2 < opt_.accumulation_dt) return t;
  if (h.size() < 3) return -1.0;
  const double d1 = h[h.size() - 1] - h[h.size() - 2];
  const double d0 = h[h.size() - 2] - h[h.size() - 3];
  if (!(d1 > 0.0 && d0 > 0.0)) return -1.0;
  const double ratio = d2 / d1, ratio0 = d1 / d0;
  if (!(ratio < 1.0) || std::abs(ratio - ratio0) > kRatioAgreement * ratio) return -1.0;
  const double tail = d2 * ratio / (1.0 - ratio);
  *ratio_out = ratio;
  return tail < opt_.accumulation_tail * std::max(1.0, std::abs(t)) ? t + tail : -1.0;
}

// The M-orthogonal projection onto E_J q + g_J = 0 (positions) or E_J v = 0
// (velocities): the smallest change in the kinetic metric, as in Moreau's
// rule; a least-squares solve copes with dependent rows. Used only for
// corrections at rounding level.
void EventDriven::project_onto(const std::vector<int>& rows, VectorXd& xa, bool positions) const {
  if (rows.empty()) return;
  const mech::MechanicalModel& m = *model_.mechanical;
  MatrixXd EJ(rows.size(), N_);
  VectorXd r(rows.size());
  for (size_t i = 0; i < rows.size(); ++i) {
    EJ.row(i) = m.E.row(rows[i]);
    r(i) = positions ? m.E.row(rows[i]).dot(xa.head(N_)) + m.g(rows[i])
                     : m.E.row(rows[i]).dot(xa.segment(N_, N_));
  }
  const Eigen::LLT<MatrixXd> llt(m.M);
  const MatrixXd MinvEt = llt.solve(EJ.transpose());
  const VectorXd lambda = (EJ * MinvEt).completeOrthogonalDecomposition().solve(r);
  if (positions)
    xa.head(N_) -= MinvEt * lambda;
  else
    xa.segment(N_, N_) -= MinvEt * lambda;
}

// The limit of an accumulation at contact r. The contacts that take part
// are r and those with an impact since the first of r's last impacts that are
// open by at most 1e-6 of their gap's scale. In the limit their gaps and
// rates vanish (each impact shrinks the rates by the ratio), so the state is
// projected, in the kinetic metric, onto E_J q + g_J = 0 and E_J v = 0: the
// nearest limit state, which never gains kinetic energy. Mode selection then
// decides their forces. Returns how the limit was taken (Event::note).
std::string EventDriven::take_accumulation_limit(int r, double t, double ratio, double t_star,
                                                 const VectorXd& gap, const VectorXd& gap_scale,
                                                 VectorXd& xa) const {
  const double since = impact_times_[r].empty() ? t : impact_times_[r].front();
  std::vector<int> joined;
  std::string names;
  for (int s = 0; s < k_; ++s) {
    const auto& h = impact_times_[s];
    const bool took_part = s == r || (!h.empty() && h.back() >= since);
    if (!took_part || gap(s) > 1e-6 * gap_scale(s)) continue;
    names += (names.empty() ? "'" : ", '") + model_.mechanical->constraints[s] + "'";
    joined.push_back(s);
  }
  const VectorXd x_before = xa;
  project_onto(joined, xa, true);
  project_onto(joined, xa, false);
  const VectorXd dq = xa.head(N_) - x_before.head(N_);
  const VectorXd dv = xa.segment(N_, N_) - x_before.segment(N_, N_);
  const double moved = std::sqrt(dq.dot(model_.mechanical->M * dq));
  const double slowed = std::sqrt(dv.dot(model_.mechanical->M * dv));
  std::ostringstream note;
  note.precision(6);
  note << "impacts at " << names << " accumulate: ";
  if (ratio > 0.0)
    note << "their intervals shrink by the ratio " << ratio << ", so the remaining impacts take "
         << (t_star - t) << " s (geometric tail d r/(1 - r))";
  else
    note << "two impacts of '" << model_.mechanical->constraints[r] << "' " << (t - since)
         << " s apart or less (accumulation_dt)";
  note << "; limit taken at t = " << t << ": their gaps and rates set to zero (positions moved by "
       << moved << ", velocities by " << slowed
       << " in the kinetic metric), then the limit mode up to t* = " << t_star;
  return note.str();
}

EventResult EventDriven::process_mechanical(double t, const VectorXd& xa0) {
  EventResult out;
  out.impulse = VectorXd::Zero(k_);
  VectorXd xa = xa0;
  const mech::MechanicalModel& m = *model_.mechanical;
  std::vector<int> closed, resting;  // zero gap; zero gap and zero rate
  bool limit_taken = false;          // an accumulation's limit is being taken
  for (int iter = 0; iter < 100; ++iter) {
    closed.clear();
    resting.clear();
    const VectorXd q = xa.head(N_), v = xa.segment(N_, N_);
    const VectorXd gap = m.E * q + m.g;
    const VectorXd gap_scale = m.E.cwiseAbs() * q.cwiseAbs() + m.g.cwiseAbs();
    const VectorXd rate = m.E * v;
    const VectorXd rate_scale = m.E.cwiseAbs() * v.cwiseAbs();
    impact::ImpactInput in;
    in.model = &m;
    in.q = q;
    in.v = v;
    bool approaching = false;
    int accumulating = -1;  // a contact whose impacts accumulate at t_star
    double acc_ratio = 0.0;
    for (int r = 0; r < k_; ++r) {
      // Zero within rounding, or within what the event time's resolution
      // (a few ulp of t times the rate) leaves in the gap.
      const double gap_tol = ldcp_.tol_rel * gap_scale(r) + ldcp_.tol_abs +
                             16.0 * kEps * std::max(1.0, std::abs(t)) * std::abs(rate(r));
      if (gap(r) < -gap_tol) {
        std::ostringstream msg;
        msg.precision(6);
        msg << "constraint '" << m.constraints[r] << "' is violated at t = " << t
            << " (gap = " << gap(r)
            << "): the state is infeasible, E q + g >= 0 must hold (thesis §3.8)";
        out.message = msg.str();
        return out;
      }
      if (gap(r) > gap_tol) continue;
      in.closed.push_back(r);
      closed.push_back(r);
      // A rate is zero within rounding of its terms, or within what rounding
      // of the state leaves in it: eps times the velocities and positions
      // times the fastest frequency (a stiff spring grazing its stop).
      const double rate_noise = 64.0 * kEps * m.E.row(r).cwiseAbs().sum() *
                                (v.cwiseAbs().maxCoeff() + rho_A_ * q.cwiseAbs().maxCoeff());
      const double rate_tol = ldcp_.tol_rel * rate_scale(r) + ldcp_.tol_abs + rate_noise;
      if (std::abs(rate(r)) <= rate_tol) resting.push_back(r);
      if (rate(r) < -rate_tol) {
        approaching = true;
        double ratio = 0.0;
        const double ts = limit_taken ? -1.0 : accumulation_time(r, t, &ratio);
        if (ts >= t && ts >= out.t_star) {
          accumulating = r;
          acc_ratio = ratio;
          out.t_star = ts;
        }
      }
    }
    if (accumulating >= 0) {
      // Right-accumulation of impacts (Remark 3.4.11): the limit state has
      // every contact that takes part in the accumulation closed (with
      // alternating impacts the others are open by a gap of the order of the
      // tail), and the remaining impacts are inelastic in the limit. Close
      // those contacts (M-orthogonal projection of q), then apply the
      // inelastic impact; the run continues from t_star in the limit mode.
      limit_taken = true;
      out.accumulation = true;
      out.note =
          take_accumulation_limit(accumulating, t, acc_ratio, out.t_star, gap, gap_scale, xa);
      continue;
    }
    if (!approaching) break;
    in.restitution = limit_taken ? VectorXd::Zero(k_) : VectorXd(restitution_);
    const impact::ImpactResult ir = impact_->apply(in, *solver_);
    out.lcp_solves += ir.lcp_solves;
    if (!ir.ok) {
      out.message = "impact at t = " + std::to_string(t) + ": " + ir.message;
      return out;
    }
    if (!ir.admissible)
      out.warnings.push_back("impact law '" + impact_->name() + "' at t = " + std::to_string(t) +
                             " gave a non-admissible jump (negative impulse or E_J v+ < 0)" +
                             (ir.message.empty() ? "" : ": " + ir.message));
    xa.segment(N_, N_) = ir.v_after;
    out.impulse += ir.impulse;
    out.jumped = true;
    for (int r : in.closed)
      if (ir.impulse(r) > 0.0) {
        auto& h = impact_times_[r];
        if (h.empty() || h.back() != t) h.push_back(t);
        if (h.size() > 4) h.erase(h.begin());
      }
    if (iter == 99) {
      out.message =
          "impacts at t = " + std::to_string(t) + " did not end after 100 rounds of the impact law";
      return out;
    }
  }
  // Put the closed gaps and the resting rates at exactly zero: they are zero
  // up to the state's rounding, and mode selection must see them so.
  project_onto(closed, xa, true);
  project_onto(resting, xa, false);
  lcs::LdcpOptions o = ldcp_;
  o.regular_only = true;  // the state is now regular: contact forces and higher
  const lcs::ModeSelection sel = lcs::select_mode(sys_, xa, o);
  out.lcp_solves += sel.lcp_solves;
  if (!sel.ok) {
    out.message = "mode selection at t = " + std::to_string(t) + ": " + sel.message;
    return out;
  }
  out.mode = sel.mode;
  out.x_plus = xa;
  out.ok = true;
  ldcp_undetermined_ = sel.undetermined;
  return out;
}

EventResult EventDriven::process_lcs(const VectorXd& xa0) {
  EventResult out;
  out.impulse = VectorXd::Zero(k_);
  VectorXd xa = xa0;
  // Theorem 3.6.3: with P-matrix leading coefficients at most one jump occurs;
  // a few more rounds are allowed and then reported.
  for (int iter = 0; iter < 4; ++iter) {
    const lcs::ModeSelection sel = lcs::select_mode(sys_, xa, ldcp_);
    out.lcp_solves += sel.lcp_solves;
    if (!sel.ok) {
      out.message = "mode selection: " + sel.message;
      return out;
    }
    bool impulsive = false;
    for (const auto& imp : sel.impulse)
      if (!imp.isZero(0.0)) impulsive = true;
    if (!impulsive) {
      out.mode = sel.mode;
      out.x_plus = xa;
      out.ok = true;
      ldcp_undetermined_ = sel.undetermined;
      return out;
    }
    out.impulse += sel.impulse[0];
    out.jumped = true;
    xa = sel.x_plus;
  }
  out.message = "re-initialisation did not reach a regular state after 4 jumps";
  return out;
}

EventResult EventDriven::process_event(double t, const VectorXd& xa) {
  return model_.is_mechanical() ? process_mechanical(t, xa) : process_lcs(xa);
}

void EventDriven::record(Trajectory& tr, double t, const VectorXd& xa, const Phase& ph) const {
  tr.max_violation = std::min(tr.max_violation, violation(xa));
  if (!opt_.record_samples) return;
  Sample s;
  s.t = t;
  s.x = user(xa);
  s.u = multipliers(ph, xa);
  s.y = sys_.C * xa + sys_.D * s.u;
  s.mode = ph.mode;
  tr.record_sample(std::move(s), opt_);
}

Trajectory EventDriven::run(const VectorXd& x0_user) {
  const auto wall0 = std::chrono::steady_clock::now();
  Trajectory tr;
  tr.method = "event";
  tr.t_end = *opt_.t_end;
  if (model_.is_mechanical()) tr.impact_law = impact_->name();
  auto fail = [&](const std::string& msg) {
    tr.status = RunStatus::kNumericalFailure;
    tr.message = msg;
  };
  VectorXd xa = augment(x0_user);
  tr.energy_initial = energy(xa);
  double t = 0.0;

  // Initial mode selection (and jump, if the initial state is not regular).
  EventResult ev = process_event(t, xa);
  tr.lcp_solves += ev.lcp_solves;
  for (const auto& w : ev.warnings) tr.add_warning(w);
  std::string err;
  Phase phase;
  if (!ev.ok) {
    fail(ev.message);
  } else {
    phase = make_phase(ev.mode, ldcp_undetermined_, ev.x_plus, err);
    if (!err.empty()) fail(err);
  }
  if (tr.status == RunStatus::kNumericalFailure) {
    tr.final_state = x0_user;
    tr.energy_final = tr.energy_initial;
    return tr;
  }
  if (ev.jumped) {
    Phase before = phase;
    before.mode.clear();
    before.F.resize(0, n_);
    record(tr, t, xa, before);
    Event e;
    e.t = t;
    e.type = EventType::kImpact;
    e.state_before = user(xa);
    e.state_after = user(ev.x_plus);
    e.mode_after = ev.mode;
    e.impulse = ev.impulse;
    tr.events.push_back(std::move(e));
  }
  xa = ev.x_plus;
  record(tr, t, xa, phase);

  const double t_end = *opt_.t_end;
  LivelockGuard livelock(
      opt_.livelock_events, rho_A_,
      model_.is_mechanical() ? model_.mechanical->constraints : std::vector<std::string>{});
  long events_in_window = 0;
  double window_start = 0.0;
  while (t < t_end) {
    ++tr.steps;
    if (opt_.progress) opt_.progress(t);
    // Sampling step: a quarter of the fastest time scale of the closed loop,
    // so a Bohl function changes the sign of its derivative at most once
    // between samples; first steps shorter where a monitor starts at zero.
    const double rho = phase.rho;
    double h_max = t_end - t;
    if (rho > 0.0) h_max = std::min(h_max, 0.5 / rho);
    h_max = std::min(h_max, (t_end - t) / 4.0 + 1e-300);
    double h_first = h_max;
    const VectorXd xstart = xa.cwiseQuotient(phase.D);  // balanced
    // Noise level of each monitor at the phase start: rounding of its terms
    // plus the time quantisation of the event time (ulp(t) times its rate).
    std::vector<double> noise(phase.monitors.size());
    for (size_t j = 0; j < phase.monitors.size(); ++j) {
      const Monitor& mon = phase.monitors[j];
      noise[j] = 64.0 * kEps * mon.w.cwiseAbs().sum() * xstart.cwiseAbs().maxCoeff() +
                 (16.0 * kEps * std::max(1.0, std::abs(t)) + opt_.event_time_tol) *
                     std::abs(mon.wA.dot(xstart));
    }
    // Per monitor: the order m0 of its first nonzero derivative at the phase
    // start (0 = the value itself; -1 = none up to n) and that derivative d0.
    std::vector<int> m0;
    std::vector<double> d0;
    {
      // Derivatives of the monitors at the phase start: d_m = w Acl^m x.
      // A derivative is rounding noise when below the zero test of mode
      // selection applied to the magnitudes of its terms |w| |Acl|^m |x|.
      // Each monitor needs its first two nonzero derivatives only: the loop
      // stops once every monitor has them (usually m <= 3), instead of
      // always forming all n + 1 (O(n^3) per phase for large models).
      const size_t nm = phase.monitors.size();
      m0.assign(nm, -1);
      d0.assign(nm, 0.0);
      std::vector<char> done(nm, 0);
      size_t remaining = nm;
      VectorXd Amx = xstart;
      VectorXd Amx_abs = xstart.cwiseAbs();
      MatrixXd Acl_abs;
      for (int m = 0; m <= n_ && remaining > 0; ++m) {
        if (m > 0) {
          if (m == 1) Acl_abs = phase.Ab.cwiseAbs();
          Amx = phase.times(Amx);
          Amx_abs = Acl_abs * Amx_abs;
        }
        for (size_t j = 0; j < nm; ++j) {
          if (done[j]) continue;
          const Monitor& mon = phase.monitors[j];
          const double dm = mon.w * Amx;
          const double zero =
              m == 0 ? noise[j] : ldcp_.tol_rel * mon.w.cwiseAbs().dot(Amx_abs) + ldcp_.tol_abs;
          if (std::abs(dm) <= zero) continue;
          if (m0[j] < 0) {
            m0[j] = m;
            d0[j] = dm;
            continue;
          }
          // Time scale of the first two nonzero Taylor terms:
          // |d_m0| t^m0/m0! = |d_m| t^m/m!  ->  t = (|d_m0| m!/(m0! |d_m|))^(1/(m-m0))
          const double ratio = std::abs(d0[j]) / std::abs(dm);
          double f = 1.0;
          for (int i = m0[j] + 1; i <= m; ++i) f *= i;
          const double tau = std::pow(ratio * f, 1.0 / (m - m0[j]));
          h_first = std::min(h_first, 0.25 * tau);
          done[j] = 1;
          --remaining;
        }
      }
    }
    h_first = std::max(h_first, 1e-15 * std::max(1.0, std::abs(t)));

    // March over the samples of this phase. A monitor is armed (watched for
    // a sign change) when it starts positive, or when it starts at zero
    // (within noise) and its first nonzero derivative is positive: it opens,
    // however little (a lift-off of 1e-10 m and its landing are both seen).
    // Such a monitor is followed as phi(t) - phi(t0), the start's rounding
    // residue removed, so it leaves exactly zero and its return is a root.
    // A monitor that starts at zero and is identically zero, or whose first
    // nonzero derivative is negative (mode selection rules that out up to
    // rounding), only counts once it leaves the noise band.
    std::vector<char> armed(phase.monitors.size());
    std::vector<double> offset(phase.monitors.size(), 0.0);
    for (size_t j = 0; j < phase.monitors.size(); ++j) {
      const double value = phase.monitors[j].w.dot(xstart);
      if (m0[j] == 0) {
        armed[j] = value > 0.0;
      } else if (m0[j] > 0 && d0[j] > 0.0) {
        armed[j] = true;
        offset[j] = value;
      }
    }
    double ta = t;
    VectorXd xa_a = xstart;
    MatrixXd Phi;
    double h_phi = -1.0;
    double h = h_first;
    double t_event = std::numeric_limits<double>::infinity();
    bool event_found = false;
    double next_out = opt_.dt_out > 0 ? (std::floor(t / opt_.dt_out + 1e-9) + 1) * opt_.dt_out
                                      : std::numeric_limits<double>::infinity();
    auto state_at = [&](double tt) -> VectorXd {
      return phase.D.cwiseProduct(phase.expv(tt - t, xstart));
    };
    while (ta < t_end && !event_found) {
      const double tb = std::min(ta + h, t_end);
      VectorXd xa_b;
      if (!phase.dense_exp()) {
        xa_b = phase.expv(tb - ta, xa_a);
      } else {
        if (tb - ta != h_phi) {
          h_phi = tb - ta;
          Phi = (phase.Ab * h_phi).exp();
        }
        xa_b = Phi * xa_a;
      }
      // Taylor terms A^k x_a / k! on this interval, built on first need:
      // root refinement then evaluates polynomials instead of exponentials.
      std::vector<VectorXd> taylor;
      bool taylor_ok = false, taylor_built = false;
      auto build_taylor = [&] {
        taylor_built = true;
        const double tau = tb - ta;
        const double xnorm = xa_a.cwiseAbs().maxCoeff();
        taylor.push_back(xa_a);
        double factor = 1.0;  // tau^k
        for (int k = 1; k <= 80; ++k) {
          taylor.push_back(phase.times(taylor.back()) / static_cast<double>(k));
          factor *= tau;
          if (k >= 4 && taylor.back().cwiseAbs().maxCoeff() * factor <= 1e-18 * xnorm &&
              taylor[k - 1].cwiseAbs().maxCoeff() * factor / tau <= 1e-17 * xnorm) {
            taylor_ok = true;
            return;
          }
        }
      };
      auto series = [&](const Eigen::RowVectorXd& w, double s, bool derivative) {
        double acc = 0.0;
        if (!derivative) {
          for (int k = static_cast<int>(taylor.size()) - 1; k >= 0; --k)
            acc = acc * s + w.dot(taylor[k]);
        } else {
          for (int k = static_cast<int>(taylor.size()) - 1; k >= 1; --k)
            acc = acc * s + k * w.dot(taylor[k]);
        }
        return acc;
      };
      for (size_t j = 0; j < phase.monitors.size(); ++j) {
        const Monitor& mon = phase.monitors[j];
        const double fa = mon.w * xa_a - offset[j];
        const double fb = mon.w * xa_b - offset[j];
        const double tol_f = 1e-12 * mon.scale;
        auto phi = [&](double tt) -> double {
          if (!taylor_built) build_taylor();
          if (taylor_ok) return series(mon.w, tt - ta, false) - offset[j];
          return mon.w * phase.expv(tt - ta, xa_a) - offset[j];
        };
        auto dphi = [&](double tt) -> double {
          if (!taylor_built) build_taylor();
          if (taylor_ok) return series(mon.w, tt - ta, true);
          return mon.wA * phase.expv(tt - ta, xa_a);
        };
        double root = std::numeric_limits<double>::infinity();
        if (!armed[j]) {
          // Started within rounding of zero: positive by mode selection, but
          // only a departure beyond the noise band counts as a sign.
          if (fb > noise[j]) {
            armed[j] = true;
          } else if (fb < -noise[j]) {
            auto shifted = [&](double tt) { return phi(tt) + noise[j]; };
            root = brent_root(shifted, ta, tb, fa + noise[j], fb + noise[j], opt_.event_time_tol);
          }
        } else {
          const double da = mon.wA * xa_a;
          const double db = mon.wA * xa_b;
          // A tangential touch (gap and rate both zero) leaves a minimum
          // within rounding of zero, of either sign: it is a graze, not an
          // impact with a spurious 1e-8 rate.
          const bool touch_shape = fa > 0.0 && da < 0.0 && db >= 0.0 && fb >= -tol_f;
          if (fb < 0.0 && !touch_shape && fa <= 0.0 && ta == t && offset[j] != 0.0) {
            // Opened at the phase start and back below zero by tb: the
            // return lies after a positive stretch that starts at t.
            root = return_after_opening(phi, ta, tb, fb, opt_.event_time_tol);
          } else if (fb < 0.0 && !touch_shape) {
            root = fa <= 0.0 ? ta : brent_root(phi, ta, tb, fa, fb, opt_.event_time_tol);
          } else if (fa > 0.0 && da < 0.0 && db > 0.0) {
            // Positive (or touching) at both ends, derivative from - to +.
            const double tm = brent_root(dphi, ta, tb, da, db, opt_.event_time_tol);
            const double fm = phi(tm);
            if (fm < -tol_f) {
              root = brent_root(phi, ta, tm, fa, fm, opt_.event_time_tol);
            } else if (fm <= tol_f) {
              root = tm;  // touches zero with zero rate
            }
          }
        }
        if (root < t_event) t_event = root;
      }
      if (std::isfinite(t_event)) {
        event_found = true;
      } else {
        // Exact output samples inside (ta, tb].
        while (next_out <= tb && next_out < t_end) {
          record(tr, next_out, state_at(next_out), phase);
          next_out += opt_.dt_out;
        }
        ta = tb;
        xa_a = xa_b;
        h = std::min(2.0 * h, h_max);
      }
    }
    if (!event_found) {
      // Reached the horizon.
      const VectorXd xend = state_at(t_end);
      record(tr, t_end, xend, phase);
      xa = xend;
      t = t_end;
      break;
    }
    // Output samples before the event.
    while (next_out < t_event) {
      record(tr, next_out, state_at(next_out), phase);
      next_out += opt_.dt_out;
    }
    const VectorXd x_minus = state_at(t_event);
    const long events_seen = static_cast<long>(tr.events.size()) + tr.events_not_recorded;
    const bool keep = static_cast<long>(tr.events.size()) < opt_.max_recorded_events;
    if (keep) record(tr, t_event, x_minus, phase);
    t = t_event;
    // Zeno guard.
    if (t - window_start > 1.0) {
      window_start = t;
      events_in_window = 0;
    }
    if (++events_in_window > opt_.max_events_per_unit_time || events_seen >= opt_.max_events) {
      std::ostringstream msg;
      msg << "more than " << events_in_window << " events in less than unit time near t = " << t
          << ": the event times accumulate without a limit the simulator can take";
      fail(msg.str());
      xa = x_minus;
      break;
    }
    ev = process_event(t, x_minus);
    tr.lcp_solves += ev.lcp_solves;
    for (const auto& w : ev.warnings) tr.add_warning(w);
    if (!ev.ok) {
      fail(ev.message);
      xa = x_minus;
      break;
    }
    const lcs::IndexSet old_mode = phase.mode;
    phase = make_phase(ev.mode, ldcp_undetermined_, ev.x_plus, err);
    if (!err.empty()) {
      fail(err);
      xa = x_minus;
      break;
    }
    xa = ev.x_plus;
    if (ev.accumulation && ev.t_star > t) {
      // Continue from the accumulation time in the limit mode; the bounces
      // left out last ev.t_star - t seconds in all.
      xa = phase.exp_apply(ev.t_star - t, xa);
      t = ev.t_star;
    }
    if (const std::string why = livelock.after_event(t, x_minus, xa, old_mode, ev); !why.empty()) {
      fail(why);
      break;
    }
    Event e;
    e.t = t;
    e.state_before = user(x_minus);
    e.state_after = user(xa);
    e.mode_after = ev.mode;
    e.impulse = ev.impulse;
    e.note = ev.note;
    if (ev.accumulation) {
      e.type = EventType::kAccumulation;
    } else if (ev.jumped) {
      e.type = EventType::kImpact;
    } else {
      bool gained = false, lost = false;
      for (int r : ev.mode)
        if (std::find(old_mode.begin(), old_mode.end(), r) == old_mode.end()) gained = true;
      for (int r : old_mode)
        if (std::find(ev.mode.begin(), ev.mode.end(), r) == ev.mode.end()) lost = true;
      e.type = lost && !gained ? EventType::kRelease : EventType::kContact;
      if (!gained && !lost) {
        // A graze or a re-selection of the same mode: not a mode change.
        if (keep) record(tr, t, xa, phase);
        continue;
      }
    }
    if (!keep) {
      if (tr.events_not_recorded++ == 0)
        tr.add_warning("more than " + std::to_string(opt_.max_recorded_events) +
                       " events: later events and their samples are counted, not recorded");
      continue;
    }
    tr.events.push_back(std::move(e));
    record(tr, t, xa, phase);
  }
  tr.final_state = user(xa);
  tr.energy_final = energy(xa);
  tr.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return tr;
}

}  // namespace

// The method on input that Integrator::run has checked (trajectory.cpp).
Trajectory integrate_event_driven(const mech::Model& model, const VectorXd& x0,
                                  const Options& opt) {
  const auto refuse = [&](const std::string& why) {
    Trajectory tr;
    tr.method = "event";
    tr.t_end = *opt.t_end;
    tr.status = RunStatus::kNumericalFailure;
    tr.message = why;
    tr.final_state = x0;
    return tr;
  };
  // The exact method is dense in the state: matrix exponentials of size n
  // (2N+1 for N coordinates) cost O(n^3) per evaluation. Refused before any
  // dense matrix is built.
  if (model.lcs_state_size() > mech::kMaxDenseLcsState)
    return refuse(
        "the exact event-driven method is dense in the state (matrix exponentials of size " +
        std::to_string(model.lcs_state_size()) + " > " + std::to_string(mech::kMaxDenseLcsState) +
        "); use a time-stepping method (--method moreau-jean) for models this large");
  if (const std::string bad = infeasible_start(model, x0); !bad.empty()) return refuse(bad);
  EventDriven ed(model, opt);
  return ed.run(x0);
}

}  // namespace lcsim::sim
