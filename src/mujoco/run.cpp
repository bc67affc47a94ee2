// The MuJoCo run of a contact scene (mujoco.cpp says what MuJoCo integrates
// and how its contacts differ): the model's settings, the state map, the
// step loop and what it records.
#include <mujoco/mujoco.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <lcsim/core/format.hpp>
#include <lcsim/mujoco/mujoco.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/scene/so3.hpp>
#include <map>
#include <optional>
#include <stdexcept>

#include "mujoco/detail.hpp"

namespace lcsim::mujoco {

namespace {

using Eigen::Matrix3d;
using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;

// A floating base: its six coordinates from `offset`, its free joint's
// qpos and qvel addresses, its reference orientation.
struct FreeBase {
  int offset = 0;
  int q = -1, v = -1;
  Matrix3d R0 = Matrix3d::Identity();
};

// Where each lcsim coordinate lives in MuJoCo, and the scene's forces.
struct Run {
  MjModelPtr m;
  MjDataPtr d;
  std::vector<FreeBase> bases;  // one per floating base
  std::vector<int> qadr,
      vadr;  // coordinate c -> qpos / qvel address (-1: a base's)
  MatrixXd K_s, D;
  VectorXd f_s;
  std::vector<int> row_body;        // contact row -> MuJoCo body of its link (-1: none)
  std::vector<Vector3d> row_local;  // its point in the link frame, minus nothing
  std::vector<double> row_radius;
  std::vector<Vector3d> row_normal;
  // A scene of bodies: MuJoCo geom -> the contact row whose point it is (-1:
  // none), so each contact's force goes to its own row.
  std::vector<int> geom_row;
  // Each contact row's world tangents (scene::ContactFrame), for the friction
  // multipliers.
  std::vector<Vector3d> row_t1, row_t2;
  // A scene of bodies' joint stops by MuJoCo joint id (joint_ranges).
  std::map<int, JointRange> stops;
};

int id_or_throw(const mjModel* m, int type, const std::string& name, const char* what) {
  const int id = mj_name2id(m, type, name.c_str());
  if (id < 0)
    throw std::invalid_argument("mujoco: MuJoCo's model has no " + std::string(what) + " '" + name +
                                "'");
  return id;
}

// Entry i of a soft constraint's MuJoCo arrays (a pair's, a geom's, a
// joint's), per Settings: solref the time constant tc and the damping
// ratio, solimp (dmin, dmax, width, midpoint 0.5, power 2).
void soften(mjtNum* solref, mjtNum* solimp, int i, double tc, const Settings& s) {
  solref[2 * i] = tc;
  solref[2 * i + 1] = s.damping_ratio;
  const double imp[5] = {s.dmin, s.dmax, s.width, 0.5, 2.0};
  std::copy(imp, imp + 5, solimp + 5 * i);
}

// A scene of bodies' contact pairs (mjcf_bodies.cpp: pair i is contact i of
// setup.contacts): condim 3 with the row's mu (sliding only) or 1, soft as
// the geoms below, no margin or gap. Its geoms have contype = conaffinity =
// 0 already (configure leaves a link's geoms colliding only in a one-URDF
// scene).
void configure_pairs(Run& r, const scene::Scene& setup, const std::vector<double>& row_mu,
                     const Settings& s, double tc) {
  mjModel* m = r.m.get();
  if (setup.bodies.empty()) return;
  for (int p = 0; p < m->npair; ++p) {
    const double mu =
        row_mu[static_cast<std::size_t>(setup.contacts[static_cast<std::size_t>(p)].row)];
    m->pair_dim[p] = mu >= 0.0 ? 3 : 1;
    const double fr[5] = {std::max(mu, 0.0), std::max(mu, 0.0), 0.0, 0.0, 0.0};
    std::copy(fr, fr + 5, m->pair_friction + 5 * p);
    soften(m->pair_solref, m->pair_solimp, p, tc, s);
    m->pair_margin[p] = 0.0;
    m->pair_gap[p] = 0.0;
  }
}

// Geoms: the contact links' collide with the planes only, with the link's
// friction mu (condim 3; frictionless: condim 1 as before), soft per
// Settings. Joints: no damping, armature, friction loss, stiffness or range
// of MuJoCo's own.
// It is one piece: each geom's and each joint's settings, pinned in one pass.
void configure(Run& r, const scene::Scene& setup, const mech::MechanicalModel& mm,
               const Settings& s, double h) {
  mjModel* m = r.m.get();
  m->opt.timestep = h;
  m->opt.integrator = mjINT_EULER;
  for (int i = 0; i < 3; ++i) m->opt.gravity[i] = setup.gravity(i);
  std::vector<bool> contact_body(static_cast<std::size_t>(m->nbody), false);
  // Each contact body's mu (check_expressible: one per link), -1 without
  // friction.
  std::vector<double> body_mu(static_cast<std::size_t>(m->nbody), -1.0);
  std::vector<double> row_mu(static_cast<std::size_t>(mm.num_constraints()), -1.0);
  for (const mech::FrictionalContact& f : mm.friction)
    row_mu[static_cast<std::size_t>(f.contact)] = f.mu;
  for (const auto& cf : setup.contacts) {
    if (!setup.bodies.empty()) break;  // pairs (configure_pairs)
    const auto b =
        static_cast<std::size_t>(id_or_throw(m, mjOBJ_BODY, cf.point.link, "body for link"));
    contact_body[b] = true;
    body_mu[b] = row_mu[static_cast<std::size_t>(cf.row)];
  }
  if (mm.has_friction()) {
    m->opt.cone = s.cone == Settings::Cone::kElliptic ? mjCONE_ELLIPTIC : mjCONE_PYRAMIDAL;
    m->opt.impratio = 1.0;
    m->opt.noslip_iterations = 0;
  }
  const double tc = s.time_constant > 0.0 ? std::max(s.time_constant, 2.0 * h) : 2.0 * h;
  for (int g = 0; g < m->ngeom; ++g) {
    const bool plane = m->geom_type[g] == mjGEOM_PLANE && m->geom_bodyid[g] == 0;
    const bool link = contact_body[static_cast<std::size_t>(m->geom_bodyid[g])];
    m->geom_contype[g] = link ? 1 : 0;
    m->geom_conaffinity[g] = plane ? 1 : 0;
    const double mu = body_mu[static_cast<std::size_t>(m->geom_bodyid[g])];
    m->geom_condim[g] = link && mu >= 0.0 ? 3 : 1;
    soften(m->geom_solref, m->geom_solimp, g, tc, s);
    m->geom_margin[g] = 0.0;
    m->geom_gap[g] = 0.0;
    for (int k = 0; k < 3; ++k) m->geom_friction[3 * g + k] = 0.0;
    if (link && mu >= 0.0) m->geom_friction[3 * g] = mu;  // sliding; MuJoCo takes the larger
  }
  configure_pairs(r, setup, row_mu, s, tc);
  for (int j = 0; j < m->nv; ++j) {
    m->dof_damping[j] = 0.0;
    m->dof_armature[j] = 0.0;
    m->dof_frictionloss[j] = 0.0;
  }
  for (int j = 0; j < m->njnt; ++j) {
    // A scene of bodies' joints have the ranges of its stops (mjcf_bodies.cpp),
    // soft as the contacts; a one-URDF scene's none (MuJoCo's URDF ranges off).
    if (setup.bodies.empty()) m->jnt_limited[j] = 0;
    m->jnt_stiffness[j] = 0.0;
    soften(m->jnt_solref, m->jnt_solimp, j, tc, s);
    m->jnt_margin[j] = 0.0;
  }
}

// The bases and joints: a one-URDF scene's free joint (kFreeJoint) and
// joints by their URDF names; a scene of bodies' free joints by body and
// joints by coordinate name (mjcf_bodies.cpp).
void map_joints(Run& r, const scene::Scene& setup, const mech::MechanicalModel& mm) {
  const mjModel* m = r.m.get();
  const auto N = static_cast<std::size_t>(mm.dofs());
  r.qadr.assign(N, -1);
  r.vadr.assign(N, -1);
  auto add_base = [&](int offset, const std::string& joint, const Matrix3d& R0) {
    const int j = id_or_throw(m, mjOBJ_JOINT, joint, "free joint");
    r.bases.push_back({offset, m->jnt_qposadr[j], m->jnt_dofadr[j], R0});
  };
  if (setup.bodies.empty() && setup.base.floating)
    add_base(0, kFreeJoint, setup.base.pose.linear());
  for (const scene::SceneBody& b : setup.bodies)
    if (b.base.floating)
      add_base(static_cast<int>(b.offset), base_joint_name(b.name), b.base.pose.linear());
  std::vector<bool> base(N, false);
  for (const FreeBase& fb : r.bases)
    for (int i = 0; i < 6; ++i) base[static_cast<std::size_t>(fb.offset + i)] = true;
  for (std::size_t c = 0; c < N; ++c) {
    if (base[c]) continue;
    const int j = id_or_throw(m, mjOBJ_JOINT, mm.coordinates[c], "joint");
    r.qadr[c] = m->jnt_qposadr[j];
    r.vadr[c] = m->jnt_dofadr[j];
  }
}

void map_coordinates(Run& r, const scene::Scene& setup, const mech::MechanicalModel& mm) {
  const mjModel* m = r.m.get();
  map_joints(r, setup, mm);
  const int k = mm.num_constraints();
  r.row_body.assign(static_cast<std::size_t>(k), -1);
  r.row_local.assign(static_cast<std::size_t>(k), Vector3d::Zero());
  r.row_radius.assign(static_cast<std::size_t>(k), 0.0);
  r.row_normal.assign(static_cast<std::size_t>(k), Vector3d::UnitZ());
  r.row_t1.assign(static_cast<std::size_t>(k), Vector3d::UnitX());
  r.row_t2.assign(static_cast<std::size_t>(k), Vector3d::UnitY());
  if (!setup.bodies.empty()) r.geom_row.assign(static_cast<std::size_t>(m->ngeom), -1);
  if (!setup.bodies.empty())
    for (const auto& [name, range] : joint_ranges(setup))
      r.stops[id_or_throw(m, mjOBJ_JOINT, name, "joint")] = range;
  for (const auto& cf : setup.contacts) {
    const auto i = static_cast<std::size_t>(cf.row);
    r.row_local[i] = cf.point.local;
    r.row_radius[i] = cf.point.radius;
    r.row_normal[i] = cf.normal;
    r.row_t1[i] = cf.tangent1;
    r.row_t2[i] = cf.tangent2;
    if (setup.bodies.empty()) {
      r.row_body[i] = mj_name2id(m, mjOBJ_BODY, cf.point.link.c_str());
    } else {
      const int g = id_or_throw(m, mjOBJ_GEOM, row_geom_name(cf.row), "geom");
      r.geom_row[static_cast<std::size_t>(g)] = static_cast<int>(cf.row);
    }
  }
  // The scene's own forces (src/bullet/multibody_world.cpp's scene_forces).
  VectorXd q_ref = VectorXd::Zero(mm.dofs());
  for (int j = 0; j < mm.dofs(); ++j)
    if (const auto it = setup.q0.find(mm.coordinates[static_cast<std::size_t>(j)]);
        it != setup.q0.end())
      q_ref(j) = it->second;
  r.K_s = MatrixXd(mm.K) - setup.lin.K_g;
  r.f_s = mm.f - setup.lin.tau_g - setup.lin.K_g * q_ref;
  r.D = MatrixXd(mm.D);
}

void set_state(Run& r, const VectorXd& q, const VectorXd& v) {
  mjData* d = r.d.get();
  for (const FreeBase& fb : r.bases) {
    const Vector3d rv = q.segment<3>(fb.offset + 3);
    const Matrix3d R = scene::exp_so3(rv) * fb.R0;
    const Eigen::Quaterniond quat(R);
    for (int i = 0; i < 3; ++i) d->qpos[fb.q + i] = q(fb.offset + i);
    d->qpos[fb.q + 3] = quat.w();
    d->qpos[fb.q + 4] = quat.x();
    d->qpos[fb.q + 5] = quat.y();
    d->qpos[fb.q + 6] = quat.z();
    const Vector3d omega_local =
        R.transpose() * (scene::left_jacobian(rv) * v.segment<3>(fb.offset + 3));
    for (int i = 0; i < 3; ++i) {
      d->qvel[fb.v + i] = v(fb.offset + i);
      d->qvel[fb.v + 3 + i] = omega_local(i);
    }
  }
  for (std::size_t c = 0; c < r.qadr.size(); ++c) {
    if (r.qadr[c] < 0) continue;
    d->qpos[r.qadr[c]] = q(static_cast<int>(c));
    d->qvel[r.vadr[c]] = v(static_cast<int>(c));
  }
}

void get_state(const Run& r, VectorXd& q, VectorXd& v) {
  const mjData* d = r.d.get();
  for (const FreeBase& fb : r.bases) {
    const Eigen::Quaterniond quat(d->qpos[fb.q + 3], d->qpos[fb.q + 4], d->qpos[fb.q + 5],
                                  d->qpos[fb.q + 6]);
    const Matrix3d R = quat.normalized().toRotationMatrix();
    const Vector3d rv = scene::log_so3(R * fb.R0.transpose());
    const Vector3d omega_local(d->qvel[fb.v + 3], d->qvel[fb.v + 4], d->qvel[fb.v + 5]);
    for (int i = 0; i < 3; ++i) {
      q(fb.offset + i) = d->qpos[fb.q + i];
      v(fb.offset + i) = d->qvel[fb.v + i];
    }
    q.segment<3>(fb.offset + 3) = rv;
    v.segment<3>(fb.offset + 3) = scene::left_jacobian(rv).lu().solve(R * omega_local);
  }
  for (std::size_t c = 0; c < r.qadr.size(); ++c) {
    if (r.qadr[c] < 0) continue;
    q(static_cast<int>(c)) = d->qpos[r.qadr[c]];
    v(static_cast<int>(c)) = d->qvel[r.vadr[c]];
  }
}

// tau on the coordinates as qfrc_applied: a floating base's Q_p is the world
// force at the root origin, Q_r the torque J_l(r)^-T Q_r (world), given to
// MuJoCo in the root's frame.
void apply_forces(Run& r, const VectorXd& q, const VectorXd& tau) {
  mjData* d = r.d.get();
  mju_zero(d->qfrc_applied, r.m->nv);
  for (const FreeBase& fb : r.bases) {
    const Vector3d rv = q.segment<3>(fb.offset + 3);
    const Matrix3d R = scene::exp_so3(rv) * fb.R0;
    const Vector3d t_world =
        scene::left_jacobian(rv).transpose().lu().solve(tau.segment<3>(fb.offset + 3));
    const Vector3d t_local = R.transpose() * t_world;
    for (int i = 0; i < 3; ++i) {
      d->qfrc_applied[fb.v + i] = tau(fb.offset + i);
      d->qfrc_applied[fb.v + 3 + i] = t_local(i);
    }
  }
  for (std::size_t c = 0; c < r.vadr.size(); ++c)
    if (r.vadr[c] >= 0) d->qfrc_applied[r.vadr[c]] = tau(static_cast<int>(c));
}

// Each MuJoCo contact's force on the scene's contact point: its normal
// component in u, its components along the row's tangents t1, t2
// (scene::ContactFrame) in ut1, ut2 (N, by row of E). A scene of bodies has
// one geom per contact row; a one-URDF scene's contact goes to the contact
// point of the same body nearest to it. MuJoCo's contact frame has the
// normal from geom1 to geom2 and f is the force on geom2.
void contact_forces(const Run& r, VectorXd& u, VectorXd& ut1, VectorXd& ut2) {
  const mjModel* m = r.m.get();
  const mjData* d = r.d.get();
  u.setZero();
  ut1.setZero();
  ut2.setZero();
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& c = d->contact[i];
    mjtNum f[6];
    mj_contactForce(m, d, i, f);
    int best = -1;
    double sign = 1.0;  // the force on the point is sign times the force on geom2
    if (!r.geom_row.empty()) {
      const int r1 = r.geom_row[static_cast<std::size_t>(c.geom1)];
      const int r2 = r.geom_row[static_cast<std::size_t>(c.geom2)];
      best = r2 >= 0 ? r2 : r1;
      sign = r2 >= 0 ? 1.0 : -1.0;
    } else {
      const bool first_is_world = m->geom_bodyid[c.geom1] == 0;
      sign = first_is_world ? 1.0 : -1.0;
      const int g = first_is_world ? c.geom2 : c.geom1;
      const int body = m->geom_bodyid[g];
      const Vector3d pos(c.pos[0], c.pos[1], c.pos[2]);
      Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> R(d->xmat + 9 * body);
      const Vector3d x(d->xpos[3 * body], d->xpos[3 * body + 1], d->xpos[3 * body + 2]);
      double best_d = 0.0;
      for (std::size_t k = 0; k < r.row_body.size(); ++k) {
        if (r.row_body[k] != body) continue;
        const Vector3d p = x + R * r.row_local[k] - r.row_radius[k] * r.row_normal[k];
        const double dist = (p - pos).norm();
        if (best < 0 || dist < best_d) {
          best = static_cast<int>(k);
          best_d = dist;
        }
      }
    }
    if (best < 0) continue;
    u(best) += f[0];
    Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> frame(c.frame);
    const Vector3d force = sign * (frame.transpose() * Vector3d(f[0], f[1], f[2]));
    ut1(best) += r.row_t1[static_cast<std::size_t>(best)].dot(force);
    ut2(best) += r.row_t2[static_cast<std::size_t>(best)].dot(force);
  }
  // A scene of bodies' joint stops: each limit row's force (>= 0) on the side
  // its Jacobian says (+1 at the lower bound, -1 at the upper), per |c|.
  for (int i = 0; i < d->nefc; ++i) {
    if (d->efc_type[i] != mjCNSTR_LIMIT_JOINT) continue;
    const auto stop = r.stops.find(d->efc_id[i]);
    if (stop == r.stops.end()) continue;
    const int dof = m->jnt_dofadr[d->efc_id[i]];
    const bool lower = d->efc_J[static_cast<std::size_t>(i) * static_cast<std::size_t>(m->nv) +
                                static_cast<std::size_t>(dof)] > 0.0;
    const JointRange& jr = stop->second;
    const int row = lower ? jr.lower_row : jr.upper_row;
    if (row >= 0) u(row) += d->efc_force[i] / (lower ? jr.lower_scale : jr.upper_scale);
  }
}

// The run's record: samples, the mode by contact force, events at its
// changes (as src/bullet's RunRecorder), energies, the worst linear gap.
struct Recorder {
  const mech::MechanicalModel& mm;
  const sim::Options& opt;
  sim::Trajectory& tr;
  sim::OutputSampler sampler;
  sim::IndexSet mode;
  VectorXd ut1, ut2;  // the last step's tangential forces by row (N)
  void sample(double t, const VectorXd& q, const VectorXd& v, const VectorXd& u) {
    const VectorXd y = mm.E * q + mm.g;
    if (y.size() > 0) tr.max_violation = std::min(tr.max_violation, std::min(0.0, y.minCoeff()));
    if (!opt.record_samples) return;
    sim::Sample s;
    s.t = t;
    s.x.resize(2 * q.size());
    s.x << q, v;
    s.u = u;
    s.y = y;
    s.mode = mode;
    // Each friction entry's multipliers along its tangent rows (its contact
    // row's world tangents), as lcsim's own runs give them.
    if (!mm.friction.empty()) {
      const auto nf = static_cast<Eigen::Index>(mm.friction.size());
      s.u_t = VectorXd::Zero(nf);
      if (mm.has_friction_3d()) s.u_t2 = VectorXd::Zero(nf);
      for (Eigen::Index e = 0; e < nf && ut1.size() > 0; ++e) {
        const int row = mm.friction[static_cast<std::size_t>(e)].contact;
        s.u_t(e) = ut1(row);
        if (s.u_t2.size() > 0) s.u_t2(e) = ut2(row);
      }
    }
    tr.record_sample(std::move(s), opt);
  }
  void step(double t, const VectorXd& x_before, const VectorXd& q, const VectorXd& v,
            const VectorXd& u, double tiny) {
    sim::IndexSet now;
    for (int i = 0; i < u.size(); ++i)
      if (u(i) > tiny) now.push_back(i);
    if (now != mode) {
      sim::Event e;
      e.t = t;
      e.state_before = x_before;
      e.state_after.resize(2 * q.size());
      e.state_after << q, v;
      e.mode_after = now;
      bool gained = false;
      for (int i : now)
        if (std::find(mode.begin(), mode.end(), i) == mode.end()) gained = true;
      e.type = gained ? sim::EventType::kImpact : sim::EventType::kRelease;
      tr.events.push_back(std::move(e));
      mode = now;
    }
    ++tr.steps;
    ++tr.lcp_solves;
  }
};

// check_expressible (throws), then the scene's MuJoCo model set up and
// mapped; std::invalid_argument when MuJoCo cannot load it.
void prepare(Run& r, const mech::Model& model, const Settings& s, double h) {
  check_expressible(model);
  const std::optional<scene::Scene> setup = scene::load_scene_details(model.source);
  r.m = setup->bodies.empty() ? load_scene_model(*setup) : load_bodies_model(*setup);
  configure(r, *setup, *model.mechanical, s, h);
  map_coordinates(r, *setup, *model.mechanical);
}

}  // namespace

