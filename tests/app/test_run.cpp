// Running a model to its outputs (src/app/run.cpp), each output against the
// same thing computed independently from the lower layers: the streamed CSV
// against io::trajectory_csv of a run that kept its samples, a scene's check
// against scene::check_linearisation of the states a kept run visited, the
// JSON against io::trajectory_json.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <lcsim/app/run.hpp>
#include <lcsim/impact/impact.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/linearisation.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/reference.hpp>
#include <lcsim/sim/sim.hpp>
#include <sstream>
#include <string>

namespace lcsim::app {
namespace {

namespace fs = std::filesystem;

scene::LoadedModel robot(const std::string& name) {
  return scene::load_model_and_scene(std::string(LCSIM_SOURCE_DIR) + "/robots/" + name);
}

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The states a run visited, thinned as a streamed check thins them.
scene::LinearisationCheck check_of(const scene::LoadedModel& m, const sim::Trajectory& kept) {
  scene::LinearisationStates visited;
  for (const auto& s : kept.samples) visited.add(s.x);
  return scene::check_linearisation(*m.scene, visited.states());
}

// A scene run with no output asked for is still checked, on a grid of
// kLinearisationStates points over its horizon: the same check, bit for bit,
// as a run on that grid that kept its samples.
TEST(RunModel, SceneIsCheckedOnItsOwnGrid) {
  const scene::LoadedModel m = robot("double_pendulum_scene.yaml");
  ASSERT_TRUE(m.scene.has_value());
  RunRequest req;
  req.options.t_end = 2.0;
  const ModelRun run = run_model(m, req);
  ASSERT_TRUE(run.trajectory.status == sim::RunStatus::kCompleted) << run.trajectory.message;
  EXPECT_TRUE(run.trajectory.samples.empty());  // streamed to the check, not kept
  ASSERT_TRUE(run.linearisation.has_value());

  sim::Options opt;
  opt.t_end = 2.0;
  opt.dt_out = 2.0 / static_cast<double>(scene::kLinearisationStates);
  const sim::Trajectory kept = sim::simulate(m.model, opt);
  const scene::LinearisationCheck expected = check_of(m, kept);
  EXPECT_EQ(run.linearisation->states, expected.states);
  EXPECT_GE(expected.states, scene::kLinearisationStates);  // the grid, not events only
  EXPECT_EQ(run.linearisation->error, expected.error);      // same states, same arithmetic
  EXPECT_EQ(run.linearisation->worst_q, expected.worst_q);
  EXPECT_EQ(run.linearisation_warning,
            scene::linearisation_warning(expected, scene::kLinearisationThreshold));
}

// The threshold decides the warning; a bad one is refused naming the field
// (the CLI maps it to its flag), before anything runs.
TEST(RunModel, ThresholdWarnsAndABadOneNamesTheField) {
  const scene::LoadedModel m = robot("double_pendulum_scene.yaml");
  RunRequest req;
  req.options.t_end = 1.0;
  req.linearisation_threshold = 1e-12;  // any swing of a pendulum exceeds it (e_F ~ theta^2/6)
  const ModelRun run = run_model(m, req);
  ASSERT_TRUE(run.linearisation.has_value());
  EXPECT_GT(run.linearisation->error, 1e-12);
  EXPECT_NE(run.linearisation_warning.find("above the threshold"), std::string::npos);

  req.linearisation_threshold = std::nan("");
  try {
    (void)run_model(m, req);
    FAIL() << "a NaN threshold ran";
  } catch (const io::InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("linearisation_threshold must be", 0), 0u) << e.what();
  }
}

// The streamed CSV is what io::trajectory_csv writes for the same run with
// its samples kept, and the JSON is io::trajectory_json with the check.
TEST(RunModel, CsvAndJsonAreTheLowerLayersOnes) {
  const scene::LoadedModel m = robot("two_carts_scene.yaml");
  const fs::path csv =
      fs::temp_directory_path() / ("lcsim_test_run_" + std::to_string(::getpid()) + ".csv");
  RunRequest req;
  req.options.t_end = 1.0;
  req.options.dt_out = 0.01;
  req.csv_path = csv.string();
  const ModelRun run = run_model(m, req);
  ASSERT_TRUE(run.trajectory.status == sim::RunStatus::kCompleted) << run.trajectory.message;
  EXPECT_TRUE(run.csv_written);

  const sim::Trajectory kept = sim::simulate(m.model, req.options);
  EXPECT_EQ(read(csv), io::trajectory_csv(m.model, kept));
  fs::remove(csv);
  const scene::LinearisationCheck lin = check_of(m, kept);
  nlohmann::json expected = io::trajectory_json(m.model, kept);
  expected["linearisation_error"] = lin.error;
  expected["linearisation_check"] = scene::to_json(lin);
  nlohmann::json got = run_json(m.model, run.trajectory, run.linearisation);
  got.erase("wall_time_s");  // a clock reading
  expected.erase("wall_time_s");
  EXPECT_EQ(got.dump(2), expected.dump(2));
}

// A refused run writes no file, is not checked, and keeps its message.
TEST(RunModel, RefusedRunLeavesNoFile) {
  const scene::LoadedModel m = robot("two_carts_scene.yaml");
  const fs::path csv =
      fs::temp_directory_path() / ("lcsim_test_refused_" + std::to_string(::getpid()) + ".csv");
  RunRequest req;
  req.options.theta = 0.7;  // the exact method reads no theta: refused
  req.csv_path = csv.string();
  const ModelRun run = run_model(m, req);
  EXPECT_EQ(run.trajectory.status, sim::RunStatus::kInvalidInput);
  EXPECT_NE(run.trajectory.message.find("theta"), std::string::npos) << run.trajectory.message;
  EXPECT_FALSE(run.csv_written);
  EXPECT_FALSE(fs::exists(csv));
  EXPECT_FALSE(run.linearisation.has_value());
}

// A matrix model with no output asked for records nothing; a runner with
// kept samples gives what calling it directly gives; an alias of an impact
// law comes back with its note.
TEST(RunModel, RunnerKeptSamplesAndAliasNote) {
  const scene::LoadedModel m = robot("two_carts.yaml");
  RunRequest req;
  const ModelRun plain = run_model(m, req);
  EXPECT_TRUE(plain.trajectory.status == sim::RunStatus::kCompleted);
  EXPECT_TRUE(plain.trajectory.samples.empty());
  EXPECT_FALSE(plain.linearisation.has_value());
  EXPECT_TRUE(plain.impact_note.empty());

  sim::Options opt;
  opt.dt_out = 0.05;
  const sim::ReferenceLaw law = sim::reference_law("bullet", opt.impact, m.model);
  req.runner = reference_runner(law);
  req.options = opt;
  req.keep_samples = true;
  const ModelRun ref = run_model(m, req);
  const sim::Trajectory direct = sim::run_reference(m.model, m.model.initial, law, opt);
  ASSERT_EQ(ref.trajectory.samples.size(), direct.samples.size());
  for (size_t i = 0; i < direct.samples.size(); ++i) {
    EXPECT_EQ(ref.trajectory.samples[i].t, direct.samples[i].t);
    EXPECT_EQ(ref.trajectory.samples[i].x, direct.samples[i].x);
  }
  EXPECT_EQ(ref.trajectory.final_state, direct.final_state);

  RunRequest alias;
  alias.options.impact = "moreau";
  const ModelRun aliased = run_model(m, alias);
  EXPECT_FALSE(aliased.impact_note.empty());
  EXPECT_EQ(aliased.impact_note, impact::laws().alias_note("moreau"));
}

TEST(ComparisonGrid, IsAMultipleOfHWithAtMost2000Points) {
  EXPECT_EQ(comparison_grid(1.0, 1e-2), 1e-2);        // 100 points: h itself
  EXPECT_EQ(comparison_grid(10.0, 1e-4), 50 * 1e-4);  // 100000 steps: every 50th, 2000 points
}

}  // namespace
}  // namespace lcsim::app
