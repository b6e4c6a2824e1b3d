// The implicit updated-Lagrangian step (formulations/implicit): the assembled
// tangent must be the derivative of the assembled residual (material +
// geometric stiffness, lumped inertia), checked against central differences
// at a deformed iterate, for elastic and plastic finite-strain models, static
// and dynamic, 2D and 3D, on 1 and 2 ranks.
#include <talus/formulations/common/time_loop.h>
#include <talus/formulations/implicit/implicit_solver.h>

#include <deal.II/base/mpi.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>

namespace
{
  using namespace talus;

  /// A block of points in a box grid clamped at x = 0, with the given model
  /// subsection text; parsed exactly as talus-implicit parses its .prm.
  template <int dim>
  double
  tangent_error(const std::string &model, const std::string &analysis, const double scale,
                const unsigned int steps_before = 0, const double gravity = 9.81,
                const std::string &implicit_extra = "", const double pressure_scale = 1.0,
                const std::string &boundary = " set fixed = 0\n")
  {
    // the B-spline needs 3 cells per direction
    const std::string  ny = implicit_extra.find("bspline") != std::string::npos ? "3" : "2";
    std::ostringstream prm_text;
    prm_text << "set dimension = " << dim << "\n"
             << "subsection time\n set end time = 1\n set time step = 0.5\nend\n"
             << "subsection implicit\n set analysis = " << analysis << "\n"
             << implicit_extra << "end\n"
             << "subsection grid\n set lower corner = 0, 0" << (dim == 3 ? ", 0" : "") << "\n set upper corner = 2, 1"
             << (dim == 3 ? ", 1" : "") << "\n set cells = 4, " << ny << (dim == 3 ? ", " + ny : std::string())
             << "\nend\n"
             << "subsection boundary conditions\n"
             << boundary << "end\n"
             << "subsection gravity\n set acceleration = 0, " << (dim == 3 ? "0, " : "") << -gravity << "\nend\n"
             << "subsection output\n set directory = test_implicit_out\n set progress = false\nend\n"
             << "set number of materials = 1\nsubsection material 0\n set density = 1000\n"
             << model << "end\n"
             << "set number of bodies = 1\nsubsection body 0\n set shape = box\n set lower corner = 0, 0"
             << (dim == 3 ? ", 0" : "") << "\n set upper corner = 1.6, 0.5" << (dim == 3 ? ", 0.5" : "")
             << "\n set particles per direction = 2\nend\n";
    const std::string file = "test_implicit_solver_" + std::to_string(dim) + ".prm";
    if (dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
      std::ofstream(file) << prm_text.str();
    MPI_Barrier(MPI_COMM_WORLD);
    dealii::ParameterHandler prm;
    implicit_mpm::declare_parameters(prm, file);
    prm.parse_input(file);
    const auto                p = implicit_mpm::parse_parameters<dim>(prm);
    implicit_mpm::Solver<dim> s(p, MPI_COMM_WORLD);
    s.setup();
    // a deformed, stressed state (b_n != I, points off their seeding positions)
    TimeLoop(s, loop_settings(p), MPI_COMM_WORLD).advance_steps(steps_before);
    // central differences: truncation ~ eps^2, round-off ~ 1e-16 |r| / eps
    const double e = s.tangent_error(0.01, scale, 1e-6, pressure_scale);
    std::printf("tangent error %.3e\n", e);
    return e;
  }

  const std::string neo_hookean = " set model = neo hookean\n subsection neo hookean\n  set young modulus = 1e6\n"
                                  "  set poisson ratio = 0.3\n end\n";
  const std::string hencky_mc   = " set model = hencky mohr coulomb\n subsection hencky mohr coulomb\n"
                                  "  set young modulus = 1e6\n  set poisson ratio = 0.3\n  set cohesion = 1e3\n"
                                  "  set friction angle = 30\n  set dilatancy angle = 5\n end\n";
  const std::string j2          = " set model = j2 plasticity\n subsection j2 plasticity\n  set young modulus = 1e6\n"
                                  "  set poisson ratio = 0.3\n  set yield stress = 5e3\n  set hardening modulus = 1e4\n end\n";

  // increments of 1e-2 m over 0.25 m cells: strains of a few percent, rotations
  // of the same order (geometric stiffness matters; plastic models yield)
  TEST(ImplicitTangent, NeoHookeanStatic2D)
  {
    EXPECT_LT(tangent_error<2>(neo_hookean, "static", 1e-2), 1e-6);
  }
  TEST(ImplicitTangent, NeoHookeanDynamic2D)
  {
    EXPECT_LT(tangent_error<2>(neo_hookean, "dynamic", 1e-2), 1e-6);
  }
  TEST(ImplicitTangent, NeoHookeanStatic3D)
  {
    EXPECT_LT(tangent_error<3>(neo_hookean, "static", 1e-2), 1e-6);
  }
  TEST(ImplicitTangent, HenckyMohrCoulombPlastic2D)
  {
    EXPECT_LT(tangent_error<2>(hencky_mc, "static", 1e-2), 1e-5);
  }
  TEST(ImplicitTangent, NeoHookeanAfterLoadSteps2D)
  {
    EXPECT_LT(tangent_error<2>(neo_hookean, "static", 1e-3, 2, 200.0), 1e-6);
  }
  // mixed u-p (seed 001 ch. 5): the block tangent (K_uu with the nodal
  // pressure, K_up, K_pu, K_pp with the PPP stabilisation over cell means)
  // against central differences; the iterate's pressures are of the size of
  // the stresses (pressure_scale ~ E). Limit 1e-8 (measured <= 9e-11): leaving
  // the cell-mean part of S out of K_pp gives 8e-8 .. 1.6e-6, so 1e-6 would
  // not see it
  const std::string neo_hookean_split = " set model = neo hookean\n subsection neo hookean\n"
                                        "  set young modulus = 1e6\n  set poisson ratio = 0.3\n"
                                        "  set volumetric energy = split\n end\n";
  const std::string neo_hookean_split_incompressible =
    " set model = neo hookean\n subsection neo hookean\n  set young modulus = 1e6\n"
    "  set poisson ratio = 0.499999\n  set volumetric energy = split\n end\n";
  const std::string mixed = " set formulation = mixed up\n";
  TEST(ImplicitTangent, MixedUpStatic2D)
  {
    EXPECT_LT(tangent_error<2>(neo_hookean_split, "static", 1e-2, 0, 9.81, mixed, 1e6), 1e-8);
  }
  TEST(ImplicitTangent, MixedUpQuasiIncompressible2D)
  {
    EXPECT_LT(tangent_error<2>(neo_hookean_split_incompressible, "static", 1e-2, 0, 9.81,
                               mixed + " set stabilisation factor = 3\n", 1e6),
              1e-8);
  }
  TEST(ImplicitTangent, MixedUpStatic3D)
  {
    EXPECT_LT(tangent_error<3>(neo_hookean_split, "static", 1e-2, 0, 9.81, mixed, 1e6), 1e-8);
  }
  TEST(ImplicitTangent, MixedUpAfterLoadSteps2D)
  {
    EXPECT_LT(tangent_error<2>(neo_hookean_split, "static", 1e-3, 2, 200.0, mixed, 1e6), 1e-8);
  }
  // mixed u-p with a plastic model (Material::split_update: tau_dev = tau -
  // J p(J) I of J2 and its derivative from the model's consistent tangent);
  // the increments yield the points (sigma_y = 5e3 Pa, strains of a few %);
  // after two load steps at 0.05 g the clamped fibres have yielded (elastic
  // bending stress ~7.7e3 Pa; at 20 g the J2 block collapses). Limit 1e-6:
  // measured <= 8.6e-9 (central differences across the return's kinks; the
  // irreducible plastic cases use 1e-5), K_pu off by 1e-3 V_n gives 1e-3
  TEST(ImplicitTangent, MixedUpJ2Plastic2D)
  {
    EXPECT_LT(tangent_error<2>(j2, "static", 1e-2, 0, 9.81, mixed, 1e6), 1e-6);
  }
  TEST(ImplicitTangent, MixedUpJ2Plastic3D)
  {
    EXPECT_LT(tangent_error<3>(j2, "static", 1e-2, 0, 9.81, mixed, 1e6), 1e-6);
  }
  TEST(ImplicitTangent, MixedUpJ2AfterLoadSteps2D)
  {
    EXPECT_LT(tangent_error<2>(j2, "static", 1e-3, 2, 0.5, mixed, 1e6), 1e-6);
  }
  // axisymmetric (x = radius, seed 001 App. C): the hoop row N_a / r_n of the
  // internal force and its four tangent blocks, on a body that touches the axis
  // (x = 0: the radial displacement there is constrained automatically; a
  // bottom roller holds it axially). Increments of 1e-2 m at points from r =
  // 0.125 m: hoop stretches of up to 8 %.
  const std::string axisymmetric  = " set geometry = axisymmetric\n";
  const std::string bottom_roller = " set roller = 2\n";
  TEST(ImplicitTangent, AxisymmetricNeoHookeanStatic)
  {
    EXPECT_LT(tangent_error<2>(neo_hookean, "static", 1e-2, 0, 9.81, axisymmetric, 1.0, bottom_roller), 1e-8);
  }
  TEST(ImplicitTangent, AxisymmetricNeoHookeanDynamic)
  {
    EXPECT_LT(tangent_error<2>(neo_hookean, "dynamic", 1e-2, 0, 9.81, axisymmetric, 1.0, bottom_roller), 1e-8);
  }
  TEST(ImplicitTangent, AxisymmetricNeoHookeanAfterLoadSteps)
  {
    EXPECT_LT(tangent_error<2>(neo_hookean, "static", 1e-3, 2, 200.0, axisymmetric, 1.0, bottom_roller), 1e-8);
  }
  TEST(ImplicitTangent, AxisymmetricHenckyMohrCoulombPlastic)
  {
    EXPECT_LT(tangent_error<2>(hencky_mc, "static", 1e-2, 0, 9.81, axisymmetric, 1.0, bottom_roller), 1e-8);
  }
  TEST(ImplicitTangent, AxisymmetricJ2Plastic)
  {
    EXPECT_LT(tangent_error<2>(j2, "static", 1e-2, 0, 9.81, axisymmetric, 1.0, bottom_roller), 1e-8);
  }
  // contact walls on the points (point_contact.h): a floor (boundary 2) under the block, whose
  // bottom row of points touches it (gap 0 with the extent r_p = V_p^(1/dim)/2); the random
  // iterate pushes about half of them into it. The penalty terms (normal, stick, Coulomb slip
  // with its non-symmetric tangent) act at the points' contact spots.
  const std::string point_floor = " set fixed = 0\n set contact = 2\n set contact method = points\n";
  TEST(ImplicitTangent, PointContactNoSlip2D)
  {
    EXPECT_LT(tangent_error<2>(neo_hookean, "dynamic", 1e-2, 0, 9.81, "", 1.0, point_floor), 1e-6);
  }
  TEST(ImplicitTangent, PointContactFrictionless2D)
  {
    EXPECT_LT(tangent_error<2>(neo_hookean, "static", 1e-2, 0, 9.81, "", 1.0,
                               point_floor + " set contact friction = frictionless\n"),
              1e-6);
  }
  TEST(ImplicitTangent, PointContactCoulomb2D)
  {
    EXPECT_LT(tangent_error<2>(neo_hookean, "static", 1e-2, 0, 9.81, "", 1.0,
                               point_floor + " set contact friction = 0.3\n set contact penalty = 10\n"),
              1e-6);
  }
  TEST(ImplicitTangent, PointContactCoulomb3D)
  {
    EXPECT_LT(tangent_error<3>(neo_hookean, "static", 1e-2, 0, 9.81, "", 1.0,
                               point_floor + " set contact friction = 0.3\n set contact penalty = 10\n"),
              1e-6);
  }
  // a rigid footing on the points (point_contact.h, 'rigid footing'): its base on the block's
  // top face (y = 0.5) over part of it (x in [0.3, 1], 3D also z in [0.1, 0.4]), so the top
  // points inside the span touch it and those outside do not; the random iterate pushes about
  // half of the touching ones into it. (The footing section follows the boundary conditions'.)
  std::string
  footing(const int dim, const std::string &interface)
  {
    return std::string(" set fixed = 2\nend\nsubsection rigid footing\n set enabled = true\n set level = 0.5\n") +
           " set lower corner = 0.3" + (dim == 3 ? ", 0.1" : "") + "\n set upper corner = 1" +
           (dim == 3 ? ", 0.4" : "") + "\n set velocity = -0.01\n set interface = " + interface + "\n";
  }
  TEST(ImplicitTangent, RigidFootingRough2D)
  {
    EXPECT_LT(tangent_error<2>(neo_hookean, "static", 1e-2, 0, 9.81, "", 1.0, footing(2, "rough")), 1e-6);
  }
  TEST(ImplicitTangent, RigidFootingSmooth3D)
  {
    EXPECT_LT(tangent_error<3>(neo_hookean, "static", 1e-2, 0, 9.81, "", 1.0, footing(3, "smooth")), 1e-6);
  }
  TEST(ImplicitTangent, J2Plastic3D)
  {
    EXPECT_LT(tangent_error<3>(j2, "static", 1e-2), 1e-5);
  }

  // F-bar ('volumetric stabilisation = f-bar'): each point's model sees dFbar with
  // the volume-weighted mean det dF of its cell, so the tangent couples all points
  // of a cell (the rank-one cell term); 2 x 2 points per cell, a random iterate
  // gives the points of a cell different det dF.
  // (a shared 'numerics' entry: the implicit_extra text sits inside 'subsection
  // implicit', which is closed and reopened around it)
  const std::string fbar =
    "end\nsubsection numerics\n set volumetric stabilisation = f-bar\nend\nsubsection implicit\n";
  TEST(ImplicitTangent, FbarNeoHookeanStatic2D)
  {
    EXPECT_LT(tangent_error<2>(neo_hookean, "static", 1e-2, 0, 9.81, fbar), 1e-6);
  }
  TEST(ImplicitTangent, FbarNeoHookeanStatic3D)
  {
    EXPECT_LT(tangent_error<3>(neo_hookean, "static", 1e-2, 0, 9.81, fbar), 1e-6);
  }
  TEST(ImplicitTangent, FbarNeoHookeanDynamicAfterLoadSteps2D)
  {
    EXPECT_LT(tangent_error<2>(neo_hookean, "dynamic", 1e-2, 2, 9.81, fbar), 1e-6);
  }
  TEST(ImplicitTangent, FbarNeoHookeanSplitQuasiIncompressible2D)
  {
    EXPECT_LT(tangent_error<2>(neo_hookean_split_incompressible, "static", 1e-4, 0, 9.81, fbar), 1e-6);
  }
  TEST(ImplicitTangent, FbarJ2Plastic2D)
  {
    EXPECT_LT(tangent_error<2>(j2, "static", 1e-2, 0, 9.81, fbar), 1e-5);
  }
  TEST(ImplicitTangent, FbarJ2Plastic3D)
  {
    EXPECT_LT(tangent_error<3>(j2, "static", 1e-2, 0, 9.81, fbar), 1e-5);
  }
  TEST(ImplicitTangent, FbarHenckyMohrCoulomb2D)
  {
    EXPECT_LT(tangent_error<2>(hencky_mc, "static", 1e-2, 0, 9.81, fbar), 1e-5);
  }


  // 'mass matrix = consistent': M_ij = sum_p m_p N_i N_j in the residual (M a,
  // alpha_R M v) and in the tangent (coef M) on the free DoFs. With h = 0.01 s
  // the inertia (1/(beta h^2) m_p ~ 6e5 N/m per point) is as large as the
  // stiffness, so a wrong factor or a wrong block shows.
  const std::string consistent = " set mass matrix = consistent\n";
  // (the implicit_extra text sits inside 'subsection implicit': the shared
  // 'damping' section is closed and reopened around it)
  const std::string viscous_damping = "end\nsubsection damping\n set viscous damping = 1.5\nend\nsubsection implicit\n";
  const std::string consistent_damped = " set mass matrix = consistent\n" + viscous_damping;
  TEST(ImplicitTangent, ConsistentMassDynamic2D)
  {
    EXPECT_LT(tangent_error<2>(neo_hookean, "dynamic", 1e-2, 0, 9.81, consistent), 1e-6);
  }
  TEST(ImplicitTangent, ConsistentMassRayleighAfterSteps2D)
  {
    EXPECT_LT(tangent_error<2>(neo_hookean, "dynamic", 1e-2, 2, 9.81, consistent_damped), 1e-6);
  }
  TEST(ImplicitTangent, ConsistentMassDynamic3D)
  {
    EXPECT_LT(tangent_error<3>(neo_hookean, "dynamic", 1e-2, 0, 9.81, consistent_damped), 1e-6);
  }
  TEST(ImplicitTangent, ConsistentMassAxisymmetricDynamic)
  {
    EXPECT_LT(
      tangent_error<2>(neo_hookean, "dynamic", 1e-2, 0, 9.81, axisymmetric + consistent_damped, 1.0, bottom_roller),
      1e-8);
  }
  TEST(ImplicitTangent, ConsistentMassPointContact2D)
  {
    EXPECT_LT(tangent_error<2>(neo_hookean, "dynamic", 1e-2, 0, 9.81, consistent, 1.0, point_floor), 1e-6);
  }

  // 'damping/stiffness damping' (Rayleigh beta): C = beta_R K_n, K_n the force tangent at the step's start (du = 0),
  // held for the step: r += beta_R K_n v^{n+1}(du), tangent += beta_R gamma/(beta h) K_n.
  // With h = 0.01 s, gamma/(beta h) = 200, so beta_R = 0.01 doubles the stiffness part of
  // the tangent: a missing or wrong damping term shows at order 1.
  const std::string rayleigh_beta =
    "end\nsubsection damping\n set stiffness damping = 0.01\nend\nsubsection implicit\n";
  TEST(ImplicitTangent, RayleighBetaDynamic2D)
  {
    EXPECT_LT(tangent_error<2>(neo_hookean, "dynamic", 1e-2, 0, 9.81, rayleigh_beta), 1e-6);
  }
  TEST(ImplicitTangent, RayleighBetaJ2AfterSteps2D)
  {
    EXPECT_LT(tangent_error<2>(j2, "dynamic", 1e-2, 2, 9.81, rayleigh_beta + viscous_damping), 1e-5);
  }
  TEST(ImplicitTangent, RayleighBetaDynamic3D)
  {
    EXPECT_LT(tangent_error<3>(neo_hookean, "dynamic", 1e-2, 0, 9.81, rayleigh_beta), 1e-6);
  }

  // 'numerics/shape function = quadratic bspline': every transfer on the B-spline basis
  // (a point couples the 3^dim nodes of its window, the walls' modified
  // splines at x = 0 and at the grid's faces). Mixed u-p couples the 4^dim
  // patch of a cell through the PPP cell means (ActiveSet::Reach::cell: with
  // the point pattern the assembly throws on an entry outside the sparsity).
  // ('numerics/shape function': the text leaves 'implicit', sets it and enters 'implicit' again)
  const std::string bspline =
    "end\nsubsection numerics\n set shape function = quadratic bspline\nend\nsubsection implicit\n";
  TEST(ImplicitTangent, BSplineNeoHookeanStatic2D)
  {
    EXPECT_LT(tangent_error<2>(neo_hookean, "static", 1e-2, 0, 9.81, bspline), 1e-6);
  }
  TEST(ImplicitTangent, BSplineNeoHookeanDynamicAfterSteps2D)
  {
    EXPECT_LT(tangent_error<2>(neo_hookean, "dynamic", 1e-2, 2, 9.81, bspline), 1e-6);
  }
  TEST(ImplicitTangent, BSplineNeoHookeanStatic3D)
  {
    EXPECT_LT(tangent_error<3>(neo_hookean, "static", 1e-2, 0, 9.81, bspline), 1e-6);
  }
  TEST(ImplicitTangent, BSplineJ2Plastic2D)
  {
    EXPECT_LT(tangent_error<2>(j2, "static", 1e-2, 0, 9.81, bspline), 1e-5);
  }
  TEST(ImplicitTangent, BSplineConsistentMassDynamic2D)
  {
    EXPECT_LT(tangent_error<2>(neo_hookean, "dynamic", 1e-2, 0, 9.81, bspline + consistent_damped), 1e-6);
  }
  TEST(ImplicitTangent, BSplineMixedUpStatic2D)
  {
    EXPECT_LT(tangent_error<2>(neo_hookean_split, "static", 1e-2, 0, 9.81, bspline + mixed, 1e6), 1e-8);
  }
  TEST(ImplicitTangent, BSplineMixedUpJ2Plastic3D)
  {
    EXPECT_LT(tangent_error<3>(j2, "static", 1e-2, 0, 9.81, bspline + mixed, 1e6), 1e-6);
  }
  TEST(ImplicitTangent, BSplineRigidFootingRough2D)
  {
    EXPECT_LT(tangent_error<2>(neo_hookean, "static", 1e-2, 0, 9.81, bspline, 1.0, footing(2, "rough")), 1e-6);
  }
} // namespace
