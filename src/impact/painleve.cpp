// Issue 27: deciding a Painlevé-type impact by enumerating the contacts'
// modes. The laws' test on the solved modes (friction.cpp,
// no_painleve_after_solve) is a sufficient condition: a normal matrix that
// is not a P-matrix in the modes the solution takes may still leave one
// motion. Here the planar Coulomb impact problem u = Wg lambda + b is solved
// in every combination of the contacts' modes (per frictional contact open,
// stick, slip+, slip-; per frictionless one open or closed), each a square
// linear system, and the motions found are counted.
#include <cmath>
#include <lcsim/core/format.hpp>

#include "impact/detail.hpp"

namespace lcsim::impact::detail {

namespace {

// Per normal j: 0 open, 1 closed (frictionless) or stick, 2 slip+ (u_T > 0,
// lambda_T = -mu lambda_N), 3 slip- (u_T < 0, lambda_T = +mu lambda_N).
using Modes = std::vector<int>;

const char* mode_name(int mode, bool frictional) {
  switch (mode) {
    case 0:
      return "open";
    case 1:
      return frictional ? "stick" : "closed";
    case 2:
      return "slip+";
    default:
      return "slip-";
  }
}

struct Problem {
  const MatrixXd& Wg;
  const VectorXd& b;
  Eigen::Index nj;
  std::vector<int> friction_of;  // per normal: its frictional row, or -1
  const VectorXd& mu;
};

// The mode's inequalities as rows F x + h >= 0 (detail::ModeInequalities)
// for a singular system: per normal open u_N >= 0; else lambda_N >= 0 and,
// sticking, mu lambda_N -+ lambda_T >= 0, slipping, sign u_T >= 0 (the
// tests of a regular system's solution in solve_modes, as rows).
ModeInequalities mode_rows(const Problem& p, const Modes& modes, const MatrixXd& P,
                           const MatrixXd& WP) {
  const Eigen::Index n = p.Wg.rows();
  ModeInequalities q{MatrixXd(0, P.cols()), VectorXd(0), {}};
  const MatrixXd zero = MatrixXd::Zero(1, n);
  for (Eigen::Index j = 0; j < p.nj; ++j) {
    const int mj = modes[static_cast<size_t>(j)], f = p.friction_of[static_cast<size_t>(j)];
    MatrixXd a = zero;
    a(0, j) = 1.0;
    q.add(mj == 0 ? a : zero, mj == 0 ? zero : a, P, WP, p.b, mj == 0);
    if (mj == 0 || f < 0) continue;
    for (const double sign : {1.0, -1.0}) {
      if (mj >= 2 && sign != (mj == 2 ? 1.0 : -1.0)) continue;
      MatrixXd r = zero;
      r(0, p.nj + f) = mj == 1 ? -sign : sign;
      if (mj == 1) r(0, j) = p.mu(f);
      q.add(mj == 1 ? zero : r, mj == 1 ? r : zero, P, WP, p.b, mj >= 2);
    }
  }
  return q;
}

// The motion of `modes`: a regular system's solution when its inequalities
// hold; a singular one (dependent rows: a box's four coplanar corners)
// judged by detail::solve_mode_system, as the cone's.
ModeOutcome solve_modes(const Problem& p, const Modes& modes, const VectorXd& lambda_law) {
  const Eigen::Index n = p.Wg.rows();
  MatrixXd P = MatrixXd::Zero(n, n);  // lambda = P x
  std::vector<Eigen::Index> rows;     // the equations u_row = 0
  for (Eigen::Index j = 0; j < p.nj; ++j) {
    const int mj = modes[static_cast<size_t>(j)], f = p.friction_of[static_cast<size_t>(j)];
    if (mj == 0) continue;
    const auto x = static_cast<Eigen::Index>(rows.size());
    P(j, x) = 1.0;
    if (mj >= 2) P(p.nj + f, x) = (mj == 2 ? -1.0 : 1.0) * p.mu(f);
    rows.push_back(j);
  }
  for (Eigen::Index j = 0; j < p.nj; ++j) {
    const int f = p.friction_of[static_cast<size_t>(j)];
    if (modes[static_cast<size_t>(j)] != 1 || f < 0) continue;
    P(p.nj + f, static_cast<Eigen::Index>(rows.size())) = 1.0;
    rows.push_back(p.nj + f);
  }
  const auto nx = static_cast<Eigen::Index>(rows.size());
  VectorXd x = VectorXd::Zero(nx);
  if (nx > 0) {
    const MatrixXd WP = p.Wg * P.leftCols(nx);
    MatrixXd A(nx, nx);
    VectorXd rhs(nx);
    for (Eigen::Index i = 0; i < nx; ++i) {
      A.row(i) = WP.row(rows[static_cast<size_t>(i)]);
      rhs(i) = -p.b(rows[static_cast<size_t>(i)]);
    }
    const Eigen::FullPivLU<MatrixXd> lu(A);
    if (!lu.isInvertible()) {
      const MatrixXd Px = P.leftCols(nx);
      return solve_mode_system(p.Wg, p.b, Px, A, rhs, mode_rows(p, modes, Px, WP), lambda_law);
    }
    x = lu.solve(rhs);
  }
  ModeOutcome out;
  out.lambda = P.leftCols(nx) * x;
  const VectorXd& lambda = out.lambda;
  const VectorXd u = p.Wg * lambda + p.b;
  // The mode's inequalities to 1e-9 of their terms (the impact's acceptance
  // of rates and impulses, detail::finish).
  const double tol_u =
      1e-9 * (1.0 + p.b.cwiseAbs().maxCoeff() + (p.Wg.cwiseAbs() * lambda.cwiseAbs()).maxCoeff());
  const double tol_l = 1e-9 * (1.0 + lambda.cwiseAbs().maxCoeff());
  for (Eigen::Index j = 0; j < p.nj; ++j) {
    const int mj = modes[static_cast<size_t>(j)], f = p.friction_of[static_cast<size_t>(j)];
    bool ok = true;
    if (mj == 0)
      ok = u(j) >= -tol_u;
    else if (mj == 1)
      ok = lambda(j) >= -tol_l &&
           (f < 0 || std::abs(lambda(p.nj + f)) <= p.mu(f) * lambda(j) + tol_l);
    else
      ok = lambda(j) >= -tol_l && (mj == 2 ? 1.0 : -1.0) * u(p.nj + f) >= -tol_u;
    if (!ok) return {};
  }
  out.kind = ModeOutcome::kMotion;
  return out;
}

std::string modes_text(const Problem& p, const Modes& modes,
                       const std::vector<std::string>& labels) {
  std::string s;
  for (Eigen::Index j = 0; j < p.nj; ++j)
    s += text(j > 0 ? " " : "", labels[static_cast<size_t>(j)], " (",
              mode_name(modes[static_cast<size_t>(j)], p.friction_of[static_cast<size_t>(j)] >= 0),
              ")");
  return s;
}

}  // namespace

PainleveVerdict decide_painleve_by_modes(const MatrixXd& Wg, const VectorXd& b, Eigen::Index nj,
                                         const std::vector<int>& normal_of, const VectorXd& mu,
                                         const VectorXd& lambda_law,
                                         const std::vector<std::string>& labels) {
  Problem p{Wg, b, nj, std::vector<int>(static_cast<size_t>(nj), -1), mu};
  long total = 1;
  for (size_t f = 0; f < normal_of.size(); ++f)
    p.friction_of[static_cast<size_t>(normal_of[f])] = static_cast<int>(f);
  for (Eigen::Index j = 0; j < nj && total <= kPainleveModeBound; ++j)
    total *= p.friction_of[static_cast<size_t>(j)] >= 0 ? 4 : 2;
  PainleveVerdict out;
  if (total > kPainleveModeBound) {
    out.message = text("the contacts' modes (", nj, " closed contacts, more than ",
                       kPainleveModeBound, " combinations) are above the enumeration's bound ",
                       kPainleveModeBound, ": not enumerated");
    return out;
  }
  out.enumerated = true;
  MotionTally tally{Wg, b, {}, {}};
  Modes modes(static_cast<size_t>(nj));
  for (long code = 0; code < total; ++code) {
    long c = code;
    for (Eigen::Index j = 0; j < nj; ++j) {
      const int base = p.friction_of[static_cast<size_t>(j)] >= 0 ? 4 : 2;
      modes[static_cast<size_t>(j)] = static_cast<int>(c % base);
      c /= base;
    }
    const auto text_of = [&] { return modes_text(p, modes, labels); };
    if (!tally.add(solve_modes(p, modes, lambda_law), text_of, out)) return out;
  }
  tally.decide(lambda_law, out);
  return out;
}

std::vector<std::string> closed_labels(const ImpactInput& in) {
  std::vector<std::string> labels;
  for (const int row : in.closed)
    labels.push_back(text(row, " ('", in.model->constraints[static_cast<size_t>(row)], "')"));
  return labels;
}

}  // namespace lcsim::impact::detail
