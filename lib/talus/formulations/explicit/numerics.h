// talus — optional numerics of the explicit solver (seed 000 chapter 6):
//  * MPM-MIXED integration of the internal force (§6.6),
//  * strain smoothing by nodal mixed discretisation (§6.7.1),
//  * contact between bodies, predictor-corrector with Coulomb friction and
//    adhesion (§6.2, Bardenhagen et al.).
// Each is a .prm switch; when a switch is off its object does not exist and the
// solver's hot loops see one null pointer test per cell or particle.
#pragma once

#include <talus/formulations/explicit/forward.h>
#include <talus/grid/background_grid.h>
#include <talus/materials/material.h>
#include <talus/shape/shape_function.h>

#include <deal.II/base/parameter_handler.h>

#include <array>
#include <string>
#include <vector>

namespace talus::explicit_mpm
{
  /// Options of chapter 6 read from the .prm (subsections `numerics`, `contact`).
  struct NumericsOptions
  {
    enum class Integration
    {
      mpm,       ///< internal force integrated at the material points (MPM-MP)
      mpm_mixed, ///< Gauss integration with the cell-averaged stress in filled cells (§6.6)
      fem,       ///< points fixed at the Gauss points of their cells, small strain (fem.h)
      ul_fem     ///< Gauss points of cells that follow the material (updated Lagrangian FEM, fem.h)
    };
    enum class Smoothing
    {
      none,
      cell, ///< volumetric strain increment replaced by the cell average (mean dilatation)
      nodal ///< nodal mixed discretisation: cell values averaged to the nodes and back (Eqs. 6.35-6.37)
    };
    // The shape functions ('numerics/shape function') are the scene's:
    // SceneParameters::shape_function (docs/shape-functions.md).
    /// Velocity transfer of the 1-phase step (docs/shape-functions.md, "APIC").
    enum class VelocityTransfer
    {
      flip, ///< v_p += h a(x_p), momentum re-projection (seed 000 Eqs. 4.46-4.48)
      apic  ///< affine particle-in-cell (Jiang et al. 2015): v_p, C_p from the nodal velocity
    };
    VelocityTransfer velocity_transfer = VelocityTransfer::flip;
    bool
    apic() const
    {
      return velocity_transfer == VelocityTransfer::apic;
    }
    /// The .prm word of `integration` (mpm, mpm-mixed, fem, ul-fem).
    const char *
    integration_name() const
    {
      return integration == Integration::fem         ? "fem"
             : integration == Integration::ul_fem    ? "ul-fem"
             : integration == Integration::mpm_mixed ? "mpm-mixed"
                                                     : "mpm";
    }
    Integration integration  = Integration::mpm;
    double      fill_factor  = 0.9;  ///< F_fill of Eq. 6.33
    bool        mixed_linear = true; ///< MPM-MIXED cell stress linear (else constant, Eq. 6.32 alone)
    Smoothing   smoothing    = Smoothing::none;
    /// 'numerics/volumetric stabilisation' (transfer/fbar.h, docs/explicit.md "F-bar"):
    /// f-bar = the increment's volume change replaced by the mass-weighted node
    /// map and remap of the points' dJ (seed 002 Eqs. 79-80), any shape kernel
    bool fbar = false;

    struct ContactPair
    {
      unsigned int a = 0, b = 0;
      double       friction = 0; ///< Coulomb coefficient mu
      double       adhesion = 0; ///< a [Pa]: tangential force cap a * A_k (Eq. 6.19)
    };
    std::vector<ContactPair> contact_pairs; ///< empty: contact off

    bool
    contact() const
    {
      return !contact_pairs.empty();
    }
    /// integration points stay at the Gauss points of their cells (fem, ul-fem)
    bool
    fem() const
    {
      return integration == Integration::fem || integration == Integration::ul_fem;
    }
    /// the solver needs a full (non-fused) P2G pass every step
    bool
    extended_p2g() const
    {
      return integration == Integration::mpm_mixed || contact() || smoothing != Smoothing::none;
    }
  };

  /// `default_integration`: the default of 'numerics/integration' (talus-fem: "fem").
  void declare_numerics_parameters(dealii::ParameterHandler &prm, const std::string &default_integration = "mpm");
  /// Reads and validates; n_bodies for the body ids of the contact pairs.
  NumericsOptions parse_numerics_parameters(dealii::ParameterHandler &prm, unsigned int n_bodies);

  /// Full P2G of lumped mass and internal + gravity force with MPM-MIXED
  /// integration and/or per-body fields for contact. Replaces the solver's
  /// P2G pass when `extended_p2g()`.
  template <int dim>
  void p2g_extended(Solver<dim> &s);

