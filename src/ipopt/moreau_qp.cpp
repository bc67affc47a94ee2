// "moreau-qp": Moreau's inelastic rule as the minimisation 3.8.1,
// min ½(w - v)'M(w - v) s.t. E_J w >= 0, solved by Ipopt through its TNLP
// interface, with restitution applied Newton-style to the multipliers as in
// "newton" (§8.2.2), so the two rules agree for every e.
#include <IpIpoptApplication.hpp>
#include <IpSolveStatistics.hpp>
#include <IpTNLP.hpp>
#include <algorithm>
#include <cmath>
#include <lcsim/ipopt/moreau_qp.hpp>
#include <string>

#include "impact/detail.hpp"

namespace lcsim::impact {

namespace {

using Ipopt::Index;
using Ipopt::Number;

// The QP on velocities divided by `vs` (the largest |v_i|), so Ipopt's
// absolute tolerances act relative to the impact's scale.
class ImpactQp : public Ipopt::TNLP {
 public:
  ImpactQp(const MatrixXd& M, const MatrixXd& EJ, const VectorXd& v) : M_(M), EJ_(EJ), v_(v) {}

  bool get_nlp_info(Index& n, Index& m, Index& nnz_jac_g, Index& nnz_h_lag,
                    IndexStyleEnum& index_style) override {
    n = static_cast<Index>(v_.size());
    m = static_cast<Index>(EJ_.rows());
    nnz_jac_g = n * m;
    nnz_h_lag = n * (n + 1) / 2;
    index_style = C_STYLE;
    return true;
  }
  bool get_bounds_info(Index n, Number* x_l, Number* x_u, Index m, Number* g_l,
                       Number* g_u) override {
    for (Index i = 0; i < n; ++i) {
      x_l[i] = -2e19;  // beyond nlp_lower_bound_inf: free
      x_u[i] = 2e19;
    }
    for (Index j = 0; j < m; ++j) {
      g_l[j] = 0.0;  // E_J w >= 0
      g_u[j] = 2e19;
    }
    return true;
  }
  bool get_starting_point(Index n, bool, Number* x, bool, Number*, Number*, Index, bool,
                          Number*) override {
    for (Index i = 0; i < n; ++i) x[i] = v_(i);
    return true;
  }
  bool eval_f(Index n, const Number* x, bool, Number& obj) override {
    const VectorXd d = Eigen::Map<const VectorXd>(x, n) - v_;
    obj = 0.5 * d.dot(M_ * d);
    return true;
  }
  bool eval_grad_f(Index n, const Number* x, bool, Number* grad) override {
    Eigen::Map<VectorXd>(grad, n) = M_ * (Eigen::Map<const VectorXd>(x, n) - v_);
    return true;
  }
  bool eval_g(Index n, const Number* x, bool, Index m, Number* g) override {
    Eigen::Map<VectorXd>(g, m) = EJ_ * Eigen::Map<const VectorXd>(x, n);
    return true;
  }
  bool eval_jac_g(Index n, const Number*, bool, Index m, Index, Index* iRow, Index* jCol,
                  Number* values) override {
    Index p = 0;
    for (Index r = 0; r < m; ++r)
      for (Index c = 0; c < n; ++c, ++p) {
        if (values)
          values[p] = EJ_(r, c);
        else {
          iRow[p] = r;
          jCol[p] = c;
        }
      }
    return true;
  }
  // Hessian of the Lagrangian: obj_factor * M (the constraints are linear).
  bool eval_h(Index n, const Number*, bool, Number obj_factor, Index, const Number*, bool, Index,
              Index* iRow, Index* jCol, Number* values) override {
    Index p = 0;
    for (Index r = 0; r < n; ++r)
      for (Index c = 0; c <= r; ++c, ++p) {
        if (values)
          values[p] = obj_factor * M_(r, c);
        else {
          iRow[p] = r;
          jCol[p] = c;
        }
      }
    return true;
  }
  void finalize_solution(Ipopt::SolverReturn, Index n, const Number* x, const Number*,
                         const Number*, Index m, const Number*, const Number* lambda, Number,
                         const Ipopt::IpoptData*, Ipopt::IpoptCalculatedQuantities*) override {
    w = Eigen::Map<const VectorXd>(x, n);
    multipliers = Eigen::Map<const VectorXd>(lambda, m);
  }

  VectorXd w, multipliers;

