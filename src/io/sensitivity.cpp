// Forward sensitivities as JSON and CSV (io/sensitivity.hpp).
#include <lcsim/core/format.hpp>
#include <lcsim/io/atomic_output.hpp>
#include <lcsim/io/json.hpp>
#include <lcsim/io/sensitivity.hpp>

namespace lcsim::io {

namespace {

nlohmann::json row_or_nulls(const Eigen::Ref<const Eigen::RowVectorXd>& v,
                            const std::vector<char>& exists) {
  nlohmann::json out = nlohmann::json::array();
  for (Eigen::Index c = 0; c < v.size(); ++c)
    out.push_back(static_cast<size_t>(c) < exists.size() && exists[static_cast<size_t>(c)]
                      ? finite_or_null(v(c))
                      : nlohmann::json(nullptr));
  return out;
}

}  // namespace

nlohmann::json sensitivity_json(const mech::Model& model, const sim::Trajectory& traj) {
  nlohmann::json j;
  j["columns"] = traj.sensitivity_columns;
  j["state"] = state_names(model);
  nlohmann::json fin = nlohmann::json::array();
  for (Eigen::Index i = 0; i < traj.dx_final.rows(); ++i)
    fin.push_back(row_or_nulls(traj.dx_final.row(i), traj.dx_final_exists));
  j["final"] = fin;
  nlohmann::json ev = nlohmann::json::array();
  for (const auto& e : traj.events)
    ev.push_back(
        {{"t", e.t}, {"type", sim::to_string(e.type)}, {"dt", row_or_nulls(e.dt, e.dt_exists)}});
  j["events"] = ev;
  nlohmann::json losses = nlohmann::json::array();
  for (const auto& l : traj.sensitivity_losses) {
    nlohmann::json cols = nlohmann::json::array();
    for (int c : l.columns) cols.push_back(traj.sensitivity_columns[static_cast<size_t>(c)]);
    losses.push_back({{"t", l.t}, {"contact", l.contact}, {"reason", l.reason}, {"columns", cols}});
  }
  j["losses"] = losses;
  return j;
}

SensitivityCsvWriter::SensitivityCsvWriter(std::filesystem::path path, const mech::Model& model)
    : path_(std::move(path)), state_(state_names(model)) {}

void SensitivityCsvWriter::write(const sim::Sample& s) {
  append_number(rows_, s.t, 17);
  for (Eigen::Index c = 0; c < s.dx.cols(); ++c)
    for (Eigen::Index i = 0; i < s.dx.rows(); ++i) {
      rows_ += ",";
      if (s.dx_exists[static_cast<size_t>(c)]) append_number(rows_, s.dx(i, c), 17);
    }
  rows_ += "\n";
}

void SensitivityCsvWriter::commit(const std::vector<std::string>& columns) const {
  std::string text = "t";
  for (const auto& c : columns)
    for (const auto& s : state_) text += ",d" + s + "/d" + c;
  write_file_atomic(path_, text + "\n" + rows_);
}

}  // namespace lcsim::io
