// Running a study on threads: each takes the next run it lacks from a shared
// counter (dynamic load balancing: runs differ in cost by orders of
// magnitude), and the collector keeps the rows in index order.
#include <atomic>
#include <cstdlib>
#include <exception>
#include <lcsim/study/execute.hpp>
#include <mutex>
#include <thread>

#include "study/collector.hpp"

namespace lcsim::study {

bool launched_by_mpirun() {
  return std::getenv("OMPI_COMM_WORLD_SIZE") != nullptr || std::getenv("PMI_SIZE") != nullptr;
}

Summary run_study(const Study& s, const ExecOptions& opt) {
  if (launched_by_mpirun()) return run_study_mpi(s, opt);
  Collector c(s, opt);
  const std::vector<std::size_t>& todo = c.todo();
  std::atomic<std::size_t> next{0};
  std::exception_ptr error;  // the first (a journal that cannot be written); the others stop
  std::mutex error_mutex;
  const auto work = [&] {
    try {
      for (std::size_t k; (k = next++) < todo.size();) c.add(run_one(s, todo[k]));
    } catch (...) {
      std::lock_guard<std::mutex> lock(error_mutex);
      if (!error) error = std::current_exception();
      next = todo.size();
    }
  };
  const int jobs =
      std::min<int>(jobs_of(opt), static_cast<int>(std::max<std::size_t>(todo.size(), 1)));
  if (jobs <= 1) {
    work();
  } else {
    std::vector<std::jthread> pool;
    for (int j = 0; j < jobs; ++j) pool.emplace_back(work);
  }
  if (error) std::rethrow_exception(error);
  return c.finish();
}

}  // namespace lcsim::study
