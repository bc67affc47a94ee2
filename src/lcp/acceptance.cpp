// The acceptance test of every LCP solver: the row-scaled residual.
#include <algorithm>
#include <cmath>
#include <lcsim/core/format.hpp>
#include <lcsim/lcp/lcp.hpp>
#include <limits>
#include <utility>

#include "lcp/detail.hpp"

namespace lcsim::lcp {

namespace {
// x / s with 0 / 0 read as 0 (s >= 0; s = 0 forces x = 0 in every use here).
double ratio(double x, double s) { return s > 0.0 ? x / s : 0.0; }
}  // namespace

double scaled_residual(const MatrixXd& M, const VectorXd& q, const VectorXd& z, int* worst_row) {
  if (worst_row) *worst_row = -1;
  const Eigen::Index k = q.size();
  if (z.size() != k || M.rows() != k || M.cols() != k)
    return std::numeric_limits<double>::infinity();
  const double zn = k ? z.cwiseAbs().maxCoeff() : 0.0;
  double worst = -1.0;
  for (Eigen::Index i = 0; i < k; ++i) {
    double w = q(i), s = std::abs(q(i));
    for (Eigen::Index j = 0; j < k; ++j) {
      w += M(i, j) * z(j);
      s += std::abs(M(i, j)) * std::abs(z(j));
    }
    const double ri = std::abs(std::min(ratio(z(i), zn), ratio(w, s)));
    // NaN (non-finite data) is the worst row there is.
    if (!(ri <= worst)) {
      worst = std::isnan(ri) ? std::numeric_limits<double>::infinity() : ri;
      if (worst_row) *worst_row = static_cast<int>(i);
    }
  }
  return std::max(worst, 0.0);
}

namespace detail {

Result finish(const MatrixXd& M, const VectorXd& q, VectorXd z, Status claimed, const Options& opt,
              std::string message) {
  Result r;
  r.z = std::move(z);
  r.w = M * r.z + q;
  r.residual = r.z.cwiseMin(r.w).cwiseAbs().maxCoeff();
  r.scaled_residual = scaled_residual(M, q, r.z, &r.worst_row);
  r.min_z = r.z.size() ? std::min(0.0, r.z.minCoeff()) : 0.0;  // k = 0: nothing to violate
  r.min_w = r.w.size() ? std::min(0.0, r.w.minCoeff()) : 0.0;
  r.status = claimed;
  r.message = std::move(message);
  const bool finite = r.z.allFinite() && r.w.allFinite();
  if (!finite) {
    r.status = Status::kNumericalFailure;
    r.message = "non-finite values in the solution" + (r.message.empty() ? "" : ": " + r.message);
    return r;
  }
  if (claimed == Status::kSolved && !(r.scaled_residual <= opt.tolerance)) {
    const int i = r.worst_row;
    r.status = Status::kNumericalFailure;
    r.message = text("residual check failed at row ", i, ": z(", i, ") = ", r.z(i), ", w(", i,
                     ") = ", r.w(i), ", row-scaled residual ", r.scaled_residual, " > tolerance ",
                     opt.tolerance, " (natural residual ", r.residual, ")");
  }
  return r;
}

}  // namespace detail

Result accept(const MatrixXd& M, const VectorXd& q, VectorXd z, const Options& opt) {
  return detail::finish(M, q, std::move(z), Status::kSolved, opt, "");
}

}  // namespace lcsim::lcp
