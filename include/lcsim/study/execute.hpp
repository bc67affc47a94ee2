// Running a study: threads or MPI ranks, a journal that loses nothing, and the
// table in run-index order (docs/study.md).
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <lcsim/study/run.hpp>
#include <lcsim/study/study.hpp>
#include <string>

namespace lcsim::study {

struct ExecOptions {
  // The table: CSV, or JSON lines when the name ends in ".jsonl". Written
  // atomically once every run is in the journal, "<out>.journal".
  std::filesystem::path out;
  // Continue the journal: only the runs it lacks are computed. Without it an
  // existing journal is an InputError (nothing is overwritten).
  bool resume = false;
  int jobs = 0;  // threads; 0 = std::thread::hardware_concurrency(); < 0 is an InputError
  // Progress lines ("120/2000 runs, 3.1 s, 48 s left"), at most one a second
  // and the last; empty: none.
  std::function<void(const std::string&)> progress;
};

struct Summary {
  std::size_t total = 0;     // runs in the study
  std::size_t resumed = 0;   // found in the journal
  std::size_t computed = 0;  // computed by this invocation
  std::size_t failed = 0;    // rows whose status is not "completed"
  double wall_time_s = 0.0;
  bool writer = true;  // this process wrote the table (MPI: rank 0 only)
};

// True if this process was started by mpirun (OMPI_COMM_WORLD_SIZE or
// PMI_SIZE in the environment): run_study then uses MPI.
bool launched_by_mpirun();

// Runs the study on `jobs` threads, or over the MPI ranks when
// launched_by_mpirun() (MPI_Init and MPI_Finalize happen inside: rank 0
// hands out run indices on request, collects rows and writes the journal and
// the table; every rank, rank 0 included, computes runs). InputError for a
// journal of another study, an existing journal without resume, or an
// output that cannot be written.
Summary run_study(const Study& s, const ExecOptions& opt);

// The table's text from rows sorted by index (CSV or JSON lines).
std::string table_text(const Study& s, const std::vector<Row>& rows, bool jsonl);

}  // namespace lcsim::study
