// lcsim._lcsim._bench_simulate: the C++ side of bench/bench_python.py, the
// same sim::simulate call timed in a C++ loop, so the per-call overhead of
// lcsim.simulate is measured side by side in one process.
#include <chrono>
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
        py::gil_scoped_release release;
        const auto start = std::chrono::steady_clock::now();
        long events = 0;
        for (int i = 0; i < calls; ++i)
          events += static_cast<long>(sim::simulate(model->model, x0, opt).events.size());
        const std::chrono::duration<double> s = std::chrono::steady_clock::now() - start;
        return py::make_tuple(s.count() / calls, events);
      },
      py::arg("model"), py::arg("x0"), py::arg("t_end"), py::arg("calls"),
      "Seconds per call of sim::simulate(model, x0, {t_end}, \"event\") over `calls` calls "
      "in a C++ loop, and the events counted (bench/bench_python.py).");
}

}  // namespace lcsim::python
