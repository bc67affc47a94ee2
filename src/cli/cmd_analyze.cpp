// `lcsim analyze MODEL [--json] [--full]`: what a model is and whether the theory
// applies to it, before simulating: dimensions, M's definiteness, rank of E,
// the Delassus matrix E M^{-1} E' and its P-property (uniqueness of the impact
// LCP (3.69)-(3.70)), notes on the model, and the well-posedness report of the
// LCS (Markov parameters (3.32), leading indices and coefficient matrices
// (3.39), Theorem 3.6.3, passivity §7.2, backward Euler guard §7.3).
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <lcsim/io/io.hpp>
#include <lcsim/lcp/lcp.hpp>
#include <lcsim/lcs/lcs.hpp>
#include <lcsim/mech/mech.hpp>
#include <lcsim/scene/linearisation.hpp>
#include <lcsim/scene/scene.hpp>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include "cli/command.hpp"
#include "cli/output.hpp"

namespace lcsim::cli {
namespace {

using Eigen::MatrixXd;

struct AnalyzeArgs {
  std::string file;
  bool json = false;
  bool full = false;      // --full: every matrix and set (default: the library's summary)
  std::string model_out;  // --model-out: the linear model as YAML
  double linearisation_threshold = scene::kLinearisationThreshold;
};

std::string num(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

std::string matrix_text(const MatrixXd& m, const std::string& indent) {
  if (m.size() == 0)
    return indent + "(" + std::to_string(m.rows()) + " x " + std::to_string(m.cols()) +
           ", empty)\n";
  std::string s;
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    s += indent + "[";
    for (Eigen::Index j = 0; j < m.cols(); ++j) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%12.6g", m(i, j));
      s += buf;
    }
    s += " ]\n";
  }
  return s;
}

std::string indices_text(const std::vector<int>& v) {
  std::string s = "(";
  for (std::size_t i = 0; i < v.size(); ++i)
    s +=
        (i ? ", " : "") + (v[i] == lcs::kInfiniteIndex ? std::string("inf") : std::to_string(v[i]));
  return s + ")";
}

nlohmann::json indices_json(const std::vector<int>& v) {
  nlohmann::json a = nlohmann::json::array();
  for (int i : v)
    a.push_back(i == lcs::kInfiniteIndex ? nlohmann::json(nullptr) : nlohmann::json(i));
  return a;
}

// What a summary leaves out (lcs::summary_left_out, mech::kSummarySets):
// the JSON names, listed in the output with how to get them.
using LeftOut = std::vector<std::string>;

// `m` as text, or, when a summary leaves it out (`name` added to `left`),
// its size only.
std::string matrix_or_size(const MatrixXd& m, const std::string& indent, bool full,
                           const std::string& name, LeftOut& left) {
  if (full || lcs::summary_shows(m.size())) return matrix_text(m, indent);
  left.push_back(name);
  return indent + "(" + std::to_string(m.rows()) + " x " + std::to_string(m.cols()) +
         ": left out of the summary; --full prints it)\n";
}

struct Coactive {
  mech::CoactiveSets sets;
  mech::CoactiveWellPosedness wp;
};

// Theorem 3.6.3 holds on every set found (CoactiveWellPosedness::
// locally_well_posed also asks that the enumeration be complete).
bool all_found_pass(const Coactive& c) {
  return std::all_of(c.wp.sets.begin(), c.wp.sets.end(),
                     [](const auto& r) { return r.row_p_matrix && r.column_p_matrix; });
}

Coactive coactive(const mech::MechanicalModel& m) {
  Coactive c;
  c.sets = mech::coactive_sets(m);
  c.wp = mech::coactive_well_posedness(m, c.sets);
  return c;
}

std::string names_text(const mech::MechanicalModel& m, const std::vector<int>& J) {
  std::string s = "{";
  for (std::size_t i = 0; i < J.size(); ++i) s += (i ? ", " : "") + m.constraints[J[i]];
  return s + "}";
}

nlohmann::json names_json(const mech::MechanicalModel& m, const std::vector<int>& J) {
  nlohmann::json a = nlohmann::json::array();
  for (int i : J) a.push_back(m.constraints[i]);
  return a;
}

nlohmann::json coactive_json(const mech::MechanicalModel& m, const Coactive& c, bool full,
                             LeftOut& left) {
  nlohmann::json j;
  nlohmann::json sets = nlohmann::json::array();
  const std::size_t shown = full ? c.wp.sets.size() : mech::kSummarySets;
  if (c.wp.sets.size() > shown) left.push_back("coactive.maximal_sets");
  if (c.sets.exclusive_pairs.size() > shown) left.push_back("coactive.exclusive_pairs");
  j["maximal_sets_count"] = c.wp.sets.size();
  j["exclusive_pairs_count"] = c.sets.exclusive_pairs.size();
  for (const auto& s : c.wp.sets) {
    if (sets.size() == shown) break;
    sets.push_back({{"constraints", names_json(m, s.indices)},
                    {"rank", s.rank},
                    {"delassus_p_matrix", s.delassus_p_matrix},
                    {"row_p_matrix", s.row_p_matrix},
                    {"column_p_matrix", s.column_p_matrix}});
  }
  j["maximal_sets"] = std::move(sets);
  nlohmann::json pairs = nlohmann::json::array();
  for (const auto& [a, b] : c.sets.exclusive_pairs) {
    if (pairs.size() == shown) break;
    pairs.push_back({m.constraints[a], m.constraints[b]});
  }
  j["exclusive_pairs"] = std::move(pairs);
  j["never_active"] = names_json(m, c.sets.never_active);
  j["complete"] = c.sets.complete;
  j["dependent"] = c.wp.dependent;
  j["delassus_p_matrix"] = c.wp.all_delassus_p;
  // Undecided (null) when the enumeration was cut short and every set found passed.
  j["locally_well_posed"] = !c.sets.complete && all_found_pass(c)
                                ? nlohmann::json()
                                : nlohmann::json(c.wp.locally_well_posed);
  j["note"] =
      "verdicts on the maximal sets of constraints that can be active together (some admissible "
      "q closes them all); other sets never reach an impact LCP or a mode";
  return j;
}

std::string coactive_text(const mech::MechanicalModel& m, const Coactive& c, bool full) {
  std::ostringstream out;
  out << "  sets active together (some admissible q closes them all): " << c.wp.sets.size()
      << " maximal" << (c.sets.complete ? "" : " (enumeration cut short)") << "\n";
  const std::size_t kShown = full ? c.wp.sets.size() : mech::kSummarySets;
  for (std::size_t i = 0; i < c.wp.sets.size() && i < kShown; ++i) {
    const auto& s = c.wp.sets[i];
    out << "    " << names_text(m, s.indices) << "  rank " << s.rank
        << ", Delassus P: " << (s.delassus_p_matrix ? "yes" : "no") << ", Theorem 3.6.3: "
        << (s.row_p_matrix && s.column_p_matrix ? "applies" : "does not apply") << "\n";
  }
  if (c.wp.sets.size() > kShown)
    out << "    ... (" << c.wp.sets.size() - kShown << " more; --full lists them)\n";
  if (!c.sets.exclusive_pairs.empty())
    out << "  never active together: " << c.sets.exclusive_pairs.size() << " pairs, e.g. "
        << m.constraints[c.sets.exclusive_pairs[0].first] << " and "
        << m.constraints[c.sets.exclusive_pairs[0].second] << "\n";
  if (!c.sets.never_active.empty())
    out << "  never active at all: " << names_text(m, c.sets.never_active) << "\n";
  const bool undecided = !c.sets.complete && all_found_pass(c);
  out << "  on " << (c.sets.complete ? "these sets" : "the sets found") << ": Delassus P-matrix "
      << (c.wp.all_delassus_p ? "yes" : "no") << ", Theorem 3.6.3 "
      << (undecided                 ? "applies on them (not decided on the sets not enumerated)"
          : c.wp.locally_well_posed ? "applies"
                                    : "does not apply")
      << (c.wp.dependent ? "; some set has dependent rows (§4.6.1)" : "") << "\n";
  return out.str();
}

// Scenes: where the linear model holds, per simulated joint (scene::linear_ranges).
void linear_ranges_section(const std::optional<scene::Scene>& scene, double threshold,
                           nlohmann::json& j, std::ostringstream& out) {
  if (!scene) {
    j["linear_ranges"] = nullptr;
    return;
  }
  const std::vector<scene::LinearRange> ranges = scene::linear_ranges(*scene, threshold);
  j["linear_ranges"] = scene::to_json(ranges);
  j["linearisation_threshold"] = threshold;
  out << "linear model: error <= " << num(100.0 * threshold)
      << " % (mass and forces, docs/model-format.md) for q in, each joint alone:\n";
  for (const auto& r : ranges)
    out << "  " << r.joint << ": [" << num(r.lower) << ", " << num(r.upper) << "] " << r.unit
        << "  (q0 = " << num(r.q0) << "; ends: " << r.lower_end << ", " << r.upper_end << ")\n";
}

void run_analyze(const AnalyzeArgs& args) {
  scene::check_linearisation_threshold(args.linearisation_threshold);
  if (!args.model_out.empty()) check_writable(args.model_out);
  const scene::LoadedModel loaded = scene::load_model_and_scene(args.file);
  const std::optional<scene::Scene>& scene = loaded.scene;
  const mech::Model& model = loaded.model;
  const std::vector<std::string> notes = scene::model_notes(loaded);
  const lcs::Lcs sys = model.as_lcs();
  const lcs::WellPosednessReport wp = lcs::analyze_well_posedness(sys);

  nlohmann::json j;
  std::ostringstream out;
  LeftOut left;
  std::vector<std::string> not_judged;
  j["name"] = model.name;
  j["source"] = model.source;
  j["kind"] = model.is_mechanical() ? "mechanical" : "lcs";
  j["state_size"] = model.state_size();
  j["constraints"] = model.num_constraints();
  j["lcs_state_size"] = sys.n();
  out << "model:       " << model.name << "  (" << model.source << ")\n";
  if (model.is_mechanical()) {
    const mech::MechanicalModel& m = *model.mechanical;
    const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<MatrixXd>(m.M.toDense()).eigenvalues();
    const long rank_e = mech::constraint_rank(m);
    j["dofs"] = m.dofs();
    j["coordinates"] = m.coordinates;
    j["constraint_names"] = m.constraints;
    j["M_min_eigenvalue"] = ev.minCoeff();
    j["M_max_eigenvalue"] = ev.maxCoeff();
    j["M_positive_definite"] = ev.minCoeff() > 0.0;
    j["E_rank"] = rank_e;
    j["lcs_augmented"] = true;
    out << "kind:        mechanical  M q'' + D q' + K q = f + E' u,  0 <= E q + g _|_ u >= 0\n"
        << "dimensions:  N = " << m.dofs() << " coordinates, k = " << m.num_constraints()
        << " constraints, state (q, v) of size " << model.state_size() << "\n"
        << "M:           positive definite: smallest eigenvalue " << num(ev.minCoeff())
        << ", largest " << num(ev.maxCoeff()) << "\n"
        << "rank E:      " << rank_e << " of " << m.num_constraints();
    std::optional<Coactive> co;
    if (m.num_constraints() > 0 && m.num_constraints() <= mech::kMaxCoactiveConstraints)
      co = coactive(m);
    not_judged = mech::coactive_not_judged(m, co ? &co->sets : nullptr, static_cast<int>(rank_e));
    if (rank_e < m.num_constraints())
      out << (!co ? "  (not judged: dependent constraints or rows that cannot be active "
                    "together; see \"not judged\" below)"
              : co->wp.dependent ? "  (dependent constraints)"
              : co->sets.complete
                  ? "  (rows that cannot be active together, not dependent constraints)"
                  : "  (rows that cannot be active together; dependent constraints in "
                    "sets not enumerated not excluded)");
    out << "\n";
    if (m.num_constraints() > 0) {
      const MatrixXd W = mech::delassus(m);
      const bool p = lcp::is_p_matrix(W);
      const std::size_t before = left.size();
      out << "Delassus matrix E M^-1 E' (impact LCP (3.69)-(3.70)):\n"
          << matrix_or_size(W, "    ", args.full, "delassus", left) << "  P-matrix: ";
      j["delassus"] = left.size() == before ? io::to_json(W) : nlohmann::json();
      j["delassus_p_matrix"] = p;
      out << (p ? "yes" : "no")
          << (p ? "  (unique impulse)"
                : "  (impulses may be non-unique; post-impact velocities still are, §4.6.1)")
          << "\n";
      if (co) {
        j["coactive"] = coactive_json(m, *co, args.full, left);
        out << coactive_text(m, *co, args.full);
      } else {
        j["coactive"] = nullptr;
        out << "  sets active together: not enumerated (k = " << m.num_constraints() << " > "
            << mech::kMaxCoactiveConstraints << "); the verdicts below are on all k rows at once\n";
      }
    } else {
      j["delassus"] = nlohmann::json::array();
      j["delassus_p_matrix"] = nullptr;
    }
    out << "LCS (3.65):  augmented with a constant state for the affine terms f and g: "
        << "x = (q, v, 1) of size 2N+1 = " << sys.n() << "\n";
  } else {
    j["lcs_augmented"] = false;
    const int rank_b = lcs::numerical_rank(sys.B), rank_c = lcs::numerical_rank(sys.C);
    out << "kind:        lcs  x' = A x + B u,  y = C x + D u,  0 <= y _|_ u >= 0\n"
        << "dimensions:  n = " << sys.n() << " states, k = " << sys.k() << " pairs\n"
        << "rank B:      " << rank_b << ",  rank C: " << rank_c << "\n";
    j["B_rank"] = rank_b;
    j["C_rank"] = rank_c;
  }
  j["notes"] = notes;
  out << "notes:";
  if (notes.empty()) out << "       none";
  out << "\n";
  for (const auto& n : notes) out << "  - " << n << "\n";

  nlohmann::json w;
  w["n"] = wp.n;
  w["k"] = wp.k;
  const LeftOut wp_left = args.full ? LeftOut{} : lcs::summary_left_out(wp);
  const auto shown = [&](const char* name) {
    return std::find(wp_left.begin(), wp_left.end(), name) == wp_left.end();
  };
  nlohmann::json markov = nlohmann::json::array();
  for (const auto& H : wp.markov) markov.push_back(io::to_json(H));
  w["markov"] = shown("markov") ? std::move(markov) : nlohmann::json();
  w["rho"] = indices_json(wp.rho);
  w["eta"] = indices_json(wp.eta);
  w["row_coefficients"] =
      shown("row_coefficients") ? io::to_json(wp.row_coefficients) : nlohmann::json();
  w["column_coefficients"] =
      shown("column_coefficients") ? io::to_json(wp.column_coefficients) : nlohmann::json();
  w["row_p_matrix"] = wp.row_p_matrix;
  w["column_p_matrix"] = wp.column_p_matrix;
  w["locally_well_posed"] = wp.locally_well_posed;
  w["passive"] = wp.passive;
  w["passivity_reason"] = wp.passivity_reason;
  w["backward_euler_risky"] = wp.backward_euler_risky;
  j["well_posedness"] = std::move(w);

  out << "well-posedness of the LCS (n = " << wp.n << ", k = " << wp.k << "):\n"
      << "  Markov parameters H^0..H^" << (wp.markov.empty() ? 0 : wp.markov.size() - 1)
      << " (3.32):\n";
  if (shown("markov"))
    for (std::size_t i = 0; i < wp.markov.size(); ++i)
      out << "    H^" << i << ":\n" << matrix_text(wp.markov[i], "      ");
  else
    out << "    (" << wp.markov.size() << " matrices of " << wp.k << " x " << wp.k
        << ": left out of the summary; --full prints them)\n";
  const auto coefficients = [&](const MatrixXd& X, const char* name) {
    if (shown(name)) return matrix_text(X, "    ");
    return "    (" + std::to_string(X.rows()) + " x " + std::to_string(X.cols()) +
           ": left out of the summary; --full prints it)\n";
  };
  out << "  leading row indices rho:    " << indices_text(wp.rho) << "\n"
      << "  leading column indices eta: " << indices_text(wp.eta) << "\n"
      << "  leading row coefficients (script M, (3.39)):\n"
      << coefficients(wp.row_coefficients, "row_coefficients")
      << "    P-matrix: " << (wp.row_p_matrix ? "yes" : "no") << "\n"
      << "  leading column coefficients (script N, (3.39)):\n"
      << coefficients(wp.column_coefficients, "column_coefficients")
      << "    P-matrix: " << (wp.column_p_matrix ? "yes" : "no") << "\n"
      << "  Theorem 3.6.3 (local well-posedness), all k rows at once: "
      << (wp.locally_well_posed ? "applies" : "does not apply")
      << (j.contains("coactive") && !j["coactive"].is_null()
              ? std::string("; on the sets that can be active together: ") +
                    (j["coactive"]["locally_well_posed"].is_null()
                         ? "not decided (enumeration cut short)"
                     : j["coactive"]["locally_well_posed"].get<bool>() ? "applies"
                                                                       : "does not apply")
              : std::string())
      << "\n"
      << "  passive (§7.2, of the LCS; D there is its feedthrough in y = C x + D u): " << wp.passive
      << (wp.passivity_reason.empty() ? "" : " (" + wp.passivity_reason + ")") << "\n"
      << "  backward Euler (§7.3): "
      << (wp.backward_euler_risky
              ? "RISKY: some rho_i >= 3, time-stepping may diverge (Example 7.3.3)"
              : "no relative degree >= 3")
      << "\n";

  linear_ranges_section(scene, args.linearisation_threshold, j, out);
  for (const auto& n : wp_left) left.push_back("well_posedness." + n);
  j["not_judged"] = not_judged;
  if (!not_judged.empty()) out << "not judged:\n";
  for (const auto& n : not_judged) out << "  - " << n << "\n";
  j["full"] = args.full;
  j["left_out"] = left;
  if (!left.empty()) {
    out << "left out of this summary (--full prints them): ";
    for (std::size_t i = 0; i < left.size(); ++i) out << (i ? ", " : "") << left[i];
    out << "\n";
  }
  if (!args.model_out.empty()) {
    io::write_file_atomic(args.model_out,
                          io::model_yaml(model, "The linear model of " + model.source +
                                                    ", written by lcsim analyze --model-out"));
    out << "model written to " << args.model_out << "\n";
  }

  if (args.json)
    std::cout << j.dump(2) << "\n";
  else
    std::cout << out.str();
}

}  // namespace

LCSIM_REGISTER_COMMAND([](CLI::App& app) {
  auto args = std::make_shared<AnalyzeArgs>();
  CLI::App* cmd = app.add_subcommand(
      "analyze", "Describe a model and check the well-posedness conditions before simulating");
  cmd->add_option("model", args->file, "model file (YAML)")->required();
  cmd->add_flag("--json", args->json, "print one JSON object");
  cmd->add_flag("--full", args->full,
                "print every matrix and set (default: a summary, which names what it leaves out)");
  cmd->add_option("--model-out", args->model_out,
                  "write the model (a scene: its linearisation) as a YAML model file");
  cmd->add_option("--linearisation-threshold", args->linearisation_threshold,
                  "scenes: relative error of the linear model for the ranges (default 0.01)");
  cmd->callback([args] { run_analyze(*args); });
});

}  // namespace lcsim::cli
