"""Dynamic mixed u-p in talus-implicit (issue 13): inertia on the displacement
rows of the u-p system, Newmark gamma = 1/2, beta = 1/4 (the bar's axial period with
u-p: verification.implicit_bar_vibration_up, check_implicit_bar.py).

Free bending vibration of the thesis's cantilever (cantilever_vibration.prm:
   8 m x 1 m, clamped, released with v0 (x/L)^2, no gravity, h = 0.25 m), period T
   from the zero crossings of y_c(t) - y_c(0), against the first period of a
   clamped-free Timoshenko beam in plane strain (kappa = 5/6; computed here), four runs:
   * u and u-p at nu = 0.3 each within 1.5 % (h = 0.25 m: -0.8 % / +0.8 %;
     h = 0.125 m: -0.4 % / +0.02 %);
   * u-p at nu = 0.4999 within 1.5 %, and its period ratio nu = 0.4999 / 0.3 within
     1 % of Timoshenko's (0.912);
   * u at nu = 0.4999 locks: its period is below half of Timoshenko's.
Usage: check_implicit_up_dynamic.py TOOLS_DIR CANTILEVER_PRM WORKDIR
"""
import math
import sys

import talus_verify as tv

tools, cant_prm, work = sys.argv[1:4]


def run(name, settings):
    text = tv.prm_set(open(cant_prm).read(), "output/directory", "out")
    for k, v in settings.items():
        text = tv.prm_set(text, k, v)
    _, out, _ = tv.run_tool(f"{tools}/talus-implicit", text, f"{work}/{name}", name)
    print(f"{name}: {out.strip().splitlines()[-2].strip()}")
    s = tv.read_csv(f"{work}/{name}/out/series.csv")
    steps = [i for i in range(len(s["time"])) if s["step"][i] > 0]
    print(f"  Newton iterations per step: max {max(s['newton_iterations'][i] for i in steps):.0f}")
    return s


# the cantilever, u and u-p at nu = 0.3 and 0.4999
def timoshenko_period(nu, E=9e7, rho=1000.0, H=1.0, L=8.0, kappa=5.0 / 6.0):
    """First bending period of a clamped-free Timoshenko beam (plane strain: E' = E / (1 - nu^2),
    G = E / (2 (1 + nu)), shear factor kappa, rotary inertia included), per unit width: the
    first root w of the 4 x 4 determinant of the clamped (w = phi = 0) and free (phi' = 0,
    w' - phi = 0) conditions on w = C1 cosh(a x) + C2 sinh(a x) + C3 cos(b x) + C4 sin(b x)."""
    Ep, G, I, A = E / (1 - nu * nu), E / (2 * (1 + nu)), H ** 3 / 12, H
    kGA, EI = kappa * G * A, Ep * I

    def det(w):
        a4, a2, a0 = kGA * EI, (kGA * rho * I + rho * A * EI) * w * w, rho * A * w * w * (rho * I * w * w - kGA)
        disc = math.sqrt(a2 * a2 - 4 * a4 * a0)
        a, b = math.sqrt((-a2 + disc) / (2 * a4)), math.sqrt((a2 + disc) / (2 * a4))
        p, q = (kGA * a * a + rho * A * w * w) / (kGA * a), (rho * A * w * w - kGA * b * b) / (kGA * b)
        ch, sh, c, s = math.cosh(a * L), math.sinh(a * L), math.cos(b * L), math.sin(b * L)
        M = [[1.0, 0.0, 1.0, 0.0], [0.0, p, 0.0, -q], [p * a * ch, p * a * sh, q * b * c, q * b * s],
             [(a - p) * sh, (a - p) * ch, -(b + q) * s, (b + q) * c]]
        d = 1.0
        for i in range(4):  # Gaussian elimination with partial pivoting
            k = max(range(i, 4), key=lambda r: abs(M[r][i]))
            if k != i:
                M[i], M[k], d = M[k], M[i], -d
            d *= M[i][i]
            for r in range(i + 1, 4):
                f = M[r][i] / M[i][i]
                for col in range(i, 4):
                    M[r][col] -= f * M[i][col]
        return d

    w_eb = 1.875104 ** 2 * math.sqrt(EI / (rho * A * L ** 4))  # Euler-Bernoulli, an upper bound
    ws = [w_eb * (0.5 + 0.001 * i) for i in range(501)]
    for lo, hi in zip(ws, ws[1:]):
        if det(lo) * det(hi) < 0:
            for _ in range(100):
                mid = 0.5 * (lo + hi)
                lo, hi = (lo, mid) if det(lo) * det(mid) <= 0 else (mid, hi)
            return 2 * math.pi / (0.5 * (lo + hi)), 2 * math.pi / w_eb
    tv.fail("no Timoshenko root found")


def bending_period(name, formulation, nu):
    # both formulations with the split Neo-Hookean (the one u-p accepts), so that they solve the same model
    s = run(name, {"implicit/formulation": formulation, "material 0/neo hookean/poisson ratio": str(nu),
                   "material 0/neo hookean/volumetric energy": "split"})
    t, y = s["time"], [v - s["centre_of_mass_y"][0] for v in s["centre_of_mass_y"]]
    tv.check(abs(t[-1] - 4.0) < 1e-9, f"{name}: the run reached its end time")
    periods = tv.crossing_periods(t[2:], y[2:])
    if len(periods) < 2:
        tv.fail(f"{name}: fewer than 2 periods between zero crossings")
    Tm = sum(periods) / len(periods)
    T_ref, T_eb = timoshenko_period(nu)
    print(f"  {name}: period {Tm:.4f} s ({len(periods)} periods); Timoshenko {T_ref:.4f} s ({Tm / T_ref - 1:+.2%}), "
          f"Euler-Bernoulli {T_eb:.4f} s")
    return Tm, T_ref


Tu3, ref3 = bending_period("cantilever_u_0.3", "irreducible", 0.3)
Tp3, _ = bending_period("cantilever_up_0.3", "mixed up", 0.3)
Tp5, ref5 = bending_period("cantilever_up_0.4999", "mixed up", 0.4999)
Tu5, _ = bending_period("cantilever_u_0.4999", "irreducible", 0.4999)
tv.check(abs(Tu3 / ref3 - 1) < 0.015, f"nu = 0.3: u within 1.5 % of Timoshenko ({Tu3 / ref3 - 1:+.2%})")
tv.check(abs(Tp3 / ref3 - 1) < 0.015, f"nu = 0.3: u-p within 1.5 % of Timoshenko ({Tp3 / ref3 - 1:+.2%})")
tv.check(abs(Tp5 / ref5 - 1) < 0.015, f"nu = 0.4999: u-p within 1.5 % of Timoshenko ({Tp5 / ref5 - 1:+.2%})")
ratio, ratio_ref = Tp5 / Tp3, ref5 / ref3
tv.check(abs(ratio / ratio_ref - 1) < 0.01,
         f"u-p period ratio nu 0.4999 / 0.3 = {ratio:.4f} within 1 % of Timoshenko's {ratio_ref:.4f}")
tv.check(Tu5 < 0.5 * ref5, f"nu = 0.4999: u locks (period {Tu5:.4f} s < half of Timoshenko's {ref5:.4f} s)")
tv.finish()
