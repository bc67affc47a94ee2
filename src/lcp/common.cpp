// Diagnostics, validation and the solver registry of the LCP layer.
#include <cmath>
#include <exception>
#include <functional>
#include <lcsim/core/format.hpp>
#include <lcsim/lcp/lcp.hpp>
#include <limits>
#include <stdexcept>
#include <utility>

#include "lcp/detail.hpp"

namespace lcsim::lcp {

std::string validate(const MatrixXd& M, const VectorXd& q) {
  if (M.rows() == 0 || M.cols() == 0)
    return "empty LCP: M is " + std::to_string(M.rows()) + "x" + std::to_string(M.cols());
  if (M.rows() != M.cols()) {
    return text("M must be square, got ", M.rows(), "x", M.cols());
  }
  if (q.size() != M.rows()) {
    return text("q has size ", q.size(), " but M is ", M.rows(), "x", M.cols());
  }
  for (Eigen::Index j = 0; j < M.cols(); ++j)
    for (Eigen::Index i = 0; i < M.rows(); ++i)
      if (!std::isfinite(M(i, j))) {
        return text("M(", i, ",", j, ") = ", M(i, j), " is not finite");
      }
  for (Eigen::Index i = 0; i < q.size(); ++i)
    if (!std::isfinite(q(i))) {
      return text("q(", i, ") = ", q(i), " is not finite");
    }
  return "";
}

double natural_residual(const MatrixXd& M, const VectorXd& q, const VectorXd& z) {
  if (z.size() != q.size() || M.rows() != q.size() || M.cols() != z.size())
    return std::numeric_limits<double>::infinity();
  if (z.size() == 0) return 0.0;
  const VectorXd w = M * z + q;
  return z.cwiseMin(w).cwiseAbs().maxCoeff();
}

Result evaluate(const MatrixXd& M, const VectorXd& q, const VectorXd& z) {
  const std::string bad = validate(M, q);
  if (!bad.empty()) return detail::invalid(bad);
  if (z.size() != q.size())
    return detail::invalid("z has size " + std::to_string(z.size()) + ", expected " +
                           std::to_string(q.size()));
  // Status kSolved iff z passes the acceptance test at the default Options{}.tolerance.
  return detail::finish(M, q, z, Status::kSolved, Options{}, "");
}

namespace detail {

std::string validate_all(const MatrixXd& M, const VectorXd& q, const Options& opt) {
  std::string bad = validate(M, q);
  if (!bad.empty()) return bad;
  if (!(opt.tolerance >= 0.0) || !std::isfinite(opt.tolerance)) {
    return text("tolerance must be finite and >= 0, got ", opt.tolerance);
  }
  if (opt.max_pivots < 0) {
    return text("max_pivots must be >= 0, got ", opt.max_pivots);
  }
  if (opt.max_iterations < 0) {
    return text("max_iterations must be >= 0, got ", opt.max_iterations);
  }
  if (!(opt.relaxation > 0.0 && opt.relaxation < 2.0)) {
    return text("relaxation must be in (0, 2), got ", opt.relaxation);
  }
  if (opt.warm_start) {
    if (opt.warm_start->size() != q.size()) {
      return text("warm start has size ", opt.warm_start->size(), ", expected ", q.size());
    }
    if (!opt.warm_start->allFinite()) return "warm start is not finite";
  }
  return "";
}

Result invalid(std::string message) {
  Result r;
  r.status = Status::kInvalidInput;
  r.message = std::move(message);
  return r;
}

}  // namespace detail

namespace {

using SolveFn = Result (*)(const MatrixXd&, const VectorXd&, const Options&);

class FnSolver final : public Solver {
 public:
  FnSolver(std::string name, SolveFn fn) : name_(std::move(name)), fn_(fn) {}
  std::string name() const override { return name_; }
  Result solve(const MatrixXd& M, const VectorXd& q, const Options& opt) const override {
    return fn_(M, q, opt);
  }

 private:
  std::string name_;
  SolveFn fn_;
};

struct Entry {
  const char* name;
  SolveFn fn;
};
constexpr Entry kSolvers[] = {
    {"lemke", &solve_lemke},
    {"pivot", &solve_principal_pivoting},
    {"pgs", &solve_pgs},
    {"enum", &solve_enumeration},
};

}  // namespace

Registry<Solver>& solvers() {
  return Registry<Solver>::instance("LCP solver", [](Registry<Solver>& reg) {
    for (const auto& e : kSolvers)
      reg.add(e.name, [e] { return std::make_unique<FnSolver>(e.name, e.fn); });
  });
}

std::vector<std::string> solver_names() { return solvers().names(); }

std::unique_ptr<Solver> make_solver(std::string_view name) { return solvers().make_or_throw(name); }

}  // namespace lcsim::lcp
