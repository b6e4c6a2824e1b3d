#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/loads/kinematics.h>
#include <talus/loads/node_target.h>
#include <talus/loads/rigid_plate.h>
#include <talus/loads/rigid_plate_nodes.h>

#include <deal.II/base/mpi.h>

#include <deal.II/base/utilities.h>

#include <array>
#include <cmath>
#include <sstream>

namespace talus::loads
{
  using dealii::Patterns::Anything;
  using dealii::Patterns::Integer;
  using dealii::Patterns::Selection;

  namespace
  {
    constexpr unsigned int max_rigid_plates = 4;

    const NodeTargetEntries plate_target{
      "boundary|region",
      "boundary",
      "'boundary': every grid node of the faces with 'boundary id'; 'region': the grid nodes inside the region box "
      "(e.g. a footing on the material's surface).",
      "",
      /*flat_region=*/true,
      /*grid_file_ids=*/true};

    // the errors of the node checks, worded once for the box check (parse) and
    // the grid check (setup)
    template <int dim>
    std::string
    no_node_message(const RigidPlate<dim> &p)
    {
      return p.target == RigidPlate<dim>::Target::boundary
               ? "holds no grid node: no face of the grid has boundary id " + std::to_string(p.boundary)
               : std::string("holds no grid node: no node of the grid lies inside its region; allowed: a region "
                             "that contains at least one grid node");
    }
    std::string
    shared_message(const std::string &count)
    {
      return "shares " + count + " node(s) with another rigid plate; a grid node can belong to one plate only";
    }
    template <int dim>
    std::string
    held_message(const RigidPlate<dim> &p, const std::string &count, const std::string &stage)
    {
      const char axes[] = {'x', 'y', 'z'};
      return "a fixed/roller wall holds its direction component at every one of its " + count + " node(s)" + stage +
             ", so the plate cannot move along " + std::string(1, axes[p.axis]) +
             " (a wall keeps the components it holds); allowed: a direction or nodes that no wall holds";
    }
  } // namespace

  template <int dim>
  PrescribedVelocity<dim>
  RigidPlate<dim>::node_condition() const
  {
    PrescribedVelocity<dim> v;
    v.target =
      target == Target::boundary ? PrescribedVelocity<dim>::Target::boundary : PrescribedVelocity<dim>::Target::region;
    v.boundary = boundary;
    v.lower    = lower;
    v.upper    = upper;
    for (unsigned int d = 0; d < dim; ++d)
      v.component[d] = rough || d == axis;
    v.where = where;
    return v;
  }

  unsigned int
  peek_rigid_plates(const std::string &prm_file)
  {
    if (prm_file.empty())
      return 0;
    return dealii::Utilities::string_to_int(
      peek_entry(prm_file, "boundary conditions", "number of rigid plates", "0", Integer(0, max_rigid_plates)));
  }

  void
  declare_rigid_plate_parameters(dealii::ParameterHandler &prm, const unsigned int dim, const unsigned int n)
  {
    prm.declare_entry(
      "number of rigid plates", "0", Integer(0, max_rigid_plates),
      "Number of 'rigid plate k' subsections: sets of grid nodes that move as one rigid body "
      "along one axis, driven by a total force or by a displacement history (docs/boundary-conditions.md).");
    for (unsigned int k = 0; k < n; ++k)
      {
        prm.enter_subsection("rigid plate " + std::to_string(k));
        declare_node_target(prm, dim, plate_target);
        prm.declare_entry("direction", dim == 2 ? "y" : "z", Selection(dim == 2 ? "x|y" : "x|y|z"),
                          "The grid axis along which the plate moves.");
        prm.declare_entry("surface", "frictionless", Selection("frictionless|rough"),
                          "frictionless: the other velocity components of the plate's nodes are free; rough: they "
                          "are held at zero (no slip).");
        prm.declare_entry("total force", "", Anything(),
                          "Force control: the force the plate exerts on the material along +direction [N; per unit "
                          "thickness in 2D] (negative pushes towards -direction), times the time function; the "
                          "plate's displacement is an unknown. Give this or 'displacement'.");
        prm.declare_entry("displacement", "", Anything(),
                          "Displacement control: the plate's displacement along +direction [m], times the time "
                          "function; its reaction is reported. Give this or 'total force'.");
        declare_time_function(prm, "the force or displacement", "the absolute time");
        prm.declare_entry(
          "drainage", "impermeable", Selection("impermeable|permeable"),
          "Two-phase families: 'permeable': the pore pressure is zero at the plate's nodes (the "
          "water drains through it); 'impermeable': no water crosses the plate. One-phase runs ignore it.");
        prm.leave_subsection();
      }
  }

