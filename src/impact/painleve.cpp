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

// The impulse of `modes`, or nullopt when its inequalities fail; `singular`
// set when its system is singular (not solved).
std::optional<VectorXd> solve_modes(const Problem& p, const Modes& modes, bool& singular) {
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
  singular = false;
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
      singular = true;
      return std::nullopt;
    }
    x = lu.solve(rhs);
  }
  const VectorXd lambda = P.leftCols(nx) * x, u = p.Wg * lambda + p.b;
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
    if (!ok) return std::nullopt;
  }
  return lambda;
}

// Equal motions: Wg (a - b) zero to 1e-8 of its terms. Wg = G M^-1 G' is
// positive semidefinite, so Wg d = 0 is G' d = 0: the same velocity after.
bool same_motion(const Problem& p, const VectorXd& a, const VectorXd& c) {
  return (p.Wg * (a - c)).cwiseAbs().maxCoeff() <=
         1e-8 * (1.0 + p.b.cwiseAbs().maxCoeff() +
                 (p.Wg.cwiseAbs() * (a.cwiseAbs() + c.cwiseAbs())).maxCoeff());
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
  std::vector<VectorXd> motions;
  std::vector<Modes> modes_of;
  Modes modes(static_cast<size_t>(nj));
  for (long code = 0; code < total; ++code) {
    long c = code;
    for (Eigen::Index j = 0; j < nj; ++j) {
      const int base = p.friction_of[static_cast<size_t>(j)] >= 0 ? 4 : 2;
      modes[static_cast<size_t>(j)] = static_cast<int>(c % base);
      c /= base;
    }
    bool singular = false;
    const std::optional<VectorXd> lambda = solve_modes(p, modes, singular);
    if (singular) {
      out.message = text("the system of the modes ", modes_text(p, modes, labels),
                         " is singular (it may hold a continuum of motions)");
      return out;
    }
    if (!lambda) continue;
    bool seen = false;
    for (const VectorXd& o : motions) seen = seen || same_motion(p, *lambda, o);
    if (seen) continue;
    motions.push_back(*lambda);
    modes_of.push_back(modes);
  }
  if (motions.size() == 1 && same_motion(p, motions[0], lambda_law)) {
    out.unique = true;
    return out;
  }
  if (motions.empty()) {
    out.message = "the contacts' modes' enumeration finds no motion (the solution fits none)";
  } else if (motions.size() == 1) {
    out.message = text("the impact has two motions: the modes ", modes_text(p, modes_of[0], labels),
                       " and the LCP's solution");
  } else {
    out.message = text("the impact has ", motions.size(), " motions: the modes ",
                       modes_text(p, modes_of[0], labels), " and the modes ",
                       modes_text(p, modes_of[1], labels));
  }
  return out;
}

std::vector<std::string> closed_labels(const ImpactInput& in) {
  std::vector<std::string> labels;
  for (const int row : in.closed)
    labels.push_back(text(row, " ('", in.model->constraints[static_cast<size_t>(row)], "')"));
  return labels;
}

}  // namespace lcsim::impact::detail
