// talus — two doubles as one value (GCC/Clang vector extension): the packed
// SSE2 arithmetic of baseline x86-64, for the B-spline kernel's hot loops
// (shape/bspline2_box.h), whose per-node data are 4 doubles (a field's
// components, padded; mass and force) handled as two pairs.
//
// Each lane computes exactly what the scalar expression would (same products,
// same order of every sum; no FMA on baseline x86-64), so a loop rewritten on
// pairs gives bitwise the results of its scalar form.
#pragma once

namespace talus::shape
{
  /// a pair of doubles (operators +, -, * lane by lane; a double operand is
  /// used in both lanes)
  typedef double Pair __attribute__((vector_size(16)));
  /// the same for loads and stores through a double * (16-byte aligned data)
  typedef double AlignedPair __attribute__((vector_size(16), may_alias));

  /// the pair at p (aligned: p 16-byte aligned)
  inline Pair
  load_aligned(const double *p)
  {
    return *reinterpret_cast<const AlignedPair *>(p);
  }
  inline void
  store_aligned(double *p, const Pair v)
  {
    *reinterpret_cast<AlignedPair *>(p) = v;
  }
  /// the pair at p (any alignment of 8)
  inline Pair
  load_unaligned(const double *p)
  {
    Pair v;
    __builtin_memcpy(&v, p, sizeof(v));
    return v;
  }
  inline void
  store_unaligned(double *p, const Pair v)
  {
    __builtin_memcpy(p, &v, sizeof(v));
  }
  inline Pair
  broadcast(const double x)
  {
    return Pair{x, x};
  }
} // namespace talus::shape
