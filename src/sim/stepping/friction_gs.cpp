// Block Gauss–Seidel for Moreau–Jean's planar Coulomb step problem (see
// friction_gs.hpp).
#include "sim/stepping/friction_gs.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace lcsim::sim::detail {

bool local_coulomb(double Wnn, double Wnt, double Wtt, double rn, double rt, double mu, double& ln,
                   double& lt) {
  ln = lt = 0.0;
  if (rn >= 0.0) return true;  // separation (or resting without load)
  const double det = Wnn * Wtt - Wnt * Wnt;
  double s_first = 1.0;  // slip direction to try first: opposite the stick force
  if (det > 0.0) {
    const double sn = (-rn * Wtt + rt * Wnt) / det, st = (-rt * Wnn + rn * Wnt) / det;
    if (sn >= 0.0 && std::abs(st) <= mu * sn) {
      ln = sn;
      lt = st;
      return true;
    }
    s_first = st > 0.0 ? -1.0 : 1.0;
  }
  // Slip s (sign of u_T): lt = -s mu ln and u_N = 0. The first direction is
  // the one the stick force left the cone by; it is accepted with u_T of
  // the wrong sign only by rounding, when the other does not hold either.
  double fallback_n = -1.0;
  for (const double s : {s_first, -s_first}) {
    const double d = Wnn - s * mu * Wnt;
    if (!(d > 0.0)) continue;
    const double n = -rn / d, t = -s * mu * n;
    if (s * (Wnt * n + Wtt * t + rt) >= 0.0) {
      ln = n;
      lt = t;
      return true;
    }
    if (s == s_first) fallback_n = n;
  }
  if (fallback_n < 0.0) return false;
  ln = fallback_n;
  lt = -s_first * mu * fallback_n;
  return true;
}

double friction_residual(const FrictionGsProblem& p, const VectorXd& lambda, const VectorXd& u) {
  double res = 0.0;
  const std::vector<int>& tan = *p.tangent_of;
  for (int a = 0; a < p.n_normal; ++a) {
    res = std::max(res, std::abs(std::min(lambda(a), u(a))));
    const int t = tan[static_cast<size_t>(a)];
    if (t < 0) continue;
    const double mu = (*p.mu)(t - p.n_normal), lr = lambda(t) + mu * lambda(a);
    const double xi = std::max(0.0, -u(t));
    res = std::max(res, std::abs(std::min(lr, u(t) + xi)));
    res = std::max(res, std::abs(std::min(xi, mu * lambda(a) - lambda(t))));
  }
  return res;
}

FrictionGsResult solve_friction_gs(const FrictionGsProblem& p, double tolerance, int max_sweeps,
                                   VectorXd& lambda, VectorXd& u) {
  const SparseRow& W = *p.W;
  const VectorXd& b = *p.b;
  const std::vector<int>& tan = *p.tangent_of;
  FrictionGsResult r;
  const double acceptance = tolerance * (1.0 + (b.size() ? b.cwiseAbs().maxCoeff() : 0.0));
  // Row a of W lambda + b without the entries in columns a and t; the
  // entries there are returned.
  auto rest = [&](int row, int a, int t, double& waa, double& wat) {
    double s = b(row);
    waa = wat = 0.0;
    for (SparseRow::InnerIterator it(W, row); it; ++it) {
      const int c = static_cast<int>(it.col());
      if (c == a)
        waa = it.value();
      else if (c == t)
        wat = it.value();
      else
        s += it.value() * lambda(c);
    }
    return s;
  };
  for (r.sweeps = 1; r.sweeps <= max_sweeps; ++r.sweeps) {
    double change = 0.0;
    for (int a = 0; a < p.n_normal; ++a) {
      const int t = tan[static_cast<size_t>(a)];
      double Wnn, Wnt, Wtt, Wtn;
      const double rn = rest(a, a, t, Wnn, Wnt);
      if (!(Wnn > 0.0)) {
        r.message = "W(" + std::to_string(a) + "," + std::to_string(a) + ") is not positive";
        return r;
      }
      if (t < 0) {
        const double ln = std::max(0.0, -rn / Wnn);
        change = std::max(change, Wnn * std::abs(ln - lambda(a)));
        lambda(a) = ln;
        continue;
      }
      const double rt = rest(t, t, a, Wtt, Wtn);
      double ln, lt;
      if (!local_coulomb(Wnn, Wnt, Wtt, rn, rt, (*p.mu)(t - p.n_normal), ln, lt)) {
        r.message =
            "Painlevé-type contact at normal row " + std::to_string(a) + ": W_NN - mu |W_NT| <= 0";
        return r;
      }
      change = std::max(change,
                        std::max(Wnn * std::abs(ln - lambda(a)), Wtt * std::abs(lt - lambda(t))));
      lambda(a) = ln;
      lambda(t) = lt;
    }
    if (change > acceptance && r.sweeps < max_sweeps) continue;
    u = b;
    for (Eigen::Index i = 0; i < W.rows(); ++i)
      for (SparseRow::InnerIterator it(W, i); it; ++it) u(i) += it.value() * lambda(it.col());
    r.residual = friction_residual(p, lambda, u);
    if (r.residual <= acceptance) {
      r.status = lcp::Status::kSolved;
      return r;
    }
  }
  r.sweeps = max_sweeps;
  r.status = lcp::Status::kIterationLimit;
  r.message = "no convergence in " + std::to_string(max_sweeps) + " sweeps";
  return r;
}

}  // namespace lcsim::sim::detail
