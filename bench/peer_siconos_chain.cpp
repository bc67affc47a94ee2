// Siconos 4.4 on the cart chain of `lcsim generate chain N --stops` (unit
// masses, unit springs between neighbours and from cart 0 to the wall, a stop
// q_i + 1 >= 0 per cart, x_i = 0.1 (i mod 3), v_i = -1): Moreau–Jean
// (MoreauJeanOSI, theta = 0.5, h = 1e-3) with the LCP solved by Lemke or PGS,
// one LagrangianLinearTIDS for the chain and one LagrangianLinearTIR +
// NewtonImpactNSL(0) Interaction per stop, as bench/bench_chain.cpp times
// lcsim. Wall time per step over the same two windows:
//   free     t in [0, 0.2]   (no stop active)
//   impacts  t in [0.7, 1.5] (every cart hits its stop)
// Usage: peer_siconos_chain N [lemke|pgs]. Prints one line:
//   siconos N=<N> solver=<s> free_us_per_step=<..> impacts_us_per_step=<..> q0_final=<..>
// Standalone (no Google Benchmark), built as C++17 (bench/CMakeLists.txt).
#include <SiconosKernel.hpp>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s N [lemke|pgs]\n", argv[0]);
    return 2;
  }
  const int n = std::atoi(argv[1]);
  const std::string solver = argc > 2 ? argv[2] : "lemke";
  const double h = 1e-3, t_end = 1.5;
  try {
    SP::SiconosVector q0(new SiconosVector(n)), v0(new SiconosVector(n));
    for (int i = 0; i < n; ++i) {
      (*q0)(i) = 0.1 * (i % 3);
      (*v0)(i) = -1.0;
    }
    SP::SimpleMatrix mass(new SimpleMatrix(n, n)), stiffness(new SimpleMatrix(n, n)),
        damping(new SimpleMatrix(n, n));
    mass->eye();
    stiffness->zero();
    damping->zero();
    (*stiffness)(0, 0) = 1.0;  // spring to the wall
    for (int i = 0; i + 1 < n; ++i) {
      (*stiffness)(i, i) += 1.0;
      (*stiffness)(i + 1, i + 1) += 1.0;
      (*stiffness)(i, i + 1) = -1.0;
      (*stiffness)(i + 1, i) = -1.0;
    }
    SP::LagrangianLinearTIDS chain(new LagrangianLinearTIDS(q0, v0, mass, stiffness, damping));
    SP::NonSmoothDynamicalSystem nsds(new NonSmoothDynamicalSystem(0.0, t_end));
    nsds->insertDynamicalSystem(chain);
    SP::NonSmoothLaw law(new NewtonImpactNSL(0.0));
    for (int i = 0; i < n; ++i) {
      SP::SimpleMatrix H(new SimpleMatrix(1, n));
      H->zero();
      (*H)(0, i) = 1.0;
      SP::SiconosVector e(new SiconosVector(1));
      (*e)(0) = 1.0;  // y = q_i + 1
      SP::Relation rel(new LagrangianLinearTIR(H, e));
      SP::Interaction inter(new Interaction(law, rel));
      nsds->link(inter, chain);
    }
    SP::MoreauJeanOSI osi(new MoreauJeanOSI(0.5));
    SP::TimeDiscretisation td(new TimeDiscretisation(0.0, h));
    SP::OneStepNSProblem lcp(new LCP(solver == "pgs" ? SICONOS_LCP_PGS : SICONOS_LCP_LEMKE));
    SP::TimeStepping sim(new TimeStepping(nsds, td, osi, lcp));
    sim->initialize();
    double free_s = 0.0, impacts_s = 0.0;
    long free_n = 0, impacts_n = 0;
    while (sim->hasNextEvent()) {
      const double t = sim->startingTime();
      const auto c0 = std::chrono::steady_clock::now();
      sim->computeOneStep();
      sim->nextStep();
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - c0).count();
      if (t < 0.2 - 1e-9) {
        free_s += s;
        ++free_n;
      } else if (t >= 0.7 - 1e-9) {
        impacts_s += s;
        ++impacts_n;
      }
    }
    std::printf(
        "siconos N=%d solver=%s free_us_per_step=%.4g impacts_us_per_step=%.4g q0_final=%.10g\n", n,
        solver.c_str(), 1e6 * free_s / free_n, 1e6 * impacts_s / impacts_n, (*chain->q())(0));
  } catch (...) {
    std::printf("siconos N=%d solver=%s failed\n", n, solver.c_str());
    return 1;
  }
  return 0;
}
