// The box sliding on the floor at a heading (issues 27 item 6 and 26): lcsim's
// exact method (d = 4, 16), Moreau-Jean, Bullet's btMultiBody (its cone and
// box friction) and MuJoCo (pyramidal and elliptic cones) beside the closed
// forms, every figure from one run of this program.
//
// The scene: robots/box.urdf (1.2 kg, 0.3 x 0.2 x 0.1 m) resting flat ON the
// floor (its four bottom corners; no impact: docs/contacts.md's friction
// test does the same), mu = 0.3, given 1 m/s at the heading psi from the
// floor's first tangent t1 = +y (t2 = n x t1 = -x), so v = (-sin psi,
// cos psi, 0). Closed forms (mech::cone_slide, one point mass carrying
// m g): the circular cone stops at v0/(mu g) after v0^2/(2 mu g) along psi;
// lcsim's d-edge pyramid as cone_slide(d) says; MuJoCo's pyramidal cone is
// lcsim's d = 2 (edges on +-t1, +-t2: MuJoCo's contact frame for the floor
// has the world's x and y as tangents, lcsim's t1, t2 up to order and
// sign); Bullet's box friction bounds the two components alone, each
// falling at mu g: it stops at v0 max(|cos psi|, |sin psi|)/(mu g), the
// last phase along the axis of the larger component.
//
// Measured: the stop time (exact method: the time of its last stick event;
// the others: the first sample from which the horizontal speed stays below
// 1e-3 m/s, which the closed forms reach 1e-3/(mu g) = 3.4e-4 s before the
// stop), the stop distance (|horizontal displacement| at T), and the final
// heading (of the horizontal velocity at the last sample faster than
// 0.05 m/s, from t1 towards t2).
//
// Usage: peer_friction_slide [h = 1e-3]
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <lcsim/bullet/bullet.hpp>
#include <lcsim/mech/cone_slide.hpp>
#include <lcsim/mujoco/mujoco.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>
#include <vector>

namespace {

using lcsim::sim::Trajectory;
namespace fs = std::filesystem;

constexpr double kMu = 0.3, kG = 9.81, kV0 = 1.0, kT = 0.6;

// The scene at heading psi with d edges, written beside box.urdf in `dir`.
std::string write_scene(const fs::path& dir, double psi, int d) {
  fs::copy_file(fs::path(LCSIM_SOURCE_DIR) / "robots" / "box.urdf", dir / "box.urdf",
                fs::copy_options::overwrite_existing);
  const fs::path p = dir / ("slide_" + std::to_string(d) + ".yaml");
  char v[160];
  std::snprintf(v, sizeof v, "box.x: %.17g, box.y: %.17g", -kV0 * std::sin(psi),
                kV0 * std::cos(psi));
  std::ofstream(p) << "name: box_slide\nurdf: box.urdf\n"
                      "base: {type: floating, pose: {xyz: [0, 0, 0.05]}}\n"
                      "planes:\n  - {name: floor, point: [0, 0, 0], normal: [0, 0, 1]}\n"
                      "contacts:\n  - {link: box, plane: floor, friction: "
                   << kMu << ", d: " << d
                   << "}\ncontact_options: {max_distance: 0.05}\ninitial:\n  v: {" << v
                   << "}\nt_end: " << kT << "\n";
  return p.string();
}

struct Slide {
  double t_stop = NAN, distance = NAN, heading = NAN;
  std::string error;
};

// Horizontal velocity (t1, t2 components) and position of sample x.
void horizontal(const Eigen::VectorXd& x, double& a1, double& a2, double& p1, double& p2) {
  const int n = static_cast<int>(x.size() / 2);
  p1 = x(1);
  p2 = -x(0);
  a1 = x(n + 1);
  a2 = -x(n);
}

Slide measure(const Trajectory& tr, bool exact) {
  Slide s;
  if (tr.status != lcsim::sim::RunStatus::kCompleted) {
    s.error = tr.message;
    return s;
  }
  double p10 = 0, p20 = 0, a1, a2, p1, p2;
  horizontal(tr.samples.front().x, a1, a2, p10, p20);
  horizontal(tr.final_state, a1, a2, p1, p2);
  s.distance = std::hypot(p1 - p10, p2 - p20);
  for (const auto& smp : tr.samples) {
    horizontal(smp.x, a1, a2, p1, p2);
    const double speed = std::hypot(a1, a2);
    if (speed > 0.05) s.heading = std::atan2(a2, a1);
    if (speed > 1e-3)
      s.t_stop = NAN;
    else if (std::isnan(s.t_stop))
      s.t_stop = smp.t;
  }
  if (exact)
    for (const auto& e : tr.events) {
      horizontal(e.state_after, a1, a2, p1, p2);
      if (std::hypot(a1, a2) < 1e-9) {
        s.t_stop = e.t;
        break;
      }
    }
  return s;
}

void row(const char* who, const Slide& s, double t_ref, double d_ref, double h_ref) {
  if (!s.error.empty()) {
    std::printf("  %-26s failed: %s\n", who, s.error.c_str());
    return;
  }
  std::printf("  %-26s %9.6f %9.6f %9.4f   %+.2e %+.2e %+.2e\n", who, s.t_stop, s.distance,
              s.heading, s.t_stop - t_ref, s.distance - d_ref, s.heading - h_ref);
}

}  // namespace

