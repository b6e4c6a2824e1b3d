#include <talus/base/errors.h>
#include <talus/materials/single_element.h>

#include <deal.II/base/symmetric_tensor.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace talus::materials
{
  namespace
  {
    const std::vector<std::pair<ElementPath, std::string>> &
    path_table()
    {
      static const std::vector<std::pair<ElementPath, std::string>> t = {
        {ElementPath::oedometer, "oedometer"},
        {ElementPath::isotropic_compression, "isotropic compression"},
        {ElementPath::drained_triaxial_compression, "drained triaxial compression"},
        {ElementPath::drained_triaxial_extension, "drained triaxial extension"},
        {ElementPath::undrained_triaxial_compression, "undrained triaxial compression"},
        {ElementPath::undrained_triaxial_extension, "undrained triaxial extension"},
        {ElementPath::simple_shear, "simple shear"}};
      return t;
    }

    struct State
    {
      Stress               sigma;
      std::vector<double>  h;
      dealii::Tensor<2, 3> F; ///< total deformation gradient (finite form)
      Strain               eps;
      double               gamma = 0;
    };

    /// One increment with the "velocity gradient increment" L (grad du): small
    /// strain d_eps = sym L, d_omega = skew L; finite strain dF = exp(L) (L is
    /// either diagonal or nilpotent in these paths, so exp is exact).
    State
    advance(const Material &m, const ElementTestSettings &set, const State &s, const dealii::Tensor<2, 3> &L)
    {
      State n = s;
      if (!set.finite_strain)
        {
          const Strain d_eps = symmetrize(L);
          const Spin   d_om  = 0.5 * (L - transpose(L));
          m.update_stress(d_eps, d_om, set.time_increment, n.sigma, ArrayView<double>(n.h.data(), n.h.size()));
          n.eps += d_eps;
        }
      else
        {
          bool diagonal = true;
          for (unsigned int i = 0; i < 3; ++i)
            for (unsigned int j = 0; j < 3; ++j)
              if (i != j && L[i][j] != 0)
                diagonal = false;
          dealii::Tensor<2, 3> dF = dealii::unit_symmetric_tensor<3>();
          if (diagonal)
            for (unsigned int i = 0; i < 3; ++i)
              dF[i][i] = std::exp(L[i][i]);
          else
            dF += L;
          Stress tau;
          m.finite_strain_update(dF, ArrayView<const double>(s.h.data(), s.h.size()),
                                 ArrayView<double>(n.h.data(), n.h.size()), tau, nullptr);
          n.F            = dF * s.F;
          const double J = determinant(n.F);
          n.sigma        = tau / J;
          // logarithmic strain 1/2 ln(F F^T)
          const dealii::SymmetricTensor<2, 3> B = symmetrize(n.F * transpose(n.F));
          const auto ev = dealii::eigenvectors(B, dealii::SymmetricTensorEigenvectorMethod::jacobi);
          n.eps         = Strain();
          for (unsigned int k = 0; k < 3; ++k)
            n.eps +=
              0.5 * std::log(ev[k].first) * dealii::symmetrize(dealii::outer_product(ev[k].second, ev[k].second));
        }
      n.gamma = s.gamma + L[0][1];
      return n;
    }
  } // namespace

  std::string
  element_path_names()
  {
    std::string s;
    for (const auto &[p, n] : path_table())
      s += (s.empty() ? "" : "|") + n;
    return s;
  }

  ElementPath
  element_path_from_name(const std::string &name)
  {
    for (const auto &[p, n] : path_table())
      if (n == name)
        return p;
    throw InputError("unknown element test path '" + name + "'; allowed: " + element_path_names());
  }

  double
  ElementRecord::q() const
  {
    const Stress s = deviator(sigma);
    return std::sqrt(1.5 * scalar_product(s, s));
  }

  void
  run_element_test(const Material &m, const ElementTestSettings &set,
                   const std::function<void(const ElementRecord &)> &out)
  {
    require(set.n_increments > 0, "element test/number of increments", "must be > 0");
    require(set.target_strain > 0, "element test/target strain", "must be > 0");
    require(set.time_increment > 0, "element test/time increment", "must be > 0");
    require(set.k0 > 0, "element test/initial stress ratio", "must be > 0");
    require(!set.finite_strain || m.has_finite_strain_form(), "element test/strain form",
            "model '" + m.model_name() + "' has no finite-strain form; use 'small'");

    State s;
    s.F              = dealii::unit_symmetric_tensor<3>();
    const double sa0 = -3.0 * set.initial_pressure / (1.0 + 2.0 * set.k0);
    s.sigma[0][0]    = sa0;
    s.sigma[1][1]    = set.k0 * sa0;
    s.sigma[2][2]    = set.k0 * sa0;
    s.h.assign(m.n_history(), 0.0);
    m.initialize_history(s.sigma, ArrayView<double>(s.h.data(), s.h.size()));

    auto emit = [&](const State &st, const unsigned int step, const unsigned int its) {
      ElementRecord r;
      r.step              = step;
      r.time              = step * set.time_increment;
      r.eps               = st.eps;
      r.gamma             = st.gamma;
      r.sigma             = st.sigma;
      r.history           = st.h;
      r.newton_iterations = its;
      out(r);
    };
    emit(s, 0, 0);

    const double d = set.target_strain / set.n_increments;
    const bool   drained =
      set.path == ElementPath::drained_triaxial_compression || set.path == ElementPath::drained_triaxial_extension;
    const double sigma_lat = s.sigma[1][1];
    double       guess_y   = 0; // lateral strain increment of the previous step

    for (unsigned int step = 1; step <= set.n_increments; ++step)
      {
        dealii::Tensor<2, 3> L;
        unsigned int         its = 0;
        switch (set.path)
          {
            case ElementPath::oedometer:
              L[0][0] = -d;
              break;
            case ElementPath::isotropic_compression:
              for (unsigned int i = 0; i < 3; ++i)
                L[i][i] = -d / 3.0;
              break;
            case ElementPath::undrained_triaxial_compression:
              L[0][0] = -d;
              L[1][1] = L[2][2] = d / 2;
              break;
            case ElementPath::undrained_triaxial_extension:
              L[0][0] = d;
              L[1][1] = L[2][2] = -d / 2;
              break;
            case ElementPath::simple_shear:
              L[0][1] = d;
              break;
            case ElementPath::drained_triaxial_compression:
            case ElementPath::drained_triaxial_extension:
              L[0][0] = (set.path == ElementPath::drained_triaxial_compression) ? -d : d;
              break;
          }

        if (!drained)
          {
            s = advance(m, set, s, L);
          }
        else
          {
            // Mixed control: axial strain prescribed, lateral stresses held at their
            // initial value. The material is isotropic and the path axisymmetric, so
            // both lateral strain increments are equal: one unknown x, solved by a
            // safeguarded Newton iteration (central-difference tangent, bisection
            // once the root is bracketed). The residual is the mean lateral stress
            // error; the two lateral stresses are checked to stay equal.
            double stress_scale = std::max(std::abs(sigma_lat), 1.0);
            for (unsigned int i = 0; i < 3; ++i)
              stress_scale = std::max(stress_scale, std::abs(s.sigma[i][i]));
            const double tol  = set.newton_tolerance * stress_scale;
            auto         eval = [&](const double x, State &trial) {
              dealii::Tensor<2, 3> Lt = L;
              Lt[1][1] = Lt[2][2] = x;
              trial               = advance(m, set, s, Lt);
              return 0.5 * (trial.sigma[1][1] + trial.sigma[2][2]) - sigma_lat;
            };
            double x = guess_y;
            State  trial, tmp;
            double R  = eval(x, trial);
            bool   ok = std::abs(R) <= tol;
            double lo = -std::numeric_limits<double>::infinity(), hi = -lo; // bracket
            auto   update_bracket = [&](const double xx, const double rr) {
              // the lateral stress increases with the lateral strain (stable material)
              if (rr < 0)
                lo = std::max(lo, xx);
              else
                hi = std::min(hi, xx);
            };
            update_bracket(x, R);
            for (its = 0; !ok && its < set.max_newton_iterations; ++its)
              {
                const double h  = 1e-6 * std::max(d, std::abs(x));
                const double Rp = eval(x + h, tmp);
                const double Rm = eval(x - h, tmp);
                const double dR = (Rp - Rm) / (2 * h);
                double       xn = (dR > 0 && std::isfinite(dR)) ? x - R / dR : x - (R > 0 ? d : -d);
                if (std::isfinite(lo) && std::isfinite(hi) && !(xn > lo && xn < hi))
                  xn = 0.5 * (lo + hi); // bisection inside the bracket
                else if (std::isfinite(lo) && xn <= lo)
                  xn = lo + std::max(d, std::abs(lo - x));
                else if (std::isfinite(hi) && xn >= hi)
                  xn = hi - std::max(d, std::abs(hi - x));
                x  = xn;
                R  = eval(x, trial);
                ok = std::abs(R) <= tol;
                update_bracket(x, R);
              }
            if (ok && std::abs(trial.sigma[1][1] - trial.sigma[2][2]) > 1e3 * tol)
              throw InstabilityError("element test: lateral stresses became unequal in the "
                                     "drained path at increment " +
                                     std::to_string(step) + " (the model is not isotropic?)");
            if (!ok)
              throw InstabilityError("element test: the drained (mixed-control) Newton loop did not "
                                     "converge at increment " +
                                     std::to_string(step) + " (lateral stress residual " + std::to_string(std::abs(R)) +
                                     " Pa, tolerance " + std::to_string(tol) + " Pa)");
            guess_y = x;
            s       = trial;
          }
        for (unsigned int i = 0; i < 3; ++i)
          for (unsigned int j = i; j < 3; ++j)
            if (!std::isfinite(s.sigma[i][j]))
              throw InstabilityError("element test: non-finite stress at increment " + std::to_string(step));
        emit(s, step, its);
      }
  }
} // namespace talus::materials
