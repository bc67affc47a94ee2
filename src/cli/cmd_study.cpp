// `lcsim study STUDY.yaml --out results.csv|.jsonl [--resume] [--jobs N]`:
// the runs of a study file on threads, or over MPI ranks when started by
// mpirun (src/study; format in docs/study.md). Progress goes to stderr; a
// summary line ends it. Failed runs are rows of the table, not an exit code.
#include <cstdio>
#include <iostream>
#include <lcsim/io/input_error.hpp>
#include <lcsim/study/execute.hpp>
#include <lcsim/study/study.hpp>
#include <memory>

#include "cli/command.hpp"
#include "cli/flag_names.hpp"

namespace lcsim::cli {
namespace {

struct StudyArgs {
  std::string file;
  std::string out;
  bool resume = false;
  int jobs = 0;
};

void run(const StudyArgs& a) {
  const study::Study s = study::load_study(a.file);
  study::ExecOptions o;
  o.out = a.out;
  o.resume = a.resume;
  o.jobs = a.jobs;
  o.progress = [](const std::string& line) { std::cerr << "study: " << line << "\n"; };
  study::Summary sum;
  try {
    sum = study::run_study(s, o);
  } catch (const io::InputError& e) {  // the library names fields, the user typed flags
    throw io::InputError(with_flag_names(e.what(), study_flags()));
  }
  if (!sum.writer) return;
  std::fprintf(stderr,
               "study: %zu runs (%zu from the journal, %zu computed), %zu not completed, "
               "%.2f s; table in %s\n",
               sum.total, sum.resumed, sum.computed, sum.failed, sum.wall_time_s, a.out.c_str());
}

void setup(CLI::App& app) {
  auto a = std::make_shared<StudyArgs>();
  auto* cmd = app.add_subcommand(
      "study", "Run a study file (axes of parameters, Monte Carlo) on threads or MPI ranks");
  cmd->add_option("study", a->file, "Study file (YAML, docs/study.md)")->required();
  cmd->add_option("--out", a->out,
                  "Table: CSV, or JSON lines if it ends in .jsonl; the journal is <out>.journal")
      ->required();
  cmd->add_flag("--resume", a->resume, "Continue the journal: compute only the runs it lacks");
  cmd->add_option("--jobs", a->jobs, "Threads (default: the number of cores; one per MPI rank)");
  cmd->callback([a] { run(*a); });
}

LCSIM_REGISTER_COMMAND(setup);

}  // namespace
}  // namespace lcsim::cli
