"""Mandel's problem with incompressible constituents (Skempton B = 1, undrained
Poisson ratio 1/2): the pore pressure of the series solution, written for
talus (issue 40; docs/semi-implicit.md 'Mandel's problem').

A rectangle -a < x < a squeezed by rigid frictionless plates with a total
force 2F per unit thickness (q = F / a), free and drained (p = 0) at x = +-a.
For a sudden load at t = 0 the excess pore pressure (compression positive) is

  p(x, t) = 2 p0 sum_n A_n (cos(alpha_n x / a) - cos(alpha_n)) exp(-alpha_n^2 T),
  A_n = sin(alpha_n) / (alpha_n - sin(alpha_n) cos(alpha_n)),  T = c t / a^2,

with alpha_n the positive roots of tan(alpha) = alpha (1 - nu) / (nu_u - nu),
p0 = q / 2 the undrained pressure (B (1 + nu_u) q / 3 with B = 1, nu_u = 1/2)
and c = k E_oed / (rho_w g). At T = 0 the series is 1/2 for |x| < a (the check
`initial_sum` below). A load ramped linearly over t_r is the superposition
(1 / t_r) integral_0^min(t, t_r) p_step(x, t - s) ds, term by term.
"""
import math


def roots(nu, nu_u=0.5, n=200):
    """The first n positive roots of sin(x) - k x cos(x) = 0, k = (1 - nu) / (nu_u - nu) > 1."""
    k = (1 - nu) / (nu_u - nu)
    f = lambda x: math.sin(x) - k * x * math.cos(x)
    out = []
    for m in range(n):
        # one root in (m pi, m pi + pi / 2) (for m = 0: in (0, pi / 2), as k > 1)
        lo, hi = m * math.pi + (1e-9 if m == 0 else 0.0), m * math.pi + math.pi / 2 - 1e-15
        flo = f(lo)
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            fm = f(mid)
            if (fm > 0) == (flo > 0):
                lo, flo = mid, fm
            else:
                hi = mid
        out.append(0.5 * (lo + hi))
    return out


class Mandel:
    def __init__(self, a, q, c, nu, ramp=0.0, n=200):
        self.a, self.q, self.c, self.ramp = a, q, c, ramp
        self.p0 = 0.5 * q
        self.alpha = roots(nu, n=n)
        self.A = [math.sin(al) / (al - math.sin(al) * math.cos(al)) for al in self.alpha]

    def initial_sum(self, x):
        return sum(A * (math.cos(al * x / self.a) - math.cos(al)) for A, al in zip(self.A, self.alpha))

    def pressure(self, x, t):
        """Excess pore pressure (compression positive) at x (0 <= x <= a), time t."""
        a, c = self.a, self.c
        s = 0.0
        for A, al in zip(self.A, self.alpha):
            lam = al * al * c / (a * a)
            if self.ramp > 0:
                tm = min(t, self.ramp)
                if lam * t > 700:
                    continue
                e = (math.exp(-lam * (t - tm)) - math.exp(-lam * t)) / (lam * self.ramp)
            else:
                e = math.exp(-lam * t)
            s += A * (math.cos(al * x / a) - math.cos(al)) * e
        return 2 * self.p0 * s


if __name__ == "__main__":
    m = Mandel(1.0, 1e3, 1.0, 0.0)
    print("initial sum at x = 0, 0.5, 0.9:", [round(m.initial_sum(x), 6) for x in (0, 0.5, 0.9)])
    best = max((m.pressure(0, T), T) for T in [i * 0.001 for i in range(1, 400)])
    print("peak p(0) / p0 (sudden, nu = 0): %.4f at T = %.3f" % (best[0] / m.p0, best[1]))
    for nu in (0.2, 0.3):
        mm = Mandel(1.0, 1e3, 1.0, nu)
        best = max((mm.pressure(0, T), T) for T in [i * 0.001 for i in range(1, 400)])
        print("peak (nu = %g): %.4f at T = %.3f" % (nu, best[0] / mm.p0, best[1]))