  template <int dim>
  std::vector<RigidPlate<dim>>
  parse_rigid_plate_parameters(dealii::ParameterHandler &prm, const bool box_grid)
  {
    std::vector<RigidPlate<dim>> plates;
    const unsigned int           n = prm.get_integer("number of rigid plates");
    for (unsigned int k = 0; k < n; ++k)
      {
        RigidPlate<dim> p;
        p.where = "boundary conditions/rigid plate " + std::to_string(k);
        prm.enter_subsection("rigid plate " + std::to_string(k));
        const auto t = parse_node_target<dim>(prm, p.where, plate_target, box_grid);
        copy_node_target(t, p);
        p.target                = t.kind == NodeTarget<dim>::Kind::boundary ? RigidPlate<dim>::Target::boundary
                                                                            : RigidPlate<dim>::Target::region;
        p.axis                  = static_cast<unsigned int>(prm.get("direction")[0] - 'x');
        p.rough                 = prm.get("surface") == "rough";
        const std::string force = prm.get("total force"), disp = prm.get("displacement");
        require(force.empty() != disp.empty(), p.where,
                force.empty() ? "give 'total force' (force control) or 'displacement' (displacement control)"
                              : "give either 'total force' or 'displacement', not both");
        if (!force.empty())
          {
            const auto v = parse_doubles(force, p.where + "/total force");
            require(v.size() == 1, p.where + "/total force", "one number [N] (the component along 'direction')");
            p.control = RigidPlate<dim>::Control::force;
            p.force   = v[0];
          }
        else
          {
            const auto v = parse_doubles(disp, p.where + "/displacement");
            require(v.size() == 1, p.where + "/displacement", "one number [m] (the component along 'direction')");
            p.control      = RigidPlate<dim>::Control::displacement;
            p.displacement = v[0];
          }
        p.function  = parse_time_function(prm, p.where);
        p.permeable = prm.get("drainage") == "permeable";
        prm.leave_subsection();
        plates.push_back(p);
      }
    return plates;
  }

  template <int dim>
  std::vector<PrescribedNodeDof>
  rigid_plate_node_dofs(const BackgroundGrid<dim> &grid, const std::vector<RigidPlate<dim>> &plates,
                        const bool owned_only)
  {
    std::vector<PrescribedVelocity<dim>> conditions;
    for (const auto &p : plates)
      conditions.push_back(p.node_condition());
    return prescribed_node_dofs(grid, conditions, owned_only);
  }

  template <int dim>
  std::vector<std::string>
  rigid_plate_series_columns(const std::vector<RigidPlate<dim>> &plates)
  {
    std::vector<std::string> c;
    for (unsigned int k = 0; k < plates.size(); ++k)
      {
        const std::string p = "plate_" + std::to_string(k) + "_";
        c.push_back(p + "displacement");
        c.push_back(p + "force");
        if (plates[k].rough)
          c.push_back(p + "tangential_force");
      }
    return c;
  }

