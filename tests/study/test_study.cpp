// Studies: axis expansion and seeding against hand-computed values, rows of
// failing runs, quantities applied to the model checked against closed
// forms, one-line errors for malformed study files.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <lcsim/io/io.hpp>
#include <lcsim/study/execute.hpp>
#include <lcsim/study/run.hpp>
#include <lcsim/study/study.hpp>
#include <string>

#include "study/detail.hpp"
#include "study/dispenser.hpp"
#include "study/journal.hpp"

namespace lcsim::study {
namespace {

const std::string kSource = std::string(LCSIM_SOURCE_DIR) + "/tests/study/in_memory.yaml";

// A study over robots/two_carts.yaml (the path is relative to kSource's directory).
Study parse(const std::string& body) {
  return parse_study("model: ../../robots/two_carts.yaml\n" + body, kSource);
}

std::string error_of(const std::string& body) {
  try {
    (void)parse(body);
  } catch (const io::InputError& e) {
    return e.what();
  }
  return "(no error)";
}

std::string cell(const Study& s, const Row& r, const std::string& column) {
  const auto cols = columns(s);
  for (std::size_t i = 0; i < cols.size(); ++i)
    if (cols[i].name == column) return r.cells.at(i);
  return "(no column " + column + ")";
}

TEST(StudySeeding, SplitMix64MatchesTheReferenceSequence) {
  // The first outputs of splitmix64.c (Vigna) from state 1234567, recomputed
  // with an independent Python transcription of the algorithm.
  std::uint64_t state = 1234567;
  EXPECT_EQ(splitmix64(state), 6457827717110365317ULL);
  EXPECT_EQ(splitmix64(state), 3203168211198807973ULL);
  EXPECT_EQ(splitmix64(state), 9817491932198370423ULL);
}

TEST(StudySeeding, DrawSeedIsTheDocumentedChain) {
  // state = 7; state = splitmix64(state) ^ 1; ... ^ 0; ... ^ 3; splitmix64:
  // computed by hand in Python from the header's definition.
  EXPECT_EQ(draw_seed(7, 1, 0, 3), 5350435690594302350ULL);
  std::uint64_t s = 5350435690594302350ULL;
  // Top 53 bits times 2^-53, from the same Python computation (exact: a
  // 53-bit integer times a power of two).
  EXPECT_EQ(uniform01(s), 0.0261281589445862);
}

TEST(StudyJournal, FingerprintIsFnv1a64) {
  // The published FNV-1a 64 test vectors (Fowler, Noll, Vo).
  EXPECT_EQ(fingerprint(""), "cbf29ce484222325");
  EXPECT_EQ(fingerprint("a"), "af63dc4c8601ec8c");
  EXPECT_EQ(fingerprint("foobar"), "85944171f73967e8");
}

TEST(StudyAxes, LinspaceAndLogspaceAgainstHandValues) {
  // 0, 0.25, ..., 1: each a + i (b - a) / 4 is exact in binary.
  EXPECT_EQ(linspace(0.0, 1.0, 5), (std::vector<double>{0.0, 0.25, 0.5, 0.75, 1.0}));
  EXPECT_EQ(linspace(2.0, 3.0, 1), (std::vector<double>{2.0}));
  const std::vector<double> l = logspace(1e-4, 1e-2, 3);
  ASSERT_EQ(l.size(), 3u);
  EXPECT_EQ(l[0], 1e-4);  // the ends are set exactly
  EXPECT_EQ(l[2], 1e-2);
  // exp((ln 1e-4 + ln 1e-2) / 2) = 1e-3 up to the rounding of log and exp:
  // a few ulp (4e-16 relative is 2 ulp at 1e-3).
  EXPECT_NEAR(l[1], 1e-3, 4e-19);
}

TEST(StudyAxes, TheLastAxisVariesFastestAndZippedQuantitiesTogether) {
  const Study s = parse(
      "axes:\n"
      "  - method: [event, moreau-jean]\n"
      "  - {h: [1e-2, 1e-3, 1e-4], theta: [0.5, 0.6, 0.7]}\n");
  ASSERT_EQ(run_count(s), 6u);
  EXPECT_EQ(quantity_keys(s), (std::vector<std::string>{"method", "h", "theta"}));
  // Run 4 = (method 1, h/theta 1): 4 = 1 * 3 + 1.
  const RunPoint p = expand(s, 4);
  EXPECT_EQ(p.axis_index, (std::vector<std::size_t>{1, 1}));
  EXPECT_EQ(p.values[0].name, "moreau-jean");
  EXPECT_EQ(p.values[1].number, 1e-3);
  EXPECT_EQ(p.values[2].number, 0.6);
}

TEST(StudyAxes, RandomDrawsDependOnTheSeedAndTheDrawNotTheRun) {
  const Study s = parse(
      "seed: 7\n"
      "axes:\n"
      "  - method: [event, moreau-jean]\n"
      "  - count: 4\n"
      "    x0.x1: {uniform: [2, 4]}\n");
  // Run 7 = method 1, draw 3 of axis 1, quantity 0: 2 + 2 u with u the
  // hand-computed uniform of DrawSeedIsTheDocumentedChain (exact: times 2, plus 2).
  EXPECT_EQ(expand(s, 7).values[1].number, 2.0 + 2.0 * 0.0261281589445862);
  // The same draw for the other method: both methods start from the same x0.
  EXPECT_EQ(expand(s, 3).values[1].number, expand(s, 7).values[1].number);
  EXPECT_NE(expand(s, 2).values[1].number, expand(s, 3).values[1].number);
}

TEST(StudyRuns, FailingRunsAreRowsWithTheirStatus) {
  const Study s = parse(
      "method: moreau-jean\n"
      "axes:\n"
      "  - h: [1e-2, -1]\n"
      "  - restitution.stop: [0.5, 2]\n");
  const Row ok = run_one(s, 0), bad_e = run_one(s, 1), bad_h = run_one(s, 2);
  EXPECT_EQ(cell(s, ok, "status"), "completed");
  EXPECT_TRUE(ok.completed);
  EXPECT_EQ(cell(s, bad_e, "status"), "invalid input");
  EXPECT_FALSE(bad_e.completed);
  EXPECT_NE(cell(s, bad_e, "message").find("restitution"), std::string::npos)
      << cell(s, bad_e, "message");
  EXPECT_EQ(cell(s, bad_h, "status"), "invalid input");
  EXPECT_NE(cell(s, bad_h, "message").find("-1"), std::string::npos) << cell(s, bad_h, "message");
  // A refused run has no final state, energy or error.
  EXPECT_EQ(cell(s, bad_h, "final_x1"), "");
  EXPECT_EQ(cell(s, bad_h, "error_final"), "");
}

TEST(StudyRuns, QuantitiesReachTheModel) {
  // K scaled by 0: no springs, x1'' = u, x2'' = 0. From x = (1, 0), v = (1, -1)
  // cart 1 moves away from the stop, so the motion is free: at t = 3,
  // x = (4, -3), v = (1, -1).
  const Study s = parse(
      "axes:\n"
      "  - {scale.K: [0], x0.x1: [1], x0.x2: [0], v0.x1: [1], v0.x2: [-1]}\n");
  const Row r = run_one(s, 0);
  ASSERT_EQ(cell(s, r, "status"), "completed") << cell(s, r, "message");
  // The exact method integrates x' = A x by matrix exponentials: rounding
  // only, a few ulp of 4 (1e-14 absolute is ~10 ulp).
  EXPECT_NEAR(std::stod(cell(s, r, "final_x1")), 4.0, 1e-14);
  EXPECT_NEAR(std::stod(cell(s, r, "final_x2")), -3.0, 1e-14);
  EXPECT_NEAR(std::stod(cell(s, r, "final_v_x1")), 1.0, 1e-14);
  EXPECT_EQ(cell(s, r, "events_impact"), "0");
  // The exact method is its own reference.
  EXPECT_EQ(cell(s, r, "error_final"), "0");
}

// A circuit's final-state columns carry its state names, as its trajectory
// CSV does (io::state_names): C1's voltage and L1's current, not x1, x2.
TEST(StudyRuns, CircuitColumnsNameTheStates) {
  const Study s =
      parse_study("model: ../../circuits/half_wave_rlc.cir\naxes:\n  - t_end: [1e-3]\n", kSource);
  const Row r = run_one(s, 0);
  ASSERT_EQ(cell(s, r, "status"), "completed") << cell(s, r, "message");
  EXPECT_EQ(cell(s, r, "final_x1"), "(no column final_x1)");
  // The same run outside the study: each named column holds its own entry.
  // The study may sample on another grid (the final state then comes from
  // another product of exponentials): rounding of a 10 V state, ~1e-14;
  // 1e-12 still tells C1.v (volts) from L1.i (tens of mA) apart.
  sim::Options opt;
  opt.t_end = 1e-3;
  const sim::Trajectory tr = sim::simulate(s.models.front(), opt);
  ASSERT_TRUE(tr.ok()) << tr.message;
  const std::vector<std::string> names = io::state_names(s.models.front());
  for (std::size_t i = 0; i < names.size(); ++i)
    EXPECT_NEAR(std::stod(cell(s, r, "final_" + names[i])), tr.final_state(static_cast<int>(i)),
                1e-12)
        << names[i];
  EXPECT_EQ(names.at(0), "C1.v");
  EXPECT_EQ(names.at(1), "L1.i");
}

TEST(StudyRuns, EventsAndEnergyOfTheThesisRun) {
  // The model's own x0 (thesis §3.7): cart 1 hits the stop at t = 1 with
  // velocity -1, the inelastic impact stops it (M = I: cart 2 keeps its
  // velocity), so exactly 1/2 J is lost and no energy elsewhere (no damping).
  // With restitution 1 the impact is elastic (v1: -1 -> +1) and no energy
  // is lost.
  const Study s = parse("axes:\n  - restitution.stop: {linspace: [0, 1, 2]}\n");
  const Row r = run_one(s, 0), elastic = run_one(s, 1);
  ASSERT_EQ(cell(s, r, "status"), "completed") << cell(s, r, "message");
  EXPECT_EQ(cell(s, r, "restitution.stop"), "0");
  EXPECT_EQ(cell(s, r, "events_impact"), "1");
  // Rounding of the energy (~1 J) over the matrix-exponential phases and the
  // event time found to ~1e-15: 1e-12 is a wide margin.
  EXPECT_NEAR(std::stod(cell(s, r, "energy_change")), -0.5, 1e-12);
  EXPECT_EQ(cell(s, r, "max_violation"), "0");
  ASSERT_EQ(cell(s, elastic, "status"), "completed") << cell(s, elastic, "message");
  EXPECT_EQ(cell(s, elastic, "restitution.stop"), "1");
  EXPECT_NEAR(std::stod(cell(s, elastic, "energy_change")), 0.0, 1e-12);
}

// mu.<constraint> sets the friction coefficient of the constraint's
// mechanical.friction entry: the block of robots/block_on_floor_friction.yaml
// (v0 = 2 m/s) sticks at x* = v0^2 / (2 mu g) (at t* = v0 / (mu g)), which the exact method hits to
// rounding (1e-12: tests/sim/test_event_friction.cpp's margin). A constraint
// without friction is a one-line error; mu < 0 a row of invalid input.
TEST(StudyRuns, FrictionCoefficientAxisAgainstTheSlidingBlocksClosedForm) {
  const std::string head = "model: ../../robots/block_on_floor_friction.yaml\n";
  const Study s = parse_study(head + "axes:\n  - mu.floor: [0.3, 0.4, -0.1]\n", kSource);
  for (const int i : {0, 1}) {
    const double mu = i == 0 ? 0.3 : 0.4;  // both stick before t_end = 1
    const Row r = run_one(s, static_cast<std::size_t>(i));
    ASSERT_EQ(cell(s, r, "status"), "completed") << cell(s, r, "message");
    EXPECT_NEAR(std::stod(cell(s, r, "final_x")), 4.0 / (2.0 * mu * 9.81), 1e-12) << mu;
  }
  const Row bad = run_one(s, 2);
  EXPECT_EQ(cell(s, bad, "status"), "invalid input");
  EXPECT_NE(cell(s, bad, "message").find("mu"), std::string::npos) << cell(s, bad, "message");
  try {
    (void)parse("axes:\n  - mu.stop: [0.2]\n");
    ADD_FAILURE() << "a constraint without friction was accepted";
  } catch (const io::InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              kSource +
                  ": axes[0].mu.stop: constraint 'stop' of model 'two_carts' has no friction (no "
                  "mechanical.friction entry, no scene contact's friction:)");
  }
}

TEST(StudyJournal, ResumeReadsWholeLinesAndRefusesAnotherStudy) {
  const std::string path = testing::TempDir() + "/study_journal_test.journal";
  std::filesystem::remove(path);
  Row a;
  a.index = 3;
  a.completed = true;
  a.cells = {"3", "x, \"y\"\n"};
  {
    Journal j(path, "study-A", 10, false);
    j.append(a);
  }
  EXPECT_THROW(Journal(path, "study-A", 10, false), io::InputError);  // no --resume
  EXPECT_THROW(Journal(path, "study-B", 10, true), io::InputError);   // another study
  {
    // A torn line after the good one: dropped, and cut off before appending.
    std::ofstream(path, std::ios::app) << "{\"i\":4,\"w\":0,\"ok\":tr";
    Journal j(path, "study-A", 10, true);
    ASSERT_EQ(j.rows().size(), 1u);
    EXPECT_EQ(j.rows()[0].index, 3u);
    EXPECT_EQ(j.rows()[0].cells, a.cells);
    a.index = 5;
    j.append(a);
  }
  Journal j(path, "study-A", 10, true);
  ASSERT_EQ(j.rows().size(), 2u);
  EXPECT_EQ(j.rows()[1].index, 5u);
  std::filesystem::remove(path);
}

TEST(StudyDispenser, GuidedBlocksOfTheIndicesLeft) {
  // 2000 runs on 2 ranks: blocks of max(1, remaining / 8): 2000 / 8 = 250,
  // then (2000 - 250 - 1) / 8 = 218 after rank 0 took run 250 for itself.
  std::vector<std::size_t> fresh(2000);
  for (std::size_t i = 0; i < fresh.size(); ++i) fresh[i] = i;
  Dispenser d(fresh);
  EXPECT_EQ(d.block(2), (std::vector<Range>{{0, 250}}));
  EXPECT_EQ(d.next(), 250u);
  EXPECT_EQ(d.block(2), (std::vector<Range>{{251, 218}}));
  EXPECT_EQ(d.remaining(), 2000u - 250 - 1 - 218);
  d.stop();
  EXPECT_EQ(d.next(), std::nullopt);
  EXPECT_TRUE(d.block(2).empty());
}

TEST(StudyDispenser, ResumedGapsGiveSeveralRangesAndEveryIndexOnce) {
  // 16 indices left by a resumed journal, one rank: blocks of 16/4 = 4,
  // then 12/4 = 3, then (after next()) 8/4 = 2, then single indices.
  const std::vector<std::size_t> todo = {3, 4, 7, 8, 9, 15, 16, 17, 18, 19, 30, 31, 32, 33, 34, 35};
  Dispenser d(todo);
  EXPECT_EQ(d.block(1), (std::vector<Range>{{3, 2}, {7, 2}}));
  EXPECT_EQ(d.block(1), (std::vector<Range>{{9, 1}, {15, 2}}));
  EXPECT_EQ(d.next(), 17u);
  EXPECT_EQ(d.block(1), (std::vector<Range>{{18, 2}}));
  for (std::size_t i : {30, 31, 32, 33, 34, 35})
    EXPECT_EQ(d.block(1), (std::vector<Range>{{i, 1}}));
  EXPECT_TRUE(d.block(1).empty());
}

TEST(StudyDispenser, MoreRanksThanRunsGetOneEachThenNone) {
  const std::vector<std::size_t> todo = {0, 1};
  Dispenser d(todo);
  EXPECT_EQ(d.block(3), (std::vector<Range>{{0, 1}}));
  EXPECT_EQ(d.block(3), (std::vector<Range>{{1, 1}}));
  EXPECT_TRUE(d.block(3).empty());
  EXPECT_EQ(d.next(), std::nullopt);
}

TEST(StudyDispenser, BlocksTravelAsTextAndOtherTextIsRefused) {
  EXPECT_EQ(encode_ranges({{3, 2}, {7, 12}}), "3 2 7 12");
  EXPECT_EQ(decode_ranges("3 2 7 12"), (std::vector<Range>{{3, 2}, {7, 12}}));
  EXPECT_EQ(encode_ranges({}), "");
  EXPECT_EQ(decode_ranges(""), std::vector<Range>{});  // the stop message
  for (const char* bad : {"3", "3 0", "3  2", "3 2 ", " 3 2", "x 2", "-1 2", "3,2"})
    EXPECT_EQ(decode_ranges(bad), std::nullopt) << bad;
  // Rows travel one a line (mpi.cpp): an encoded row never holds a newline.
  Row r;
  r.cells = {"a\nb", "c\r\n"};
  EXPECT_EQ(encode_row(r).find('\n'), std::string::npos);
  EXPECT_EQ(decode_row(encode_row(r))->cells, r.cells);
}

TEST(StudyFile, MalformedFilesGiveOneLineErrorsNamingFileKeyAndValue) {
  const std::string f = kSource + ": ";
  EXPECT_EQ(error_of("axes:\n  - x0.nope: [1]\n"),
            f + "axes[0].x0.nope: no coordinate 'nope' in model 'two_carts' (it has x1, x2)");
  EXPECT_EQ(error_of("axes:\n  - method: [event, rk4]\n").rfind(f + "axes[0].method[1]: ", 0), 0u);
  EXPECT_EQ(
      error_of("axes:\n  - {h: [1, 2], theta: [0.5]}\n"),
      f + "axes[0].theta: has 1 values, the axis 2 (the quantities of one axis vary together)");
  EXPECT_EQ(error_of("axes:\n  - h: {logspace: [0, 1, 3]}\n"),
            f + "axes[0].h.logspace: ends must be > 0 (got 0, 1)");
  EXPECT_EQ(error_of("axes:\n  - x0.x1: {uniform: [0, 1]}\n"),
            f + "axes[0].x0.x1: a random draw needs `count:` in its axis");
  EXPECT_EQ(error_of("axes:\n  - h: [abc]\n"), f + "axes[0].h[0]: not a number (got 'abc')");
  EXPECT_EQ(error_of("sede: 1\n").rfind(f + "sede: unknown key", 0), 0u);
  EXPECT_EQ(error_of("seed: -1\n"), f + "seed: expected a whole number in [0, 2^53) (got '-1')");
  EXPECT_EQ(error_of("axes:\n  - h: [1]\n  - h: [2]\n"),
            f + "axes[1].h: set by two axes (each quantity is set by one)");
  const std::string no_model = [] {
    try {
      (void)parse_study("axes: []\n", "s.yaml");
    } catch (const io::InputError& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  }();
  EXPECT_EQ(no_model, "s.yaml: model: give either `model:` or `models:` (a list)");
}

TEST(StudyTable, JsonLinesHoldNumbersAndNullsAndCsvQuotes) {
  const Study s = parse("axes:\n  - h: [1e-3]\n");
  Row r;
  r.cells.assign(columns(s).size(), "");
  r.cells[0] = "0";
  r.cells[1] = "0.001";
  r.cells[2] = "completed";
  r.cells[3] = "a, \"quoted\" message";
  const std::string csv = table_text(s, {r}, false);
  EXPECT_NE(csv.find("0,0.001,completed,\"a, \"\"quoted\"\" message\","), std::string::npos) << csv;
  const std::string jsonl = table_text(s, {r}, true);
  EXPECT_EQ(jsonl.rfind("{\"index\":0,\"h\":0.001,\"status\":\"completed\",\"message\":\"a, "
                        "\\\"quoted\\\" message\",\"t_reached\":null",
                        0),
            0u)
      << jsonl;
}

}  // namespace
}  // namespace lcsim::study