double mj_step_time(const mech::Model& model, const VectorXd& x0, double h, long steps,
                    const Settings& s) {
  mju_user_warning = [](const char*) {};
  Run r;
  prepare(r, model, s, h);
  r.d = MjDataPtr(mj_makeData(r.m.get()));
  const int N = model.mechanical->dofs();
  const VectorXd q = x0.head(N), v = x0.tail(N);
  set_state(r, q, v);
  apply_forces(r, q, r.f_s - r.K_s * q - r.D * v);
  const auto t0 = std::chrono::steady_clock::now();
  for (long j = 0; j < steps; ++j) mj_step(r.m.get(), r.d.get());
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return wall / static_cast<double>(std::max(1L, steps));
}

// The step, and MuJoCo's own contacts and friction (Settings::cone) at a
// scene's contacts: check_expressible refuses friction anywhere else.
namespace {
sim::OptionsUsed mujoco_options_used() {
  sim::OptionsUsed u;
  u.h = u.needs_mechanical = u.friction = u.friction_3d = true;
  return u;
}
}  // namespace

// It is one piece: the step loop's stages (forces, mj_step, read back, record,
// divergence) share the run's state and read in order.
sim::Trajectory simulate_mujoco(const mech::Model& model, const VectorXd& x0,
                                const sim::Options& options, const Settings& s) {
  sim::Options opt = options;
  if (auto refused = sim::refuse_invalid_run(model, x0, opt, "mujoco", mujoco_options_used()))
    return std::move(*refused);
  sim::Trajectory tr;
  tr.method = "mujoco " + settings_description(s, opt.h, model.mechanical->has_friction());
  tr.dynamics = "the URDF's nonlinear multibody (MuJoCo)";
  tr.t_end = *opt.t_end;
  tr.final_state = x0;
  if (std::string why = settings_error(s); !why.empty()) {
    tr.status = sim::RunStatus::kInvalidInput;
    tr.message = why;
    return tr;
  }
  // MuJoCo prints its warnings by default; the run reads them from
  // mjData::warning (a bad acceleration ends it as a numerical failure).
  mju_user_warning = [](const char*) {};
  const auto wall0 = std::chrono::steady_clock::now();
  const mech::MechanicalModel& mm = *model.mechanical;
  Run r;
  try {
    prepare(r, model, s, opt.h);
  } catch (const std::invalid_argument& e) {
    tr.status = sim::RunStatus::kInvalidInput;
    tr.message = e.what();
    return tr;
  }
  for (int i = 0; i < mm.num_constraints(); ++i)
    if (mm.restitution(i) > 0.0) {
      tr.warn("mujoco-restitution-lost", 0.0,
              "mujoco: restitution is lost: MuJoCo's contacts are damped "
              "springs (solref), "
              "constraint '" +
                  mm.constraints[static_cast<std::size_t>(i)] +
                  "' has e = " + short_number(mm.restitution(i)));
      break;
    }
  r.d = MjDataPtr(mj_makeData(r.m.get()));
  const int N = mm.dofs(), k = mm.num_constraints();
  VectorXd q = x0.head(N), v = x0.tail(N), u = VectorXd::Zero(k);
  set_state(r, q, v);
  mj_forward(r.m.get(), r.d.get());
  tr.energy_initial = mech::total_energy(mm, q, v);
  tr.max_violation = 0.0;
  Recorder rec{
      mm, opt, tr, sim::OutputSampler(opt.dt_out), {}, VectorXd::Zero(k), VectorXd::Zero(k)};
  rec.sample(0.0, q, v, u);
  sim::DivergenceGuard guard(model, x0, *opt.t_end);
  const sim::StepGrid grid = sim::StepGrid::of(*opt.t_end, opt.h);
  const double weight = (mm.f.cwiseAbs().sum() + 1.0);
  VectorXd x_before(2 * N);
  for (long j = 1; j <= grid.n; ++j) {
    const bool last = j == grid.n;
    const double h = last ? grid.h_last : grid.h;
    const double t = last ? *opt.t_end : j * opt.h;
    r.m->opt.timestep = h;
    x_before << q, v;
    apply_forces(r, q, r.f_s - r.K_s * q - r.D * v);
    mj_step(r.m.get(), r.d.get());
    contact_forces(r, u, rec.ut1, rec.ut2);
    get_state(r, q, v);
    std::string why = r.d->warning[mjWARN_BADQACC].number > 0
                          ? "diverged at t = " + short_number(t) +
                                ": MuJoCo's accelerations are not finite (mjWARN_BADQACC)"
                          : guard.check(t, q, v, last);
    if (!why.empty()) {
      tr.status = sim::RunStatus::kNumericalFailure;
      tr.message = "mujoco: " + why;
      tr.t_end = t - h;
      tr.final_state = x_before;
      return tr;
    }
    rec.step(t, x_before, q, v, u, 1e-9 * weight);
    if (rec.sampler.want(t, opt.h, last)) rec.sample(t, q, v, u);
  }
  tr.final_state.resize(2 * N);
  tr.final_state << q, v;
  tr.energy_final = mech::total_energy(mm, q, v);
  tr.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  sim::check_diverged(model, x0, tr);
  return tr;
}

namespace {

class MujocoIntegrator : public sim::Integrator {
 public:
  std::string name() const override { return "mujoco"; }
  sim::OptionsUsed options_used() const override { return mujoco_options_used(); }

 protected:
  std::string refusal(const mech::Model& model) const override {
    try {
      check_expressible(model);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  }
  sim::Trajectory integrate(const mech::Model& model, const VectorXd& x0,
                            const sim::Options& opt) const override {
    return simulate_mujoco(model, x0, opt);
  }
};

}  // namespace

void register_backends() {
  sim::integrators().add("mujoco", [] { return std::make_unique<MujocoIntegrator>(); });
}

}  // namespace lcsim::mujoco
