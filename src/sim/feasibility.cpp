#include <lcsim/core/format.hpp>
#include <lcsim/mech/tolerances.hpp>
#include <lcsim/sim/sim.hpp>

namespace lcsim::sim {

std::string infeasible_start(const mech::Model& model, const VectorXd& x0) {
  if (!model.is_mechanical()) return "";
  const mech::MechanicalModel& m = *model.mechanical;
  if (x0.size() != 2 * m.dofs() || m.num_constraints() == 0) return "";
  const VectorXd q = x0.head(m.dofs());
  const VectorXd gap = mech::gaps(m, q);
  const VectorXd scale = mech::gap_scale(m.E, q, m.g);
  for (int r = 0; r < m.num_constraints(); ++r) {
    if (gap(r) >= -mech::zero_tolerance(scale(r))) continue;  // mech/tolerances.hpp
    return text("constraint '", m.constraints[r], "' is violated at t = 0 (gap = ", gap(r),
                "): the state is infeasible, E q + g >= 0 must hold (thesis §3.8); "
                "mech::project_feasible gives the nearest feasible positions");
  }
  return "";
}

}  // namespace lcsim::sim