  /// Strain smoothing (§6.7.1): after the nodal velocities are known, a volumetric
  /// strain increment per cell with points; the update pass replaces each point's
  /// volumetric part by it. Kept variationally consistent: the element value
  /// is the volume-weighted mean of the cell's points (the projection with the
  /// quadrature the force uses), and the internal force of the same step takes
  /// the transpose, each point's mean in-plane stress replaced by its cell's
  /// (cell) or by the nodal smoothing's transpose (nodal): the smoothed strain
  /// does the work the force does (docs/explicit.md "Strain smoothing").
  /// With contact every body is a field of its own (its corrected velocities,
  /// the cells of its points).
  template <int dim>
  class StrainSmoothing
  {
  public:
    /// `n_fields`: 1, or with contact the number of bodies
    StrainSmoothing(const BackgroundGrid<dim> &grid, NumericsOptions::Smoothing kind, bool bspline,
                    unsigned int n_fields);
    /// At the start of the step's P2G (the points where they stay for the
    /// step): every field's cells, point volumes per cell and the mean
    /// stresses the force takes (force_stress_correction).
    void collect(Solver<dim> &s);
    /// The P2G's -V sigma of a point of `field` in `cell` with mean in-plane
    /// stress replaced by the cell's (t = -V sigma on entry).
    inline void
    force_stress_correction(const unsigned int cell, const unsigned int field, const double *P, const double V,
                            double (&t)[dim][dim]) const
    {
      using L  = PropertyLayout<dim>;
      double m = 0;
      for (unsigned int d = 0; d < dim; ++d)
        m += P[L::stress + d];
      const double c = V * (m / dim - force_mean[field * n_cells + cell]);
      for (unsigned int d = 0; d < dim; ++d)
        t[d][d] += c;
    }
    /// From the nodal velocities the update pass moves with: the solver's
    /// nodal_p after nodal_velocity(), or with contact every body's v~_b
    /// (Contact::BodyFields::momentum after the contact law). After collect().
    void compute(Solver<dim> &s, double dt);
    /// After a repartition: the per-cell arrays and the nodal vector re-sized
    /// for the new local mesh (all recomputed every step, nothing travels).
    void grid_changed(const BackgroundGrid<dim> &grid);
    /// The field of a point: 0, or with contact its body.
    inline unsigned int
    field_of(const double *P) const
    {
      return n_fields > 1 ? static_cast<unsigned int>(P[PropertyLayout<dim>::body]) : 0;
    }
    /// Replace the volumetric part of d_eps (in-plane trace in 2D) by the value
    /// of the cell for the point's field.
    inline void
    apply(const unsigned int cell, const unsigned int field, materials::Strain &d_eps) const
    {
      double tr = 0;
      for (unsigned int d = 0; d < dim; ++d)
        tr += d_eps[d][d];
      const double c = (cell_value[field * n_cells + cell] - tr) / dim;
      for (unsigned int d = 0; d < dim; ++d)
        d_eps[d][d] += c;
    }

  private:
    NumericsOptions::Smoothing kind;
    bool                       bspline;
    unsigned int               n_fields, n_cells = 0;
    /// per field and cell (index field * n_cells + cell): the element values,
    /// sum V_p of the field's points, and the mean stress the force takes
    std::vector<double> cell_value, cell_weight, force_mean;
    /// per cell: nodal_average_transposed's factor Omega_c / W_c
    std::vector<double> scale;
    /// per field: the cells that hold its points in this step
    std::vector<std::vector<unsigned int>> cells;
    /// the element values: the volume-weighted means over each cell's points
    template <class K>
    void point_means(K, Solver<dim> &s, double dt);
    /// Eqs. 6.35-6.36 for one field over its cells
    void nodal_average(const Solver<dim> &s, unsigned int field);
    /// the transpose of nodal_average for the force's mean stresses
    void nodal_average_transposed(const Solver<dim> &s, unsigned int field);
    /// both through the vertices of the field's cells: a_c <- scale_c sum_{i of c}
    /// X0_i / X1_i (no scale: 1 / nv), X0_i = sum_{c at i} (share ? a_c / nv : a_c Omega_c),
    /// X1_i = sum Omega_c
    void   through_vertices(const Solver<dim> &s, unsigned int field, double *a, bool share, const double *scale);
    Vector nodal; ///< two scalar slots per node (components 0 and 1)
  };

  /// Contact between bodies (§6.2). Every body gets its own nodal mass, volume,
  /// force, momentum and outward normal (distributed vectors, allocated only
  /// when contact is on). At nodes where a body meets another one, the
  /// predictor-corrector of Bardenhagen et al. corrects the body's velocity:
  /// free separation, no interpenetration, Coulomb friction with adhesion for
  /// the pairs listed in the .prm, sticking for pairs not listed. The point
  /// walks are templates on the shape kernel (linear Q1 or quadratic B-spline,
  /// docs/explicit.md "Contact between bodies").
  template <int dim>
  class Contact
  {
  public:
    /// `fbar`: every body also gets its own F-bar map (BodyFields::volume_increment);
    /// `affine`: APIC, the offset of C_p (0: FLIP)
    Contact(const BackgroundGrid<dim> &grid, const NumericsOptions &o, unsigned int n_bodies, bool bspline, bool fbar,
            unsigned int affine);

