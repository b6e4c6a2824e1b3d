"""The former refusals of the 2-phase step (issue 12 item 2): each shared load
entry now runs with coupled 2-phase materials and does what it means there.
(Mass scaling below 1, the one entry still refused, is in check_bad_input_two_phase.py;
stages, convergence, loads/traction, local damping and mass scaling >= 1 together
in check_two_phase_staged.py.)
Scene: the hydrostatic 2-phase column (hydrostatic_2phase.prm, H = 1 m, E = 10 MPa,
n = 0.3, k = 1e-2 m/s) unless stated.
  * K0 (body 0/initial stress, K0 = nu/(1 - nu) = 3/7 with nu = 0.3): effective
    stress from the buoyant weight and hydrostatic pore pressure at setup are the
    discrete equilibrium: after 0.05 s undamped, every point moved less than
    1e-3 of the stress-free settlement gamma' H^2 / (2 E_oed), p within 1e-3 of
    rho_L g H of rho_L g (H - Y), sigma'_xx / sigma'_yy = K0 within 1e-6;
  * loads/velocity on a body (no gravity, v = 0.01 m/s up, base free): solid and liquid
    point velocities equal v to 1e-12, displacement v t to 1e-9 relative;
  * loads/velocity on the base nodes (boundary 2, y, 1 mm/s up; no gravity,
    local damping 0.5, sides on rollers): after 0.8 s the column moves with the
    base, mean solid and liquid point velocities within 1 % of 1 mm/s;
  * damping/viscous damping 20 1/s (no local damping): the column settles,
    final kinetic energy < 1e-3 of its peak, pore pressure hydrostatic within 2 %;
  * alias: 'damping/local damping = 0.1' gives the same particles as the
    scene's 'two phase/local damping = 0.1' (identical files);
  * alias: a 'loads/traction' on the top face gives the same particles as
    'body 0/traction face' (Terzaghi scene, 0.01 s, identical files);
  * boundary conditions/friction (block_friction.prm, gravity tilted 30 deg,
    mu = 0.3, the block made a saturated coupled soil): it stays on the floor
    (neither phase enters the impermeable wall: the block's lowest point sinks
    less than 1e-4 m, the centre rises less than 5e-4 m) and slides with a mean
    acceleration between the dry-friction value g (sin - mu cos) and the
    frictionless g sin (the pore pressure at the base lowers the effective normal
    stress that friction acts on).
Usage: check_two_phase_loads.py TOOL HYDROSTATIC_PRM TERZAGHI_PRM BLOCK_PRM WORKDIR
"""
import filecmp
import math
import sys

import talus_verify as tv

tool, hyd_prm, terz_prm, block_prm, work = sys.argv[1:6]
E, nu, n, rho_S, rho_L, g, H = 1e7, 0.3, 0.3, 2650.0, 1000.0, 9.81, 1.0
E_oed = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
gamma_b = (1 - n) * (rho_S - rho_L) * g
hyd = open(hyd_prm).read()


def run(text, name):
    text = tv.prm_set(text, "output/directory", name)
    tv.run_tool(tool, text, work, name)
    return tv.read_csv(f"{work}/{name}/particles_final.csv")


# ---- K0
K0 = nu / (1 - nu)
t = tv.prm_set(hyd, "material 0/linear elastic/poisson ratio", str(nu))
t = tv.prm_set(t, "two phase/local damping", "0")
t = tv.prm_set(t, "time/end time", "0.05")
t = tv.prm_set(t, "body 0/initial stress/K0 procedure", "true")
t = tv.prm_set(t, "body 0/initial stress/K0", f"{K0:.15g}")
p = run(t, "k0")
u_ref = gamma_b * H * H / (2 * E_oed)
umax = max(math.hypot(a, b) for a, b in zip(p["u_x"], p["u_y"]))
Y = [y - u for y, u in zip(p["pos_y"], p["u_y"])]
perr = max(abs(pp - rho_L * g * (H - yy)) for pp, yy in zip(p["pore_pressure"], Y)) / (rho_L * g * H)
kerr = max(abs(sx / sy - K0) for sx, sy in zip(p["stress_xx"], p["stress_yy"]))
tv.check(umax < 1e-3 * u_ref, f"K0: largest displacement {umax:.3e} m < 1e-3 x {u_ref:.3e} m")
tv.check(perr < 1e-3, f"K0: pore pressure hydrostatic within {perr:.2e} of rho_L g H (< 1e-3)")
tv.check(kerr < 1e-6, f"K0: sigma'_xx / sigma'_yy - K0 = {kerr:.2e} (< 1e-6)")

# ---- prescribed velocity of a body (both phases)
v = 0.01
t = tv.prm_set(hyd, "gravity/acceleration", "0, 0")
t = tv.prm_set(t, "boundary conditions/roller", "0, 1")  # the base must not hold the grid back
t = tv.prm_set(t, "time/end time", "0.01")
t = tv.prm_set(t, "loads/number of velocity conditions", "1")
t = tv.prm_set(t, "loads/velocity 0/apply to", "body")
t = tv.prm_set(t, "loads/velocity 0/velocity", f"0, {v}")
p = run(t, "velocity_body")
ev = max(max(abs(a - v) for a in p["v_y"]), max(abs(a - v) for a in p["liquid_velocity_y"])) / v
eu = max(abs(a - v * 0.01) for a in p["u_y"]) / (v * 0.01)
tv.check(ev < 1e-12 and eu < 1e-9, f"body velocity: solid and liquid velocities {ev:.1e}, displacement {eu:.1e} "
                                  f"relative off v, v t")

