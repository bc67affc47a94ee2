// The impact layer: impact laws behind one interface.
//
// Public face of src/impact. An impact law maps a pre-impact velocity and the
// closed contacts (zero gap) to a post-impact velocity and an impulse.
#pragma once

#include <Eigen/Dense>
#include <lcsim/core/registry.hpp>
#include <lcsim/lcp/lcp.hpp>
#include <lcsim/mech/mech.hpp>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace lcsim::impact {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using IndexSet = std::vector<int>;

struct ImpactResult {
  Status status = Status::kNumericalFailure;  // kOk when computed; message says why not
  bool ok() const { return status == Status::kOk; }
  std::string message;
  VectorXd v_after;  // post-impact velocity (N)
  VectorXd impulse;  // per constraint (k, zero outside the closed set)
  IndexSet mode;     // constraints with positive impulse
  double energy_before = 0.0, energy_after = 0.0;  // kinetic energy (J)
  double worst_rate = 0.0;  // most negative E_J v+ (0 if none): admissibility
  int lcp_solves = 0;
  lcp::Status lcp_status = lcp::Status::kSolved;
  // Appended fields (the integrator uses only those above).
  // false when the result is computed but not an admissible impact: a negative
  // impulse entry (rule [177], "flip") or E_J v+ < 0 beyond rounding.
  bool admissible = true;
  int iterations = 0;  // sequential: pairwise impacts done; moreau-qp: Ipopt iterations
  // Sequential: v before the first pairwise impact, then after each one (only
  // filled when ImpactInput::record_iterates is set).
  std::vector<VectorXd> iterates;
};

struct ImpactInput {
  const mech::MechanicalModel* model = nullptr;
  VectorXd q, v;         // configuration and pre-impact velocity
  IndexSet closed;       // constraints with zero gap (0-based, sorted)
  VectorXd restitution;  // per constraint (k); empty = the model's
  // Appended fields.
  int max_iterations = 0;        // sequential: cap on pairwise impacts (0 = 100000)
  bool record_iterates = false;  // sequential: fill ImpactResult::iterates
};

class ImpactLaw {
 public:
  virtual ~ImpactLaw() = default;
  virtual std::string name() const = 0;
  virtual ImpactResult apply(const ImpactInput& in, const lcp::Solver& solver) const = 0;
};
// The laws by name: those below, and "moreau-qp" in programs that link the
// component lcsim::ipopt (include/lcsim/ipopt/moreau_qp.hpp).
Registry<ImpactLaw>& laws();
// Throws std::invalid_argument naming the unknown law and the known ones.
std::unique_ptr<ImpactLaw> make_impact_law(std::string_view name);
std::vector<std::string> impact_law_names();

// The rules, by name (docs/impact-rules.md). All work on the closed set J
// (constraints with zero gap), velocities in the model's units (m/s), impulses
// per constraint (N s), energies in J. e_i is ImpactInput::restitution or the
// model's.
//
// "moreau", "newton": Moreau's inelastic impact LCP (3.69)-(3.70) on J, with
// per-contact Newton restitution applied to the inelastic impulse (§8.2.2):
// v+ = v + sum_i (1 + e_i) M^{-1} E_i' lambda_i. e = 0 is Moreau's rule.
ImpactResult moreau_newton(const ImpactInput& in, const lcp::Solver& solver);
// "moreau-restitution": the Moreau–Jean law, restitution inside the LCP:
// 0 <= E_J v+ + e∘E_J v ⟂ lambda >= 0, v+ = v + M^{-1} E_J' lambda.
ImpactResult moreau_restitution(const ImpactInput& in, const lcp::Solver& solver);
// "sequential": pairwise impacts in turn (Example 1.4.1): sweep over J in
// index order, resolve each approaching contact alone with its restitution,
// lambda_i = -(1 + e_i) E_i v / (E_i M^{-1} E_i'), until a sweep finds no
// approaching contact. ok = false if the cap is reached first.
ImpactResult sequential(const ImpactInput& in);
// "flip": the mode rule of ref. [177] recalled in Example 3.8.3: I = the closed
// constraints with E_i v < 0; solve E_I w = 0, w = v + M^{-1} E_I' lambda
// (least-squares lambda of minimal norm if E_I is rank deficient), then apply
// restitution Newton-style. admissible = false if some lambda_i < 0 or
// E_J v+ < 0: the rule then yields no admissible impact.
ImpactResult flip_rule(const ImpactInput& in);

// Tolerances shared by the rules: |x| <= kRelTol * scale + kAbsTol counts as
// zero, where scale is |E_i||v| for a rate (as the integrator's is_zero).
inline constexpr double kRelTol = 1e-12;
inline constexpr double kAbsTol = 1e-13;

}  // namespace lcsim::impact
