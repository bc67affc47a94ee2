// Stick / slip selection at an event of the event-driven method (issue 17).
// After the normal mode I is selected, each frictional contact in I slides
// (its sliding velocity t'v - velocity is nonzero: slip in that direction,
// which is also what an impact's outcome slip+/slip- leaves) or not (zero to
// rounding, or the impact's outcome stick). The contacts that do not slide
// get their mode from the acceleration-level friction LCP (the relay LCP
// (4.44) of thesis §4.6.2; the structure of impact::friction_lcp with
// W = G M^{-1} G' and the free accelerations as rates, the slipping
// contacts entering with their fixed force columns E_i - sigma mu t_i):
// stick where the stick force is inside the cone, else slip the way the
// tangential acceleration drives. The choice is then checked on the phase
// itself: each of its friction monitors must start positive or leave zero
// upwards (its first nonzero derivative), which also settles the degenerate
// points (the stick force exactly on the cone's edge) as the LDCP does for
// the normals; the other combinations are tried when it fails.
#include <algorithm>
#include <cmath>
#include <lcsim/impact/impact.hpp>
#include <sstream>

#include "sim/exact/event_driven_detail.hpp"

namespace lcsim::sim::detail {

namespace {

constexpr FrictionMode kCandidates[] = {FrictionMode::kStick, FrictionMode::kSlipPositive,
                                        FrictionMode::kSlipNegative};
// Combinations tried when the LCP's choice is not consistent: 3^8 phases.
constexpr size_t kMaxEnumerated = 8;

}  // namespace

// The frictional contacts of `mode` that do not slide (entries of
// mechanical.friction); fm gets slip+/slip- for those that do, open for
// those outside the mode.
std::vector<int> EventDriven::zero_sliding(const lcs::IndexSet& mode, const VectorXd& xa,
                                           std::vector<FrictionMode>& fm) const {
  const mech::MechanicalModel& m = *model_.mechanical;
  const VectorXd q = xa.head(N_), v = xa.segment(N_, N_);
  std::vector<int> zero;
  fm.assign(m.friction.size(), FrictionMode::kOpen);
  for (size_t f = 0; f < m.friction.size(); ++f) {
    const mech::FrictionalContact& fc = m.friction[f];
    if (std::find(mode.begin(), mode.end(), fc.contact) == mode.end()) continue;
    const double s = fc.sliding(v);
    // Zero as a normal rate is in process_mechanical: the rounding of its
    // terms, and of the state through the fastest frequency.
    const double noise = 64.0 * kEps * fc.tangent.cwiseAbs().sum() *
                         (v.cwiseAbs().maxCoeff() + rho_A_ * q.cwiseAbs().maxCoeff());
    const double tol = mech::zero_tolerance(
                           fc.tangent.cwiseAbs().dot(v.cwiseAbs()) + std::abs(fc.velocity), ldcp_) +
                       noise;
    if (std::abs(s) <= tol ||
        outcome_[static_cast<size_t>(fc.contact)] == impact::ContactOutcome::kStick) {
      zero.push_back(static_cast<int>(f));
      fm[f] = FrictionMode::kStick;
    } else {
      fm[f] = s > 0.0 ? FrictionMode::kSlipPositive : FrictionMode::kSlipNegative;
    }
  }
  return zero;
}

// Sets the sliding velocities of `zero` exactly to zero (t'v = the belt's
// velocity), keeping E_I v = 0: project_rows (cone_modes.cpp) on their
// tangent rows (they are zero up to the state's rounding, or to the impact
// law's stick tolerance).
void EventDriven::project_sliding(const lcs::IndexSet& mode, const std::vector<int>& zero,
                                  VectorXd& xa) const {
  const mech::MechanicalModel& m = *model_.mechanical;
  std::vector<RowVectorXd> rows;
  std::vector<double> target;
  for (const int f : zero) {
    const mech::FrictionalContact& fc = m.friction[static_cast<size_t>(f)];
    rows.push_back(RowVectorXd(fc.tangent.transpose()));
    target.push_back(fc.velocity);
  }
  project_rows(mode, rows, target, xa);
}

// The acceleration-level friction LCP over the normals of `mode` and the
// contacts `zero`, with `fixed` giving the slipping contacts' directions:
// the modes it selects for `zero` (others as in `fixed`), or `fixed` with
// stick for `zero` when it has no solution.
std::vector<FrictionMode> EventDriven::friction_lcp_modes(const lcs::IndexSet& mode,
                                                          const std::vector<FrictionMode>& fixed,
                                                          const std::vector<int>& zero,
                                                          const VectorXd& xa, long& solves) const {
  const mech::MechanicalModel& m = *model_.mechanical;
  const Eigen::Index nn = static_cast<Eigen::Index>(mode.size());
  const Eigen::Index nz = static_cast<Eigen::Index>(zero.size());
  MatrixXd H(nn + nz, N_), G(nn + nz, N_);
  std::vector<int> normal_of(zero.size());
  VectorXd mu(nz);
  for (Eigen::Index i = 0; i < nn; ++i) H.row(i) = m.E.row(mode[static_cast<size_t>(i)]);
  G.topRows(nn) = H.topRows(nn);
  for (size_t f = 0; f < fixed.size(); ++f) {
    if (fixed[f] == FrictionMode::kOpen || fixed[f] == FrictionMode::kStick) continue;
    const auto it = std::find(mode.begin(), mode.end(), m.friction[f].contact);
    const double sigma = fixed[f] == FrictionMode::kSlipPositive ? 1.0 : -1.0;
    G.row(it - mode.begin()) -= sigma * m.friction[f].mu * m.friction[f].tangent.transpose();
  }
  for (Eigen::Index z = 0; z < nz; ++z) {
    const mech::FrictionalContact& fc = m.friction[static_cast<size_t>(zero[z])];
    H.row(nn + z) = G.row(nn + z) = fc.tangent.transpose();
    normal_of[z] = static_cast<int>(std::find(mode.begin(), mode.end(), fc.contact) - mode.begin());
    mu(z) = fc.mu;
  }
  const VectorXd rates = H * (sys_.A.middleRows(N_, N_) * xa);  // free accelerations
  const impact::FrictionLcp p = impact::friction_lcp(H * Minv_ * G.transpose(), rates.head(nn),
                                                     rates.tail(nz), normal_of, mu);
  int lcp_solves = 0;
  const lcp::Result res = impact::solve_friction_lcp(p, *solver_, &lcp_solves, nullptr);
  solves += lcp_solves;
  std::vector<FrictionMode> fm = fixed;
  if (!res.ok()) return fm;
  const VectorXd w = p.M * res.z + p.q;
  const VectorXd w_scale = p.M.cwiseAbs() * res.z.cwiseAbs() + p.q.cwiseAbs();
  for (Eigen::Index z = 0; z < nz; ++z) {
    // Sliding acceleration t'v' = w_T - xi; zero to the rounding of its terms.
    const double a = w(nn + z) - res.z(nn + nz + z);
    const double tol = mech::zero_tolerance(w_scale(nn + z) + std::abs(res.z(nn + nz + z)), ldcp_);
    FrictionMode& mode_z = fm[static_cast<size_t>(zero[z])];
    mode_z = a > tol ? FrictionMode::kSlipPositive
                     : (a < -tol ? FrictionMode::kSlipNegative : FrictionMode::kStick);
  }
  return fm;
}

// True if every friction monitor of `ph` starts positive, or at zero and
// leaves it upwards (or stays at zero identically).
bool EventDriven::consistent(const Phase& ph, const VectorXd& xa, double t) const {
  const MonitorStart& st = selection_start(ph, xa, t);
  for (size_t j = 0; j < ph.monitors.size(); ++j) {
    if (ph.monitors[j].friction < 0) continue;
    if (st.m0[j] >= 0 && !(st.d0[j] > 0.0)) return false;
  }
  return true;
}

// Selects out.friction for out.mode at state xa (sliding velocities that
// vanish set exactly to zero). "" or the failure message.
std::string EventDriven::select_friction(double t, const lcs::IndexSet& undetermined, VectorXd& xa,
                                         EventResult& out) {
  if (has_cone_) return select_cone_friction(t, undetermined, xa, out);  // cone_modes.cpp
  std::vector<FrictionMode> fixed;
  const std::vector<int> zero = zero_sliding(out.mode, xa, fixed);
  out.friction = fixed;
  if (zero.empty()) return "";
  project_sliding(out.mode, zero, xa);
  const std::vector<FrictionMode> first =
      friction_lcp_modes(out.mode, fixed, zero, xa, out.lcp_solves);
  std::string err, painleve;
  auto accept = [&](const std::vector<FrictionMode>& fm) {
    err.clear();
    const Phase& ph = make_phase(out.mode, fm, undetermined, xa, err);
    if (!err.empty()) {
      if (painleve.empty() && err.find("Painlev") != std::string::npos) painleve = err;
      return false;
    }
    return consistent(ph, xa, t);
  };
  if (accept(first)) {
    out.friction = first;
    return "";
  }
  if (zero.size() <= kMaxEnumerated) {
    std::vector<FrictionMode> fm = fixed;
    for (long code = 0, n = std::lround(std::pow(3.0, static_cast<double>(zero.size()))); code < n;
         ++code) {
      long c = code;
      for (int f : zero) {
        fm[static_cast<size_t>(f)] = kCandidates[c % 3];
        c /= 3;
      }
      if (fm != first && accept(fm)) {
        out.friction = fm;
        return "";
      }
    }
  }
  if (!painleve.empty()) return painleve;
  std::ostringstream msg;
  msg << "stick / slip selection at t = " << t << ": no mode of the contacts";
  for (int f : zero)
    msg << " '"
        << model_.mechanical
               ->constraints[static_cast<size_t>(friction_contacts_[static_cast<size_t>(f)])]
        << "'";
  msg << " is consistent (each of stick, slip+, slip- leaves a friction monitor negative)";
  return msg.str();
}

// The LDCP selects the normal mode without friction: with redundant
// contacts (a box flat on four corners) it keeps an independent subset I
// (two diagonal corners) and leaves the others undetermined (K: gap and
// force identically zero in the frictionless phase, so not monitored). With
// friction that is no longer so: the friction forces' moment about I turns
// the body, and a corner of K is pressed into the floor unseen. So when the
// phase selected on I presses a constraint of K shut (its gap's first
// nonzero derivative negative), or no friction mode on I is consistent, the
// modes are selected again on I ∪ K (the redundant normals held together,
// their forces' resultant determined: friction_feedback), and that choice is
// taken when every one of its monitors, normal forces included, starts
// consistently. Otherwise the selection on I stands (as before).
std::string EventDriven::select_friction_and_normals(double t, const lcs::ModeSelection& sel,
                                                     const lcs::IndexSet& held, VectorXd& xa,
                                                     EventResult& out,
                                                     lcs::IndexSet& undetermined) {
  if (sel.undetermined.empty()) return select_friction_releasing(t, sel, xa, out, undetermined);
  const auto in_held = [&](int r) { return std::find(held.begin(), held.end(), r) != held.end(); };
  // I ∪ K: taken when its friction modes are selected and every monitor of
  // its phase starts consistently.
  const auto try_union = [&]() {
    EventResult all = out;
    all.mode = sel.mode;
    all.mode.insert(all.mode.end(), sel.undetermined.begin(), sel.undetermined.end());
    std::sort(all.mode.begin(), all.mode.end());
    VectorXd x2 = xa;
    const bool selected = select_friction(t, {}, x2, all).empty();
    out.lcp_solves = all.lcp_solves;  // counted whether taken or not
    if (!selected) return false;
    std::string err;
    const Phase& ph = make_phase(all.mode, all.friction, {}, x2, err);
    if (!err.empty() || !all_consistent(ph, x2, t)) return false;
    out.mode = all.mode;
    out.friction = all.friction;
    undetermined.clear();
    xa = x2;
    return true;
  };
  // The ending phase held them all (the box sliding on its four corners
  // comes to rest): keep holding them if that is consistent, so the event
  // is the friction change it is, not a release of corners that stay shut.
  if (std::all_of(sel.mode.begin(), sel.mode.end(), in_held) &&
      std::all_of(sel.undetermined.begin(), sel.undetermined.end(), in_held) && try_union())
    return "";
  VectorXd x1 = xa;
  const std::string why = select_friction(t, sel.undetermined, x1, out);
  // Only a slip's friction, fixed by mu, can press K shut: sticking forces
  // are the held rows' multipliers, which balance the body on I.
  const bool slips = std::any_of(out.friction.begin(), out.friction.end(), [](FrictionMode f) {
    return f != FrictionMode::kOpen && f != FrictionMode::kStick;
  });
  if (why.empty() && !slips) {
    xa = x1;
    return "";
  }
  lcs::IndexSet lifting;  // constraints of I whose force leaves zero downwards
  if (why.empty()) {
    std::string err;
    const Phase& ph = make_phase(out.mode, out.friction, sel.undetermined, x1, err);
    if (err.empty()) lifting = lifting_normals(ph, x1, t);
    if (err.empty() && !presses_shut(ph, sel.undetermined, x1, t)) {
      if (lifting.empty()) {
        xa = x1;
        return "";
      }
    }
  }
  if (try_union()) return "";
  if (release_normal(t, sel, lifting, xa, out, undetermined)) return "";
  xa = x1;
  return why;
}

// No undetermined constraint: the friction modes on the LDCP's mode; when a
// slip's friction unloads a normal force that starts at zero, the phase
// would end at once and the same selection follow again, so that constraint
// is released (release_normal) when the phase without it starts
// consistently.
std::string EventDriven::select_friction_releasing(double t, const lcs::ModeSelection& sel,
                                                   VectorXd& xa, EventResult& out,
                                                   lcs::IndexSet& undetermined) {
  if (std::string why = select_friction(t, sel.undetermined, xa, out); !why.empty()) return why;
  if (std::none_of(out.friction.begin(), out.friction.end(), [](FrictionMode f) {
        return f != FrictionMode::kOpen && f != FrictionMode::kStick;
      }))
    return "";
  std::string err;
  const Phase& ph = make_phase(out.mode, out.friction, sel.undetermined, xa, err);
  if (!err.empty()) return "";
  const lcs::IndexSet lifting = lifting_normals(ph, xa, t);
  if (!lifting.empty()) (void)release_normal(t, sel, lifting, xa, out, undetermined);
  return "";
}

// The constraints of ph.mode whose normal force starts at zero and leaves it
// downwards: a slip's friction (fixed by mu, not seen by the frictionless
// LDCP) unloads them, so the phase on I would end at once, and the same
// selection would follow again (the quadruped landing on three independent
// feet, one of them slipping).
lcs::IndexSet EventDriven::lifting_normals(const Phase& ph, const VectorXd& xa, double t) const {
  const MonitorStart& st = selection_start(ph, xa, t);
  lcs::IndexSet out;
  for (size_t j = 0; j < ph.monitors.size(); ++j) {
    const Monitor& mon = ph.monitors[j];
    if (mon.friction >= 0 || !mon.multiplier) continue;
    if (st.m0[j] >= 0 && !(st.d0[j] > 0.0)) out.push_back(mon.constraint);
  }
  return out;
}

// I ∪ K without one constraint j of `lifting` (it leaves: its gap is
// monitored); failing that, the same with j shut without force,
// undetermined, when its row of E lies in the span of the others' (its gap
// is then identically zero: the quadruped's hind foot unloaded while the
// fourth, dependent foot takes the load). Taken when its normal rows are
// independent, its friction modes are selected and every monitor of its
// phase starts consistently: the first such candidate in the order of
// `lifting`; false when none is. `undetermined` is the taken candidate's.
// (I without j, K opened too, was tried and left out: it let the quadruped
// of tests/scene/test_exact_box_friction.cpp rock onto a diagonal and meet
// a Painlevé-type landing later.)
bool EventDriven::release_normal(double t, const lcs::ModeSelection& sel,
                                 const lcs::IndexSet& lifting, VectorXd& xa, EventResult& out,
                                 lcs::IndexSet& undetermined) {
  const int n = static_cast<int>(lifting.size());
  for (int c = 0; c < 2 * n; ++c) {
    const int j = lifting[static_cast<size_t>(c % n)];
    const bool keep_j = c >= n;  // j shut without force, undetermined
    EventResult cand = out;
    cand.mode.clear();
    for (const lcs::IndexSet* part : {&sel.mode, &sel.undetermined})
      for (const int r : *part)
        if (r != j) cand.mode.push_back(r);
    std::sort(cand.mode.begin(), cand.mode.end());
    if (keep_j && !spans_row(cand.mode, j)) continue;
    const lcs::IndexSet und = keep_j ? lcs::IndexSet{j} : lcs::IndexSet{};
    VectorXd x2 = xa;
    const bool selected = select_friction(t, und, x2, cand).empty();
    out.lcp_solves = cand.lcp_solves;  // counted whether taken or not
    if (!selected) continue;
    std::string err;
    const Phase& ph = make_phase(cand.mode, cand.friction, und, x2, err);
    if (!err.empty() || redundant_normals(ph) || !all_consistent(ph, x2, t)) continue;
    out.mode = cand.mode;
    out.friction = cand.friction;
    undetermined = und;
    xa = x2;
    return true;
  }
  return false;
}

// Whether row j of E lies in the span of the rows `mode` (rank unchanged).
bool EventDriven::spans_row(const lcs::IndexSet& mode, int j) const {
  const Eigen::Index nI = static_cast<Eigen::Index>(mode.size());
  MatrixXd EI(nI + 1, N_);
  for (Eigen::Index i = 0; i < nI; ++i)
    EI.row(i) = model_.mechanical->E.row(mode[static_cast<size_t>(i)]);
  EI.row(nI) = model_.mechanical->E.row(j);
  return Eigen::FullPivLU<MatrixXd>(EI).rank() == Eigen::FullPivLU<MatrixXd>(EI.topRows(nI)).rank();
}

bool EventDriven::presses_shut(const Phase& ph, const lcs::IndexSet& which, const VectorXd& xa,
                               double t) const {
  // The gaps of `which` as monitors over ph's state (each monitor's start is
  // its own: ph's need not be started again).
  std::vector<Monitor> gaps;
  for (const int r : which) {
    Monitor mon;
    mon.constraint = r;
    mon.multiplier = false;
    RowVectorXd w = sys_.C.row(r);
    for (size_t i = 0; i < ph.mode.size(); ++i) w += sys_.D(r, ph.mode[i]) * ph.F.row(i);
    mon.w = w.cwiseProduct(ph.D.transpose());
    mon.wA = ph.row_times(mon.w);
    gaps.push_back(std::move(mon));
  }
  const MonitorStart st = monitor_start(ph, xa.cwiseQuotient(ph.D), t, 1.0, &gaps);
  for (size_t j = 0; j < gaps.size(); ++j)
    if (st.m0[j] >= 0 && !(st.d0[j] > 0.0)) return true;
  return false;
}

bool EventDriven::all_consistent(const Phase& ph, const VectorXd& xa, double t) const {
  const MonitorStart& st = selection_start(ph, xa, t);
  for (size_t j = 0; j < ph.monitors.size(); ++j)
    if (st.m0[j] >= 0 && !(st.d0[j] > 0.0)) return false;
  return true;
}

bool EventDriven::redundant_normals(const Phase& ph) const {
  const Eigen::Index nI = static_cast<Eigen::Index>(ph.mode.size());
  MatrixXd EI(nI, N_);
  for (Eigen::Index i = 0; i < nI; ++i)
    EI.row(i) = model_.mechanical->E.row(ph.mode[static_cast<size_t>(i)]);
  return Eigen::FullPivLU<MatrixXd>(EI).rank() < nI;
}

}  // namespace lcsim::sim::detail