  template <int dim>
  void
  check_rigid_plates_on_box(const std::vector<RigidPlate<dim>> &plates, const dealii::Point<dim> &lower,
                            const dealii::Point<dim> &upper, const std::vector<unsigned int> &cells,
                            const std::vector<BoundaryCondition> &walls)
  {
    std::vector<std::array<int, 2 * dim>> ranges; // per plate: i0, i1 per axis
    for (const auto &p : plates)
      {
        // per axis the range of node indices the plate holds
        int  i0[dim], i1[dim];
        bool any = true;
        for (unsigned int d = 0; d < dim; ++d)
          {
            const int    n = static_cast<int>(cells[d]);
            const double h = (upper[d] - lower[d]) / n, tol = 1e-9 * h; // as prescribed_node_dofs
            if (p.target == RigidPlate<dim>::Target::boundary && p.boundary / 2 == d)
              i0[d] = i1[d] = p.boundary % 2 ? n : 0;
            else if (p.target == RigidPlate<dim>::Target::boundary)
              i0[d] = 0, i1[d] = n;
            else
              {
                // (the wording of check_scene_consistency; talus-semi-implicit runs this check before it)
                require(p.lower[d] <= upper[d] && p.upper[d] >= lower[d], p.where + "/region lower corner",
                        "the region lies outside the grid (grid extent " + std::to_string(lower[d]) + " .. " +
                          std::to_string(upper[d]) + " along " + std::string(1, char('x' + d)) + ")");
                i0[d] = std::max(0, static_cast<int>(std::ceil((p.lower[d] - tol - lower[d]) / h)));
                i1[d] = std::min(n, static_cast<int>(std::floor((p.upper[d] + tol - lower[d]) / h)));
              }
            any = any && i0[d] <= i1[d];
          }
        require(any, p.where, no_node_message(p));
        // a node is free along the axis unless it lies on a face whose wall
        // holds that component: some node is free iff every axis has an index
        // in the range on no such face
        bool free = true;
        for (unsigned int d = 0; d < dim; ++d)
          {
            const int n        = static_cast<int>(cells[d]);
            bool      holds[2] = {false, false}; // the lower / upper face of axis d
            for (const auto &w : walls)
              if (w.id / 2 == d && w.id < 2 * dim)
                holds[w.id % 2] = holds[w.id % 2] || w.kind == BoundaryCondition::Kind::fixed || d == p.axis;
            const int held = (holds[0] && i0[d] == 0) + (holds[1] && i1[d] == n && n != 0);
            free           = free && i1[d] - i0[d] + 1 > held;
          }
        unsigned long long n_nodes = 1;
        for (unsigned int d = 0; d < dim; ++d)
          n_nodes *= static_cast<unsigned long long>(i1[d] - i0[d] + 1);
        require(free, p.where, held_message(p, std::to_string(n_nodes), ""));
        std::array<int, 2 * dim> r;
        for (unsigned int d = 0; d < dim; ++d)
          r[2 * d] = i0[d], r[2 * d + 1] = i1[d];
        for (unsigned int j = 0; j < ranges.size(); ++j)
          {
            bool overlap = true;
            for (unsigned int d = 0; d < dim; ++d)
              overlap = overlap && std::max(r[2 * d], ranges[j][2 * d]) <= std::min(r[2 * d + 1], ranges[j][2 * d + 1]);
            unsigned long long n_shared = 1;
            for (unsigned int d = 0; d < dim; ++d)
              n_shared *= overlap ? static_cast<unsigned long long>(std::min(r[2 * d + 1], ranges[j][2 * d + 1]) -
                                                                    std::max(r[2 * d], ranges[j][2 * d]) + 1)
                                  : 0;
            require(!overlap, p.where, shared_message(std::to_string(n_shared)));
          }
        ranges.push_back(r);
      }
  }

  template <int dim>
  std::vector<RigidPlateNodes>
  check_rigid_plate_nodes(const BackgroundGrid<dim> &grid, const std::vector<RigidPlate<dim>> &plates,
                          const std::vector<std::vector<BoundaryCondition>> &stage_walls,
                          const std::vector<std::string> &stage_names, MPI_Comm comm)
  {
    const unsigned int n = plates.size(), n_stages = stage_walls.size(), nc = 2 + n_stages;
    // per plate: owned nodes, nodes shared with an earlier plate, and per stage
    // the nodes whose axis component that stage's walls hold
    std::vector<unsigned long long>         count(n * nc, 0);
    const unsigned int                      n_owned = grid.partitioner->locally_owned_size();
    std::vector<std::vector<unsigned char>> flags;
    for (const auto &walls : stage_walls)
      flags.push_back(wall_dof_flags(grid, walls));
    std::vector<int> owner(n_owned, -1);
    for (const auto &p : rigid_plate_node_dofs(grid, plates, /*owned_only=*/true))
      {
        if (p.component != plates[p.condition].axis)
          continue;
        unsigned long long *c = &count[p.condition * nc];
        c[0] += 1;
        if (owner[p.node] >= 0 && owner[p.node] != static_cast<int>(p.condition))
          c[1] += 1;
        owner[p.node] = static_cast<int>(p.condition);
        for (unsigned int j = 0; j < n_stages; ++j)
          if (flags[j][p.dof])
            c[2 + j] += 1;
      }
    if (n > 0)
      MPI_Allreduce(MPI_IN_PLACE, count.data(), static_cast<int>(count.size()), MPI_UNSIGNED_LONG_LONG, MPI_SUM, comm);
    std::vector<RigidPlateNodes> out(n);
    for (unsigned int k = 0; k < n; ++k)
      {
        const auto               &pl = plates[k];
        const unsigned long long *c  = &count[k * nc];
        require(c[0] > 0, pl.where, no_node_message(pl));
        require(c[1] == 0, pl.where, shared_message(std::to_string(c[1])));
        for (unsigned int j = 0; j < n_stages; ++j)
          require(c[2 + j] < c[0], pl.where,
                  held_message(pl, std::to_string(c[0]),
                               n_stages > 1 ? " in stage '" + stage_names[j] + "'" : std::string()));
        out[k].nodes = c[0];
        out[k].held.assign(c + 2, c + nc);
      }
    return out;
  }

