// The one way the LCP layer rescales an LCP (row equilibration, symmetric scaling).
#include <algorithm>
#include <cmath>
#include <lcsim/lcp/lcp.hpp>
#include <utility>

#include "lcp/detail.hpp"

namespace lcsim::lcp::detail {

double row_scale(double m) {
  int e = 0;
  if (m > 0.0 && std::isfinite(m)) std::frexp(m, &e);  // m = f 2^e, f in [0.5, 1)
  // Clamped so that the factor itself stays a normal number (a subnormal
  // row, e ~ -1070, would otherwise give 2^1070 = inf).
  return std::ldexp(1.0, -std::clamp(e, -1000, 1000));
}

Scaling scale(const MatrixXd& M, const VectorXd& q, VectorXd r, VectorXd c) {
  Scaling s;
  s.M = r.asDiagonal() * M * c.asDiagonal();
  s.q = r.cwiseProduct(q);
  s.r = std::move(r);
  s.c = std::move(c);
  return s;
}

Scaling equilibrate_rows(const MatrixXd& M, const VectorXd& q) {
  const Eigen::Index k = q.size();
  VectorXd r(k);
  for (Eigen::Index i = 0; i < k; ++i) {
    const double m = M.row(i).cwiseAbs().maxCoeff();
    r(i) = row_scale(m > 0.0 ? m : std::abs(q(i)));
  }
  return scale(M, q, std::move(r), VectorXd::Ones(k));
}

Scaling symmetric_scaling(const MatrixXd& M, const VectorXd& q) {
  const Eigen::Index k = q.size();
  VectorXd d(k);
  for (Eigen::Index i = 0; i < k; ++i) d(i) = M(i, i) > 0.0 ? 1.0 / std::sqrt(M(i, i)) : 1.0;
  const double qd = k ? d.cwiseProduct(q).cwiseAbs().maxCoeff() : 0.0;
  const double s = qd > 0.0 ? qd : 1.0;
  return scale(M, q, d / s, s * d);
}

}  // namespace lcsim::lcp::detail
