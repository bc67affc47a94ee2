// lcsim._lcsim._run_study: a study file run as `lcsim study` runs it (the
// study layer's run_study, on threads), for lcsim.study in __init__.py.
#include <lcsim/study/execute.hpp>
#include <lcsim/study/study.hpp>
#include <string>

#include "bindings.hpp"

namespace lcsim::python {

void bind_study(py::module_& m) {
  m.def(
      "_run_study",
      [](const std::string& path, const std::string& out, bool resume, int jobs,
         py::object progress) {
        const study::Study s = study::load_study(path);
        study::ExecOptions o;
        o.out = out;
        o.resume = resume;
        o.jobs = jobs;
        if (!progress.is_none())
          o.progress = [progress](const std::string& line) {
            py::gil_scoped_acquire gil;
            progress(line);
          };
        study::Summary sum;
        {
          py::gil_scoped_release nogil;
          sum = study::run_study(s, o);
        }
        py::dict d;
        d["total"] = sum.total;
        d["resumed"] = sum.resumed;
        d["computed"] = sum.computed;
        d["failed"] = sum.failed;
        d["wall_time_s"] = sum.wall_time_s;
        return d;
      },
      py::arg("path"), py::arg("out"), py::arg("resume") = false, py::arg("jobs") = 0,
      py::arg("progress") = py::none(),
      "Runs the study file `path` into the table `out` (its journal is <out>.journal); "
      "returns the summary. Use lcsim.study.");
}

}  // namespace lcsim::python