  template <int dim>
  std::string
  rigid_plate_log_line(const RigidPlate<dim> &pl, const unsigned int k, const RigidPlateNodes &count)
  {
    const char         ax[] = {'x', 'y', 'z'};
    std::ostringstream os;
    os << "  rigid plate " << k << " ("
       << (pl.target == RigidPlate<dim>::Target::boundary ? "boundary id " + std::to_string(pl.boundary)
                                                          : std::string("region"))
       << "): " << count.nodes << " grid node(s)";
    if (!count.held.empty() && count.held[0] > 0)
      os << " (" << count.held[0] << " held along " << ax[pl.axis] << " by a wall, they stay)";
    os << ", direction " << ax[pl.axis] << ", " << (pl.rough ? "rough" : "frictionless") << ", "
       << (pl.control == RigidPlate<dim>::Control::force
             ? "force control: total force " + dealii::Utilities::to_string(pl.force) + " N x f(t)"
             : "displacement control: displacement " + dealii::Utilities::to_string(pl.displacement) +
                 " m x f(t), reaction reported")
       << " (its own time function, absolute time)";
    return os.str();
  }

  template <int dim>
  void
  refuse_rigid_plates(const std::vector<RigidPlate<dim>> &plates, const std::string &tool, const std::string &reason)
  {
    require(plates.empty(), plates.empty() ? std::string() : plates.front().where,
            tool + " cannot honour a rigid plate: " + reason);
  }

  template struct RigidPlate<2>;
  template struct RigidPlate<3>;
  template std::vector<RigidPlate<2>>     parse_rigid_plate_parameters<2>(dealii::ParameterHandler &, bool);
  template std::vector<RigidPlate<3>>     parse_rigid_plate_parameters<3>(dealii::ParameterHandler &, bool);
  template std::vector<PrescribedNodeDof> rigid_plate_node_dofs(const BackgroundGrid<2> &,
                                                                const std::vector<RigidPlate<2>> &, bool);
  template std::vector<PrescribedNodeDof> rigid_plate_node_dofs(const BackgroundGrid<3> &,
                                                                const std::vector<RigidPlate<3>> &, bool);
  template std::vector<std::string>       rigid_plate_series_columns(const std::vector<RigidPlate<2>> &);
  template std::vector<std::string>       rigid_plate_series_columns(const std::vector<RigidPlate<3>> &);
  template void check_rigid_plates_on_box(const std::vector<RigidPlate<2>> &, const dealii::Point<2> &,
                                          const dealii::Point<2> &, const std::vector<unsigned int> &,
                                          const std::vector<BoundaryCondition> &);
  template void check_rigid_plates_on_box(const std::vector<RigidPlate<3>> &, const dealii::Point<3> &,
                                          const dealii::Point<3> &, const std::vector<unsigned int> &,
                                          const std::vector<BoundaryCondition> &);
  template std::vector<RigidPlateNodes> check_rigid_plate_nodes(const BackgroundGrid<2> &,
                                                                const std::vector<RigidPlate<2>> &,
                                                                const std::vector<std::vector<BoundaryCondition>> &,
                                                                const std::vector<std::string> &, MPI_Comm);
  template std::vector<RigidPlateNodes> check_rigid_plate_nodes(const BackgroundGrid<3> &,
                                                                const std::vector<RigidPlate<3>> &,
                                                                const std::vector<std::vector<BoundaryCondition>> &,
                                                                const std::vector<std::string> &, MPI_Comm);
  template std::string rigid_plate_log_line(const RigidPlate<2> &, unsigned int, const RigidPlateNodes &);
  template std::string rigid_plate_log_line(const RigidPlate<3> &, unsigned int, const RigidPlateNodes &);
  template void refuse_rigid_plates(const std::vector<RigidPlate<2>> &, const std::string &, const std::string &);
  template void refuse_rigid_plates(const std::vector<RigidPlate<3>> &, const std::string &, const std::string &);
} // namespace talus::loads
