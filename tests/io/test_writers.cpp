// Writers: atomic file output, the CSV trajectory and the JSON run summary.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <sstream>
#include <string>

namespace lcsim::io {
namespace {

// Any model file, as every command reads it (matrix models and scenes).
using scene::load_model;
using scene::parse_model;

namespace fs = std::filesystem;
using Eigen::VectorXd;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A fresh empty directory per test.
fs::path scratch_dir(const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) / ("lcsim_io_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::vector<std::string> entries(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

TEST(WriteFileAtomic, WritesAndReplaces) {
  const fs::path dir = scratch_dir("write");
  const fs::path file = dir / "out.csv";
  write_file_atomic(file, "first\n");
  EXPECT_EQ(slurp(file), "first\n");
  write_file_atomic(file, "second\n");
  EXPECT_EQ(slurp(file), "second\n");
  write_file_atomic(file, "");
  EXPECT_EQ(slurp(file), "");
  EXPECT_EQ(entries(dir), std::vector<std::string>{"out.csv"});  // no temporary left over
}

TEST(WriteFileAtomic, FailureLeavesNoPartialFile) {
  const fs::path dir = scratch_dir("fail");
  // The target is a directory: the temporary file is written in full, then
  // the rename fails. The temporary must be removed and the directory kept.
  const fs::path target = dir / "taken";
  fs::create_directory(target);
  std::ofstream(dir / "keep.txt") << "old";
  try {
    write_file_atomic(target, std::string(1 << 16, 'x'));
    FAIL() << "wrote over a directory";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(target.string() + ": cannot write: ", 0), 0u) << e.what();
  }
  EXPECT_EQ(entries(dir), (std::vector<std::string>{"keep.txt", "taken"}));
  EXPECT_TRUE(fs::is_directory(target));
  EXPECT_TRUE(fs::is_empty(target));

  // A directory that does not exist: nothing can be created at all.
  const fs::path missing = dir / "no" / "such" / "out.json";
  try {
    write_file_atomic(missing, "{}");
    FAIL() << "wrote into a missing directory";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              missing.string() + ": cannot write: No such file or directory");
  }
  EXPECT_FALSE(fs::exists(dir / "no"));
  EXPECT_EQ(slurp(dir / "keep.txt"), "old");
}

mech::Model two_carts_model() {
  return parse_model(
      "name: carts\n"
      "mechanical:\n"
      "  M: [[1, 0], [0, 1]]\n"
      "  K: [[2, -1], [-1, 1]]\n"
      "  E: [[1, 0], [1, -1]]\n"
      "  coordinates: [x1, x2]\n"
      "  constraints: [stop, hook]\n",
      "carts.yaml");
}

// A hand-made trajectory: one impact at t = 0.1 with a jump (two samples
// share t), a sample with empty u and y, and non-representable decimals.
sim::Trajectory hand_made() {
  sim::Trajectory tr;
  tr.method = "event";
  tr.t_end = 3.0;
  sim::Sample a;
  a.t = 0.0;
  a.x = (VectorXd(4) << 1.0 / 3.0, 0.1, -1, 2).finished();
  a.u = VectorXd::Zero(2);
  a.y = (VectorXd(2) << 1.0 / 3.0, 0.1).finished();
  sim::Sample b = a;
  b.t = 0.1;
  b.u = VectorXd();  // not recorded: blank cells
  b.y = VectorXd();
  b.mode = {0, 1};
  tr.samples = {a, b};
  sim::Event e;
  e.t = 0.1;
  e.type = sim::EventType::kImpact;
  e.state_before = a.x;
  e.state_after = (VectorXd(4) << 0, 0, 0.5, 0.5).finished();
  e.mode_after = {0, 1};
  e.impulse = (VectorXd(2) << 1.5, 0.25).finished();
  tr.events = {e};
  tr.final_state = e.state_after;
  tr.energy_initial = 2.5;
  tr.energy_final = 1.0 / 7.0;
  tr.max_violation = -1e-17;
  tr.lcp_solves = 3;
  tr.steps = 2;
  tr.warn("grazing", 0.1, "grazing contact at t = 0.1");
  tr.warn("grazing", 0.2, "grazing contact at t = 0.2");
  tr.wall_time_s = 0.125;
  return tr;
}

TEST(TrajectoryCsv, HeaderAndRowsMechanical) {
  const std::string csv = trajectory_csv(two_carts_model(), hand_made());
  std::istringstream in(csv);
  std::string header, row0, row1, extra;
  std::getline(in, header);
  std::getline(in, row0);
  std::getline(in, row1);
  EXPECT_EQ(header, "t,x1,x2,v_x1,v_x2,u_stop,u_hook,y_stop,y_hook,mode");
  // %.17g: 1/3 and 0.1 are printed with 17 significant digits and read back exactly.
  EXPECT_EQ(row0,
            "0,0.33333333333333331,0.10000000000000001,-1,2,0,0,0.33333333333333331,"
            "0.10000000000000001,");
  EXPECT_EQ(row1, "0.10000000000000001,0.33333333333333331,0.10000000000000001,-1,2,,,,,0;1");
  EXPECT_FALSE(std::getline(in, extra));
  EXPECT_EQ(std::stod("0.33333333333333331"), 1.0 / 3.0);
}

TEST(TrajectoryCsv, HeaderLcs) {
  const mech::Model model =
      parse_model("lcs:\n  A: [[0, 1], [0, 0]]\n  B: [[0], [1]]\n  C: [[1, 0]]\n", "lcs.yaml");
  sim::Trajectory tr;
  sim::Sample s;
  s.t = 0.5;
  s.x = (VectorXd(2) << 1, 2).finished();
  s.u = (VectorXd(1) << 3).finished();
  s.y = (VectorXd(1) << 4).finished();
  s.mode = {0};
  tr.samples = {s};
  EXPECT_EQ(trajectory_csv(model, tr), "t,x1,x2,u1,y1,mode\n0.5,1,2,3,4,0\n");
}

TEST(TrajectoryCsv, QuotesNamesWithCommas) {
  const mech::Model model = parse_model(
      "mechanical:\n  M: [[1]]\n  E: [[1]]\n  coordinates: ['a,b']\n  constraints: ['say "
      "\"hi\"']\n",
      "q.yaml");
  EXPECT_EQ(trajectory_csv(model, sim::Trajectory{}),
            "t,\"a,b\",\"v_a,b\",\"u_say \"\"hi\"\"\",\"y_say \"\"hi\"\"\",mode\n");
}

TEST(TrajectoryCsv, WrongStateSizeIsAProgrammingError) {
  sim::Trajectory tr = hand_made();
  tr.samples[0].x = VectorXd::Zero(5);  // e.g. the augmented (q, v, 1)
  EXPECT_THROW(trajectory_csv(two_carts_model(), tr), std::logic_error);
}

// The streaming writer: while the run goes only a temporary exists beside
// the target; commit() puts exactly trajectory_csv's text (the hand-written
// rows above) in place; no commit, nothing.
TEST(TrajectoryCsvWriter, CommitGivesTheCsvAndNothingElse) {
  const fs::path dir = scratch_dir("stream");
  const fs::path file = dir / "t.csv";
  const sim::Trajectory tr = hand_made();
  {
    TrajectoryCsvWriter w(file, two_carts_model());
    for (const auto& s : tr.samples) w.write(s);
    EXPECT_EQ(entries(dir),
              std::vector<std::string>{w.temporary_path().substr(dir.string().size() + 1)});
    EXPECT_EQ(fs::path(w.temporary_path()).filename().string().rfind(".t.csv.tmp-", 0), 0u);
    w.commit();
  }
  EXPECT_EQ(slurp(file), trajectory_csv(two_carts_model(), tr));
  EXPECT_EQ(entries(dir), std::vector<std::string>{"t.csv"});
  {
    // A run that failed: the writer goes away without commit; the old file stays.
    TrajectoryCsvWriter w(dir / "t.csv", two_carts_model());
    w.write(tr.samples[0]);
  }
  EXPECT_EQ(slurp(file), trajectory_csv(two_carts_model(), tr));
  EXPECT_EQ(entries(dir), std::vector<std::string>{"t.csv"});
}

// Rows past the 1 MiB buffer go to disk as they come: 20000 rows of the
// hand-made sample, the same text as trajectory_csv of them held in memory.
TEST(TrajectoryCsvWriter, LongRunsAreFlushedAndWhole) {
  const fs::path dir = scratch_dir("stream_long");
  sim::Trajectory tr;
  tr.samples.assign(20000, hand_made().samples[0]);
  for (std::size_t i = 0; i < tr.samples.size(); ++i) tr.samples[i].t = 1e-3 * i;
  TrajectoryCsvWriter w(dir / "t.csv", two_carts_model());
  for (const auto& s : tr.samples) w.write(s);
  EXPECT_GT(fs::file_size(w.temporary_path()), 0u);  // flushed before commit
  w.commit();
  EXPECT_EQ(slurp(dir / "t.csv"), trajectory_csv(two_carts_model(), tr));
}

TEST(TrajectoryCsvWriter, UnwritableTargetFailsAtOnce) {
  const fs::path dir = scratch_dir("stream_bad");
  EXPECT_THROW(TrajectoryCsvWriter(dir / "no" / "t.csv", two_carts_model()), InputError);
  EXPECT_TRUE(entries(dir).empty());
}

// A wrong sample is a programming error, reported at commit (write must not
// throw: it runs inside the integrator); nothing is written.
TEST(TrajectoryCsvWriter, WrongSampleIsReportedAtCommit) {
  const fs::path dir = scratch_dir("stream_wrong");
  sim::Trajectory tr = hand_made();
  tr.samples[0].x = VectorXd::Zero(5);
  {
    TrajectoryCsvWriter w(dir / "t.csv", two_carts_model());
    w.write(tr.samples[0]);
    EXPECT_THROW(w.commit(), std::logic_error);
  }
  EXPECT_TRUE(entries(dir).empty());
}

// What a signal handler calls: every tracked temporary is removed, the
// others are not touched.
TEST(TemporaryFiles, RemovedOnRequest) {
  const fs::path dir = scratch_dir("tracked");
  TrajectoryCsvWriter w(dir / "t.csv", two_carts_model());
  std::ofstream(dir / "other.txt") << "keep";
  const std::string mine = (dir / ".mine.tmp").string();
  std::ofstream(mine) << "x";
  track_temporary_file(mine);
  remove_temporary_files();
  EXPECT_EQ(entries(dir), std::vector<std::string>{"other.txt"});
  untrack_temporary_file(mine);
}

TEST(TrajectoryJson, RoundTrip) {
  const sim::Trajectory tr = hand_made();
  const std::string text = trajectory_json(two_carts_model(), tr).dump(2);
  const nlohmann::json j = nlohmann::json::parse(text);
  for (const char* key :
       {"model", "method", "t_end", "final_state", "events", "energy_initial", "energy_final",
        "max_violation", "lcp_solves", "steps", "warnings", "status", "message", "wall_time_s"})
    EXPECT_TRUE(j.contains(key)) << key;
  // nlohmann writes the shortest text that reads back as the same double, so
  // the round trip is exact (EXPECT_EQ, no tolerance).
  EXPECT_EQ(j["model"], "carts");
  EXPECT_EQ(j["method"], "event");
  EXPECT_EQ(j["t_end"].get<double>(), 3.0);
  EXPECT_EQ(j["final_state"].get<std::vector<double>>(), (std::vector<double>{0, 0, 0.5, 0.5}));
  ASSERT_EQ(j["events"].size(), 1u);
  const nlohmann::json& e = j["events"][0];
  EXPECT_EQ(e["t"].get<double>(), 0.1);
  EXPECT_EQ(e["type"], "impact");
  EXPECT_EQ(e["state_before"].get<std::vector<double>>(),
            (std::vector<double>{1.0 / 3.0, 0.1, -1, 2}));
  EXPECT_EQ(e["state_after"].get<std::vector<double>>(), (std::vector<double>{0, 0, 0.5, 0.5}));
  EXPECT_EQ(e["mode_after"].get<std::vector<int>>(), (std::vector<int>{0, 1}));
  EXPECT_EQ(e["impulse"].get<std::vector<double>>(), (std::vector<double>{1.5, 0.25}));
  EXPECT_EQ(j["energy_initial"].get<double>(), 2.5);
  EXPECT_EQ(j["energy_final"].get<double>(), 1.0 / 7.0);
  EXPECT_EQ(j["max_violation"].get<double>(), -1e-17);
  EXPECT_EQ(j["lcp_solves"].get<long>(), 3);
  EXPECT_EQ(j["steps"].get<long>(), 2);
  // Two warnings of one kind: one entry, counted, with the first message and time.
  ASSERT_EQ(j["warnings"].size(), 1u);
  EXPECT_EQ(j["warnings"][0]["kind"], "grazing");
  EXPECT_EQ(j["warnings"][0]["count"], 2);
  EXPECT_EQ(j["warnings"][0]["first_t"], 0.1);
  EXPECT_EQ(j["warnings"][0]["message"], "grazing contact at t = 0.1");
  EXPECT_EQ(j["status"], "completed");
  EXPECT_EQ(j["message"], "");
  EXPECT_EQ(j["wall_time_s"].get<double>(), 0.125);
}

// A model with friction: the tangential multipliers and friction modes per
// frictional contact in the CSV (blank where a sample records none) and the
// events' tangential impulses and modes in the JSON summary.
TEST(TrajectoryWriters, FrictionColumnsAndEventKeys) {
  const mech::Model model = parse_model(
      "name: f\nmechanical:\n  M: [[1, 0], [0, 1]]\n  E: [[0, 1]]\n  constraints: [floor]\n"
      "  friction:\n    - {contact: floor, tangent: [1, 0], mu: 0.5, velocity: 0.25}\n",
      "f.yaml");
  sim::Trajectory tr;
  sim::Sample a;
  a.x = (VectorXd(4) << 0, 0, 1, 0).finished();
  a.u = VectorXd::Constant(1, 2.0);
  a.y = VectorXd::Zero(1);
  a.mode = {0};
  a.u_t = VectorXd::Constant(1, -1.0);
  a.friction_mode = {sim::FrictionMode::kSlipPositive};
  sim::Sample b = a;
  b.t = 0.5;
  b.u_t = VectorXd();
  b.friction_mode.clear();
  tr.samples = {a, b};
  EXPECT_EQ(trajectory_csv(model, tr),
            "t,q1,q2,v_q1,v_q2,u_floor,y_floor,ut_floor,fm_floor,mode\n"
            "0,0,0,1,0,2,0,-1,slip+,0\n0.5,0,0,1,0,2,0,,,0\n");
  sim::Event e;
  e.state_before = e.state_after = a.x;
  e.impulse = VectorXd::Constant(1, 0.5);
  e.friction_impulse = VectorXd::Constant(1, -0.125);
  e.friction_mode_after = {sim::FrictionMode::kStick};
  tr.events = {e};
  const nlohmann::json j = trajectory_json(model, tr);
  EXPECT_EQ(j["events"][0]["friction_impulse"].get<std::vector<double>>(),
            std::vector<double>{-0.125});
  EXPECT_EQ(j["events"][0]["friction_mode_after"].get<std::vector<std::string>>(),
            std::vector<std::string>{"stick"});
  // Frictionless models keep their keys (byte-identical JSON as before).
  EXPECT_FALSE(
      trajectory_json(two_carts_model(), hand_made())["events"][0].contains("friction_impulse"));
}

TEST(TrajectoryJson, FailedRunAndLcsEnergies) {
  const mech::Model model = parse_model("lcs:\n  A: [[0]]\n  B: [[1]]\n  C: [[1]]\n", "lcs.yaml");
  sim::Trajectory tr;
  tr.status = sim::RunStatus::kNumericalFailure;
  tr.message = "LCP ray termination at t = 0.5";
  const nlohmann::json j = trajectory_json(model, tr);
  EXPECT_EQ(j["status"], "numerical failure");
  EXPECT_EQ(j["message"], "LCP ray termination at t = 0.5");
  EXPECT_TRUE(j["energy_initial"].is_null());  // no energy for a general LCS
  EXPECT_TRUE(j["events"].is_array());
  EXPECT_TRUE(j["final_state"].is_array());
}

TEST(ToJson, MatrixIsListOfRows) {
  const Eigen::MatrixXd m = (Eigen::MatrixXd(2, 3) << 1, 2, 3, 4, 5, 6).finished();
  EXPECT_EQ(to_json(m).dump(), "[[1.0,2.0,3.0],[4.0,5.0,6.0]]");
  EXPECT_EQ(to_json(VectorXd()).dump(), "[]");
}

}  // namespace
}  // namespace lcsim::io
