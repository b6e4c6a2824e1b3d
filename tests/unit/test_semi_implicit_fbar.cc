// The grid-free F-bar pieces (transfer/fbar.h, shared by the explicit and semi-implicit families) and the
// J^e = sqrt(det b_e) the modified F-bar reads from the finite-strain models.
#include <talus/transfer/fbar.h>
#include <deal.II/base/symmetric_tensor.h>
#include <talus/materials/hencky_mohr_coulomb.h>

#include <gtest/gtest.h>

#include <vector>

using namespace talus;
using dealii::Tensor;

namespace
{
  Tensor<2, 3>
  compression(const double ex, const double ey, const double ez)
  {
    Tensor<2, 3> f;
    f[0][0] = 1 - ex;
    f[1][1] = 1 - ey;
    f[2][2] = 1 - ez;
    f[0][1] = 0.003; // a little shear: the scaling must keep it in proportion
    return f;
  }
} // namespace

// the patch test of the increment: where the smoothed dJ equals the point's
// own and J^e its patch mean (a uniform compression), F-bar and modified F-bar
// hand the model the increment unchanged
TEST(SemiImplicitFbar, UniformCompressionIsLeftExact)
{
  const Tensor<2, 3> dF2 = compression(0.01, 0.02, 0);
  const Tensor<2, 3> a2  = transfer::stabilised_increment<2>(dF2, determinant(dF2));
  EXPECT_LT((a2 - dF2).norm(), 1e-15);
  const Tensor<2, 3> dF3 = compression(0.01, 0.02, 0.005);
  const Tensor<2, 3> a3  = transfer::stabilised_increment<3>(dF3, determinant(dF3));
  EXPECT_LT((a3 - dF3).norm(), 1e-15);
}

// Eq. 79: det of the result is the smoothed dJ (2D: the in-plane block
// scaled, the out-of-plane stretch kept), the isochoric part unchanged
TEST(SemiImplicitFbar, DeterminantFollowsTheSmoothedIncrement)
{
  const Tensor<2, 3> dF     = compression(0.01, 0.02, 0);
  const double       dJ_bar = 0.985;
  const auto         f      = transfer::stabilised_increment<2>(dF, dJ_bar);
  EXPECT_NEAR(determinant(f), dJ_bar, 1e-14);
  EXPECT_EQ(f[2][2], 1.0);
  EXPECT_NEAR(f[0][1] / f[1][1], dF[0][1] / dF[1][1], 1e-14); // isochoric part unchanged
  const auto h = transfer::stabilised_increment<3>(compression(0.01, 0.02, 0.03), dJ_bar);
  EXPECT_NEAR(determinant(h), dJ_bar, 1e-14);
}

// Eq. 82: b_e-bar = (Jebar / J^e)^(2/3) b_e has sqrt(det) = Jebar and the same
// principal directions and stretch ratios (an isotropic scaling of b_e)
TEST(SemiImplicitFbar, ElasticBTakesThePatchMean)
{
  const Tensor<2, 3>                  F     = compression(0.01, 0.02, 0.03);
  const dealii::SymmetricTensor<2, 3> b     = dealii::symmetrize(F * transpose(F));
  const double                        Je    = std::sqrt(determinant(b));
  double                              h[6]  = {b[0][0], b[1][1], b[2][2], b[0][1], b[1][2], b[0][2]};
  const double                        Jebar = 1.013;
  transfer::scale_elastic_b(h, Jebar / Je);
  dealii::SymmetricTensor<2, 3> bb;
  bb[0][0] = h[0], bb[1][1] = h[1], bb[2][2] = h[2], bb[0][1] = h[3], bb[1][2] = h[4], bb[0][2] = h[5];
  EXPECT_NEAR(std::sqrt(determinant(bb)), Jebar, 1e-14);
  EXPECT_NEAR(bb[0][1] / bb[0][0], b[0][1] / b[0][0], 1e-14);
  EXPECT_NEAR(bb[2][2] / bb[1][1], b[2][2] / b[1][1], 1e-14);
}

// the fixed 1.5 h patches: 10 cells -> 7 patches (the last one cut), index x
// fastest, positions outside the box clamped to the nearest patch
TEST(SemiImplicitFbar, PatchTiling)
{
  transfer::PatchTiling<2> t;
  t.reinit(dealii::Point<2>(0, -1), dealii::Point<2>(10, 2), std::vector<unsigned int>{10, 6}, 1.5);
  EXPECT_EQ(t.count[0], 7u);
  EXPECT_EQ(t.count[1], 4u);
  EXPECT_EQ(t.size(), 28u);
  EXPECT_NEAR(t.side[0], 1.5, 1e-15);
  EXPECT_NEAR(t.side[1], 0.75, 1e-15);
  EXPECT_EQ(t.index(dealii::Point<2>(0.1, -0.9)), 0u);
  EXPECT_EQ(t.index(dealii::Point<2>(1.6, -0.9)), 1u);
  EXPECT_EQ(t.index(dealii::Point<2>(1.6, -0.2)), 8u);
  EXPECT_EQ(t.index(dealii::Point<2>(9.99, 1.99)), 27u);
  EXPECT_EQ(t.index(dealii::Point<2>(10.5, 2.5)), 27u);
  transfer::PatchTiling<2> cellwise; // patch size 1: the cell-wise average of Mast et al.
  cellwise.reinit(dealii::Point<2>(0, 0), dealii::Point<2>(3, 3), std::vector<unsigned int>{3, 3}, 1.0);
  EXPECT_EQ(cellwise.size(), 9u);
}

// J^e of the models that keep b_e: after an elastic increment from a stress
// free state it is det(dF)
TEST(SemiImplicitFbar, ElasticJacobianOfTheModels)
{
  const Tensor<2, 3> dF = compression(0.01, 0.02, 0.0);
  {
    materials::HenckyMohrCoulomb m(1e7, 0.3, 1e9, 30, 0);
    std::vector<double>          h0(m.n_history()), h1(m.n_history());
    m.initialize_history(materials::Stress(), dealii::ArrayView<double>(h0));
    EXPECT_NEAR(m.elastic_jacobian(h0), 1.0, 1e-14);
    materials::Stress tau;
    m.finite_strain_update(dF, dealii::ArrayView<const double>(h0), dealii::ArrayView<double>(h1), tau, nullptr);
    EXPECT_NEAR(m.elastic_jacobian(h1), determinant(dF), 1e-13);
  }
}
