// A model's analysis report (`lcsim analyze`, Python's `lcsim.analyze`): what
// a model is and whether the theory applies to it, before simulating:
// dimensions, M's definiteness, rank of E, the Delassus matrix E M^{-1} E'
// and its P-property (uniqueness of the impact LCP (3.69)-(3.70)), the sets of
// constraints that can be active together, notes on the model, the
// well-posedness report of the LCS (Markov parameters (3.32), leading indices
// and coefficient matrices (3.39), Theorem 3.6.3, passivity §7.2, backward
// Euler guard §7.3) and, for a scene, where its linear model holds.
//
// One report for both front ends: the CLI prints `json` (--json) or `text`,
// Python returns `json` as a dict. The text names the option `full` as
// "full = true"; the CLI shows it as its flag.
#pragma once

#include <lcsim/scene/linearisation.hpp>
#include <lcsim/scene/scene.hpp>
#include <nlohmann/json.hpp>
#include <string>

namespace lcsim::app {

struct AnalysisOptions {
  // Every matrix and set. false: a summary, which leaves out a matrix of more
  // than lcs::kSummaryEntries numbers and the sets beyond mech::kSummarySets,
  // and names what it left out ("left_out").
  bool full = false;
  // Scenes: relative error of the linear model that bounds its ranges
  // (scene::linear_ranges), dimensionless, finite and > 0.
  double linearisation_threshold = scene::kLinearisationThreshold;
};

// io::InputError when an option is out of range (the threshold; the message is
// scene::check_linearisation_threshold's).
void check_analysis_options(const AnalysisOptions& options);

struct AnalysisReport {
  nlohmann::json json;  // what `lcsim analyze --json` prints
  std::string text;     // the same report in words (`lcsim analyze`)
};

// Checks `options`, then analyses `loaded` (a scene: its linearisation). May
// throw io::InputError (the options; a model beyond mech::kMaxDenseLcsState).
AnalysisReport analysis_report(const scene::LoadedModel& loaded,
                               const AnalysisOptions& options = {});

}  // namespace lcsim::app