 private:
  MatrixXd M_, EJ_;
  VectorXd v_;
};

std::string status_name(Ipopt::ApplicationReturnStatus s) {
  using A = Ipopt::ApplicationReturnStatus;
  switch (s) {
    case A::Solve_Succeeded:
      return "Solve_Succeeded";
    case A::Solved_To_Acceptable_Level:
      return "Solved_To_Acceptable_Level";
    case A::Infeasible_Problem_Detected:
      return "Infeasible_Problem_Detected";
    case A::Search_Direction_Becomes_Too_Small:
      return "Search_Direction_Becomes_Too_Small";
    case A::Diverging_Iterates:
      return "Diverging_Iterates";
    case A::User_Requested_Stop:
      return "User_Requested_Stop";
    case A::Feasible_Point_Found:
      return "Feasible_Point_Found";
    case A::Maximum_Iterations_Exceeded:
      return "Maximum_Iterations_Exceeded";
    case A::Restoration_Failed:
      return "Restoration_Failed";
    case A::Error_In_Step_Computation:
      return "Error_In_Step_Computation";
    case A::Maximum_CpuTime_Exceeded:
      return "Maximum_CpuTime_Exceeded";
    case A::Not_Enough_Degrees_Of_Freedom:
      return "Not_Enough_Degrees_Of_Freedom";
    case A::Invalid_Problem_Definition:
      return "Invalid_Problem_Definition";
    case A::Invalid_Option:
      return "Invalid_Option";
    case A::Invalid_Number_Detected:
      return "Invalid_Number_Detected";
    default:
      return "Ipopt status " + std::to_string(static_cast<int>(s));
  }
}

// Ipopt, silent, to the tolerances the minimisation 3.8.1 needs.
Ipopt::SmartPtr<Ipopt::IpoptApplication> ipopt_application() {
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
  auto opts = app->Options();
  opts->SetStringValue("sb", "yes");  // no banner
  opts->SetIntegerValue("print_level", 0);
  opts->SetNumericValue("tol", 1e-12);
  opts->SetNumericValue("constr_viol_tol", 1e-12);
  opts->SetNumericValue("compl_inf_tol", 1e-12);
  opts->SetNumericValue("dual_inf_tol", 1e-12);
  opts->SetNumericValue("acceptable_tol", 1e-9);
  opts->SetNumericValue("bound_relax_factor", 0.0);  // keep E_J w >= 0 unrelaxed
  opts->SetStringValue("hessian_constant", "yes");   // the Hessian is M
  opts->SetStringValue("jac_c_constant", "yes");
  opts->SetStringValue("jac_d_constant", "yes");
  opts->SetStringValue("mu_strategy", "adaptive");
  opts->SetIntegerValue("max_iter", 500);
  return app;
}

// Search_Direction_Becomes_Too_Small: Ipopt's step vanished before its
// tolerance was met, typically at the optimum of a degenerate problem
// (dependent rows). Accept the point on its evidence: the KKT conditions
// (3.66)-(3.67) hold to 1e-9 on the scaled problem (v / vs).
bool kkt_holds(const ImpactInput& in, const detail::Setup& s, const ImpactQp& qp, double vs) {
  if (qp.w.size() != in.v.size()) return false;
  const VectorXd lam = (-qp.multipliers).cwiseMax(0.0);
  const VectorXd rate = s.EJ * qp.w;
  const VectorXd stat = in.model->M * (qp.w - in.v / vs) - s.EJ.transpose() * lam;
  const double scale = 1.0 + (in.model->M * (in.v / vs)).cwiseAbs().maxCoeff();
  return rate.minCoeff() >= -1e-9 && stat.cwiseAbs().maxCoeff() <= 1e-9 * scale &&
         lam.cwiseProduct(rate).cwiseAbs().maxCoeff() <= 1e-9 * scale;
}

}  // namespace

ImpactResult moreau_qp(const ImpactInput& in) {
  ImpactResult out;
  const auto s = detail::prepare(in, out);
  if (!s) return out;
  const double vs = std::max(in.v.cwiseAbs().maxCoeff(), 1e-300);
  if (in.v.cwiseAbs().maxCoeff() == 0.0) {  // at rest: nothing to project
    detail::finish(in, *s, VectorXd::Zero(in.closed.size()), in.v, 0.0, out);
    out.status = Status::kOk;
    return out;
  }
  Ipopt::SmartPtr<ImpactQp> qp = new ImpactQp(in.model->M, s->EJ, in.v / vs);
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = ipopt_application();
  Ipopt::ApplicationReturnStatus st = app->Initialize("");  // "": read no ipopt.opt
  if (st != Ipopt::Solve_Succeeded) {
    out.message = "moreau-qp: Ipopt failed to initialise: " + status_name(st);
    return out;
  }
  st = app->OptimizeTNLP(qp);
  if (Ipopt::IsValid(app->Statistics())) out.iterations = app->Statistics()->IterationCount();
  const bool solved = st == Ipopt::Solve_Succeeded || st == Ipopt::Solved_To_Acceptable_Level;
  const bool kkt =
      !solved && st == Ipopt::Search_Direction_Becomes_Too_Small && kkt_holds(in, *s, *qp, vs);
  if (!solved && !kkt) {
    out.message = "moreau-qp: Ipopt did not solve the minimisation 3.8.1: " + status_name(st);
    return out;
  }
  // Ipopt's Lagrangian is f + lambda' g: at E_i w = 0 (lower bound active)
  // lambda_i <= 0, and M(w - v) = -E_J' lambda. The impulse is -lambda.
  const VectorXd lambda = (-qp->multipliers).cwiseMax(0.0) * vs;
  const VectorXd w = qp->w * vs;
  // Inactive constraints keep multipliers of the order of the barrier
  // parameter (~1e-13 relative); count a contact in the mode above 1e-9.
  const double threshold =
      1e-9 * std::max(lambda.maxCoeff(),
                      s->W.diagonal().maxCoeff() > 0.0 ? vs / s->W.diagonal().maxCoeff() : 0.0);
  // Restitution Newton-style on the inelastic impulse; e = 0 keeps Ipopt's w.
  const VectorXd extra = s->e_J.cwiseProduct(lambda);
  const VectorXd impulse = lambda + extra;
  detail::finish(in, *s, impulse, w + s->MinvEt * extra, threshold, out);
  out.status = Status::kOk;
  if (kkt) {
    out.message = "Ipopt: " + status_name(st) + ", KKT conditions checked to 1e-9";
    return out;
  }
  out.message = st == Ipopt::Solved_To_Acceptable_Level
                    ? "Ipopt: Solved_To_Acceptable_Level after " + std::to_string(out.iterations) +
                          " iterations"
                    : "";
  return out;
}

namespace {
class MoreauQpLaw final : public ImpactLaw {
 public:
  std::string name() const override { return "moreau-qp"; }
  ImpactResult apply(const ImpactInput& in, const lcp::Solver&) const override {
    return moreau_qp(in);
  }
};
}  // namespace

void register_moreau_qp() {
  laws().add("moreau-qp", [] { return std::make_unique<MoreauQpLaw>(); });
}

}  // namespace lcsim::impact
