// The impact layer: impact laws behind one interface.
//
// Public face of src/impact. An impact law maps a pre-impact velocity and the
// closed contacts (zero gap) to a post-impact velocity and an impulse.
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "lcp/lcp.hpp"
#include "mech/mech.hpp"

namespace lcsim::impact {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using IndexSet = std::vector<int>;

struct ImpactResult {
  bool ok = false;
  std::string message;
  VectorXd v_after;   // post-impact velocity (N)
  VectorXd impulse;   // per constraint (k, zero outside the closed set)
  IndexSet mode;      // constraints with positive impulse
  double energy_before = 0.0, energy_after = 0.0;  // kinetic energy (J)
  double worst_rate = 0.0;  // most negative E_J v+ (0 if none): admissibility
  int lcp_solves = 0;
  lcp::Status lcp_status = lcp::Status::kSolved;
};

struct ImpactInput {
  const mech::MechanicalModel* model = nullptr;
  VectorXd q, v;        // configuration and pre-impact velocity
  IndexSet closed;      // constraints with zero gap (0-based, sorted)
  VectorXd restitution; // per constraint (k); empty = the model's
};

class ImpactLaw {
 public:
  virtual ~ImpactLaw() = default;
  virtual std::string name() const = 0;
  virtual ImpactResult apply(const ImpactInput& in, const lcp::Solver& solver) const = 0;
};
// Throws std::invalid_argument naming the unknown law and the known ones.
std::unique_ptr<ImpactLaw> make_impact_law(std::string_view name);
std::vector<std::string> impact_law_names();

// Moreau's inelastic impact LCP (3.69)-(3.70) on the closed set J, with
// per-contact Newton restitution applied to the inelastic impulse (§8.2.2):
// v+ = v + sum_i (1 + e_i) M^{-1} E_i' lambda_i. e = 0 is Moreau's rule.
ImpactResult moreau_newton(const ImpactInput& in, const lcp::Solver& solver);

}  // namespace lcsim::impact
