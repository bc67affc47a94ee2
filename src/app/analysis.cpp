// The analysis report (analysis.hpp), in stages named for the sections they
// write: the model, its mechanical part (M, rank E, the Delassus matrix and the
// sets active together) or its LCS part, the notes, the well-posedness of the
// LCS, a scene's linear ranges, and what was not judged or left out. Each
// stage writes its JSON fields and its lines of text from the same values.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cstdio>
#include <lcsim/app/analysis.hpp>
#include <lcsim/circuit/circuit.hpp>
#include <lcsim/core/format.hpp>
#include <lcsim/io/json.hpp>
#include <lcsim/io/yaml.hpp>
#include <lcsim/lcp/lcp.hpp>
#include <lcsim/lcs/lcs.hpp>
#include <lcsim/mech/mech.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace lcsim::app {
namespace {

using Eigen::MatrixXd;

// The option that makes the report full, as the text names it (the CLI shows
// its flag instead).
constexpr const char* kFullOption = "full = true";

// What a summary leaves out (lcs::summary_left_out, mech::kSummarySets):
// the JSON names, listed in the output with how to get them.
using LeftOut = std::vector<std::string>;

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

// Leading indices (3.39), an infinite one as "inf" (text) or null (JSON).
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

// The sets of constraints that can be active together and the verdicts on them.
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
    out << "    ... (" << c.wp.sets.size() - kShown << " more; " << kFullOption << " lists them)\n";
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

// The report as it is written, stage by stage.
struct Draft {
  const AnalysisOptions& options;
  nlohmann::json j;
  std::ostringstream out;
  LeftOut left;  // what the summary left out, by JSON name
  std::vector<std::string> not_judged;
};

// `m` as text, or, when a summary leaves it out (`name` added to `left`),
// its size only.
std::string matrix_or_size(const MatrixXd& m, const std::string& indent, bool full,
                           const std::string& name, LeftOut& left) {
  if (full || lcs::summary_shows(m.size())) return matrix_text(m, indent);
  left.push_back(name);
  return indent + "(" + std::to_string(m.rows()) + " x " + std::to_string(m.cols()) +
         ": left out of the summary; " + kFullOption + " prints it)\n";
}

void describe_model(Draft& d, const mech::Model& model, const lcs::Lcs& sys) {
  d.j["name"] = model.name;
  d.j["source"] = model.source;
  d.j["kind"] = model.is_mechanical() ? "mechanical" : "lcs";
  d.j["state_size"] = model.state_size();
  d.j["constraints"] = model.num_constraints();
  d.j["lcs_state_size"] = sys.n();
  d.out << "model:       " << model.name << "  (" << model.source << ")\n";
}

// Why rank E < k, when it is: the sets active together tell dependent rows
// from rows that cannot be active together.
const char* rank_remark(const std::optional<Coactive>& co) {
  if (!co)
    return "  (not judged: dependent constraints or rows that cannot be active "
           "together; see \"not judged\" below)";
  if (co->wp.dependent) return "  (dependent constraints)";
  if (co->sets.complete)
    return "  (rows that cannot be active together, not dependent constraints)";
  return "  (rows that cannot be active together; dependent constraints in "
         "sets not enumerated not excluded)";
}

// M's eigenvalues, rank E and the sets active together (when k is small
// enough to enumerate them); what cannot be judged.
std::optional<Coactive> mass_and_rank(Draft& d, const mech::Model& model) {
  const mech::MechanicalModel& m = *model.mechanical;
  const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<MatrixXd>(m.M.toDense()).eigenvalues();
  const long rank_e = mech::constraint_rank(m);
  d.j["dofs"] = m.dofs();
  d.j["coordinates"] = m.coordinates;
  d.j["constraint_names"] = m.constraints;
  d.j["M_min_eigenvalue"] = ev.minCoeff();
  d.j["M_max_eigenvalue"] = ev.maxCoeff();
  d.j["M_positive_definite"] = ev.minCoeff() > 0.0;
  d.j["E_rank"] = rank_e;
  d.j["lcs_augmented"] = true;
  d.out << "kind:        mechanical  M q'' + D q' + K q = f + E' u,  0 <= E q + g _|_ u >= 0\n"
        << "dimensions:  N = " << m.dofs() << " coordinates, k = " << m.num_constraints()
        << " constraints, state (q, v) of size " << model.state_size() << "\n"
        << "M:           positive definite: smallest eigenvalue " << short_number(ev.minCoeff())
        << ", largest " << short_number(ev.maxCoeff()) << "\n"
        << "rank E:      " << rank_e << " of " << m.num_constraints();
  std::optional<Coactive> co;
  if (m.num_constraints() > 0 && m.num_constraints() <= mech::kMaxCoactiveConstraints)
    co = coactive(m);
  d.not_judged = mech::coactive_not_judged(m, co ? &co->sets : nullptr, static_cast<int>(rank_e));
  if (rank_e < m.num_constraints()) d.out << rank_remark(co);
  d.out << "\n";
  return co;
}

// The Delassus matrix E M^-1 E' and its P-property, then the sets active
// together (k > 0 only).
void delassus_section(Draft& d, const mech::MechanicalModel& m, const std::optional<Coactive>& co) {
  if (m.num_constraints() == 0) {
    d.j["delassus"] = nlohmann::json::array();
    d.j["delassus_p_matrix"] = nullptr;
    return;
  }
  const bool full = d.options.full;
  const MatrixXd W = mech::delassus(m);
  const bool p = lcp::is_p_matrix(W);
  const std::size_t before = d.left.size();
  d.out << "Delassus matrix E M^-1 E' (impact LCP (3.69)-(3.70)):\n"
        << matrix_or_size(W, "    ", full, "delassus", d.left) << "  P-matrix: ";
  d.j["delassus"] = d.left.size() == before ? io::to_json(W) : nlohmann::json();
  d.j["delassus_p_matrix"] = p;
  d.out << (p ? "yes" : "no")
        << (p ? "  (unique impulse)"
              : "  (impulses may be non-unique; post-impact velocities still are, §4.6.1)")
        << "\n";
  if (co) {
    d.j["coactive"] = coactive_json(m, *co, full, d.left);
    d.out << coactive_text(m, *co, full);
  } else {
    d.j["coactive"] = nullptr;
    d.out << "  sets active together: not enumerated (k = " << m.num_constraints() << " > "
          << mech::kMaxCoactiveConstraints << "); the verdicts below are on all k rows at once\n";
  }
}

void mechanical_section(Draft& d, const mech::Model& model, const lcs::Lcs& sys) {
  const std::optional<Coactive> co = mass_and_rank(d, model);
  delassus_section(d, *model.mechanical, co);
  const mech::MechanicalModel& m = *model.mechanical;
  d.out << "LCS (3.65):  augmented with a constant state for the affine terms f and g: ";
  if (!m.has_inputs()) {
    d.out << "x = (q, v, 1) of size 2N+1 = " << sys.n() << "\n";
    return;
  }
  // The inputs' exosystems follow (docs/inputs.md): name their states.
  std::string sizes;
  for (const mech::Input& in : m.inputs)
    sizes += (sizes.empty() ? "" : ", ") + in.name + ": " + std::to_string(in.exo_size());
  d.out << "x = (q, v, 1, w) of size " << sys.n() << ", w the inputs' exosystem states (" << sizes
        << ")\n";
}

void lcs_section(Draft& d, const lcs::Lcs& sys) {
  d.j["lcs_augmented"] = false;
  const int rank_b = lcs::numerical_rank(sys.B), rank_c = lcs::numerical_rank(sys.C);
  d.out << "kind:        lcs  x' = A x + B u,  y = C x + D u,  0 <= y _|_ u >= 0\n"
        << "dimensions:  n = " << sys.n() << " states, k = " << sys.k() << " pairs\n"
        << "rank B:      " << rank_b << ",  rank C: " << rank_c << "\n";
  d.j["B_rank"] = rank_b;
  d.j["C_rank"] = rank_c;
}

// A SPICE netlist's circuit (issue 29): thesis Ch. 5's passivity, then
// well-posedness or the condition that fails, on the circuit with its
// sources set to zero (the exosystem's states left out).
void circuit_section(Draft& d, const circuit::Circuit& c) {
  const circuit::PassivityReport r = circuit::judge_passivity(c);
  nlohmann::json diodes = nlohmann::json::array();
  std::string forms;
  for (std::size_t p = 0; p < c.diode_element.size(); ++p) {
    const bool voltage = c.diode_form[p] == circuit::DiodeForm::kVoltage;
    const std::string& name = c.netlist.elements[c.diode_element[p]].name;
    diodes.push_back({{"name", name}, {"form", voltage ? "voltage" : "current"}});
    forms += (p ? ", " : "") + name + (voltage ? " (voltage form)" : "");
  }
  d.j["circuit"] = {{"title", c.netlist.title},
                    {"circuit_states", c.circuit_states},
                    {"exosystem_states", c.model.exo_states},
                    {"diodes", diodes},
                    {"initial_state", c.initial_note},
                    {"passive", r.passive},
                    {"passive_reason", r.passive_reason},
                    {"negative_elements", r.negative_elements},
                    {"B_full_column_rank", r.full_column_rank_b},
                    {"controllable", r.controllable},
                    {"observable", r.observable},
                    {"globally_well_posed", r.globally_well_posed},
                    {"locally_well_posed", r.locally_well_posed},
                    {"verdict", r.verdict}};
  d.out << "circuit:     " << c.netlist.title << "\n"
        << "             " << c.circuit_states << " circuit states, " << c.model.exo_states
        << " exosystem states (sources), diodes: " << (forms.empty() ? "none" : forms) << "\n"
        << "initial:     " << c.initial_note << "\n"
        << "passive:     " << r.passive << " (sources set to zero): " << r.passive_reason << "\n";
  if (!r.negative_elements.empty())
    d.out << "             negative values: " << io::yaml::join(r.negative_elements) << "\n";
  d.out << "well posed:  " << r.verdict << "\n";
}

// A switched circuit (ideal switches, docs/circuits.md): thesis Ch. 5's
// passivity and verdict for every configuration its schedule visits, each
// named by its switches' states, with the first time it holds (the lines
// above judge the one at t = 0). A circuit without switches adds nothing.
void configurations_section(Draft& d, const circuit::Circuit& c) {
  const mech::Model& m = c.model;
  if (m.configurations.size() < 2) return;
  nlohmann::json list = nlohmann::json::array();
  d.out << "configurations: " << m.configurations.size()
        << " visited by the switches' schedule, each judged as above:\n";
  for (std::size_t k = 0; k < m.configurations.size(); ++k) {
    circuit::Circuit ck = c;
    ck.model.lcs = m.configurations[k].lcs;  // the same states and energy in every one
    const circuit::PassivityReport r = circuit::judge_passivity(ck);
    std::string name;
    nlohmann::json states = nlohmann::json::object();
    for (std::size_t s = 0; s < c.switch_element.size(); ++s) {
      const std::string& sw =
          c.netlist.elements[static_cast<std::size_t>(c.switch_element[s])].name;
      const bool on = k < c.switch_on.size() && s < c.switch_on[k].size() && c.switch_on[k][s];
      name += (s ? ", " : "") + sw + (on ? " on" : " off");
      states[sw] = on ? "on" : "off";
    }
    double first = -1.0;  // the first time configuration k holds
    for (std::size_t i = 0; i < m.switch_config.size() && first < 0.0; ++i)
      if (m.switch_config[i] == static_cast<int>(k)) first = i == 0 ? 0.0 : m.switch_times[i - 1];
    list.push_back({{"switches", states},
                    {"first_holds_at", first},
                    {"passive", r.passive},
                    {"passive_reason", r.passive_reason},
                    {"globally_well_posed", r.globally_well_posed},
                    {"locally_well_posed", r.locally_well_posed},
                    {"verdict", r.verdict}});
    d.out << "  " << name << " (from t = " << short_number(first) << " s): passive " << r.passive
          << "; " << r.verdict << "\n";
  }
  d.j["circuit"]["configurations"] = list;
}

void notes_section(Draft& d, const std::vector<std::string>& notes) {
  d.j["notes"] = notes;
  d.out << "notes:";
  if (notes.empty()) d.out << "       none";
  d.out << "\n";
  for (const auto& n : notes) d.out << "  - " << n << "\n";
}

bool shown(const LeftOut& wp_left, const char* name) {
  return std::find(wp_left.begin(), wp_left.end(), name) == wp_left.end();
}

void well_posedness_json(Draft& d, const lcs::WellPosednessReport& wp, const LeftOut& wp_left) {
  nlohmann::json w;
  w["n"] = wp.n;
  w["k"] = wp.k;
  nlohmann::json markov = nlohmann::json::array();
  for (const auto& H : wp.markov) markov.push_back(io::to_json(H));
  w["markov"] = shown(wp_left, "markov") ? std::move(markov) : nlohmann::json();
  w["rho"] = indices_json(wp.rho);
  w["eta"] = indices_json(wp.eta);
  w["row_coefficients"] =
      shown(wp_left, "row_coefficients") ? io::to_json(wp.row_coefficients) : nlohmann::json();
  w["column_coefficients"] = shown(wp_left, "column_coefficients")
                                 ? io::to_json(wp.column_coefficients)
                                 : nlohmann::json();
  w["row_p_matrix"] = wp.row_p_matrix;
  w["column_p_matrix"] = wp.column_p_matrix;
  w["locally_well_posed"] = wp.locally_well_posed;
  w["passive"] = wp.passive;
  w["passivity_reason"] = wp.passivity_reason;
  w["backward_euler_risky"] = wp.backward_euler_risky;
  d.j["well_posedness"] = std::move(w);
}

// A coefficient matrix of (3.39), or its size when the summary leaves it out.
std::string coefficients_text(const MatrixXd& X, const LeftOut& wp_left, const char* name) {
  if (shown(wp_left, name)) return matrix_text(X, "    ");
  return "    (" + std::to_string(X.rows()) + " x " + std::to_string(X.cols()) +
         ": left out of the summary; " + kFullOption + " prints it)\n";
}

// Theorem 3.6.3 on all k rows, and on the sets active together when they
// were enumerated (the "coactive" section written before).
std::string theorem_363_text(const Draft& d, const lcs::WellPosednessReport& wp) {
  std::string s = wp.locally_well_posed ? "applies" : "does not apply";
  if (!d.j.contains("coactive") || d.j["coactive"].is_null()) return s;
  const nlohmann::json& lwp = d.j["coactive"]["locally_well_posed"];
  return s + "; on the sets that can be active together: " +
         (lwp.is_null()     ? "not decided (enumeration cut short)"
          : lwp.get<bool>() ? "applies"
                            : "does not apply");
}

void well_posedness_text(Draft& d, const lcs::WellPosednessReport& wp, const LeftOut& wp_left) {
  std::ostringstream& out = d.out;
  out << "well-posedness of the LCS (n = " << wp.n << ", k = " << wp.k << "):\n"
      << "  Markov parameters H^0..H^" << (wp.markov.empty() ? 0 : wp.markov.size() - 1)
      << " (3.32):\n";
  if (shown(wp_left, "markov"))
    for (std::size_t i = 0; i < wp.markov.size(); ++i)
      out << "    H^" << i << ":\n" << matrix_text(wp.markov[i], "      ");
  else
    out << "    (" << wp.markov.size() << " matrices of " << wp.k << " x " << wp.k
        << ": left out of the summary; " << kFullOption << " prints them)\n";
  out << "  leading row indices rho:    " << indices_text(wp.rho) << "\n"
      << "  leading column indices eta: " << indices_text(wp.eta) << "\n"
      << "  leading row coefficients (script M, (3.39)):\n"
      << coefficients_text(wp.row_coefficients, wp_left, "row_coefficients")
      << "    P-matrix: " << (wp.row_p_matrix ? "yes" : "no") << "\n"
      << "  leading column coefficients (script N, (3.39)):\n"
      << coefficients_text(wp.column_coefficients, wp_left, "column_coefficients")
      << "    P-matrix: " << (wp.column_p_matrix ? "yes" : "no") << "\n"
      << "  Theorem 3.6.3 (local well-posedness), all k rows at once: " << theorem_363_text(d, wp)
      << "\n"
      << "  passive (§7.2, of the LCS; D there is its feedthrough in y = C x + D u): " << wp.passive
      << (wp.passivity_reason.empty() ? "" : " (" + wp.passivity_reason + ")") << "\n"
      << "  backward Euler (§7.3): "
      << (wp.backward_euler_risky
              ? "RISKY: some rho_i >= 3, time-stepping may diverge (Example 7.3.3)"
              : "no relative degree >= 3")
      << "\n";
}

// Scenes: where the linear model holds, per simulated joint (scene::linear_ranges).
void linear_ranges_section(Draft& d, const std::optional<scene::Scene>& scene) {
  if (!scene) {
    d.j["linear_ranges"] = nullptr;
    return;
  }
  const double threshold = d.options.linearisation_threshold;
  const std::vector<scene::LinearRange> ranges = scene::linear_ranges(*scene, threshold);
  d.j["linear_ranges"] = scene::to_json(ranges);
  d.j["linearisation_threshold"] = threshold;
  d.out << "linear model: error <= " << short_number(100.0 * threshold)
        << " % (mass and forces, docs/model-format.md) for q in, each joint alone:\n";
  for (const auto& r : ranges)
    d.out << "  " << r.joint << ": [" << short_number(r.lower) << ", " << short_number(r.upper)
          << "] " << r.unit << "  (q0 = " << short_number(r.q0) << "; ends: " << r.lower_end << ", "
          << r.upper_end << ")\n";
}

// Scenes with contacts (docs/contacts.md): each contact's gap at q0, whether
// it is closed, and how far its linear gap holds (scene::contact_ranges).
// Absent for every other model, whose reports stay as they were.
void contacts_section(Draft& d, const std::optional<scene::Scene>& scene) {
  if (!scene || scene->contacts.empty()) return;
  const double threshold = d.options.linearisation_threshold;
  const std::vector<scene::ContactRange> ranges = scene::contact_ranges(*scene, threshold);
  d.j["contacts"] = scene::to_json(ranges);
  d.out << "contacts at q0 (gap m; the linear gap is off by <= " << short_number(100.0 * threshold)
        << " % of the contact point's displacement for the tightest coordinate moved "
           "alone):\n";
  for (const auto& r : ranges)
    d.out << "  " << r.contact << " on " << r.plane << ": gap " << short_number(r.gap)
          << (r.closed ? " (closed)" : "") << ", |" << r.coordinate
          << " - q0| <= " << short_number(r.range) << " " << r.unit << " (" << r.end << ")\n";
}

// What was not judged, whether the report is full, and what the summary left out.
void closing_section(Draft& d) {
  d.j["not_judged"] = d.not_judged;
  if (!d.not_judged.empty()) d.out << "not judged:\n";
  for (const auto& n : d.not_judged) d.out << "  - " << n << "\n";
  d.j["full"] = d.options.full;
  d.j["left_out"] = d.left;
  if (d.left.empty()) return;
  d.out << "left out of this summary (" << kFullOption << " prints them): ";
  for (std::size_t i = 0; i < d.left.size(); ++i) d.out << (i ? ", " : "") << d.left[i];
  d.out << "\n";
}

}  // namespace

