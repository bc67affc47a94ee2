// Where finished rows go, whichever executor computed them (internal to
// src/study): the journal, the rows in memory and the progress line. Safe to
// call from several threads.
#pragma once

#include <chrono>
#include <cstddef>
#include <lcsim/study/execute.hpp>
#include <memory>
#include <mutex>
#include <vector>

#include "study/journal.hpp"

namespace lcsim::study {

class Collector {
 public:
  // Opens the journal (see Journal) and lists the runs it lacks.
  Collector(const Study& s, const ExecOptions& opt);
  const std::vector<std::size_t>& todo() const { return todo_; }
  void add(const Row& row);
  // Syncs the journal, writes the table atomically, and returns the summary.
  Summary finish();

 private:
  void progress(bool last);
  const Study& study_;
  const ExecOptions& opt_;
  std::unique_ptr<Journal> journal_;
  std::vector<Row> rows_;
  std::vector<std::size_t> todo_;
  std::size_t resumed_ = 0, computed_ = 0;
  std::mutex mutex_;
  std::chrono::steady_clock::time_point start_, last_progress_;
};

// The jobs to use: opt.jobs, or the hardware's concurrency when 0 (at least 1).
int jobs_of(const ExecOptions& opt);

// Runs the study over MPI ranks (mpi.cpp).
Summary run_study_mpi(const Study& s, const ExecOptions& opt);

}  // namespace lcsim::study
