#include <talus/base/errors.h>
#include <talus/materials/linear_elastic.h>

#include <deal.II/base/parameter_handler.h>

#include <gtest/gtest.h>

#include <cmath>

using namespace talus::materials;

TEST(LinearElastic, UniaxialStrainClosedForm)
{
  const double  E = 1e7, nu = 0.3;
  LinearElastic m(E, nu);
  Stress        s;
  Strain        de;
  de[0][0] = 1e-4;
  m.update_stress(de, Spin(), 1e-3, s, {});
  const double Ec     = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu));
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
  EXPECT_NEAR(s[0][0], Ec * 1e-4, 1e-12 * Ec);
  EXPECT_NEAR(s[1][1], lambda * 1e-4, 1e-12 * Ec);
  EXPECT_NEAR(s[2][2], lambda * 1e-4, 1e-12 * Ec);
  EXPECT_DOUBLE_EQ(s[0][1], 0.0);
  EXPECT_NEAR(m.constrained_modulus(), Ec, 1e-9 * Ec);
}

TEST(LinearElastic, ObjectiveUnderRigidRotation)
{
  // A pre-stressed point rotated rigidly by a small spin increment per step: the
  // stress must rotate with the body (Jaumann rate) and its invariants stay fixed.
  LinearElastic m(1e7, 0.25);
  Stress        s;
  s[0][0]         = -100.0;
  s[1][1]         = -40.0;
  s[0][1]         = 15.0;
  s[2][2]         = -60.0;
  const double I1 = trace(s), J2 = second_invariant(deviator(s));
  const int    n     = 2000;
  const double theta = M_PI / 2;
  Spin         w;
  w[0][1] = -theta / n;
  w[1][0] = theta / n;
  for (int i = 0; i < n; ++i)
    m.update_stress(Strain(), w, 1e-3, s, {});
  EXPECT_NEAR(trace(s), I1, 1e-10 * std::abs(I1));
  EXPECT_NEAR(second_invariant(deviator(s)), J2, 1e-10 * std::abs(J2));
  // after 90 degrees, sigma_xx and sigma_yy swap, sigma_xy changes sign
  EXPECT_NEAR(s[0][0], -40.0, 1e-4);
  EXPECT_NEAR(s[1][1], -100.0, 1e-4);
  EXPECT_NEAR(s[0][1], -15.0, 1e-4);
}

TEST(LinearElastic, RejectsBadParameters)
{
  EXPECT_THROW(LinearElastic(-1.0, 0.3), talus::InputError);
  EXPECT_THROW(LinearElastic(1.0, 0.5), talus::InputError);
}
