// The box sliding on the floor at a heading, for the peers' friction tests
// (tests/bullet, tests/mujoco): robots/box.urdf resting flat ON the floor
// (its four bottom corners, no impact), friction mu, speed v0 at the heading
// psi from the floor's first tangent t1 = +y (t2 = n x t1 = -x: the velocity
// is v0 (-sin psi, cos psi, 0)), and what a run of it measures.
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <lcsim/sim/sim.hpp>
#include <string>

namespace lcsim::test_support {

// The scene file, written (with box.urdf) into `dir`; d the lcsim cone's edges.
inline std::string write_slide_scene(const std::filesystem::path& dir, double psi, double mu,
                                     double v0, double t_end, int d = 4) {
  namespace fs = std::filesystem;
  fs::create_directories(dir);
  fs::copy_file(fs::path(LCSIM_SOURCE_DIR) / "robots" / "box.urdf", dir / "box.urdf",
                fs::copy_options::overwrite_existing);
  const fs::path p = dir / "slide.yaml";
  std::ofstream out(p);
  out.precision(17);
  out << "name: box_slide\nurdf: box.urdf\n"
         "base: {type: floating, pose: {xyz: [0, 0, 0.05]}}\n"
         "planes:\n  - {name: floor, point: [0, 0, 0], normal: [0, 0, 1]}\n"
         "contacts:\n  - {link: box, plane: floor, friction: "
      << mu << ", d: " << d
      << "}\ncontact_options: {max_distance: 0.05}\ninitial:\n  v: {box.x: " << -v0 * std::sin(psi)
      << ", box.y: " << v0 * std::cos(psi) << "}\nt_end: " << t_end << "\n";
  return p.string();
}

// The box of write_slide_scene at rest against the floor (mu 0.3) and a wall
// at its +x face (mu 0.5): one link with two coefficients, which neither
// peer can hold (each has one friction per collider or geom).
inline std::string write_two_mu_scene(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  fs::create_directories(dir);
  fs::copy_file(fs::path(LCSIM_SOURCE_DIR) / "robots" / "box.urdf", dir / "box.urdf",
                fs::copy_options::overwrite_existing);
  const fs::path p = dir / "two_mu.yaml";
  std::ofstream(p) << "name: box_two_mu\nurdf: box.urdf\n"
                      "base: {type: floating, pose: {xyz: [0, 0, 0.05]}}\n"
                      "planes:\n  - {name: floor, point: [0, 0, 0], normal: [0, 0, 1]}\n"
                      "  - {name: wall, point: [0.15, 0, 0], normal: [-1, 0, 0]}\n"
                      "contacts:\n  - {link: box, plane: floor, friction: 0.3}\n"
                      "  - {link: box, plane: wall, friction: 0.5, name: box_wall}\n"
                      "contact_options: {max_distance: 0.05}\nt_end: 0.1\n";
  return p.string();
}

// What a run of the sliding box shows.
struct SlideMeasure {
  double t_stop = NAN;    // first sample from which the horizontal speed stays <= v_stop
  double distance = NAN;  // |horizontal displacement| at the end of the run
  double heading = NAN;   // of the horizontal velocity at the last sample faster than v_fast
  double max_height_change = 0.0;  // max |z - z(0)| over the samples
};

inline SlideMeasure measure_slide(const sim::Trajectory& tr, double v_stop, double v_fast) {
  SlideMeasure s;
  auto at = [](const Eigen::VectorXd& x, int i) { return x(i); };
  const Eigen::VectorXd& x0 = tr.samples.front().x;
  const int n = static_cast<int>(x0.size() / 2);
  const Eigen::VectorXd& xf = tr.final_state;
  s.distance = std::hypot(at(xf, 0) - at(x0, 0), at(xf, 1) - at(x0, 1));
  for (const auto& smp : tr.samples) {
    const double a1 = smp.x(n + 1), a2 = -smp.x(n);  // along t1 and t2
    const double speed = std::hypot(a1, a2);
    if (speed > v_fast) s.heading = std::atan2(a2, a1);
    if (speed > v_stop)
      s.t_stop = NAN;
    else if (std::isnan(s.t_stop))
      s.t_stop = smp.t;
    s.max_height_change = std::max(s.max_height_change, std::abs(smp.x(2) - x0(2)));
  }
  return s;
}

}  // namespace lcsim::test_support
