// Modified Cam-Clay: undrained paths end on the critical state line at the
// closed-form pressure, isotropic compression follows the NCL, validation.
#include <talus/base/errors.h>
#include <talus/materials/modified_cam_clay.h>
#include <talus/materials/single_element.h>

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace talus::materials;

namespace
{
  ElementRecord
  run(const Material &m, const ElementPath path, const double strain, const unsigned int n, const double p0,
      std::vector<ElementRecord> *all = nullptr)
  {
    ElementTestSettings set;
    set.path             = path;
    set.target_strain    = strain;
    set.n_increments     = n;
    set.initial_pressure = p0;
    ElementRecord last;
    run_element_test(m, set, [&](const ElementRecord &r) {
      last = r;
      if (all)
        all->push_back(r);
    });
    return last;
  }
} // namespace

TEST(ModifiedCamClay, UndrainedCompressionEndsOnCriticalStateLine)
{
  // With no volume change, p' exp(eps_v^e/kappa*) and p_c exp(-eps_v^p/(lambda*-kappa*))
  // telescope exactly, so at critical state (p_c = 2 p'):
  //   p'_f = (p_c0 / 2)^Lambda p0^(1 - Lambda),  Lambda = (lambda - kappa)/lambda,  q_f = M p'_f.
  const double M = 1.2, lam = 0.2, kap = 0.04, p0 = 200e3;
  const double Lambda = (lam - kap) / lam;
  for (const double ocr : {1.0, 1.5, 4.0}) // normally, lightly and heavily overconsolidated
    {
      ModifiedCamClay            m(M, lam, kap, 0.25, 1.0, ocr);
      std::vector<ElementRecord> rec;
      const ElementRecord        last = run(m, ElementPath::undrained_triaxial_compression, 0.4, 4000, p0, &rec);
      const double               pf   = std::pow(ocr * p0 / 2, Lambda) * std::pow(p0, 1 - Lambda);
      EXPECT_NEAR(last.p(), pf, 1e-6 * pf) << "OCR " << ocr;
      EXPECT_NEAR(last.q(), M * pf, 1e-6 * pf) << "OCR " << ocr;
      EXPECT_NEAR(last.history[ModifiedCamClay::h_preconsolidation], 2 * pf, 1e-6 * pf);
      // isochoric: specific volume unchanged
      EXPECT_NEAR(last.history[ModifiedCamClay::h_specific_volume], 2.0, 1e-12);
      // NC clay: p' falls monotonically; heavily OC clay: p' rises
      if (ocr == 1.0)
        {
          EXPECT_LT(last.p(), p0);
        }
      if (ocr == 4.0)
        {
          EXPECT_GT(last.p(), p0);
        }
      // on or inside the yield surface all along the path
      for (const auto &r : rec)
        {
          const double pc = r.history[ModifiedCamClay::h_preconsolidation];
          EXPECT_LE(r.q() * r.q() / (M * M) + r.p() * (r.p() - pc), 1e-9 * pc * pc);
        }
    }
  // extension: the same |q| = M p' end point with this (circular deviatoric) surface
  ModifiedCamClay     m(M, lam, kap, 0.25, 1.0, 1.0);
  const ElementRecord last = run(m, ElementPath::undrained_triaxial_extension, 0.4, 4000, p0);
  const double        pf   = std::pow(p0 / 2, Lambda) * std::pow(p0, 1 - Lambda);
  EXPECT_NEAR(last.p(), pf, 1e-6 * pf);
  EXPECT_NEAR(last.q(), M * pf, 1e-6 * pf);
  EXPECT_GT(last.sigma[0][0], last.sigma[1][1]); // axial is the minor compression
}

TEST(ModifiedCamClay, IsotropicCompressionFollowsNormalCompressionLine)
{
  // on the NCL dv = -lambda d ln p'; with v updated as v exp(-d eps_v) and
  // lambda* = lambda / v_n the integration is first order in the increment
  const double        lam = 0.15, kap = 0.03, e0 = 1.2, p0 = 100e3;
  ModifiedCamClay     m(1.0, lam, kap, 0.3, e0, 1.0);
  const ElementRecord last = run(m, ElementPath::isotropic_compression, 0.1, 4000, p0);
  const double        v    = last.history[ModifiedCamClay::h_specific_volume];
  EXPECT_NEAR(v, (1 + e0) * std::exp(-0.1), 1e-12);
  EXPECT_NEAR((1 + e0 - v) / std::log(last.p() / p0), lam, 1e-4 * lam);
  EXPECT_NEAR(last.history[ModifiedCamClay::h_preconsolidation], last.p(), 1e-9 * last.p());
  EXPECT_NEAR(last.q(), 0.0, 1e-6);

  // unloading is elastic along kappa: p_c stays, the plastic strain stays
  ModifiedCamClay     oc(1.0, lam, kap, 0.3, e0, 3.0);
  const ElementRecord r1 = run(oc, ElementPath::isotropic_compression, 0.01, 100, p0);
  EXPECT_NEAR(r1.history[ModifiedCamClay::h_preconsolidation], 3 * p0, 1e-9 * p0);
  EXPECT_EQ(r1.history[ModifiedCamClay::h_plastic_vol_strain], 0.0);
}

TEST(ModifiedCamClay, DrainedCompressionReachesCriticalState)
{
  // drained, sigma_r' constant: the stress path has slope 3 and ends at q = M p'
  const double        M = 1.0, p0 = 100e3;
  ModifiedCamClay     m(M, 0.2, 0.05, 0.3, 1.0, 1.0);
  const ElementRecord last = run(m, ElementPath::drained_triaxial_compression, 0.5, 5000, p0);
  // path q = 3 (p - p0) meets q = M p at p = 3 p0 / (3 - M); drained hardening
  // approaches it asymptotically (0.5 % away after 50 % axial strain)
  const double pf = 3 * p0 / (3 - M);
  EXPECT_NEAR(last.p(), pf, 1e-2 * pf);
  EXPECT_LT(last.p(), pf);
  EXPECT_NEAR(last.q(), 3 * (last.p() - p0), 1e-6 * pf);
}

TEST(ModifiedCamClay, RejectsBadParameters)
{
  EXPECT_THROW(ModifiedCamClay(0, 0.2, 0.04, 0.25, 1, 1), talus::InputError);
  EXPECT_THROW(ModifiedCamClay(1, 0.2, 0.2, 0.25, 1, 1), talus::InputError); // kappa = lambda
  EXPECT_THROW(ModifiedCamClay(1, 0.2, 0.04, 0.5, 1, 1), talus::InputError);
  EXPECT_THROW(ModifiedCamClay(1, 0.2, 0.04, 0.25, 0, 1), talus::InputError);
  EXPECT_THROW(ModifiedCamClay(1, 0.2, 0.04, 0.25, 1, 0.9), talus::InputError);
  EXPECT_THROW(ModifiedCamClay(1, 0.2, 0.04, 0.25, 1, 1, 0.0), talus::InputError);
}