# ---- prescribed velocity of the base nodes (both phases)
v = 1e-3
t = tv.prm_set(hyd, "gravity/acceleration", "0, 0")
t = tv.prm_set(t, "boundary conditions/roller", "0, 1")
t = tv.prm_set(t, "two phase/local damping", "0.5")
t = tv.prm_set(t, "time/end time", "0.8")
t = tv.prm_set(t, "loads/number of velocity conditions", "1")
t = tv.prm_set(t, "loads/velocity 0/apply to", "boundary")
t = tv.prm_set(t, "loads/velocity 0/boundary id", "2")
t = tv.prm_set(t, "loads/velocity 0/components", "y")
t = tv.prm_set(t, "loads/velocity 0/velocity", f"0, {v}")
p = run(t, "velocity_base")
ms = sum(p["v_y"]) / len(p["v_y"]) / v
ml = sum(p["liquid_velocity_y"]) / len(p["v_y"]) / v
tv.check(abs(ms - 1) < 0.01 and abs(ml - 1) < 0.01,
         f"base velocity: mean solid / liquid velocity {ms:.4f} / {ml:.4f} of the prescribed 1 mm/s (1 %)")

# ---- viscous damping
t = tv.prm_set(hyd, "two phase/local damping", "0")
t = tv.prm_set(t, "damping/viscous damping", "20")
p = run(t, "viscous")
s = tv.read_csv(f"{work}/viscous/series.csv")
ke = s["kinetic_energy"]
Y = [y - u for y, u in zip(p["pos_y"], p["u_y"])]
perr = max(abs(pp - rho_L * g * (H - yy)) for pp, yy in zip(p["pore_pressure"], Y)) / (rho_L * g * H)
tv.check(ke[-1] < 1e-3 * max(ke), f"viscous damping: final kinetic energy {ke[-1]:.2e} J < 1e-3 x peak {max(ke):.2e} J")
tv.check(perr < 0.02, f"viscous damping: pore pressure hydrostatic within {100 * perr:.2f} % (< 2 %)")

# ---- aliases give the same run
run(hyd, "alias_two_phase_damping")
t = tv.prm_set(hyd, "two phase/local damping", "0")
t = tv.prm_set(t, "damping/local damping", "0.1")
run(t, "shared_local_damping")
same = filecmp.cmp(f"{work}/alias_two_phase_damping/particles_final.csv",
                   f"{work}/shared_local_damping/particles_final.csv", shallow=False)
tv.check(same, "'two phase/local damping' and 'damping/local damping' give identical particles")
terz = tv.prm_set(open(terz_prm).read(), "time/end time", "0.01")
run(terz, "alias_traction_face")
t = tv.prm_set(terz, "body 0/traction face", "none")
t = tv.prm_set(t, "loads/number of tractions", "1")
t = tv.prm_set(t, "loads/traction 0/face", "y+")
t = tv.prm_set(t, "loads/traction 0/traction", "0, -10000")
run(t, "shared_traction")
same = filecmp.cmp(f"{work}/alias_traction_face/particles_final.csv", f"{work}/shared_traction/particles_final.csv",
                   shallow=False)
tv.check(same, "'body 0/traction face' and 'loads/traction 0' give identical particles")

# ---- rigid-wall friction with a saturated block
th, mu, T = math.radians(30.0), 0.3, 0.3
t = tv.prm_set(open(block_prm).read(), "time/end time", str(T))
t = tv.prm_set(t, "time/courant number", "0.9")
t = tv.prm_set(t, "material 0/density", str(rho_S))
for k, val in (("drainage", "coupled"), ("porosity", "0.3"), ("hydraulic conductivity", "1e-3")):
    t = tv.prm_set(t, f"material 0/pore liquid/{k}", val)
t = tv.prm_set(t, "output/final particles csv", "true")
p = run(t, "friction")
s = tv.read_csv(f"{work}/friction/series.csv")
ux, uy = s["probe0_ux"], s["probe0_uy"]
a_mean = 2 * ux[-1] / s["time"][-1] ** 2
lo, hi = g * (math.sin(th) - mu * math.cos(th)), g * math.sin(th)
sink = -min(p["u_y"])
print(f"friction: mean acceleration {a_mean:.4f} m/s^2 (dry friction {lo:.4f}, frictionless {hi:.4f}); "
      f"lowest displacement into the floor {sink:.2e} m, largest rise of the probe {max(uy):.2e} m")
tv.check(lo * 0.98 < a_mean < hi, f"friction: {lo:.3f} * 0.98 < mean acceleration {a_mean:.3f} < {hi:.3f} m/s^2")
tv.check(sink < 1e-4 and max(uy) < 5e-4, f"friction: stays on the floor (sinks {sink:.2e} m, rises {max(uy):.2e} m)")
tv.finish()
