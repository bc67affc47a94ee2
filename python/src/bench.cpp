// lcsim._lcsim._bench_simulate: the C++ side of bench/bench_python.py, the
// same sim::simulate call timed in a C++ loop, so the per-call overhead of
// lcsim.simulate is measured side by side in one process.
#include <time.h>

#include <lcsim/sim/sim.hpp>
#include <optional>

#include "bindings.hpp"

namespace lcsim::python {

void bind_bench(py::module_& m) {
  m.def(
      "_bench_simulate",
      [](const ModelHandle& model, const Eigen::VectorXd& x0, double t_end, int calls) {
        sim::Options opt;
        opt.t_end = t_end;
        long events = 0;
        // CPU time of this thread, as bench_python.py reads time.thread_time():
        // on a shared machine it is what the call costs, whatever else runs.
        auto now = [] {
          timespec ts{};
          clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
          return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
        };
        double seconds = 0.0;
        {
          py::gil_scoped_release release;
          const double start = now();
          for (int i = 0; i < calls; ++i)
            events += static_cast<long>(sim::simulate(model->model, x0, opt).events.size());
          seconds = now() - start;
        }
        return py::make_tuple(seconds / calls, events);
      },
      py::arg("model"), py::arg("x0"), py::arg("t_end"), py::arg("calls"),
      "Thread CPU seconds per call of sim::simulate(model, x0, {t_end}, \"event\") over `calls` "
      "calls "
      "in a C++ loop, and the events counted (bench/bench_python.py).");
}

}  // namespace lcsim::python
