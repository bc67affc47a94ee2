// Block Gauss–Seidel for Moreau–Jean's step with 3-D Coulomb friction on
// the polyhedral cone (see cone_gs.hpp).
#include "sim/stepping/cone_gs.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <lcsim/impact/impact.hpp>
#include <limits>
#include <string>

#include "sim/stepping/friction_gs.hpp"

namespace lcsim::sim::detail {
namespace {

constexpr double kHolds = 1e-12;  // a facet's conditions hold to this relative violation
constexpr double kPi = 3.14159265358979323846;

// i modulo n in [0, n): one addition for the neighbours of an index in
// range (every caller's case), the division only beyond (perf: the two
// divisions per call were a tenth of the residual).
int wrap_index(int i, int n) {
  if (i >= 0 && i < n) return i;
  if (i < 0 && i >= -n) return i + n;
  if (i >= n && i < 2 * n) return i - n;
  return ((i % n) + n) % n;
}

// The polygon P_d: its vertices D_i (impact::cone_edge, exact on the axes)
// and the outward normals n_i of its faces (between D_i and D_i+1).
struct Polygon {
  int d = 0;
  std::vector<double> c, s, nc, ns;
  double inradius = 1.0;  // cos(pi/(2d))
  explicit Polygon(int edges) : d(edges) {
    for (int i = 0; i < 2 * d; ++i) {
      const auto [ci, si] = impact::cone_edge(i, d);
      c.push_back(ci);
      s.push_back(si);
      const double a = kPi * (i + 0.5) / d;
      nc.push_back(std::cos(a));
      ns.push_back(std::sin(a));
    }
    inradius = std::cos(kPi / (2.0 * d));
  }
  int wrap(int i) const { return wrap_index(i, 2 * d); }
  // The least t with p in t P_d.
  double gauge(double p1, double p2) const {
    double g = 0.0;
    for (int i = 0; i < 2 * d; ++i) g = std::max(g, p1 * nc[i] + p2 * ns[i]);
    return g / inradius;
  }
  // The vertex nearest the direction of p (0 for p = 0).
  int nearest_vertex(double p1, double p2) const {
    if (p1 == 0.0 && p2 == 0.0) return 0;
    return wrap(static_cast<int>(std::lround(std::atan2(p2, p1) * d / kPi)));
  }
};

// One contact's local problem: u = Wl x + r, x = (lambda_N, p1, p2).
struct Local {
  Eigen::Matrix3d Wl;
  Eigen::Vector3d r;
  double mu = 0.0;
  const Polygon* P = nullptr;
};

// A candidate solution and how far its conditions are from holding
// (relative; <= kHolds: it holds). viol = inf: it could not be solved.
struct Candidate {
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  double viol = std::numeric_limits<double>::infinity();
};

Candidate stick(const Local& L) {
  Candidate c;
  bool invertible = false;
  Eigen::Matrix3d inv;
  L.Wl.computeInverseWithCheck(inv, invertible, 0.0);
  if (!invertible) return c;
  c.x = -(inv * L.r);
  const double cap = L.mu * c.x(0);
  const double g = L.P->gauge(c.x(1), c.x(2));
  const double tiny = std::numeric_limits<double>::min();
  c.viol =
      std::max({0.0, -c.x(0) / (std::abs(c.x(0)) + tiny), (g - cap) / (std::abs(cap) + g + tiny)});
  return c;
}

// Sliding with the force on vertex i: p = mu lambda_N D_i, u_N = 0, and D_i
// minimises D.u_T over the vertices (its neighbours do not go lower).
Candidate vertex(const Local& L, int i) {
  Candidate c;
  const Polygon& P = *L.P;
  const Eigen::Vector3d col = L.Wl * Eigen::Vector3d(1.0, L.mu * P.c[i], L.mu * P.s[i]);
  if (!(col(0) > 0.0)) return c;
  const double ln = -L.r(0) / col(0);
  c.x = Eigen::Vector3d(ln, L.mu * ln * P.c[i], L.mu * ln * P.s[i]);
  const double u1 = L.r(1) + col(1) * ln, u2 = L.r(2) + col(2) * ln;
  const auto along = [&](int k) { return P.c[k] * u1 + P.s[k] * u2; };
  const double here = along(i);
  const double lower = std::max(here - along(P.wrap(i - 1)), here - along(P.wrap(i + 1)));
  c.viol = std::max(0.0, lower / (std::hypot(u1, u2) + std::numeric_limits<double>::min()));
  return c;
}

// Sliding with the force on face i: p = mu (a D_i + (lambda_N - a) D_i+1),
// 0 <= a <= lambda_N, u_N = 0, u_T = -sigma n_i with sigma >= 0. Unknowns
// (lambda_N, a, sigma).
Candidate face(const Local& L, int i) {
  Candidate c;
  const Polygon& P = *L.P;
  const int j = P.wrap(i + 1);
  Eigen::Matrix3d A;
  A.col(0) = L.Wl * Eigen::Vector3d(1.0, L.mu * P.c[j], L.mu * P.s[j]);
  A.col(1) = L.Wl * Eigen::Vector3d(0.0, L.mu * (P.c[i] - P.c[j]), L.mu * (P.s[i] - P.s[j]));
  A.col(2) = Eigen::Vector3d(0.0, P.nc[i], P.ns[i]);
  bool invertible = false;
  Eigen::Matrix3d inv;
  A.computeInverseWithCheck(inv, invertible, 0.0);
  if (!invertible) return c;
  const Eigen::Vector3d y = -(inv * L.r);
  const double ln = y(0), a = y(1), sigma = y(2);
  c.x = Eigen::Vector3d(ln, L.mu * (ln * P.c[j] + a * (P.c[i] - P.c[j])),
                        L.mu * (ln * P.s[j] + a * (P.s[i] - P.s[j])));
  // Relative: the weights to lambda_N, the speed sigma to the rates r (m/s).
  const double tiny = std::numeric_limits<double>::min();
  c.viol = std::max({0.0, -ln / (std::abs(ln) + tiny), std::max(-a, a - ln) / (std::abs(ln) + tiny),
                     -sigma / (L.r.cwiseAbs().maxCoeff() + tiny)});
  return c;
}

// The local solve (cone_gs.hpp): x gets the impulses, facet (the last
// one found on entry: where the search starts) the facet found (-1: open
// or stick). False when no candidate could be solved.
bool local_cone(const Local& L, Eigen::Vector3d& x, int& facet) {
  const int hint = facet;
  x.setZero();
  facet = -1;
  if (L.r(0) >= 0.0) return true;  // separation (or resting without load)
  Candidate best = stick(L);
  if (best.viol <= kHolds) {
    x = best.x;
    return true;
  }
  const int n = 4 * L.P->d;  // codes: 2i vertex i, 2i + 1 face i
  const int start = hint >= 0 && hint < n ? hint : 2 * L.P->nearest_vertex(best.x(1), best.x(2));
  int best_code = -1;
  for (int k = 0; k < n; ++k) {
    const int step = (k + 1) / 2, code = wrap_index(start + (k % 2 ? step : -step), n);
    const Candidate c = code % 2 ? face(L, code / 2) : vertex(L, code / 2);
    if (c.viol < best.viol) {
      best = c;
      best_code = code;
      if (c.viol <= kHolds) break;
    }
  }
  if (!std::isfinite(best.viol)) return false;
  x = best.x;
  facet = best_code;
  return true;
}

}  // namespace

double cone_residual(const ConeGsProblem& p, const VectorXd& lambda, const VectorXd& u) {
  double res = 0.0;
  const int nN = p.n_normal, nF = p.n_friction;
  std::vector<Polygon> polygons;  // the edges' tables by d (no trigonometry per contact)
  auto polygon = [&](int d) -> const Polygon& {
    for (const Polygon& q : polygons)
      if (q.d == d) return q;
    polygons.emplace_back(d);
    return polygons.back();
  };
  for (const int d : *p.d)
    if (d > 1) polygon(d);
  for (int a = 0; a < nN; ++a) {
    res = std::max(res, std::abs(std::min(lambda(a), u(a))));
    const int t = (*p.tangent_of)[static_cast<size_t>(a)];
    if (t < 0) continue;
    const int j = t - nN, t2 = nN + nF + j, d = (*p.d)[static_cast<size_t>(j)];
    const double cap = (*p.mu)(j)*lambda(a), p1 = lambda(t), p2 = d > 1 ? lambda(t2) : 0.0;
    const double u1 = u(t), u2 = d > 1 ? u(t2) : 0.0;
    double b0, b1, w0, w1, xi = 0.0;  // the two bracketing edges' beta and w
    if (d == 1) {
      xi = std::abs(u1);
      b0 = std::max(p1, 0.0), b1 = std::max(-p1, 0.0), w0 = u1 + xi, w1 = -u1 + xi;
    } else {
      const Polygon& P = polygon(d);
      const int i = P.wrap(static_cast<int>(std::floor(std::atan2(p2, p1) * d / kPi)));
      const int k1 = P.wrap(i + 1);
      const double ci = P.c[i], si = P.s[i], cj = P.c[k1], sj = P.s[k1];
      const double det = ci * sj - si * cj;  // sin(pi/d) > 0
      b0 = (p1 * sj - p2 * cj) / det, b1 = (ci * p2 - si * p1) / det;
      for (int k = 0; k < 2 * d; ++k) xi = std::max(xi, -(P.c[k] * u1 + P.s[k] * u2));
      w0 = ci * u1 + si * u2 + xi, w1 = cj * u1 + sj * u2 + xi;
    }
    res = std::max({res, std::abs(std::min(b0, w0)), std::abs(std::min(b1, w1)),
                    std::abs(std::min(xi, cap - b0 - b1))});
  }
  return res;
}

// It is one piece: a sweep's loop over contacts and its stopping test share the
// iterate, the change and the polygon tables (as solve_friction_gs).
ConeGsResult solve_cone_gs(const ConeGsProblem& p, double tolerance, int max_sweeps,
                           VectorXd& lambda, std::vector<int>& facet, VectorXd& u) {
  const SparseRow& W = *p.W;
  const VectorXd& b = *p.b;
  const int nN = p.n_normal, nF = p.n_friction;
  ConeGsResult r;
  const double acceptance = tolerance * (1.0 + (b.size() ? b.cwiseAbs().maxCoeff() : 0.0));
  std::vector<Polygon> polygons;  // by d, built on first use
  auto polygon = [&](int d) -> const Polygon& {
    for (const Polygon& q : polygons)
      if (q.d == d) return q;
    polygons.emplace_back(d);
    return polygons.back();
  };
  // Row `row` of W lambda + b without the columns in `own` (their entries go to w).
  auto rest = [&](int row, const int(&own)[3], double(&w)[3]) {
    double s = b(row);
    w[0] = w[1] = w[2] = 0.0;
    for (SparseRow::InnerIterator it(W, row); it; ++it) {
      const int c = static_cast<int>(it.col());
      if (c == own[0])
        w[0] = it.value();
      else if (c == own[1])
        w[1] = it.value();
      else if (c == own[2])
        w[2] = it.value();
      else
        s += it.value() * lambda(c);
    }
    return s;
  };
  for (const int d : *p.d) polygon(d);  // no reallocation inside the sweeps
  for (r.sweeps = 1; r.sweeps <= max_sweeps; ++r.sweeps) {
    double change = 0.0;
    for (int a = 0; a < nN; ++a) {
      const int t = (*p.tangent_of)[static_cast<size_t>(a)];
      const int j = t - nN, t2 = t < 0 ? -1 : nN + nF + j;
      const int own[3] = {a, t, t2};
      double w[3][3];
      Local L;
      L.r(0) = rest(a, own, w[0]);
      if (!(w[0][0] > 0.0)) {
        r.message = "W(" + std::to_string(a) + "," + std::to_string(a) + ") is not positive";
        return r;
      }
      Eigen::Vector3d x = Eigen::Vector3d::Zero();
      if (t < 0) {
        x(0) = std::max(0.0, -L.r(0) / w[0][0]);
        change = std::max(change, w[0][0] * std::abs(x(0) - lambda(a)));
        lambda(a) = x(0);
        continue;
      }
      L.r(1) = rest(t, own, w[1]);
      L.r(2) = rest(t2, own, w[2]);
      for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) L.Wl(i, k) = w[i][k];
      L.mu = (*p.mu)(j);
      const int d = (*p.d)[static_cast<size_t>(j)];
      bool solved = true;
      if (d == 1) {
        solved = local_coulomb(w[0][0], w[0][1], w[1][1], L.r(0), L.r(1), L.mu, x(0), x(1));
      } else {
        L.P = &polygon(d);
        solved = local_cone(L, x, facet[static_cast<size_t>(j)]);
      }
      if (!solved) {
        r.message = "Painlevé-type contact at normal row " + std::to_string(a) +
                    ": no facet of its cone can be solved";
        return r;
      }
      change =
          std::max({change, w[0][0] * std::abs(x(0) - lambda(a)),
                    w[1][1] * std::abs(x(1) - lambda(t)), w[2][2] * std::abs(x(2) - lambda(t2))});
      lambda(a) = x(0), lambda(t) = x(1), lambda(t2) = x(2);
    }
    if (change > acceptance && r.sweeps < max_sweeps) continue;
    u = b;
    for (Eigen::Index i = 0; i < W.rows(); ++i)
      for (SparseRow::InnerIterator it(W, i); it; ++it) u(i) += it.value() * lambda(it.col());
    r.residual = cone_residual(p, lambda, u);
    if (r.residual <= acceptance) {
      r.status = lcp::Status::kSolved;
      return r;
    }
  }
  r.sweeps = max_sweeps;
  r.status = lcp::Status::kIterationLimit;
  r.message = "no convergence in " + std::to_string(max_sweeps) + " sweeps (natural residual " +
              short_number(r.residual) + ", acceptance " + short_number(acceptance) + ")";
  return r;
}

}  // namespace lcsim::sim::detail
