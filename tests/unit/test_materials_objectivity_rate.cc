// Objectivity of the rate-form models (Mohr-Coulomb, Tresca, Modified Cam-Clay,
// Newtonian, Bingham, frictional fluid): a rigid rotation superposed on a loading
// path rotates the stress and changes nothing else (history), to 1e-10.
//
// Path A: strain increments d_eps_k, no spin. Path B: the same deformation seen by
// an observer rotating with the constant spin increment W per step, i.e. spin W and
// strain increments Q_{k+1} d_eps_k Q_{k+1}^T with Q_k = R^k, R the Cayley rotation
// of W computed here independently. Expect sigma_B,k = Q_k sigma_A,k Q_k^T.
#include <talus/materials/bingham.h>
#include <talus/materials/frictional_fluid.h>
#include <talus/materials/modified_cam_clay.h>
#include <talus/materials/mohr_coulomb.h>
#include <talus/materials/newtonian.h>
#include <talus/materials/tresca.h>

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <memory>
#include <vector>

using namespace talus::materials;
using dealii::Tensor;

namespace
{
  Stress
  rotate(const Tensor<2, 3> &Q, const Stress &s)
  {
    const Tensor<2, 3> r = Q * Tensor<2, 3>(s) * transpose(Q);
    return symmetrize(r);
  }

  struct Case
  {
    std::string                                name;
    std::function<std::unique_ptr<Material>()> make;
    double                                     scale;   ///< strain increment size
    unsigned int                               check_h; ///< history slot that must become non-zero
  };

  void
  run_case(const Case &c, const Tensor<2, 3> &W, const Tensor<2, 3> &Q0)
  {
    const auto m = c.make();
    // independent Cayley rotation R = (I - W/2)^-1 (I + W/2)
    Tensor<2, 3> I;
    for (unsigned int i = 0; i < 3; ++i)
      I[i][i] = 1;
    const Tensor<2, 3> R = invert(I - 0.5 * W) * (I + 0.5 * W);
    const Spin         w = W;

    Stress sA;
    sA[0][0]               = -100e3;
    sA[1][1]               = -80e3;
    sA[2][2]               = -120e3;
    sA[0][1]               = 5e3;
    Tensor<2, 3>        Q  = Q0;
    Stress              sB = rotate(Q, sA);
    std::vector<double> hA(m->n_history()), hB(m->n_history());
    m->initialize_history(sA, ArrayView<double>(hA.data(), hA.size()));
    m->initialize_history(sB, ArrayView<double>(hB.data(), hB.size()));

    Strain B1, B2;
    B1[0][0] = -2.0, B1[1][1] = 1.0, B1[2][2] = 0.4, B1[0][1] = 0.7, B1[1][2] = -0.4, B1[0][2] = 0.3;
    B2[0][0] = 1.0, B2[1][1] = -1.5, B2[0][2] = 0.9, B2[1][2] = 0.5;
    const double dt   = 1e-3;
    double       hmax = 0;
    for (unsigned int k = 0; k < 60; ++k)
      {
        const Strain de = c.scale * (B1 + std::sin(0.3 * k) * B2);
        m->update_stress(de, Spin(), dt, sA, ArrayView<double>(hA.data(), hA.size()));
        Q = R * Q;
        m->update_stress(rotate(Q, de), w, dt, sB, ArrayView<double>(hB.data(), hB.size()));

        const Stress expected = rotate(Q, sA);
        const double ref      = std::max(sA.norm(), 1.0);
        for (unsigned int i = 0; i < 3; ++i)
          for (unsigned int j = i; j < 3; ++j)
            ASSERT_NEAR(sB[i][j], expected[i][j], 1e-10 * ref) << c.name << " step " << k << " component " << i << j;
        for (unsigned int h = 0; h < hA.size(); ++h)
          ASSERT_NEAR(hB[h], hA[h], 1e-10 * std::max(std::abs(hA[h]), 1e-12 * ref))
            << c.name << " step " << k << " history " << h;
        hmax = std::max(hmax, std::abs(hA[c.check_h]));
      }
    // the path must exercise the inelastic part of the model
    EXPECT_GT(hmax, 0.0) << c.name << ": path stayed elastic";
  }

  std::vector<Case>
  cases()
  {
    return {
      {"mohr coulomb", [] { return std::make_unique<MohrCoulomb>(20e6, 0.3, 10e3, 30, 10, 20e3); }, 1e-3,
       MohrCoulomb::h_plastic_shear_strain},
      {"tresca", [] { return std::make_unique<Tresca>(20e6, 0.45, 30e3); }, 1e-3, Tresca::h_plastic_shear_strain},
      {"modified cam clay", [] { return std::make_unique<ModifiedCamClay>(1.1, 0.2, 0.04, 0.25, 1.0, 1.2); }, 2e-3,
       ModifiedCamClay::h_plastic_shear_strain},
      {"newtonian", [] { return std::make_unique<Newtonian>(2e9, 1e3, -1e9); }, 1e-6, Newtonian::h_volumetric_strain},
      {"bingham", [] { return std::make_unique<Bingham>(1e7, 0.3, 1e8, 20e3, 10, 1e5, -1e9); }, 1e-3,
       Bingham::h_effective_viscosity},
      {"frictional fluid", [] { return std::make_unique<FrictionalFluid>(1e7, 0.3, 1e6, 30, 10, 1e5, -1e9); }, 1e-3,
       FrictionalFluid::h_effective_viscosity},
    };
  }
} // namespace

TEST(ObjectivityRateForm, SuperposedRigidRotation)
{
  // spin increment about an oblique axis, 0.05 rad per step (3 rad in total)
  Tensor<2, 3> W;
  const double a[3] = {0.6, -0.48, 0.64}; // unit axis
  const double th   = 0.05;
  W[0][1] = -th * a[2], W[1][0] = th * a[2];
  W[0][2] = th * a[1], W[2][0] = -th * a[1];
  W[1][2] = -th * a[0], W[2][1] = th * a[0];
  Tensor<2, 3> I;
  for (unsigned int i = 0; i < 3; ++i)
    I[i][i] = 1;
  for (const auto &c : cases())
    run_case(c, W, I);
}

TEST(ObjectivityRateForm, IsotropyUnderFixedRotation)
{
  // no spin, frame rotated once: sigma(Q d_eps Q^T, Q sigma Q^T) = Q sigma(d_eps, sigma) Q^T
  const double c = std::cos(1.1), s = std::sin(1.1);
  Tensor<2, 3> Rz, Rx;
  Rz[0][0] = c, Rz[0][1] = -s, Rz[1][0] = s, Rz[1][1] = c, Rz[2][2] = 1;
  Rx[0][0] = 1, Rx[1][1] = c, Rx[1][2] = -s, Rx[2][1] = s, Rx[2][2] = c;
  for (const auto &cs : cases())
    run_case(cs, Tensor<2, 3>(), Rz * Rx);
}
