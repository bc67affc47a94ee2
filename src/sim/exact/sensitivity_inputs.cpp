// Forward sensitivities in an input's own parameters (docs/sensitivities.md,
// docs/inputs.md): a sine's amplitude, offset, frequency, damping and phase;
// a piecewise linear input's point values and times, its delay, and a
// pulse's levels, rise, width, fall and period.
//
// The input is the output l w of its exosystem w' = A_w w, re-initialised
// at its breakpoints to w(t_b) (mech::Input::exo_state). A parameter theta
// enters
// - A_w (frequency: dA_w(s, c) = 2 pi = -dA_w(c, s); damping: dA_w(s, s) =
//   dA_w(c, c) = -1) and l (amplitude: dl = (0, 1, 0)), so the augmented
//   LCS (A, B, C) moves by dA (its exosystem block, and for a force input
//   its v rows M^-1 gain dl) and dC (a moving stop's gain dl). In mode I a
//   mechanical model's rows all have leading index 2, so with R = C_I A^2 and
//   script M = C_I A B_I (= E_I M^-1 E_I'), F = -(script M)^-1 R and
//   dF = -(script M)^-1 (dR + d(script M) F), dR = dC_I A^2 + C_I (dA A +
//   A dA), d(script M) = dC_I A B_I + C_I dA B_I, dAcl = dA + B_I dF; a free
//   gap's monitor C_r moves by dC_r;
// - the exosystem's state: at t = 0 and at each breakpoint the rows of w
//   are the closed form's dw(t)/dtheta at fixed t (right limit). A parameter
//   that moves the breakpoint itself (a point's time, the delay, the period)
//   has dt_b/dtheta = dtau and the re-initialised state's total derivative
//   dw(t_b)/dtheta + w'+ dtau; q and v are continuous, so the saltation
//   S+ = J S- + (J x'- - x'+) dtau (J zero on w) is reached by setting the
//   rows of w of S- to dw/dtheta + (w'+ - w'-) dtau before the common
//   saltation (which adds (w'- - w'+) dtau back on those rows);
// - an impact on a moving stop: the law acts on E_A v + gdot_A with
//   gdot = C_w A_w w, whose derivative at fixed x is (dC A + C dA) x, so
//   dv+/dtheta = M^-1 E_A' Tc d(gdot_A) (Tc as in moving_stop_columns).
#include <cmath>
#include <numbers>

#include "sim/exact/sensitivity.hpp"

