// Bullet's friction box beside lcsim's Moreau–Jean on a block sliding on a
// rough floor (issue 17, docs/friction.md): stop time and slide
// distance against the closed form t* = |v0| / (mu g), d = v0^2 / (2 mu g) at
// h = 1e-2 ... 1e-4, and the observed orders (least-squares slope of
// log |error| against log h over the step sizes with a nonzero error). Run
// from the source directory:
//   build/bench/table_friction_bullet [robots/block_on_floor_friction.yaml]
#include <cmath>
#include <cstdio>
#include <lcsim/bullet/bullet.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>
#include <vector>

using namespace lcsim;

namespace {

const double kSteps[] = {1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 1e-4};

struct Row {
  double h = 0.0;
  bullet::SlideStop bullet, mj;
  int min_points = 0, max_points = 0;
  double max_tilt = 0.0, max_gap = 0.0, max_v_after = 0.0;
};

// Moreau–Jean through the registry, as `lcsim simulate --method moreau-jean`.
bullet::SlideStop mj_stop(const mech::Model& model, const bullet::FrictionBlock& b, double h,
                          double v_tol) {
  sim::Options o;
  o.t_end = b.t_end;
  o.h = h;
  const sim::Trajectory tr = sim::integrators().make("moreau-jean")->run(model, model.initial, o);
  if (tr.status != sim::RunStatus::kCompleted) {
    std::fprintf(stderr, "moreau-jean at h = %g: %s\n", h, tr.message.c_str());
    return {};
  }
  std::vector<double> t, x, v;
  for (const sim::Sample& s : tr.samples) {
    t.push_back(s.t);
    x.push_back(s.x(b.tangent_coordinate));
    v.push_back(s.x(2 + b.tangent_coordinate));
  }
  return bullet::slide_stop(t, x, v, v_tol);
}

Row measure(const mech::Model& model, const bullet::FrictionBlock& b, double h,
            bullet::FrictionBoxSettings s) {
  Row r;
  r.h = h;
  s.h = h;
  const bullet::FrictionBoxRun run = bullet::simulate_friction_box(b, s);
  if (run.status != Status::kOk) std::fprintf(stderr, "bullet: %s\n", run.message.c_str());
  r.bullet = run.stop;
  r.min_points = 1 << 30;
  for (std::size_t j = 1; j < run.samples.size(); ++j) {
    const bullet::FrictionBoxSample& p = run.samples[j];
    r.min_points = std::min(r.min_points, p.contact_points);
    r.max_points = std::max(r.max_points, p.contact_points);
    r.max_tilt = std::max(r.max_tilt, std::abs(p.tilt));
    r.max_gap = std::max(r.max_gap, std::abs(p.gap));
    if (p.t > run.stop.time) r.max_v_after = std::max(r.max_v_after, std::abs(p.v));
  }
  r.mj = mj_stop(model, b, h, s.stop_velocity);
  return r;
}

// Least-squares slope of log |e| against log h (entries with e != 0).
double order(const std::vector<Row>& rows, double (*err)(const Row&)) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int n = 0;
  for (const Row& r : rows) {
    const double e = std::abs(err(r));
    if (!(e > 0.0)) continue;
    const double lx = std::log(r.h), ly = std::log(e);
    sx += lx;
    sy += ly;
    sxx += lx * lx;
    sxy += lx * ly;
    ++n;
  }
  if (n < 2) return NAN;
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

double g_tstar = 0.0, g_dist = 0.0;
double bt(const Row& r) { return r.bullet.time - g_tstar; }
double bd(const Row& r) { return r.bullet.distance - g_dist; }
double mt(const Row& r) { return r.mj.time - g_tstar; }
double md(const Row& r) { return r.mj.distance - g_dist; }

void print(const std::vector<Row>& rows) {
  std::printf(
      "| h | Bullet t - t* | Bullet d - d* | MJ t - t* | MJ d - d* | Bullet - MJ t |"
      " Bullet - MJ d | Bullet points | max tilt (rad) | max abs gap (m) |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Row& r : rows)
    std::printf("| %g | %.3e | %.3e | %.3e | %.3e | %.3e | %.3e | %d-%d | %.1e | %.1e |\n", r.h,
                bt(r), bd(r), mt(r), md(r), r.bullet.time - r.mj.time,
                r.bullet.distance - r.mj.distance, r.min_points, r.max_points, r.max_tilt,
                r.max_gap);
  std::printf("\nobserved order (least-squares slope of log|error| vs log h):\n");
  std::printf("  Bullet: stop time %.2f, distance %.2f\n", order(rows, bt), order(rows, bd));
  std::printf("  Moreau-Jean: stop time %.2f, distance %.2f\n\n", order(rows, mt), order(rows, md));
}

}  // namespace

int main(int argc, char** argv) {
  const std::string path = argc > 1 ? argv[1] : "robots/block_on_floor_friction.yaml";
  const mech::Model model = scene::load_model(path);
  const bullet::FrictionBlockOf of = bullet::friction_block_of(model);
  if (of.status != Status::kOk) {
    std::fprintf(stderr, "%s\n", of.message.c_str());
    return 2;
  }
  const bullet::FrictionBlock& b = of.block;
  g_tstar = b.stop_time();
  g_dist = b.slide_distance();
  std::printf("%s: m = %g kg, mu = %g, g = %g m/s^2, v0 = %g m/s, %s\n", path.c_str(), b.mass, b.mu,
              b.gravity, b.v0, bullet::version_string().c_str());
  std::printf("closed form: t* = %.9g s, d = %.9g m\n\n", g_tstar, g_dist);
  // The default scene, then the settings it was chosen against.
  struct Variant {
    const char* what;
    int multipoint_iterations;
    bool free_rotation;
  };
  const Variant variants[] = {
      {"default settings (multipoint_iterations 8, free rotation)", 8, true},
      {"multipoint_iterations 4, free rotation", 4, true},
      {"multipoint_iterations 0 (Bullet's default contact generation), free rotation", 0, true},
      {"multipoint_iterations 0, translation only (free_rotation false)", 0, false},
  };
  for (const Variant& var : variants) {
    std::printf("Bullet, %s:\n\n", var.what);
    bullet::FrictionBoxSettings s;
    s.multipoint_iterations = var.multipoint_iterations;
    s.free_rotation = var.free_rotation;
    std::vector<Row> rows;
    for (double h : kSteps) rows.push_back(measure(model, b, h, s));
    print(rows);
  }
  return 0;
}
