// `lcsim compare MODEL --h H`: the model run in Bullet beside lcsim's exact
// event-driven solution of the nearest exact law (sim::reference_law: the
// inelastic one when the model has restitution, which Bullet loses at the
// scene's stop ERP) (bullet::compare_trajectories):
//   deviation_max  largest max-abs state difference over the Bullet samples
//                  (on a grid that is a multiple of h, at most ~2000 points;
//                  the exact run is sampled on the same grid),
//   error_final    max-abs difference of the final states,
//   event_shifts   Bullet's constraint switches (first step with a nonzero
//                  impulse, first step without) matched in order with the
//                  exact switches: t_bullet - t_exact,
//   energy_drift   Bullet's (E_final - E_initial) minus the exact run's (J),
//   max_violation  Bullet's most negative gap,
//   bullet_solver  which Bullet constraint solver ran.
// `--peer mujoco` runs a contact scene in MuJoCo instead (mujoco::simulate_mujoco),
// compared the same way.
// A contact scene with friction at its contacts runs with the peer's own
// friction (--bullet-friction, --mujoco-cone; reported in bullet_solver).
// --peer-out writes the peer's samples as a trajectory CSV (with the
// friction multipliers along each contact's two tangents).
// Any other model with friction must be a block on a floor (bullet::friction_block_of):
// Bullet's box on a plane runs beside the exact run, and the stick times and
// slide distances of the closed form, the exact run and Bullet are printed.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <lcsim/app/run.hpp>
#include <lcsim/bullet/bullet.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/linearisation.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/reference.hpp>
#include <lcsim/sim/sim.hpp>
#include <memory>
#include <nlohmann/json.hpp>
#ifdef LCSIM_HAS_MUJOCO
#include <lcsim/mujoco/mujoco.hpp>
#endif

#include "cli/command.hpp"
#include "cli/flag_names.hpp"
#include "cli/output.hpp"
#include "cli/run_inputs.hpp"

