// lcsim._lcsim: the extension module behind the Python package lcsim.
#include <lcsim/impact/impact.hpp>
#include <lcsim/lcp/lcp.hpp>
#include <lcsim/sim/sim.hpp>
#include <stdexcept>

#include "bindings.hpp"

namespace lcsim::python {

void raise_input_error(const std::string& message) { throw io::InputError(message); }

}  // namespace lcsim::python

PYBIND11_MODULE(_lcsim, m) {
  namespace py = pybind11;
  using namespace lcsim;
  m.doc() = "lcsim's C++ library (linear complementarity systems, impacts, LCPs) for Python.";
  // Invalid input, as the library reports it: io::InputError (files, options,
  // models) and std::invalid_argument (unknown method or solver names).
  static py::exception<io::InputError> input_error(m, "InputError", PyExc_ValueError);
  input_error.doc() =
      "Invalid input: the library's message names the file or field, the element and the value.";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const io::InputError& e) {
      input_error(e.what());
    } catch (const std::invalid_argument& e) {
      input_error(e.what());
    }
  });
  m.def("integrator_names", &sim::integrator_names,
        "The simulation methods (sim::integrators()): 'event', 'euler', 'moreau-jean', ...");
  m.def("impact_law_names", &impact::impact_law_names, "The impact laws (impact::laws()).");
  m.def("solver_names", &lcp::solver_names, "The LCP solvers (lcp::solvers()).");
  lcsim::python::bind_model(m);
  lcsim::python::bind_simulate(m);
  lcsim::python::bind_tools(m);
  lcsim::python::bind_bench(m);
  lcsim::python::bind_study(m);
}
