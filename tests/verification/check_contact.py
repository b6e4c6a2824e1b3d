"""Contact between bodies (seed 000 §6.2) — issue 5 verification.

1. Block sliding on a stiff lower body under gravity tilted by theta (grid
   aligned with the slope). Coulomb friction: the block centre moves by
   u(t) = 1/2 g (sin theta - mu cos theta) t^2 when tan theta > mu (checked within
   2 % for t >= 0.1 s, theta = 30 deg, mu = 0.3 and mu = 0) and stays at rest when
   tan theta < mu (theta = 10 deg, mu = 0.3: |u| < 1 % of the frictionless
   displacement). Adhesion a (mu = 0): u(t) = 1/2 (g sin theta - a B / m) t^2 within
   3 % for t >= 0.2 s (a = 400 Pa) and at rest when a B > m g sin theta (a = 3000 Pa).
2. Two elastic disks colliding (Sulsky), frictionless contact: no interpenetration
   (the points of each disk stay on their side of the symmetry line x + y = 1 at
   every sampled time), momentum conserved to round-off, the disks separate
   (velocities reversed, gap > 2 cells at the end), 1 and 2 ranks agree to 1e-10.
With a last argument `f-bar`, every run also sets numerics/volumetric stabilisation = f-bar
(each body maps and remaps its own dJ, docs/explicit.md "F-bar with contact"); with `cell` or
`nodal`, numerics/strain smoothing (each body's cell values from its own velocities, "Strain
smoothing with contact"): the same checks.
Usage: check_contact.py TOOL SLIDING_PRM DISKS_PRM WORKDIR [f-bar|cell|nodal]
"""
import math
import sys

import talus_verify as tv

tool, sliding_prm, disks_prm, work = sys.argv[1:5]
DEVICE = sys.argv[5] if len(sys.argv) > 5 else "none"
if DEVICE not in ("none", "f-bar", "cell", "nodal"):
    sys.exit(f"check_contact.py: unknown device '{DEVICE}' (none, f-bar, cell, nodal)")


def scene(path):
    text = open(path).read()
    if DEVICE == "f-bar":
        return tv.prm_set(text, "numerics/volumetric stabilisation", "f-bar")
    if DEVICE in ("cell", "nodal"):
        return tv.prm_set(text, "numerics/strain smoothing", DEVICE)
    return text

g = 9.81
B, m_block = 0.2, 2000 * 0.2 * 0.1  # block width [m], mass per unit thickness [kg/m]


def sliding(theta_deg, mu, adhesion, name):
    th = math.radians(theta_deg)
    text = scene(sliding_prm)
    text = tv.prm_set(text, "gravity/acceleration", f"{g * math.sin(th)!r}, {-g * math.cos(th)!r}")
    text = tv.prm_set(text, "contact/pairs", f"0, 1, {mu}, {adhesion}")
    text = tv.prm_set(text, "output/directory", name)
    tv.run_tool(tool, text, work, name)
    s = tv.read_csv(f"{work}/{name}/series.csv")
    acc = g * math.sin(th) - mu * g * math.cos(th) - adhesion * B / m_block
    return s["time"], s["probe0_ux"], 0.5 * max(acc, 0.0), 0.5 * g * math.sin(th)


for theta, mu, adh, t_min, tol in [(30, 0.3, 0, 0.1, 0.02), (30, 0.0, 0, 0.1, 0.02), (30, 0.0, 400, 0.2, 0.03)]:
    t, u, c, _ = sliding(theta, mu, adh, f"slide_{theta}_{mu}_{adh}")
    err = max(abs(x - c * tt * tt) / (c * tt * tt) for tt, x in zip(t, u) if tt >= t_min)
    tv.check(err < tol, f"theta {theta} deg, mu {mu}, adhesion {adh} Pa: u(t) within {tol:.0%} of "
                        f"{c:.4f} t^2 for t >= {t_min} s (max error {err:.2e}; u({t[-1]:.2f} s) = {u[-1]:.5f} m)")
for theta, mu, adh in [(10, 0.3, 0), (30, 0.0, 3000)]:
    t, u, c, free = sliding(theta, mu, adh, f"stick_{theta}_{mu}_{adh}")
    umax = max(abs(x) for x in u)
    tv.check(c == 0 and umax < 0.01 * free * t[-1] ** 2,
             f"theta {theta} deg, mu {mu}, adhesion {adh} Pa: at rest (max |u| {umax:.2e} m, "
             f"frictionless {free * t[-1] ** 2:.3f} m)")

# ---------------------------------------------------------------- disks
base = tv.prm_set(scene(disks_prm), "contact/pairs", "0, 1, 0, 0")
scale = 2 * 1000 * math.pi * 0.2 ** 2 * 0.1 * math.sqrt(2)
gaps = []
for T in [1.0, 1.25, 1.5, 1.75, 2.0, 3.0]:
    name = f"disks_{T}"
    text = tv.prm_set(tv.prm_set(base, "time/end time", str(T)), "output/directory", name)
    tv.run_tool(tool, text, work, name)
    a = tv.read_csv(f"{work}/{name}/particles_final.csv")
    A, Bd = [], []
    for i in range(len(a["id"])):
        X0 = a["pos_x"][i] - a["u_x"][i] + a["pos_y"][i] - a["u_y"][i]
        s = (a["pos_x"][i] + a["pos_y"][i]) / math.sqrt(2)
        (A if X0 < 1 else Bd).append((s, (a["v_x"][i] + a["v_y"][i]) / math.sqrt(2)))
    gap = min(x for x, _ in Bd) - max(x for x, _ in A)
    vA = sum(v for _, v in A) / len(A)
    vB = sum(v for _, v in Bd) / len(Bd)
    gaps.append(gap)
    print(f"  t = {T}: gap between the disks along the line of centres {gap:.4f} m, "
          f"approach speeds {vA:+.4f} / {vB:+.4f} m/s")
tv.check(min(gaps) > 0, f"no interpenetration: smallest gap {min(gaps):.4f} m (> 0)")
tv.check(vA < -0.1 and vB > 0.1 and gaps[-1] > 0.05,
         f"disks separate: final velocities {vA:+.4f} / {vB:+.4f} m/s along the line of centres, gap {gaps[-1]:.3f} m")
s = tv.read_csv(f"{work}/disks_3.0/series.csv")
pmax = max(math.hypot(px, py) for px, py in zip(s["momentum_x"], s["momentum_y"]))
tv.check(pmax <= 1e-12 * scale, f"momentum conserved to round-off (max |p| = {pmax:.2e}, scale {scale:.2e})")
e = [k + w for k, w in zip(s["kinetic_energy"], s["strain_energy"])]
print(f"  energy (kinetic + strain): initial {e[0]:.4f} J, max {max(e):.4f} J, final {e[-1]:.4f} J")

text = tv.prm_set(tv.prm_set(base, "time/end time", "3.0"), "output/directory", "disks_np2")
tv.run_tool(tool, text, work, "disks_np2", np=2)
a = tv.read_csv(f"{work}/disks_3.0/particles_final.csv")
b = tv.read_csv(f"{work}/disks_np2/particles_final.csv")
worst = max(tv.relative_differences(a, b).values())
tv.check(a["id"] == b["id"] and worst <= 1e-10, f"contact on 1 and 2 ranks agrees to 1e-10 relative (worst {worst:.2e})")
tv.finish()
