// talus — contact walls on the points' side for talus-implicit (issue 13,
// docs/implicit.md "Contact walls on the points"): a rigid plane (a face of the
// box grid) pushes on the material points that penetrate it, by a penalty that
// acts at the point through its shape functions, inside Newton with its
// consistent tangent. Tangentially: no slip (a penalty on the slip since the
// point touched the wall: a stick anchor per point and wall), frictionless, or
// Coulomb friction (stick/slip return with mu). The contact point moves with
// the material instead of jumping between grid nodes (the node-based
// 'contact' walls of implicit_constraints.cc). The same law serves a rigid
// footing: a plane of finite span moving at a prescribed rate (docs/implicit.md,
// "Rigid footing on the points").
//
// Per point and wall (a point carries no surface; its extent r_p = V_p^(1/dim)/2,
// the half side of the square/cube of its volume; axisymmetric: of its area).
// The contact acts at the point's contact spot, the material at x_p + s r_p e_a
// (towards the wall), whose shape values are N_i + s r_p dN_i/dx_a (exact for Q1,
// linear along an axis): the spot turns with the material, so the disk rolls
// about its contact and not about the point's centre (docs/implicit.md).
//   gap   g  = s (w - x_a)            (x the spot, x = x_n + N Du; s = +-1 the
//                                      outward normal of the box face, w its
//                                      coordinate on axis a)
//   pen   p  = max(0, -g)             active per Newton iterate
//   k_n   = penalty x M V_p / h_a^2   (M the constrained modulus of the point's
//                                      material, h_a the cell size normal to the wall)
//   f     = -k_n p n_out + f_t        (external force at the spot; r_i -= N_i f,
//                                      K_ij += N_i N_j (-df/dx))
//   f_t   = -k_t (x_t - X_anchor)     stick (k_t = k_n), or -mu k_n p t  slip
//                                      (t = the slip direction) when k_t |x_t - X_anchor| > mu k_n p
// The anchor is the spot's tangential position at the start of the step in
// which it touched the wall (kept while it stays in contact, moved to the
// Coulomb limit when it slips; dropped when it leaves); it lives in the point's
// properties, so it migrates with the point and is in the checkpoints.
#pragma once

#include <talus/grid/nodal_space.h>
#include <talus/materials/material.h>
#include <talus/particles/material_point_set.h>
#include <talus/transfer/active_set.h>

#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>

#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace talus::implicit_mpm
{
  /// One rigid plane: normal along `axis`, outward normal `sign` e_axis (the
  /// material is on the other side), at coordinate `wall`. A box face of the
  /// grid (a contact wall), or the base of a rigid footing: bounded along the
  /// other axes and moving along its normal.
  struct ContactPlane
  {
    unsigned int axis     = 0;
    int          sign     = -1;
    double       wall     = 0;
    double       cell     = 1; ///< cell size normal to the plane (the penalty's h)
    double       penalty  = 1; ///< kappa: k_n = kappa M V_p / h^2
    double       friction = std::numeric_limits<double>::infinity(); ///< +inf no slip, 0 frictionless, else mu
    /// a footing's base: wall = wall_0 + velocity t at the end of the step,
    /// wall_n at its start (set_time)
    double wall_0 = 0, velocity = 0, wall_n = 0;
    /// a footing's base (its normal force is reported as the footing's
    /// reaction) acts only on points whose contact spot lies, at the start of
    /// the step, within [lower, upper] along the other axes (in increasing axis
    /// order) and not deeper than the point's extent behind the plane (a point
    /// beside the footing that flows over its edge is not pulled through the
    /// footing: docs/implicit.md, "Rigid footing on the points"); a wall is
    /// unbounded
    bool   footing  = false;
    double lower[2] = {0, 0}, upper[2] = {0, 0};
  };

  /// Totals of one assembly or of a converged step (global: summed over ranks).
  struct PointContactStats
  {
    unsigned long long in_contact = 0, slipping = 0, new_contacts = 0, released = 0;
    double             normal_force = 0, tangential_force = 0; ///< sums of |f_n|, |f_t| over the points
    double             footing_force  = 0; ///< sum of f_n over the points on footing planes (along -sign e_axis)
    unsigned long long behind_footing = 0; ///< points within a footing's span but deeper than their extent (ignored)
    double             max_penetration_ratio = 0; ///< largest p / r_p
  };

  template <int dim>
  class PointContact
  {
  public:
    /// bspline: the grid basis of the solver (quadratic B-splines, else linear Q1)
    PointContact(std::vector<ContactPlane>                                      planes,
                 const std::vector<std::shared_ptr<const materials::Material>> &materials, const bool axisymmetric,
                 const bool bspline);

    /// Adds the block 'contact' (x_n, then per wall: anchor (dim) and flag) to
    /// the layout; call before the points are initialised.
    void extend_layout(PropertyLayout<dim> &layout);
    /// New points: no contact (flags 0).
    void initialize_points(MaterialPointSet<dim> &points) const;
    /// Start of a step: x_n of every point (read by the assemblies of the step).
    void start_step(MaterialPointSet<dim> &points) const;
    /// The moving planes (footings) to their positions at the start (t_n) and
    /// the end (t) of the step.
    void set_time(const double t_n, const double t);
    /// Whether plane c acts on a point whose contact spot was at xs_n at the
    /// start of the step (extent r): 1 yes (always for a wall), 0 the
    /// spot is outside the plane's span, -1 within it but behind the plane.
    int acts_on(const ContactPlane &c, const double *xs_n, const double r) const;
    /// Residual (and tangent) terms at the iterate du (ghosts up to date),
    /// added with `constraints` to A (may be null) and b; compresses both.
    /// Returns the figures of this iterate. Collective.
    PointContactStats assemble(MaterialPointSet<dim> &points, const ActiveSet<dim> &active,
                               const dealii::AffineConstraints<double> &constraints, const Vector &du,
                               dealii::TrilinosWrappers::SparseMatrix *A, Vector &b) const;
    /// After convergence (before the convective phase moves the points): the
    /// stick anchors and contact flags of the converged increment. Collective.
    PointContactStats commit(MaterialPointSet<dim> &points, const NodalSpace<dim> &space, const Vector &du) const;

    const std::vector<ContactPlane> &
    walls() const
    {
      return planes;
    }
    unsigned int
    offset() const
    {
      return offset_;
    }

    /// The per-spot law: at x (current position of the contact spot), x_n (at
    /// the start of the step), with the offset r (0: x is the spot), stiffness
    /// k and anchor state of wall w;
    /// writes the force on the point (f), its derivative df/dx (D, row-major
    /// dim x dim), and returns 0 (no contact), 1 (stick) or 2 (slip).
    struct Law
    {
      double f[dim], D[dim][dim], pen, anchor[dim];
    };
    int law(const ContactPlane &c, const double *x, const double *x_n, const double *state, const double r,
            const double k, Law &out) const;

    /// the extent r_p and stiffness k_n of a point (properties P, x_n)
    void extent_and_stiffness(const double *P, const ContactPlane &c, double &r, double &k) const;

  private:
    std::vector<ContactPlane> planes;
    std::vector<double>       modulus; ///< per material: constrained modulus M
    bool                      axisymmetric;
    bool                      bspline;
    unsigned int              offset_ = 0;
  };
} // namespace talus::implicit_mpm
