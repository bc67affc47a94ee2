// The exact method with 3-D friction (issue 27's target: the box sliding at
// an angle, to rest, in under 100 us) beside Moreau–Jean at h = 1e-3 on the
// same run, in one process: time per run and error against the closed form
// mech::cone_slide.
//
// The box: m = 4 kg, translating and tilting (x, y, z, rx, ry), on its four
// corners (+-0.3, +-0.2) m with its centre of mass at the floor, mu = 0.3,
// d = 4, from 1 m/s at psi = 0.3 pi/d (between an edge and a bisector: one
// turn onto the bisector, then the stop), horizon t_stop + 0.1 s; events
// only (dt_out = 0) for the exact method, every step kept by Moreau–Jean
// (its samples are its steps). A point mass (x, y, z) on one contact is
// timed too. Times: the fastest of R runs (steady_clock), so the load of the
// shared machine inflates them least.
//
//   ./build/bench/table_event_friction3d [R]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <lcsim/mech/cone_slide.hpp>
#include <lcsim/sim/sim.hpp>
#include <numbers>
#include <string>

namespace {

using Eigen::VectorXd;
using lcsim::mech::MechanicalModel;

constexpr double kG = 9.81, kMu = 0.3, kS0 = 1.0;
constexpr int kD = 4;

lcsim::mech::Model box4() {
  const double m = 4.0, a = 0.3, b = 0.2;
  MechanicalModel mm;
  mm.M = Eigen::Matrix<double, 5, 1>(m, m, m, 0.1, 0.2).asDiagonal().toDenseMatrix().sparseView();
  Eigen::MatrixXd E(4, 5);
  int r = 0;
  for (double cx : {-a, a})
    for (double cy : {-b, b}) E.row(r++) << 0, 0, 1, cy, -cx;
  mm.E = E.sparseView();
  mm.f = (VectorXd(5) << 0, 0, -m * kG, 0, 0).finished();
  for (int c = 0; c < 4; ++c) {
    lcsim::mech::FrictionalContact fc(c, (VectorXd(5) << 1, 0, 0, 0, 0).finished(), kMu);
    fc.tangent2 = (VectorXd(5) << 0, 1, 0, 0, 0).finished().sparseView();
    fc.edges = kD;
    mm.friction.push_back(fc);
  }
  return lcsim::mech::model_of(mm, "box4");
}

lcsim::mech::Model point_mass() {
  MechanicalModel mm;
  mm.M = Eigen::MatrixXd::Identity(3, 3).sparseView();
  mm.E = Eigen::RowVector3d(0, 0, 1).sparseView();
  mm.f = Eigen::Vector3d(0, 0, -kG);
  lcsim::mech::FrictionalContact fc(0, Eigen::Vector3d(1, 0, 0), kMu);
  fc.tangent2 = Eigen::Vector3d(0, 1, 0).sparseView();
  fc.edges = kD;
  mm.friction.push_back(fc);
  return lcsim::mech::model_of(mm, "point_mass");
}

struct Timed {
  lcsim::sim::Trajectory tr;
  double us = 1e300;  // fastest run (microseconds)
};

Timed time_runs(const lcsim::mech::Model& model, const VectorXd& x0, const lcsim::sim::Options& o,
                const std::string& method, int R) {
  Timed t;
  const auto integ = lcsim::sim::make_integrator(method);
  for (int i = 0; i < R; ++i) {
    const auto start = std::chrono::steady_clock::now();
    lcsim::sim::Trajectory tr = integ->run(model, x0, o);
    const auto end = std::chrono::steady_clock::now();
    t.us = std::min(t.us, std::chrono::duration<double, std::micro>(end - start).count());
    if (i == 0) t.tr = std::move(tr);
  }
  return t;
}

// The first sample at rest (tangential speed <= 1e-12 s0) and its position.
void stop_of(const lcsim::sim::Trajectory& tr, int N, double& t, double& x, double& y) {
  t = x = y = NAN;
  for (const lcsim::sim::Sample& s : tr.samples)
    if (s.t > 0 && std::hypot(s.x(N), s.x(N + 1)) <= 1e-12 * kS0) {
      t = s.t, x = s.x(0), y = s.x(1);
      return;
    }
}

void row(const char* name, const lcsim::mech::Model& model, int R) {
  const int N = model.mechanical->dofs();
  const double psi = 0.3 * std::numbers::pi / kD;
  const lcsim::mech::ConeSlide cf = lcsim::mech::cone_slide(kS0, psi, kMu, kG, kD);
  VectorXd x0 = VectorXd::Zero(2 * N);
  x0(N) = kS0 * std::cos(psi), x0(N + 1) = kS0 * std::sin(psi);
  lcsim::sim::Options o;
  o.t_end = cf.t_stop + 0.1;
  const Timed ev = time_runs(model, x0, o, "event", R);
  lcsim::sim::Options om = o;
  om.h = 1e-3;
  om.dt_out = 1e-3;
  const Timed mj = time_runs(model, x0, om, "moreau-jean", std::max(1, R / 10));
  if (!ev.tr.ok() || !mj.tr.ok()) {
    std::printf("%s: a run failed: %s %s\n", name, ev.tr.message.c_str(), mj.tr.message.c_str());
    std::exit(1);
  }
  const double et = ev.tr.events.back().t - cf.t_stop;
  const double ex = std::hypot(ev.tr.final_state(0) - cf.x, ev.tr.final_state(1) - cf.y);
  double mt, mx, my;
  stop_of(mj.tr, N, mt, mx, my);
  std::printf("| %s | event | %.1f | %zu events | %.1e | %.1e |\n", name, ev.us,
              ev.tr.events.size(), et, ex);
  std::printf("| %s | moreau-jean h = 1e-3 | %.1f | %zu samples | %.1e | %.1e |\n", name, mj.us,
              mj.tr.samples.size(), mt - cf.t_stop, std::hypot(mx - cf.x, my - cf.y));
  std::printf("| %s | ratio MJ / event | %.1f | | | |\n", name, mj.us / ev.us);
}

}  // namespace

int main(int argc, char** argv) {
  const int R = argc > 1 ? std::atoi(argv[1]) : 200;
  std::printf(
      "| model | method | us per run (fastest of runs) | work | stop time error (s) | "
      "rest position error (m) |\n|---|---|---|---|---|---|\n");
  row("box on four corners", box4(), R);
  row("point mass", point_mass(), R);
  return 0;
}
