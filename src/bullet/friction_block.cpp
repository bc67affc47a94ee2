// A block sliding on a rough floor, read from an lcsim model: the parameters
// the Bullet scene of friction_box.cpp needs, the closed form, and where a
// run sticks (slide_stop, used on Bullet's and lcsim's runs alike).
#include <cmath>
#include <lcsim/bullet/bullet.hpp>
#include <lcsim/core/format.hpp>
#include <stdexcept>
#include <string>

namespace lcsim::bullet {

namespace {

FrictionBlockOf refuse(const mech::Model& model, const std::string& why) {
  FrictionBlockOf out;
  out.status = Status::kInvalidInput;
  out.message = "bullet friction box: model '" + model.name + "' is not a block on a floor: " + why;
  return out;
}

// The one nonzero of row i of E (the column, or -1 when there are 0 or 2+).
int single_column(const mech::SparseMatrix& E, int i) {
  int col = -1;
  for (int j = 0; j < E.cols(); ++j)
    if (E.coeff(i, j) != 0.0) {
      if (col >= 0) return -1;
      col = j;
    }
  return col;
}

// "" when M = m I, D = 0, K = 0 (the rigid block), else why not.
std::string rigid_block_error(const mech::MechanicalModel& m) {
  const double m0 = m.M.coeff(0, 0);
  if (m.M.coeff(0, 1) != 0.0 || m.M.coeff(1, 0) != 0.0)
    return "mechanical.M(0, 1) = " + short_number(m.M.coeff(0, 1)) +
           ": one rigid block needs a diagonal M (its mass on both coordinates)";
  if (std::abs(m.M.coeff(1, 1) - m0) > 1e-12 * m0)
    return "mechanical.M(1, 1) = " + short_number(m.M.coeff(1, 1)) +
           " differs from M(0, 0) = " + short_number(m0) +
           ": one rigid block has one mass on both coordinates";
  if (m.K.norm() != 0.0) return "mechanical.K is not zero: a block on a floor has no spring";
  if (m.D.norm() != 0.0) return "mechanical.D is not zero: a block on a floor has no damper";
  return "";
}

// The first bad field of b and why ("mu must be in [0, 10] (got -1)"), or "".
std::string block_rule_error(const FrictionBlock& b) {
  auto bad = [](const char* name, double value, const char* rule) {
    return std::string(name) + " must be " + rule + " (got " + short_number(value) + ")";
  };
  if (!(std::isfinite(b.mass) && b.mass > 0.0)) return bad("mass", b.mass, "finite and > 0");
  // Bullet clamps the combined friction coefficient to [-10, 10]
  // (calculateCombinedFriction, MAX_FRICTION).
  if (!(b.mu >= 0.0 && b.mu <= 10.0)) return bad("mu", b.mu, "in [0, 10]");
  if (!(std::isfinite(b.gravity) && b.gravity > 0.0))
    return bad("gravity", b.gravity, "finite and > 0");
  if (!std::isfinite(b.x0)) return bad("x0", b.x0, "finite");
  if (!std::isfinite(b.v0)) return bad("v0", b.v0, "finite");
  if (!(std::isfinite(b.t_end) && b.t_end > 0.0)) return bad("t_end", b.t_end, "finite and > 0");
  return "";
}

}  // namespace

double FrictionBlock::stop_time() const {
  return mu > 0.0 ? std::abs(v0) / (mu * gravity) : std::numeric_limits<double>::infinity();
}

double FrictionBlock::slide_distance() const {
  return mu > 0.0 ? v0 * v0 / (2.0 * mu * gravity) : std::numeric_limits<double>::infinity();
}

std::string friction_block_error(const FrictionBlock& b) {
  const std::string why = block_rule_error(b);
  return why.empty() ? why : "bullet friction box: " + why;
}

FrictionBlockOf friction_block_of(const mech::Model& model, const Eigen::VectorXd& x0_in) {
  if (!model.is_mechanical()) return refuse(model, "it is a general LCS, not a mechanical model");
  if (auto p = mech::check_model(model)) return refuse(model, p->field + ": " + p->what);
  const mech::MechanicalModel& m = *model.mechanical;
  if (m.dofs() != 2)
    return refuse(model, "it has " + std::to_string(m.dofs()) +
                             " coordinates (a block on a floor has 2: along and normal to it)");
  if (m.num_constraints() != 1)
    return refuse(model, "mechanical.E has " + std::to_string(m.num_constraints()) +
                             " rows (a block on a floor has 1: the floor)");
  if (m.friction.size() != 1)
    return refuse(model, "mechanical.friction has " + std::to_string(m.friction.size()) +
                             " entries (the floor needs exactly 1)");
  const int n = single_column(m.E, 0);
  if (n < 0 || m.E.coeff(0, n) <= 0.0)
    return refuse(model, "mechanical.E[0] must be c e_n with c > 0 (a floor c q_n + g >= 0)");
  const int t = 1 - n;
  const mech::FrictionalContact& fc = m.friction[0];
  if (fc.tangent.coeff(n) != 0.0 || fc.tangent.coeff(t) == 0.0)
    return refuse(model, "mechanical.friction[0].tangent must be along coordinate " +
                             std::to_string(t) + " only (got " + short_number(fc.tangent.coeff(0)) +
                             ", " + short_number(fc.tangent.coeff(1)) + ")");
  if (std::string why = rigid_block_error(m); !why.empty()) return refuse(model, why);
  if (m.f(t) != 0.0)
    return refuse(model, "mechanical.f[" + std::to_string(t) + "] = " + short_number(m.f(t)) +
                             ": the closed form has no force along the floor");
  if (!(m.f(n) < 0.0))
    return refuse(model, "mechanical.f[" + std::to_string(n) + "] = " + short_number(m.f(n)) +
                             ": gravity must press the block onto the floor (f < 0)");
  const Eigen::VectorXd x0 = x0_in.size() > 0 ? x0_in : model.initial;
  if (x0.size() != 4)
    return refuse(model, "the initial state has " + std::to_string(x0.size()) +
                             " entries (expected 4: q then v)");
  if (!x0.allFinite()) return refuse(model, "the initial state is not finite");
  const double c = m.E.coeff(0, n), gap = c * x0(n) + m.g(0);
  if (std::abs(gap) > 1e-12 * (std::abs(c * x0(n)) + std::abs(m.g(0)) + 1e-300))
    return refuse(model,
                  "the block starts at gap " + short_number(gap) + " (it must start on the floor)");
  if (x0(2 + n) != 0.0)
    return refuse(model, "initial[" + std::to_string(2 + n) + "] = " + short_number(x0(2 + n)) +
                             ": the block must start with no normal velocity");
  FrictionBlockOf out;
  FrictionBlock& b = out.block;
  b.mass = m.M.coeff(0, 0);
  b.mu = fc.mu * std::abs(fc.tangent.coeff(t)) / c;  // |s P_T| <= mu |s| / c (c P_N)
  b.gravity = -m.f(n) / b.mass;
  b.x0 = x0(t);
  b.v0 = x0(2 + t);
  b.t_end = std::isfinite(model.t_end) ? model.t_end : b.t_end;
  b.tangent_coordinate = t;
  b.normal_coordinate = n;
  if (std::string why = block_rule_error(b); !why.empty()) return refuse(model, why);
  return out;
}

SlideStop slide_stop(const std::vector<double>& t, const std::vector<double>& x,
                     const std::vector<double>& v, double v_tol) {
  if (t.empty() || x.size() != t.size() || v.size() != t.size())
    throw std::invalid_argument("slide_stop: t, x, v need equal sizes >= 1 (got " +
                                std::to_string(t.size()) + ", " + std::to_string(x.size()) + ", " +
                                std::to_string(v.size()) + ")");
  if (!(std::isfinite(v_tol) && v_tol >= 0.0))
    throw std::invalid_argument("slide_stop: v_tol must be finite and >= 0 (got " +
                                short_number(v_tol) + ")");
  std::size_t j = t.size();
  while (j > 0 && std::abs(v[j - 1]) <= v_tol) --j;
  SlideStop s;
  if (j == t.size()) return s;  // still sliding at the end
  s.time = t[j];
  s.distance = std::abs(x[j] - x[0]);
  return s;
}

}  // namespace lcsim::bullet
