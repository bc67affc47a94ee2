// Forward sensitivities of a run (sim::Options::sensitivity) as JSON and as
// a CSV beside the trajectory's (docs/sensitivities.md).
#pragma once

#include <filesystem>
#include <lcsim/io/csv.hpp>
#include <lcsim/mech/mech.hpp>
#include <lcsim/sim/sim.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace lcsim::io {

// {"columns": [...], "state": [...], "final": [[dx_i/dtheta_c per column c]
// per state entry i, null where absent], "events": [{"t", "type", "dt": [...,
// null where absent]}], "losses": [{"t", "contact", "reason", "columns"}]}.
nlohmann::json sensitivity_json(const mech::Model& model, const sim::Trajectory& traj);

// The samples' dx as CSV: t, then "d<state>/d<column>" for each column and
// each state entry (column-major), an empty field where the derivative does
// not exist. Kept in memory and written whole by commit() (write_file_atomic,
// InputError when it cannot), with the run's columns
// (Trajectory::sensitivity_columns): a failed run leaves no file.
class SensitivityCsvWriter {
 public:
  SensitivityCsvWriter(std::filesystem::path path, const mech::Model& model);
  void write(const sim::Sample& s);
  void commit(const std::vector<std::string>& columns) const;

 private:
  std::filesystem::path path_;
  std::vector<std::string> state_;
  std::string rows_;
};

}  // namespace lcsim::io
