// Assembly and sparse-solve time against dofs for the chip under a representative load (issue 4),
// so that the micro-model can size its default mesh. One periodic interval of a rough chip surface
// (10 µm, Ra 0.2 µm, correlation length 1 µm, 5 µm thick, quadratic NURBS), Johnson–Cook steel of
// seed 000 Table 1 at 500 °C, bottom fixed, the top pressed by 800 MPa with a 200 MPa shear
// traction, loaded in 4 quasi-static steps until it yields. Per refinement level: the time of one
// tangent assembly, of one factorisation + solve by UMFPACK (symbolic analysis reused) and, in the
// same run, by two peers on the same matrix: Eigen's own SparseLU and CHOLMOD's supernodal Cholesky
// (the tangent of this associative model is symmetric); and the assembly of the mean-dilatation (F-bar)
// element, loaded the same way, against the displacement element's. Usage: chip_solver_bench [max_level]
#include <Eigen/CholmodSupport>
#include <Eigen/SparseLU>
#include <Eigen/UmfPackSupport>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>

#include "micro/solid/time_integrator.hpp"
#include "micro/spline/profile.hpp"

using namespace mufric;
using Clock = std::chrono::steady_clock;

namespace {

double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

template <class F>
double best_of(int repeats, F f) {
  double best = 1e300;
  for (int r = 0; r < repeats; ++r) {
    const auto t = Clock::now();
    f();
    best = std::min(best, ms_since(t));
  }
  return best;
}

}  // namespace

// Assemblies are cheap beside the factorisations: more repeats, so that the best of them is a timing
// on a machine that other processes share.
constexpr int kAssemblyRepeats = 20;

int main(int argc, char** argv) {
  const int max_level = argc > 1 ? std::atoi(argv[1]) : 4;
  spline::RoughnessSpec spec;
  spec.length = 10e-6;
  spec.ra = 0.2e-6;
  spec.correlation_length = 1e-6;
  spec.samples = 512;
  const spline::SplineCurve surface = spline::fit_periodic_profile(spline::synthetic_rough_profile(spec), 2, 32).curve;
  solid::JohnsonCookParameters jc;
  solid::MaterialState initial;
  initial.temperature = 773.15;
  std::printf("| elements | dofs | assembly [ms] | UMFPACK [ms] | Eigen SparseLU [ms] | ratio | CHOLMOD [ms] | ratio | load run [s] | Newton its | F-bar assembly [ms] | ratio |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (int level = 0; level <= max_level; ++level) {
    const int parts = 1 << level;
    const auto patch = spline::SplineSurface::extruded(surface, -5e-6, 2, 4).subdivided(parts, parts);
    solid::TimeIntegrationOptions options;
    options.scheme = solid::TimeScheme::quasi_static;
    options.dt = 1e-9;
    options.end_time = 4e-9;
    const auto loaded = [&](solid::VolumetricTreatment volumetric) {
      auto problem = std::make_unique<solid::SolidProblem>(solid::IgaSpace(patch), std::make_shared<solid::J2JohnsonCook>(jc),
                                                           initial, volumetric);
      problem->fix_side(numerics::Side::bottom, 0);
      problem->fix_side(numerics::Side::bottom, 1);
      problem->add_load({numerics::Side::top, Eigen::Vector2d(200e6, 0.0), 800e6, [](double t) { return t / 4e-9; }});
      return problem;
    };
    const auto problem_ptr = loaded(solid::VolumetricTreatment::full);
    solid::SolidProblem& problem = *problem_ptr;
    solid::TimeIntegrator integrator(problem, options);
    const auto start = Clock::now();
    const auto report = integrator.run();
    const double run_seconds = ms_since(start) / 1e3;
    const auto f_bar = loaded(solid::VolumetricTreatment::mean_dilatation);
    solid::TimeIntegrator f_bar_integrator(*f_bar, options);
    const auto f_bar_report = f_bar_integrator.run();
    if (!report.completed || !f_bar_report.completed) {
      std::fprintf(stderr, "level %d: %s\n", level, (report.completed ? f_bar_report : report).reason.c_str());
      return 1;
    }
    // The tangent at the loaded state, constrained as the integrator does.
    solid::SparseMatrix tangent = problem.assemble(integrator.u(), options.dt, true).tangent.selfadjointView<Eigen::Lower>();
    problem.constrain(tangent);
    const Eigen::VectorXd rhs = Eigen::VectorXd::Ones(tangent.rows());
    const int repeats = level < 3 ? 5 : 2;
    const double assembly = best_of(kAssemblyRepeats, [&] { problem.assemble(integrator.u(), options.dt, true); });
    Eigen::UmfPackLU<solid::SparseMatrix> umfpack;
    umfpack.analyzePattern(tangent);
    const double umf = best_of(repeats, [&] {
      umfpack.factorize(tangent);
      const Eigen::VectorXd x = umfpack.solve(rhs);
    });
    Eigen::SparseLU<solid::SparseMatrix> eigen_lu;
    eigen_lu.analyzePattern(tangent);
    const double elu = best_of(repeats, [&] {
      eigen_lu.factorize(tangent);
      const Eigen::VectorXd x = eigen_lu.solve(rhs);
    });
    Eigen::CholmodSupernodalLLT<solid::SparseMatrix> cholmod;
    cholmod.analyzePattern(tangent);
    const double chol = best_of(repeats, [&] {
      cholmod.factorize(tangent);
      const Eigen::VectorXd x = cholmod.solve(rhs);
    });
    if (cholmod.info() != Eigen::Success) std::fprintf(stderr, "level %d: CHOLMOD refused the tangent\n", level);
    const double f_bar_assembly = best_of(kAssemblyRepeats, [&] { f_bar->assemble(f_bar_integrator.u(), options.dt, true); });
    std::printf("| %d | %ld | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %d | %.2f | %.2f |\n", problem.space().element_count(),
                static_cast<long>(problem.dof_count()), assembly, umf, elu, elu / umf, chol, chol / umf, run_seconds,
                report.newton_iterations, f_bar_assembly, f_bar_assembly / assembly);
    std::fflush(stdout);
  }
}