namespace lcsim::cli {
namespace {

struct CompareArgs {
  std::string model;
  std::string x0;
  double t_end = std::nan("");
  bool t_end_given = false;  // --t-end nan is an error, not the model's horizon
  double h = 1e-3;
  bool json = false;
  double stop_erp = bullet::WorldSettings{}.stop_erp;
  int iterations = bullet::WorldSettings{}.solver_iterations;
  std::string peer = "bullet";  // or "mujoco"
  // Friction at a contact scene's contacts: Bullet's model
  // (bullet::parse_friction) and MuJoCo's cone (mujoco::parse_cone).
  std::string bullet_friction = "cone";
  std::string mujoco_cone = "pyramidal";
  // The peer's samples (on the comparison grid) as a trajectory CSV, its
  // friction multipliers u_t, u_t2 among them; "" = none.
  std::string peer_out;
};

// A block on a floor with friction: Bullet's box beside the exact run
// (bullet::compare_friction_box), along the floor.
void print_friction(const mech::Model& model, const CompareArgs& a,
                    const bullet::FrictionComparison& c) {
  const bullet::SlideStop* stops[] = {&c.closed_form, &c.exact, &c.bullet};
  const char* names[] = {"closed form", "exact run", "bullet"};
  if (a.json) {
    nlohmann::json j;
    j["model"] = model.name;
    j["h"] = a.h;
    j["t_end"] = c.block.t_end;
    j["bullet_scene"] = "friction box";
    for (int i = 0; i < 3; ++i)
      j["stop"][names[i]] = {{"time", io::finite_or_null(stops[i]->time)},
                             {"distance", io::finite_or_null(stops[i]->distance)}};
    j["deviation_max"] = c.deviation_max;
    j["deviation_t"] = c.deviation_t;
    j["error_final"] = c.error_final;
    j["max_tilt"] = c.max_tilt;
    j["min_contact_points"] = c.min_contact_points;
    j["bullet_version"] = bullet::version_string();
    j["steps"] = c.steps;
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  std::printf(
      "model %s, t_end %g, h %g: %s, a box on a plane (sequential impulse, %d iterations)\n",
      model.name.c_str(), c.block.t_end, a.h, bullet::version_string().c_str(), a.iterations);
  std::printf("               stick time      slide distance  (NaN: still sliding)\n");
  for (int i = 0; i < 3; ++i)
    std::printf("%-14s %-15.9g %-15.9g\n", names[i], stops[i]->time, stops[i]->distance);
  std::printf("deviation max  %.3e (position and velocity along the floor, at t = %.6g)\n",
              c.deviation_max, c.deviation_t);
  std::printf("error final    %.3e\n", c.error_final);
  std::printf("bullet's box   tilts at most %.3e rad, on at least %d contact points\n", c.max_tilt,
              c.min_contact_points);
}

// What is printed of Bullet's run beside the comparison.
struct BulletRun {
  const sim::Trajectory& trajectory;
  std::string peer;  // "Bullet 3.24 (double precision)", "MuJoCo 2.2.2"
  std::string name() const { return peer.substr(0, peer.find(' ')); }  // "Bullet", "MuJoCo"
  std::string solver;                                                  // bullet::solver_description
  double stop_erp = 0.0;
  double t_end = 0.0;  // the horizon (s)
  double per_step() const {
    return trajectory.steps ? trajectory.wall_time_s / trajectory.steps : 0.0;
  }
};

void print_comparison_json(const mech::Model& model, const CompareArgs& a, const BulletRun& bt,
                           const sim::ReferenceLaw& law, const bullet::Comparison& c) {
  nlohmann::json j;
  j["model"] = model.name;
  j["h"] = a.h;
  j["t_end"] = bt.t_end;
  j["deviation_max"] = io::finite_or_null(c.deviation_max);
  j["deviation_t"] = c.deviation_t;
  j["error_final"] = io::finite_or_null(c.error_final);
  nlohmann::json shifts = nlohmann::json::array();
  for (const auto& s : c.event_shifts)
    shifts.push_back({{"constraint", model.mechanical->constraints[s.constraint]},
                      {"kind", s.activation ? "activation" : "release"},
                      {"t_exact", s.t_exact},
                      {"t_bullet", io::finite_or_null(s.t_other)},
                      {"shift", io::finite_or_null(s.shift)}});
  j["event_shifts"] = std::move(shifts);
  j["unmatched_bullet_switches"] = c.unmatched_other;
  j["energy_drift"] = c.energy_drift;
  j["max_violation"] = c.max_violation;
  j["reference_law"] = law.label();
  j["reference_reason"] = law.reason;
  j["peer"] = a.peer;
  j["bullet_solver"] = bt.solver;  // the peer's settings (kept under this key for Bullet's)
  j["stop_erp"] = bt.stop_erp;
  j["bullet_version"] = bt.peer;
  j["steps"] = bt.trajectory.steps;
  j["wall_time_per_step_s"] = bt.per_step();
  std::printf("%s\n", j.dump(2).c_str());
}

void print_comparison_text(const mech::Model& model, const CompareArgs& a, const BulletRun& bt,
                           const sim::ReferenceLaw& law, const bullet::Comparison& c) {
  // The scene's own ERP (rb6's stop ERP, the multibody's limit ERP) is in
  // bullet_solver.
  std::printf("model %s, t_end %g, h %g: %s, %s\n", model.name.c_str(), bt.t_end, a.h,
              bt.peer.c_str(), bt.solver.c_str());
  std::printf("reference      exact run, %s (%s)\n", law.label().c_str(), law.reason.c_str());
  std::printf("deviation max  %.3e (at t = %.6g)\n", c.deviation_max, c.deviation_t);
  std::printf("error final    %.3e\n", c.error_final);
  const std::string who = bt.name();
  std::printf("energy drift   %.3e J (%s's change minus the exact change)\n", c.energy_drift,
              who.c_str());
  std::printf("max violation  %.3e\n", c.max_violation);
  std::printf("time per step  %.3g s (%ld steps)\n", bt.per_step(), bt.trajectory.steps);
  std::printf("event shifts (t_%s - t_exact):\n", a.peer.c_str());
  for (const auto& s : c.event_shifts) {
    std::printf("  %-10s %-10s t_exact %-14.9g ",
                model.mechanical->constraints[s.constraint].c_str(),
                s.activation ? "activation" : "release", s.t_exact);
    if (std::isfinite(s.t_other))
      std::printf("t_%s %-14.9g shift %.3e\n", a.peer.c_str(), s.t_other, s.shift);
    else
      std::printf("no %s switch\n", who.c_str());
  }
  if (c.unmatched_other)
    std::printf("  (%d %s switches match no exact switch)\n", c.unmatched_other, who.c_str());
}

// The runs' options: the horizon, Bullet's h, and the comparison grid (left
// at 0 for an h the runs will refuse; h is checked by them, sim::check_run).
sim::Options compare_options(const CompareArgs& a, const mech::Model& model) {
  sim::Options opt;
  opt.t_end = resolve_horizon(model, a.model, a.t_end_given, a.t_end);
  opt.h = a.h;
  if (std::isfinite(a.h) && a.h > 0.0) opt.dt_out = app::comparison_grid(*opt.t_end, a.h);
  return opt;
}

// One run of the pair (app::run_model), its samples on the comparison grid
// kept for the pairing; exits (check_status) unless it completed.
sim::Trajectory compare_run(const scene::LoadedModel& loaded, app::RunRequest req,
                            const std::string& what) {
  req.keep_samples = true;
  app::ModelRun run = app::run_model(loaded, req);
  check_status(run.trajectory.status,
               "compare: the " + what + " run failed: " + with_flag_names(run.trajectory.message));
  // A scene's linear model checked at the run's states, as `simulate`
  // checks its run (default threshold).
  if (!run.linearisation_warning.empty())
    std::cerr << "lcsim: warning: " << run.linearisation_warning << "\n";
  return std::move(run.trajectory);
}

// Bullet's run on the comparison grid, paired with the exact run.
void compare_bullet(const scene::LoadedModel& loaded, const CompareArgs& a, app::RunRequest req,
                    const sim::ReferenceLaw& law, const sim::Trajectory& exact) {
  const mech::Model& model = loaded.model;
  bullet::WorldSettings ws;
  ws.stop_erp = a.stop_erp;
  ws.solver_iterations = a.iterations;
  ws.friction = bullet::parse_friction(a.bullet_friction);
  if (std::string why = bullet::settings_error(ws); !why.empty()) throw io::InputError(why);
  const std::string bullet_solver = bullet::solver_description(model, ws);
  req.runner = [&ws](const mech::Model& m, const Eigen::VectorXd& x0, const sim::Options& opt) {
    return bullet::simulate_bullet(m, x0, opt, ws);
  };
  req.check_linearisation = false;  // the exact run's states are checked
  req.csv_path = a.peer_out;
  const sim::Trajectory bt = compare_run(loaded, req, "Bullet");
  const bullet::Comparison c = bullet::compare_trajectories(exact, bt, 1e-9 * a.h);
  // What the Bullet scene does differently (lost restitution, explicit
  // springs, a scene run as rb6), as `simulate` prints it.
  print_warnings(bt);
  const BulletRun run{bt, bullet::version_string(), bullet_solver, ws.stop_erp, *req.options.t_end};
  if (a.json)
    print_comparison_json(model, a, run, law, c);
  else
    print_comparison_text(model, a, run, law, c);
}

#ifdef LCSIM_HAS_MUJOCO
// MuJoCo's run on the comparison grid, paired with the exact run (the
// pairing of bullet::compare_trajectories; MuJoCo's switches are its
// contact points' first and last steps with a force).
void compare_mujoco(const scene::LoadedModel& loaded, const CompareArgs& a, app::RunRequest req,
                    const sim::Trajectory& exact) {
  const mech::Model& model = loaded.model;
  mujoco::Settings ms;
  ms.cone = mujoco::parse_cone(a.mujoco_cone);
  req.runner = [&ms](const mech::Model& m, const Eigen::VectorXd& x0, const sim::Options& opt) {
    return mujoco::simulate_mujoco(m, x0, opt, ms);
  };
  req.check_linearisation = false;  // the exact run's states are checked
  req.csv_path = a.peer_out;
  const sim::Trajectory mj = compare_run(loaded, req, "MuJoCo");
  const bullet::Comparison c = bullet::compare_trajectories(exact, mj, 1e-9 * a.h);
  print_warnings(mj);
  const sim::ReferenceLaw law = sim::reference_law("mujoco", req.options.impact, model);
  const BulletRun run{mj, mujoco::version_string(),
                      mujoco::settings_description(ms, a.h, model.mechanical->has_friction()), 0.0,
                      *req.options.t_end};
  if (a.json)
    print_comparison_json(model, a, run, law, c);
  else
    print_comparison_text(model, a, run, law, c);
}
#endif

// `--peer mujoco`: the exact run beside MuJoCo's.
void run_compare_mujoco(const scene::LoadedModel& loaded, const CompareArgs& a) {
#ifdef LCSIM_HAS_MUJOCO
  const mech::Model& model = loaded.model;
  mujoco::check_expressible(model);         // invalid_argument naming it: exit 2
  (void)mujoco::parse_cone(a.mujoco_cone);  // before anything runs
  app::RunRequest req;
  req.x0 = resolve_initial_state(model, a.model, a.x0);
  req.options = compare_options(a, model);
  const sim::ReferenceLaw law = sim::reference_law("mujoco", req.options.impact, model);
  app::RunRequest exact_req = req;
  exact_req.runner = app::reference_runner(law);
  const sim::Trajectory exact = compare_run(loaded, exact_req, "exact event-driven");
  compare_mujoco(loaded, a, req, exact);
#else
  (void)loaded;
  (void)a;
  throw io::InputError("peer: this lcsim was built without MuJoCo (libmujoco-dev not found)");
#endif
}

void run_compare(const CompareArgs& a) {
  if (a.peer != "bullet" && a.peer != "mujoco")
    throw io::InputError("peer: unknown peer '" + a.peer + "' (bullet, mujoco)");
  const scene::LoadedModel loaded = scene::load_model_and_scene(a.model);
  if (a.peer == "mujoco") return run_compare_mujoco(loaded, a);
  const mech::Model& model = loaded.model;
  // A block on a floor with friction (a matrix model) runs as Bullet's box on
  // a plane; a contact scene with friction at its contacts as its multibody.
  const bool friction =
      model.is_mechanical() && !model.mechanical->friction.empty() && !loaded.scene;
  (void)bullet::parse_friction(a.bullet_friction);  // before anything runs
  if (!friction) bullet::check_expressible(model);  // invalid_argument naming it: exit 2
  app::RunRequest req;
  req.x0 = resolve_initial_state(model, a.model, a.x0);
  req.options = compare_options(a, model);
  // Like with like (issue 13): Bullet loses restitution at the scene's stop
  // ERP, so its exact counterpart is the nearest exact law (sim::reference_law).
  const sim::ReferenceLaw law = sim::reference_law("bullet", req.options.impact, model);
  app::RunRequest exact_req = req;
  exact_req.runner = app::reference_runner(law);
  const sim::Trajectory exact = compare_run(loaded, exact_req, "exact event-driven");
  if (!friction) return compare_bullet(loaded, a, req, law, exact);
  bullet::FrictionBoxSettings fs;
  fs.h = a.h;
  fs.solver_iterations = a.iterations;
  const bullet::FrictionComparison c =
      bullet::compare_friction_box(model, *req.x0, exact, fs, 1e-9 * a.h);
  check_status(c.status, "compare: " + c.message);
  print_friction(model, a, c);
}

void setup(CLI::App& app) {
  auto a = std::make_shared<CompareArgs>();
  auto* cmd = app.add_subcommand(
      "compare", "Run a model in Bullet beside the exact event-driven solution and compare");
  cmd->add_option("model", a->model, "Model file (YAML)")->required();
  cmd->add_option("--x0", a->x0, "Initial state a,b,... (q then v); default: the model's");
  auto* t_end = cmd->add_option("--t-end", a->t_end, "Horizon (s); default: the model's t_end");
  cmd->add_option("--h", a->h, "Bullet's time step (s); default 1e-3");
  cmd->add_option("--stop-erp", a->stop_erp,
                  "ERP of Bullet's 6DOF2 limits in (0, 1] (rb6 scenes only); default 0.2");
  cmd->add_option("--iterations", a->iterations, "Bullet solver iterations; default 100");
  cmd->add_option("--peer", a->peer,
                  "The peer: bullet (default) or mujoco (contact scenes; MuJoCo's soft contacts)");
  cmd->add_option("--bullet-friction", a->bullet_friction,
                  "Bullet's friction at a contact scene's contacts: cone (default: two "
                  "directions, implicit cone), box (two directions, each bounded alone) or "
                  "one-direction (Bullet's default single row)");
  cmd->add_option("--mujoco-cone", a->mujoco_cone,
                  "MuJoCo's friction cone at a contact scene's contacts: pyramidal (default, "
                  "MuJoCo's) or elliptic");
  cmd->add_option("--peer-out", a->peer_out,
                  "Write the peer's samples (on the comparison grid) as a trajectory CSV, its "
                  "friction multipliers u_t, u_t2 per contact among them");
  cmd->add_flag("--json", a->json, "Print the comparison as JSON");
  cmd->callback([a, t_end] {
    a->t_end_given = t_end->count() > 0;
    run_compare(*a);
  });
}

LCSIM_REGISTER_COMMAND(setup);

}  // namespace
}  // namespace lcsim::cli