namespace lcsim::sim::detail {

namespace {

// A piecewise linear input's parameter as moves of its points: dv per
// point value, dt per point time, the origin (delay) and the period.
struct PlMove {
  VectorXd dv, dt;
  double origin = 0.0, period = 0.0;
};

PlMove pl_move(const mech::Input& in, const SensParam& p) {
  const Eigen::Index n = static_cast<Eigen::Index>(in.times.size());
  PlMove m{VectorXd::Zero(n), VectorXd::Zero(n)};
  const auto mark = [&](VectorXd& d, std::initializer_list<Eigen::Index> at) {
    for (Eigen::Index k : at)
      if (k < n) d(k) = 1.0;
  };
  switch (p.kind) {
    case 'v':
      m.dv(p.j) = 1.0;
      break;
    case 't':  // the point and those sharing its time (a jump moves as one)
      for (Eigen::Index k = 0; k < n; ++k)
        if (in.times[static_cast<size_t>(k)] == in.times[static_cast<size_t>(p.j)]) m.dt(k) = 1.0;
      break;
    case 'y':
      m.origin = 1.0;
      break;
    case 'T':
      m.period = 1.0;
      break;
    // A pulse's points (src/io/model_inputs.cpp): (0, v1), (rise, v2),
    // (rise + width, v2), (rise + width + fall, v1).
    case '1':
      mark(m.dv, {0, 3});
      break;
    case '2':
      mark(m.dv, {1, 2});
      break;
    case 'r':
      mark(m.dt, {1, 2, 3});
      break;
    case 'd':
      mark(m.dt, {2, 3});
      break;
    case 'l':
      mark(m.dt, {3});
      break;
    default:
      break;
  }
  return m;
}

// The piece of a piecewise linear input holding t (the right limit at a
// breakpoint): its point i (-1 before the first) and repetition k, as
// mech::Input's own search (src/mech/inputs.cpp) finds it, to the bit.
struct PieceAt {
  int i = -1;
  long k = 0;
  double start = -std::numeric_limits<double>::infinity();
};

PieceAt piece_at(const mech::Input& in, double t) {
  long k0 = 0, k1 = 0;
  if (in.period > 0.0) {
    const double kk = std::floor((t - in.origin) / in.period);
    k0 = std::max(0L, static_cast<long>(kk) - 1);
    k1 = std::max(0L, static_cast<long>(kk) + 2);
  }
  PieceAt p;
  for (long k = k0; k <= k1; ++k)
    for (size_t i = 0; i < in.times.size(); ++i) {
      if (in.period > 0.0 && !(in.times[i] < in.period)) continue;
      const double base =
          in.period > 0.0 ? in.origin + static_cast<double>(k) * in.period : in.origin;
      const double b = base + in.times[i];
      if (b <= t && b >= p.start) p = {static_cast<int>(i), k, b};
    }
  return p;
}

// d w(t) / dtheta at fixed t of a piecewise linear input, w = (value,
// slope) on the piece holding t; *dstart: the piece start's derivative.
Eigen::Vector2d pl_state_derivative(const mech::Input& in, const PlMove& mv, double t,
                                    double* dstart) {
  const PieceAt pc = piece_at(in, t);
  *dstart = 0.0;
  if (pc.i < 0) return {mv.dv(0), 0.0};
  const auto i = static_cast<size_t>(pc.i);
  const Eigen::Index ii = pc.i;
  double s = 0.0, ds = 0.0;
  if (i + 1 < in.times.size()) {
    const double span = in.times[i + 1] - in.times[i];
    if (span > 0.0) {
      s = (in.values[i + 1] - in.values[i]) / span;
      ds = (mv.dv(ii + 1) - mv.dv(ii)) / span - s * (mv.dt(ii + 1) - mv.dt(ii)) / span;
    }
  } else {
    s = in.period > 0.0 ? 0.0 : in.tail_slope;
  }
  *dstart = mv.origin + static_cast<double>(pc.k) * mv.period + mv.dt(ii);
  return {mv.dv(ii) + ds * (t - pc.start) - s * *dstart, ds};
}

// d w(t) / dtheta at fixed t of a sine, w = (o, e sin a, e cos a) with
// e = exp(-damping tau), a = 2 pi frequency tau + phase, tau = t - origin.
Eigen::Vector3d sine_state_derivative(const mech::Input& in, char kind, double t) {
  if (kind == 'o') return {1.0, 0.0, 0.0};
  const double tau = t - in.origin;
  if (tau < 0.0 || kind == 'a') return Eigen::Vector3d::Zero();
  const double e = std::exp(-in.damping * tau),
               a = 2.0 * std::numbers::pi * in.frequency * tau + in.phase;
  const double s = e * std::sin(a), c = e * std::cos(a);
  if (kind == 'p') return {0.0, c, -s};
  if (kind == 'y') {  // w depends on t - origin: -w'
    const double om = 2.0 * std::numbers::pi * in.frequency;
    return {0.0, in.damping * s - om * c, om * s + in.damping * c};
  }
  if (kind == 'w')
    return {0.0, 2.0 * std::numbers::pi * tau * c, -2.0 * std::numbers::pi * tau * s};
  return {0.0, -tau * s, -tau * c};  // 'z' damping
}

// The offset of input j's exosystem in the augmented state (q, v, 1, w).
int exo_offset(const mech::MechanicalModel& m, int j) {
  int at = 2 * m.dofs() + 1;
  for (int i = 0; i < j; ++i) at += m.inputs[static_cast<size_t>(i)].exo_size();
  return at;
}

// Whether input `in` has a breakpoint at exactly t (a piece or the sine
// starting there).
bool breakpoint_at(const mech::Input& in, double t) {
  if (in.sine) return in.origin > 0.0 && in.origin == t;
  return piece_at(in, t).start == t;
}

// The unit perturbation of the augmented LCS by an input's parameter: its
// exosystem block (frequency, damping) and output row (amplitude).
struct InputDelta {
  MatrixXd A, C;
};

InputDelta input_delta(const mech::MechanicalModel& m, const lcs::Lcs& sys, const SensParam& p) {
  InputDelta d{MatrixXd::Zero(sys.n(), sys.n()), MatrixXd::Zero(sys.k(), sys.n())};
  const mech::Input& in = m.inputs[static_cast<size_t>(p.i)];
  const int at = exo_offset(m, p.i), N = m.dofs();
  if (p.kind == 'w') {
    d.A(at + 1, at + 2) = 2.0 * std::numbers::pi;
    d.A(at + 2, at + 1) = -2.0 * std::numbers::pi;
  } else if (p.kind == 'z') {
    d.A(at + 1, at + 1) = d.A(at + 2, at + 2) = -1.0;
  } else if (p.kind == 'a' && in.sine) {
    const Eigen::LDLT<MatrixXd> Mf{MatrixXd(m.M)};
    for (const mech::InputUse& u : m.force_inputs)
      if (u.input == p.i) d.A.block(N, at + 1, N, 1) += Mf.solve(u.gain);
    for (const mech::InputUse& u : m.gap_inputs)
      if (u.input == p.i) d.C.col(at + 1) += u.gain;
  }
  return d;
}

}  // namespace

MatrixXd input_param_dA(const mech::MechanicalModel& m, const lcs::Lcs& sys, const SensParam& p) {
  return input_delta(m, sys, p).A;
}

bool input_param_kind(char kind) {
  return std::string_view("aowzpvty12drlT").find(kind) != std::string_view::npos;
}

void Sensitivity::input_mode_derivatives(size_t p, const lcs::IndexSet& mode) {
  const InputDelta d = input_delta(*model_.mechanical, sys_, cols_.params[p]);
  const Eigen::Index kI = static_cast<Eigen::Index>(mode.size());
  MatrixXd dF = MatrixXd::Zero(kI, n_), dAcl = d.A;
  if (kI > 0 && !(d.A.isZero(0.0) && d.C.isZero(0.0))) {
    MatrixXd CI(kI, n_), dCI(kI, n_), BI(n_, kI);
    for (Eigen::Index a = 0; a < kI; ++a) {
      CI.row(a) = sys_.C.row(mode[static_cast<size_t>(a)]);
      dCI.row(a) = d.C.row(mode[static_cast<size_t>(a)]);
      BI.col(a) = sys_.B.col(mode[static_cast<size_t>(a)]);
    }
    const MatrixXd CA = CI * sys_.A;
    const MatrixXd R = CA * sys_.A, Mc = CA * BI;
    const MatrixXd dR = dCI * sys_.A * sys_.A + CI * d.A * sys_.A + CA * d.A;
    const MatrixXd dMc = dCI * sys_.A * BI + CI * d.A * BI;
    const Eigen::PartialPivLU<MatrixXd> Mf(Mc);
    const MatrixXd F = -Mf.solve(R);
    dF = -Mf.solve(dR + dMc * F);
    dAcl += BI * dF;
  }
  dAb_[p] = D_.cwiseInverse().asDiagonal() * dAcl * D_.asDiagonal();
  dF_[p] = dF;
  MatrixXd dW = d.C;
  for (int r : mode) dW.row(r).setZero();  // the mode's rows: multiplier monitors (dF)
  dW_[p] = dW;
}

void Sensitivity::input_start(MatrixXd& S) {
  const mech::MechanicalModel& m = *model_.mechanical;
  for (size_t p = 0; p < cols_.params.size(); ++p) {
    const SensParam& sp = cols_.params[p];
    if (!input_param_kind(sp.kind)) continue;
    const mech::Input& in = m.inputs[static_cast<size_t>(sp.i)];
    const int at = exo_offset(m, sp.i), col = nx0_ + static_cast<int>(p);
    if (in.sine) {
      S.block(at, col, 3, 1) = sine_state_derivative(in, sp.kind, 0.0);
      // Its delay at 0 where the sine starts off its offset: see below.
      if (sp.kind == 'y' && in.origin == 0.0 && in.value(0.0) != in.offset)
        lose(0.0, -1,
             "input '" + in.name +
                 "' jumps at t = 0, its delay's breakpoint: only one-sided "
                 "derivatives exist in " +
                 sp.name,
             {col}, true);
      continue;
    }
    const PlMove mv = pl_move(in, sp);
    double dstart = 0.0;
    S.block(at, col, 2, 1) = pl_state_derivative(in, mv, 0.0, &dstart);
    // A breakpoint at t = 0 that moves with the parameter, where the input
    // jumps (two points at t = 0 of different values): moved later, the run
    // holds the value before the jump for a while, so only one-sided
    // derivatives exist. Without a jump the value moves by O(h) over O(h).
    const PieceAt pc = piece_at(in, 0.0);
    if (pc.start == 0.0 && dstart != 0.0 && in.value(0.0) != in.values.front())
      lose(0.0, -1,
           "input '" + in.name + "' jumps at a breakpoint at t = 0 that moves with " + sp.name +
               ": only one-sided derivatives exist",
           {col}, true);
  }
}

void Sensitivity::reset_exosystem(int rows) {
  if (!mech_) {  // a general LCS's inputs: functions of t alone
    S_minus_.bottomRows(rows).setZero();
    return;
  }
  const mech::MechanicalModel& m = *model_.mechanical;
  S_minus_.bottomRows(rows).setZero();
  const double tb = event_t_;
  const VectorXd w_plus = mech::exosystem_states(m.inputs, tb);
  const MatrixXd Aw = sys_.A.bottomRightCorner(rows, rows);
  const VectorXd wdot_jump = Aw * w_plus - xdot_minus_.tail(rows);  // w'+ - w'-
  for (size_t p = 0; p < cols_.params.size(); ++p) {
    const SensParam& sp = cols_.params[p];
    const int col = nx0_ + static_cast<int>(p);
    if (!input_param_kind(sp.kind) || !exists_[static_cast<size_t>(col)]) continue;
    const mech::Input& in = m.inputs[static_cast<size_t>(sp.i)];
    const int at = exo_offset(m, sp.i), w0 = n_ - rows;
    double dtau = 0.0;
    if (in.sine) {
      S_minus_.block(at, col, 3, 1) = sine_state_derivative(in, sp.kind, tb);
      if (sp.kind == 'y' && in.origin == tb) dtau = 1.0;  // the delay's breakpoint
    } else {
      const PlMove mv = pl_move(in, sp);
      double dstart = 0.0;
      S_minus_.block(at, col, 2, 1) = pl_state_derivative(in, mv, tb, &dstart);
      if (piece_at(in, tb).start == tb) dtau = dstart;  // this breakpoint moves
    }
    if (dtau == 0.0) continue;
    // Another input's breakpoint at the same time does not move with it:
    // the two events part on either side (one-sided derivatives).
    bool alone = true;
    for (size_t j = 0; j < m.inputs.size() && alone; ++j)
      if (static_cast<int>(j) != sp.i && breakpoint_at(m.inputs[j], tb)) {
        lose(tb, -1,
             "input '" + in.name + "' has a breakpoint moving with " + sp.name +
                 " at the time of input '" + m.inputs[j].name +
                 "''s: coinciding breakpoints, only one-sided derivatives exist",
             {col}, true);
        alone = false;
      }
    if (!alone) continue;
    S_minus_.block(w0, col, rows, 1) += wdot_jump * dtau;
    dtau_(col) = dtau;
  }
}

VectorXd Sensitivity::input_impact_dv(size_t p, const std::vector<int>& A, const MatrixXd& EA,
                                      const Eigen::LDLT<MatrixXd>& Wf,
                                      const VectorXd& one_e) const {
  const InputDelta d = input_delta(*model_.mechanical, sys_, cols_.params[p]);
  const VectorXd dgdot = (d.C * sys_.A + sys_.C * d.A) * x_minus_;
  const int a = static_cast<int>(A.size());
  VectorXd dA(a);
  for (int i = 0; i < a; ++i) dA(i) = dgdot(A[static_cast<size_t>(i)]);
  const VectorXd dmu = law_ == 'r' ? VectorXd(Wf.solve(-one_e.cwiseProduct(dA)))
                                   : VectorXd(-one_e.cwiseProduct(Wf.solve(dA)));
  return G_ * EA.transpose() * dmu;
}

}  // namespace lcsim::sim::detail
