// talus — the one particle walk. Every pass over the material points of a set
// (P2G, G2P, the fused explicit update, ...) is this walk with an op:
//
//   op.begin_cell(c)         once per active cell: gather nodal data, reset sums
//   op.point(c, it)          once per point of the cell (it: particle iterator)
//   op.end_cell(c)           once per active cell: scatter the cell's sums
//
// The walk follows the set's (cell, count) list in storage order with one
// particle iterator (no cell look-ups) and prefetches a few points ahead.
// Ops are templates (kernel and physics as template parameters) so the hot
// loop is one inlined pass; compose ops with transfer::Fused.
#pragma once

#include <talus/particles/material_point_set.h>

namespace talus::transfer
{
  /// Walks `distance` particles ahead of a loop and prefetches their data.
  /// Points that changed cell sit in recycled storage slots scattered in
  /// memory; prefetching hides most of that latency (measured on the 3D bench:
  /// 317 -> 227 ns per particle-step with 8 points ahead).
  template <int dim>
  class Prefetcher
  {
  public:
    Prefetcher(dealii::Particles::ParticleHandler<dim> &ph, const unsigned int distance)
        : it(ph.begin())
        , end(ph.end())
    {
      for (unsigned int i = 0; i < distance && it != end; ++i)
        ++it;
    }
    inline void
    next(const bool with_location)
    {
      if (it == end)
        return;
      const double *P = it->get_properties().data();
      __builtin_prefetch(P);
      __builtin_prefetch(P + 8);
      __builtin_prefetch(&it->get_reference_location());
      if (with_location)
        __builtin_prefetch(&it->get_location());
      ++it;
    }

  private:
    typename dealii::Particles::ParticleHandler<dim>::particle_iterator it, end;
  };

  /// Points prefetched ahead by the walks (8 measured best on the 3D bench).
  inline constexpr unsigned int prefetch_distance = 8;

  template <int dim>
  using PointIterator = typename dealii::Particles::ParticleHandler<dim>::particle_iterator;

  /// Whether an op walks the points of a cell itself: `whole_cell(c, n, pt,
  /// ahead)` instead of begin_cell/point/end_cell (the explicit update pass,
  /// which updates the stresses of a cell in one call per model).
  template <class Op>
  constexpr auto
  walks_whole_cells(int) -> decltype(Op::whole_cells, bool())
  {
    return Op::whole_cells;
  }
  template <class Op>
  constexpr bool
  walks_whole_cells(long)
  {
    return false;
  }

  /// The walk. `Op::prefetch_location` (a static constexpr bool) says whether
  /// the op reads the points' locations (then they are prefetched too).
  template <int dim, class Op>
  inline void
  for_each_active_cell(MaterialPointSet<dim> &set, Op &op)
  {
    auto            pt = set.handler.begin();
    Prefetcher<dim> ahead(set.handler, prefetch_distance);
    for (const auto [c, n_in_cell] : set.active_cells())
      {
        if constexpr (walks_whole_cells<Op>(0))
          op.whole_cell(c, n_in_cell, pt, ahead); // advances pt and ahead by n_in_cell
        else
          {
            op.begin_cell(c);
            for (unsigned int k = 0; k < n_in_cell; ++k, ++pt, ahead.next(Op::prefetch_location))
              op.point(c, pt);
            op.end_cell(c);
          }
      }
  }

  /// An op made of three callables (begin_cell(c), point(c, it), end_cell(c)),
  /// for the walks of features off the hot path (MPM-MIXED, contact, FEM,
  /// results): the walk stays this one; the feature keeps its arithmetic.
  template <class Begin, class Point, class End>
  struct CellOps
  {
    Begin                 begin;
    Point                 at_point;
    End                   end;
    static constexpr bool prefetch_location = false;
    inline void
    begin_cell(const unsigned int c)
    {
      begin(c);
    }
    template <class It>
    inline bool
    point(const unsigned int c, It &it)
    {
      at_point(c, it);
      return true;
    }
    inline void
    end_cell(const unsigned int c)
    {
      end(c);
    }
  };

  /// The walk with an op given as three callables.
  template <int dim, class Begin, class Point, class End>
  inline void
  for_each_active_cell(MaterialPointSet<dim> &set, Begin &&begin, Point &&point, End &&end)
  {
    CellOps<Begin &, Point &, End &> op{begin, point, end};
    for_each_active_cell(set, op);
  }

  /// The walk with only a per-point callable point(c, it) (c: the point's cell).
  template <int dim, class Point>
  inline void
  for_each_point(MaterialPointSet<dim> &set, Point &&point)
  {
    const auto nothing = [](const unsigned int) {};
    for_each_active_cell(set, nothing, point, nothing);
  }

  /// Two ops in one pass: `first` runs on every point; `second` only on those
  /// for which first.point returned true (e.g. the points that stayed in their
  /// cell after an update, which the fused P2G of the next step then adds).
  template <class First, class Second>
  struct Fused
  {
    Fused(First &first, Second &second)
        : first(first)
        , second(second)
    {
    }
    First                &first;
    Second               &second;
    static constexpr bool prefetch_location = First::prefetch_location || Second::prefetch_location;
    /// a first op that walks whole cells runs second on the points that stayed
    static constexpr bool whole_cells = walks_whole_cells<First>(0);
    template <class It, class Ahead>
    inline void
    whole_cell(const unsigned int c, const unsigned int n, It &it, Ahead &ahead)
    {
      first.whole_cell(c, n, it, ahead, second);
    }
    inline void
    begin_cell(const unsigned int c)
    {
      first.begin_cell(c);
      second.begin_cell(c);
    }
    template <class It>
    inline bool
    point(const unsigned int c, It &it)
    {
      if (first.point(c, it))
        {
          if constexpr (moves_points<First>(0))
            second.point_at(c, it, first.xi_new); // no read-back from storage
          else
            second.point(c, it);
          return true;
        }
      return false;
    }
    template <class Op>
    static constexpr auto
    moves_points(int) -> decltype(Op::moves_points, bool())
    {
      return Op::moves_points;
    }
    template <class Op>
    static constexpr bool
    moves_points(long)
    {
      return false;
    }
    inline void
    end_cell(const unsigned int c)
    {
      first.end_cell(c);
      second.end_cell(c);
    }
  };
  template <class First, class Second>
  Fused(First &, Second &) -> Fused<First, Second>;
} // namespace talus::transfer
