// A study over a URDF scene keeps the scene (issue 24, item 5): its
// restitution axis changes a parameter of the constraints, never the kind of
// model run. Bullet runs a scene as a btMultiBody from its URDF; before the
// fix a changed restitution made the scene a matrix model, which Bullet
// refused for its non-diagonal M.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <lcsim/io/io.hpp>
#include <lcsim/io/text.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <lcsim/study/run.hpp>
#include <lcsim/study/study.hpp>
#include <string>

namespace lcsim::study {
namespace {

const std::string kRobots = std::string(LCSIM_SOURCE_DIR) + "/robots/";

std::string cell(const Study& s, const Row& r, const std::string& column) {
  const auto cols = columns(s);
  for (std::size_t i = 0; i < cols.size(); ++i)
    if (cols[i].name == column) return r.cells.at(i);
  return "(no column " + column + ")";
}

void write(const std::filesystem::path& p, const std::string& text) { std::ofstream(p) << text; }

// robots/double_pendulum_scene.yaml (restitution 0.5 on the shoulder's
// stop; M is not diagonal) with the restitution `e` written in the scene, in
// a directory of its own beside a copy of its URDF.
std::filesystem::path scene_with_restitution(const std::filesystem::path& dir, const char* e) {
  std::filesystem::create_directories(dir);
  std::filesystem::copy_file(kRobots + "double_pendulum.urdf", dir / "double_pendulum.urdf",
                             std::filesystem::copy_options::overwrite_existing);
  std::string text = io::read_file(kRobots + "double_pendulum_scene.yaml");
  const std::string from = "restitution: {shoulder_lower: 0.5}";
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos);
  text.replace(at, from.size(), std::string("restitution: {shoulder_lower: ") + e + "}");
  const std::filesystem::path p = dir / "scene.yaml";
  write(p, text);
  return p;
}

TEST(StudyScene, RestitutionAxisKeepsTheSceneForBullet) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("lcsim_scene_study_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  const std::filesystem::path base = scene_with_restitution(dir / "base", "0.5");
  const std::filesystem::path other = scene_with_restitution(dir / "other", "0");
  write(dir / "base" / "study.yaml",
        "model: scene.yaml\nmethod: bullet\nreference: none\nt_end: 2\nh: 1e-3\n"
        "axes:\n  - restitution.shoulder_lower: [0, 0.5]\n");
  const Study s = load_study(dir / "base" / "study.yaml");
  // `simulate --method bullet` of the scene that says restitution 0: the row
  // must be that run, cell for cell (same Bullet world, same steps: equal,
  // not near).
  const mech::Model m = scene::load_model(other);
  sim::Options o = s.base;
  o.dt_out = 0.0;
  o.record_samples = false;
  const auto bullet = sim::make_integrator("bullet");
  const sim::Trajectory t = bullet->run(m, m.initial, sim::keep_used(o, bullet->options_used()));
  ASSERT_EQ(t.status, sim::RunStatus::kCompleted) << t.message;
  const Row r = run_one(s, 0);
  ASSERT_EQ(cell(s, r, "status"), "completed") << cell(s, r, "message");
  EXPECT_EQ(cell(s, r, "steps"), std::to_string(t.steps));
  EXPECT_EQ(cell(s, r, "warnings"), std::to_string(t.warning_count()));
  const std::vector<std::string> q = {"shoulder", "elbow", "v_shoulder", "v_elbow"};
  for (std::size_t i = 0; i < q.size(); ++i)
    EXPECT_EQ(cell(s, r, "final_" + q[i]),
              io::format_number(t.final_state(static_cast<Eigen::Index>(i))))
        << q[i];
  // The scene's own restitution, 0.5: Bullet's multibody limits are
  // inelastic, so it warns that the restitution is lost (one warning more
  // than the run with e = 0), and the motion is the same.
  const Row r5 = run_one(s, 1);
  ASSERT_EQ(cell(s, r5, "status"), "completed") << cell(s, r5, "message");
  EXPECT_EQ(std::stoi(cell(s, r5, "warnings")), t.warning_count() + 1);
  EXPECT_EQ(cell(s, r5, "final_shoulder"), cell(s, r, "final_shoulder"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace lcsim::study