int main(int argc, char** argv) {
  const double h = argc > 1 ? std::atof(argv[1]) : 1e-3;
  const fs::path dir = fs::temp_directory_path() / ("lcsim_slide_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  lcsim::sim::Options o;
  o.t_end = kT;
  o.h = h;
  o.dt_out = h;
  std::printf(
      "box sliding on the floor, v0 = %g m/s, mu = %g, h = %g (run-time errors are "
      "against the closed form named on each row)\n",
      kV0, kMu, h);
  for (const double psi : {0.0, M_PI / 8, M_PI / 4}) {
    const auto circ = lcsim::mech::cone_slide(kV0, psi, kMu, kG, 4);
    std::printf("psi = %.4f rad\n  %-26s %9s %9s %9s   %9s %9s %9s\n", psi, "", "t_stop",
                "distance", "heading", "dt", "dd", "dheading");
    std::printf("  %-26s %9.6f %9.6f %9.4f\n", "closed form, circular", circ.circular_t_stop,
                circ.circular_distance, psi);
    for (int d : {2, 4, 16}) {
      const auto c = lcsim::mech::cone_slide(kV0, psi, kMu, kG, d);
      char name[40];
      std::snprintf(name, sizeof name, "closed form, d = %d", d);
      std::printf("  %-26s %9.6f %9.6f %9.4f\n", name, c.t_stop, std::hypot(c.x, c.y), c.heading);
    }
    const double c1 = kV0 * std::abs(std::cos(psi)), c2 = kV0 * std::abs(std::sin(psi));
    const double box_t = std::max(c1, c2) / (kMu * kG);
    const double box_d = std::hypot(c1 * c1, c2 * c2) / (2 * kMu * kG);
    const double box_h = std::abs(c1 - c2) < 1e-12 ? psi : (c1 > c2 ? 0.0 : M_PI / 2);
    std::printf("  %-26s %9.6f %9.6f %9.4f\n", "closed form, Bullet's box", box_t, box_d, box_h);
    for (int d : {4, 16}) {
      const auto m = lcsim::scene::load_model(write_scene(dir, psi, d));
      const auto c = lcsim::mech::cone_slide(kV0, psi, kMu, kG, d);
      lcsim::sim::Options oe = o;
      oe.dt_out = 1e-3;
      char name[40];
      std::snprintf(name, sizeof name, "exact, d = %d", d);
      row(name, measure(lcsim::sim::simulate(m, m.initial, oe, "event"), true), c.t_stop,
          std::hypot(c.x, c.y), c.heading);
      std::snprintf(name, sizeof name, "moreau-jean, d = %d", d);
      row(name, measure(lcsim::sim::simulate(m, m.initial, o, "moreau-jean"), false), c.t_stop,
          std::hypot(c.x, c.y), c.heading);
    }
    const auto m = lcsim::scene::load_model(write_scene(dir, psi, 4));
    for (auto f : {lcsim::bullet::WorldSettings::Friction::kCone,
                   lcsim::bullet::WorldSettings::Friction::kBox,
                   lcsim::bullet::WorldSettings::Friction::kOneDirection}) {
      lcsim::bullet::WorldSettings ws;
      ws.friction = f;
      const bool cone = f == lcsim::bullet::WorldSettings::Friction::kCone;
      const bool one = f == lcsim::bullet::WorldSettings::Friction::kOneDirection;
      row(cone  ? "bullet cone (vs circular)"
          : one ? "bullet one-direction (vs box)"
                : "bullet box (vs box)",
          measure(lcsim::bullet::simulate_bullet(m, m.initial, o, ws), false),
          cone ? circ.circular_t_stop : box_t, cone ? circ.circular_distance : box_d,
          cone ? psi : box_h);
    }
    for (auto cone :
         {lcsim::mujoco::Settings::Cone::kPyramidal, lcsim::mujoco::Settings::Cone::kElliptic}) {
      lcsim::mujoco::Settings ms;
      ms.cone = cone;
      const bool ell = cone == lcsim::mujoco::Settings::Cone::kElliptic;
      const auto c2 = lcsim::mech::cone_slide(kV0, psi, kMu, kG, 2);
      row(ell ? "mujoco elliptic (vs circ.)" : "mujoco pyramidal (vs d=2)",
          measure(lcsim::mujoco::simulate_mujoco(m, m.initial, o, ms), false),
          ell ? circ.circular_t_stop : c2.t_stop,
          ell ? circ.circular_distance : std::hypot(c2.x, c2.y), ell ? psi : c2.heading);
    }
  }
  std::error_code ec;
  fs::remove_all(dir, ec);
  return 0;
}