    /// After a repartition: the per-body nodal fields re-sized for the new DoF
    /// numbering (every step fills them from the points: P2G, contact law), the
    /// node marker cleared; the contact node list is collected every step.
    void grid_changed();
    /// Full P2G of the combined mass and force (into the solver's nodal_mass,
    /// nodal_a) and of every body's mass, volume, force and momentum (and, with
    /// B-splines, its outward normal), with integration = mpm, on the run's
    /// kernel. (MPM-MIXED with contact: p2g_extended, linear only.)
    void p2g(Solver<dim> &s);
    /// Lagrangian phase: after nodal_acceleration(), the corrected per-body
    /// accelerations a~_b = (v~_b - v_b^t) / dt (Eq. 6.21). APIC: the body's
    /// momentum vector then holds its corrected v^L_b = v~_b^t + dt a~_b, from
    /// which the update pass takes v_p, C_p and the displacement (the contact law
    /// acts once, on v^L; there is no convective phase).
    void correct_accelerations(Solver<dim> &s, double dt);
    /// G2P of the particle velocities with the per-body accelerations and P2G
    /// of the momentum per body and combined (replaces the solver's pass).
    void g2p_velocity_p2g_momentum(Solver<dim> &s, double dt);
    /// Convective phase: per-body nodal velocities from momentum, corrected
    /// by the same contact law (after the solver's nodal_velocity()).
    void correct_velocities(Solver<dim> &s, double dt);
    /// Displacement increments dt * v~_b of body b on the stencil of a cell of
    /// kernel K (with what K needs for gradients), after correct_velocities().
    template <class K>
    inline void
    body_increments(const typename K::Cell &cell, const unsigned int body, const double dt, typename K::Field &du) const
    {
      K::gather(cell, fields[body].momentum.begin(), dt, du, true);
    }

    /// Statistics of the last step (for the log): nodes with > 1 body, nodes corrected.
    unsigned long long contact_nodes = 0, corrected_nodes = 0;

    struct BodyFields
    {
      Vector mass;     ///< lumped mass (every component of a node holds it)
      Vector volume;   ///< lumped volume sum V_p N_i (for the adhesion area; every component)
      Vector force;    ///< internal + gravity force; after correct_accelerations: a~_b
      Vector momentum; ///< momentum (APIC: with the affine term); after correct_velocities (APIC:
                       ///< correct_accelerations): v~_b
      Vector gradient; ///< outward normal of the body (minus the gradient of its mass field)
      /// F-bar: sum N m dJ of the body's points, then dJ_I (sized only in f-bar
      /// runs: Solver::volume_averages_with)
      Vector volume_increment;
    };
    std::vector<BodyFields> fields;

  private:
    friend void                p2g_extended<dim>(Solver<dim> &s);
    const BackgroundGrid<dim> &grid;
    unsigned int               n_bodies;
    bool                       fbar;
    unsigned int               affine;
    /// quadratic B-splines: normals from the points (p2g), nodes from the cells' patches
    bool bspline;
    /// quadratic B-splines: a node is a contact node only where at least two
    /// bodies' nodal volumes each fill this fraction of its capacity (docs/explicit.md)
    static constexpr double bspline_share = 0.1;
    /// quadratic B-splines: capacity of every node, the integral of its shape
    /// function over the grid (the nodal volume sum V_p N_i of a grid full of
    /// points); computed when first needed after a (re)partition
    Vector capacity;
    bool   capacity_ready = false;
    template <class K>
    void compute_capacity(K);
    /// pair_index[a * n + b]: index into pairs or -1 (stick)
    std::vector<int>                          pair_index;
    std::vector<NumericsOptions::ContactPair> pairs;
    double                                    cell_volume = 0;
    double                                    h[dim];
    /// owned active nodes: local DoF indices of their dim components
    std::vector<std::array<unsigned int, dim>> nodes;
    std::vector<unsigned char>                 node_marker;
    /// per body: the friction-wall node states of its field in this step
    /// (LoadControl::body_accelerations, read by body_velocities)
    std::vector<std::vector<unsigned char>> wall_state;
    template <class K>
    void p2g_with(K, Solver<dim> &s);
    template <class K>
    void g2p_with(K, Solver<dim> &s, double dt);
    template <class K>
    void collect_nodes_with(K, const Solver<dim> &s);
    void collect_nodes(const Solver<dim> &s);
    void compute_normals(const Solver<dim> &s);
    /// the contact law at one node: predicted per-body velocities vb (in),
    /// corrected (out); returns true if a correction was applied
    bool correct_node(const std::array<unsigned int, dim> &dofs, const std::vector<unsigned char> &constrained,
                      std::vector<double> &mb, std::vector<std::array<double, dim>> &vb, double dt);
  };
} // namespace talus::explicit_mpm