void check_analysis_options(const AnalysisOptions& options) {
  scene::check_linearisation_threshold(options.linearisation_threshold);
}

AnalysisReport analysis_report(const scene::LoadedModel& loaded, const AnalysisOptions& options) {
  check_analysis_options(options);
  const mech::Model& model = loaded.model;
  const std::vector<std::string> notes = scene::model_notes(loaded);
  const lcs::Lcs sys = model.as_lcs();
  const lcs::WellPosednessReport wp = lcs::analyze_well_posedness(sys);

  Draft d{options, {}, {}, {}, {}};
  describe_model(d, model, sys);
  if (model.is_mechanical())
    mechanical_section(d, model, sys);
  else
    lcs_section(d, sys);
  if (loaded.circuit) {
    circuit_section(d, *loaded.circuit);
    configurations_section(d, *loaded.circuit);
  }
  notes_section(d, notes);
  const LeftOut wp_left = options.full ? LeftOut{} : lcs::summary_left_out(wp);
  well_posedness_json(d, wp, wp_left);
  well_posedness_text(d, wp, wp_left);
  linear_ranges_section(d, loaded.scene);
  contacts_section(d, loaded.scene);
  for (const auto& n : wp_left) d.left.push_back("well_posedness." + n);
  closing_section(d);
  return {std::move(d.j), d.out.str()};
}

}  // namespace lcsim::app
