// One run of a study: the point's quantities applied to the model, the run
// through sim::simulate's checked entry, its reference run, and the row that
// records it (docs/study.md lists the columns).
#pragma once

#include <cstddef>
#include <lcsim/study/study.hpp>
#include <string>
#include <vector>

namespace lcsim::study {

// The columns of the study's table: "index", the quantity keys, then
// status, message, t_reached, events_impact, events_release,
// events_contact, events_accumulation, events_unrecorded, energy_change,
// max_violation, steps, lcp_solves, warnings, reference, reference_status,
// error_final, and the final state (one column per state entry: q names then
// "v_" names for a single mechanical model, x1.. otherwise).
// A text column (names, status, messages) is quoted in CSV and a JSON string
// in JSON lines; the others are numbers (blank or null when there is none).
struct Column {
  std::string name;
  bool text = false;
};
std::vector<Column> columns(const Study& s);

// A row: cells already formatted (numbers as the shortest text that reads
// back as the same double), so that every process writes the same bytes.
// wall_time_s is the one measured, non-deterministic value: it is kept in the
// journal, never in the table.
struct Row {
  std::size_t index = 0;
  bool completed = false;  // the run (and its reference) completed
  double wall_time_s = 0.0;
  std::vector<std::string> cells;  // as columns()
};

// Runs point `index` of the study. Never throws for a bad value or a
// numerical failure: a run that cannot be made (a restitution outside
// [0, 1], h <= 0, an infeasible x0, ...) or fails gives a row with that
// status and message.
Row run_one(const Study& s, std::size_t index);

}  // namespace lcsim::study
