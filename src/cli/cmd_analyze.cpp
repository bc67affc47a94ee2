// `lcsim analyze MODEL [--json]`: what a model is and whether the theory
// applies to it, before simulating: dimensions, M's definiteness, rank of E,
// the Delassus matrix E M^{-1} E' and its P-property (uniqueness of the impact
// LCP (3.69)-(3.70)), notes on the model, and the well-posedness report of the
// LCS (Markov parameters (3.32), leading indices and coefficient matrices
// (3.39), Theorem 3.6.3, passivity §7.2, backward Euler guard §7.3).
#include <Eigen/Eigenvalues>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include "cli/command.hpp"
#include "cli/output.hpp"
#include "io/io.hpp"
#include "lcp/lcp.hpp"
#include "lcs/lcs.hpp"

namespace lcsim::cli {
namespace {

using Eigen::MatrixXd;

struct AnalyzeArgs {
  std::string file;
  bool json = false;
  std::string model_out;  // --model-out: the linear model as YAML
  double linearisation_threshold = io::kLinearisationThreshold;
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

// Scenes: where the linear model holds, per simulated joint (io::linear_ranges).
void linear_ranges_section(const std::optional<io::Scene>& scene, double threshold,
                           nlohmann::json& j, std::ostringstream& out) {
  if (!scene) {
    j["linear_ranges"] = nullptr;
    return;
  }
  const std::vector<io::LinearRange> ranges = io::linear_ranges(*scene, threshold);
  j["linear_ranges"] = io::to_json(ranges);
  j["linearisation_threshold"] = threshold;
  out << "linear model: error <= " << num(100.0 * threshold)
      << " % (mass and forces, docs/model-format.md) for q in, each joint alone:\n";
  for (const auto& r : ranges)
    out << "  " << r.joint << ": [" << num(r.lower) << ", " << num(r.upper) << "] " << r.unit
        << "  (q0 = " << num(r.q0) << "; ends: " << r.lower_end << ", " << r.upper_end << ")\n";
}

void run_analyze(const AnalyzeArgs& args) {
  io::check_linearisation_threshold(args.linearisation_threshold);
  if (!args.model_out.empty()) check_writable(args.model_out);
  const std::optional<io::Scene> scene = io::load_scene_details(args.file);
  const mech::Model model = scene ? scene->model : io::load_model(args.file);
  const std::vector<std::string> notes = io::model_notes(model);
  const lcs::Lcs sys = model.as_lcs();
  const lcs::WellPosednessReport wp = lcs::analyze_well_posedness(sys);

  nlohmann::json j;
  std::ostringstream out;
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
        << "rank E:      " << rank_e << " of " << m.num_constraints()
        << (rank_e < m.num_constraints() ? "  (dependent constraints)" : "") << "\n";
    if (m.num_constraints() > 0) {
      const MatrixXd W = mech::delassus(m);
      const bool p = lcp::is_p_matrix(W);
      j["delassus"] = io::to_json(W);
      j["delassus_p_matrix"] = p;
      out << "Delassus matrix E M^-1 E' (impact LCP (3.69)-(3.70)):\n"
          << matrix_text(W, "    ") << "  P-matrix: " << (p ? "yes" : "no")
          << (p ? "  (unique impulse)"
                : "  (impulses may be non-unique; post-impact velocities still are, §4.6.1)")
          << "\n";
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
  nlohmann::json markov = nlohmann::json::array();
  for (const auto& H : wp.markov) markov.push_back(io::to_json(H));
  w["markov"] = std::move(markov);
  w["rho"] = indices_json(wp.rho);
  w["eta"] = indices_json(wp.eta);
  w["row_coefficients"] = io::to_json(wp.row_coefficients);
  w["column_coefficients"] = io::to_json(wp.column_coefficients);
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
  for (std::size_t i = 0; i < wp.markov.size(); ++i) {
    out << "    H^" << i << ":\n" << matrix_text(wp.markov[i], "      ");
  }
  out << "  leading row indices rho:    " << indices_text(wp.rho) << "\n"
      << "  leading column indices eta: " << indices_text(wp.eta) << "\n"
      << "  leading row coefficients (script M, (3.39)):\n"
      << matrix_text(wp.row_coefficients, "    ")
      << "    P-matrix: " << (wp.row_p_matrix ? "yes" : "no") << "\n"
      << "  leading column coefficients (script N, (3.39)):\n"
      << matrix_text(wp.column_coefficients, "    ")
      << "    P-matrix: " << (wp.column_p_matrix ? "yes" : "no") << "\n"
      << "  Theorem 3.6.3 (local well-posedness): "
      << (wp.locally_well_posed ? "applies" : "does not apply") << "\n"
      << "  passive (§7.2): " << wp.passive
      << (wp.passivity_reason.empty() ? "" : " (" + wp.passivity_reason + ")") << "\n"
      << "  backward Euler (§7.3): "
      << (wp.backward_euler_risky
              ? "RISKY: some rho_i >= 3, time-stepping may diverge (Example 7.3.3)"
              : "no relative degree >= 3")
      << "\n";

  linear_ranges_section(scene, args.linearisation_threshold, j, out);
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
  cmd->add_option("--model-out", args->model_out,
                  "write the model (a scene: its linearisation) as a YAML model file");
  cmd->add_option("--linearisation-threshold", args->linearisation_threshold,
                  "scenes: relative error of the linear model for the ranges (default 0.01)");
  cmd->callback([args] { run_analyze(*args); });
});

}  // namespace lcsim::cli
