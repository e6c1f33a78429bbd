#!/usr/bin/env python3
"""Independent reference solution: spring-mass nutation damper
(data of Roithmayr & Hodges).

Model (free system, no external loads):
  * Bus: rigid, mass 5274.4 kg, inertia about its own CM
    diag(1375.7, 1292.5, 1402.4) kg m^2, CM at the hub origin O.
  * Particle: mass 52.744 kg at r0 + rho z (hub frame), r0 = (1, 0, 0) m,
    i.e. it slides along the hub-fixed line through r0 parallel to hub z.
    Spring k = 52.744 N/m (relaxed at rho = 0), dashpot c = 105.49 N s/m.
    The spring/dashpot force acts on the particle along z, its reaction on
    the bus at the bus point r0 (same line of action).

Equations of motion: sympy.physics.mechanics.KanesMethod with generalised
speeds u = [w1, w2, w3 (hub body rates, hub axes),
            v1, v2, v3 (inertial velocity of bus CM, hub axes), rho'].
The bus therefore translates freely; initial v is chosen so that the total
linear momentum is zero.  Attitude is carried numerically as a unit quaternion.

Integration: scipy solve_ivp, DOP853, rtol = atol = 1e-12, segment by segment
between output times.

|H| (about the system CM), T (CM frame), momentum, CM position are computed by
hand-written numpy code independent of the sympy derivation.

Usage: python nutation_damper.py      Writes ../data/nutation_damper.csv (tests/data/).
"""
import os
import time

import numpy as np
import sympy as sp
import sympy.physics.mechanics as me
from scipy.integrate import solve_ivp

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.basename(__file__)

P = dict(m_bus=5274.4, I_bus=(1375.7, 1292.5, 1402.4), m_p=52.744,
         r0=(1.0, 0.0, 0.0), k=52.744, c=105.49)
OMEGA0 = np.array([0.1, 0.0, 1.0])
T_OUT = [0.0, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0]
RTOL = ATOL = 1e-12
NU = 7


def derive():
    t0 = time.time()
    mb, I1, I2, I3, mp, bx, by, bz, k, c = sp.symbols("m_b I_1 I_2 I_3 m_p b_x b_y b_z k c")
    consts = [mb, I1, I2, I3, mp, bx, by, bz, k, c]
    cvals = [P["m_bus"], *P["I_bus"], P["m_p"], *P["r0"], P["k"], P["c"]]
    w = me.dynamicsymbols("w1:4")
    v = me.dynamicsymbols("v1:4")
    rho, urho = me.dynamicsymbols("rho u_rho")

    N = me.ReferenceFrame("N")
    B = me.ReferenceFrame("B")
    B.set_ang_vel(N, w[0] * B.x + w[1] * B.y + w[2] * B.z)
    O = me.Point("O")
    O.set_vel(N, v[0] * B.x + v[1] * B.y + v[2] * B.z)
    A = O.locatenew("A", bx * B.x + by * B.y + bz * B.z)     # bus point on the damper line
    A.v2pt_theory(O, N, B)
    Pp = A.locatenew("P", rho * B.z)
    Pp.set_vel(B, urho * B.z)
    Pp.v1pt_theory(O, N, B)

    bus = me.RigidBody("bus", O, B, mb, (me.inertia(B, I1, I2, I3), O))
    part = me.Particle("particle", Pp, mp)
    Fs = (-k * rho - c * urho) * B.z
    loads = [(Pp, Fs), (A, -Fs)]
    u_ind = list(w) + list(v) + [urho]
    km = me.KanesMethod(N, q_ind=[rho], u_ind=u_ind, kd_eqs=[rho.diff() - urho])
    fr, _ = km.kanes_equations([bus, part], loads)
    fr_expect = [0] * 6 + [-k * rho - c * urho]
    for i in range(NU):
        assert sp.simplify(fr[i] - fr_expect[i]) == 0, (i, fr[i])

    qs = sp.symbols("q0:1")
    us = sp.symbols(f"u0:{NU}")
    sub = {rho: qs[0]}
    sub.update(dict(zip(u_ind, us)))
    sub.update(dict(zip(consts, cvals)))
    Mn = me.msubs(km.mass_matrix, sub)
    Fn = me.msubs(km.forcing, sub)
    free = Mn.free_symbols | Fn.free_symbols
    assert free <= set(qs) | set(us), free
    fM = sp.lambdify([qs], list(Mn), modules="math", cse=True)
    fF = sp.lambdify([qs, us], list(Fn), modules="math", cse=True)
    KE = bus.kinetic_energy(N) + part.kinetic_energy(N)
    fKE = sp.lambdify([qs, us], me.msubs(KE, sub), modules="math")
    print(f"[derive] KanesMethod done in {time.time() - t0:.1f} s", flush=True)
    return fM, fF, fKE


def quat_to_dcm(q):
    q = q / np.linalg.norm(q)
    w, x, y, z = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


def mechanics(rho, om, v, rhod):
    """H about system CM (hub axes), T in CM frame, P, r_cm, spring energy."""
    mb, mp = P["m_bus"], P["m_p"]
    Ib = np.diag(P["I_bus"])
    z = np.array([0.0, 0.0, 1.0])
    r = np.array(P["r0"]) + rho * z
    Vp = v + np.cross(om, r) + rhod * z
    Mtot = mb + mp
    Psum = mb * v + mp * Vp
    r_cm = mp * r / Mtot
    H = Ib @ om + mp * np.cross(r, Vp) - np.cross(r_cm, Psum)
    T = 0.5 * mb * v @ v + 0.5 * om @ Ib @ om + 0.5 * mp * Vp @ Vp
    return dict(H=H, T=T - Psum @ Psum / (2 * Mtot), T_abs=T, P=Psum, r_cm=r_cm,
                V=0.5 * P["k"] * rho ** 2)


def main():
    fM, fF, fKE = derive()
    iq, ir, irho, iu, ie = 0, 4, 7, 8, 8 + NU
    nstate = ie + 1
    c = P["c"]
    ncall = [0]

    def rhs(t, y):
        ncall[0] += 1
        q = y[iq:iq + 4]
        u = y[iu:iu + NU]
        qv = [y[irho]]
        M = np.array(fM(qv)).reshape(NU, NU)
        ud = np.linalg.solve(M, np.array(fF(qv, u)))
        w1, w2, w3 = u[0:3]
        q0, q1, q2, q3 = q
        dy = np.empty(nstate)
        dy[iq:iq + 4] = 0.5 * np.array([
            -q1 * w1 - q2 * w2 - q3 * w3,
            q0 * w1 + q2 * w3 - q3 * w2,
            q0 * w2 + q3 * w1 - q1 * w3,
            q0 * w3 + q1 * w2 - q2 * w1,
        ])
        dy[ir:ir + 3] = quat_to_dcm(q) @ u[3:6]
        dy[irho] = u[6]
        dy[iu:iu + NU] = ud
        dy[ie] = c * u[6] ** 2
        return dy

    Mtot = P["m_bus"] + P["m_p"]
    m0 = mechanics(0.0, OMEGA0, np.zeros(3), 0.0)
    v0 = -m0["P"] / Mtot
    u0 = np.concatenate([OMEGA0, v0, [0.0]])
    y0 = np.zeros(nstate)
    y0[iq] = 1.0
    y0[iu:iu + NU] = u0
    y0[ir:ir + 3] = -m0["r_cm"]     # inertial origin at the system CM

    def diag(y):
        u = y[iu:iu + NU]
        mm = mechanics(y[irho], u[0:3], u[3:6], u[6])
        C = quat_to_dcm(y[iq:iq + 4])
        mm["H_N"] = C @ mm["H"]
        mm["P_N"] = C @ mm["P"]
        mm["cm_N"] = y[ir:ir + 3] + C @ mm["r_cm"]
        mm["Ediss"] = y[ie]
        mm["nut"] = np.degrees(np.arccos(np.clip(mm["H"][2] / np.linalg.norm(mm["H"]), -1, 1)))
        mm["qnorm"] = np.linalg.norm(y[iq:iq + 4])
        return mm

    d0 = diag(y0)
    H0 = np.linalg.norm(d0["H"])
    E0 = d0["T"] + d0["V"]
    KE_sym = fKE([0.0], u0)
    print(f"initial |H| = {H0:.8f} N m s")
    print(f"initial T   = {d0['T']:.8f} J")
    print(f"initial nutation angle (hub z vs H) = {d0['nut']:.8f} deg")
    print(f"initial v_bus (hub axes) = {v0}  |P| = {np.linalg.norm(d0['P']):.3e}")
    print(f"check: sympy KE at t0 = {KE_sym:.12f}, numpy T_abs = {d0['T_abs']:.12f}, "
          f"rel diff {abs(KE_sym - d0['T_abs']) / d0['T_abs']:.2e}")

    rows = []
    mx = dict(dH=0.0, dE=0.0, P=0.0, cm=0.0, qn=0.0)

    def record(t, y):
        d = diag(y)
        dH = np.linalg.norm(d["H_N"] - d0["H_N"]) / H0
        dE = abs(d["T"] + d["V"] + d["Ediss"] - E0) / E0
        mx["dH"] = max(mx["dH"], dH)
        mx["dE"] = max(mx["dE"], dE)
        mx["P"] = max(mx["P"], np.linalg.norm(d["P_N"]))
        mx["cm"] = max(mx["cm"], np.linalg.norm(d["cm_N"]))
        mx["qn"] = max(mx["qn"], abs(d["qnorm"] - 1))
        w = y[iu:iu + 3]
        rows.append((t, w[0], w[1], w[2], np.linalg.norm(d["H"]), d["T"]))
        print(f"t={t:7.2f}  w=({w[0]: .12e},{w[1]: .12e},{w[2]: .12e})  |H|={np.linalg.norm(d['H']):.10f}"
              f"  T={d['T']:.10f}  rho={y[irho]: .3e}  Ed={d['Ediss']:.10f}  nut={d['nut']:8.5f} deg"
              f"  dH={dH:.2e} dE={dE:.2e}", flush=True)

    cpu0 = time.process_time()
    y = y0.copy()
    record(0.0, y)
    for ta, tb in zip(T_OUT[:-1], T_OUT[1:]):
        sol = solve_ivp(rhs, (ta, tb), y, method="DOP853", rtol=RTOL, atol=ATOL)
        if not sol.success:
            raise RuntimeError(sol.message)
        y = sol.y[:, -1]
        record(tb, y)
    cpu = time.process_time() - cpu0
    print(f"\nintegration: {cpu:.1f} s CPU, {ncall[0]} RHS calls")
    print(f"SELF-CHECK max |H_N(t) - H_N(0)| / |H0|         = {mx['dH']:.3e}  (limit 1e-9)")
    print(f"SELF-CHECK max |T+V+E_diss - (T0+V0)| / (T0+V0) = {mx['dE']:.3e}  (limit 1e-9)")
    print(f"           (V = spring energy k rho^2/2)")
    print(f"           max |P| = {mx['P']:.3e} kg m/s, max |r_cm| drift = {mx['cm']:.3e} m, "
          f"max ||q|-1| = {mx['qn']:.3e}")
    ok = mx["dH"] <= 1e-9 and mx["dE"] <= 1e-9
    print("SELF-CHECK", "PASSED" if ok else "FAILED")

    out = os.path.join(HERE, "..", "data", "nutation_damper.csv")
    with open(out, "w") as fh:
        fh.write("# Spring-mass nutation damper reference (Roithmayr & Hodges data): rigid bus (translating freely)\n")
        fh.write("#   + particle sliding on a bus-fixed line parallel to hub z with spring and dashpot;\n")
        fh.write("#   free system, no external forces/torques; total linear momentum zero.\n")
        fh.write(f"# Generated by {SCRIPT} (sympy.physics.mechanics KanesMethod, 7 generalised speeds:\n")
        fh.write("#   hub body rates, bus CM velocity in hub axes, rho'; attitude by quaternion).\n")
        fh.write(f"# Bus: m={P['m_bus']} kg, inertia about own CM diag{P['I_bus']} kg m^2, CM at hub origin.\n")
        fh.write(f"# Particle: m={P['m_p']} kg at r0 + rho z, r0={P['r0']} m; spring k={P['k']} N/m"
                 f" (relaxed at rho=0), dashpot c={P['c']} N s/m.\n")
        fh.write(f"# Initial: rho=0, rho'=0, hub rates w0=({OMEGA0[0]}, {OMEGA0[1]}, {OMEGA0[2]}) rad/s,"
                 " attitude identity, bus CM velocity set for zero total linear momentum.\n")
        fh.write(f"# Integrator: scipy solve_ivp DOP853, rtol={RTOL:g}, atol={ATOL:g}, integrated segment-wise"
                 " between output times.\n")
        fh.write(f"# Initial |H| = {H0:.8f} N m s, T = {d0['T']:.8f} J, nutation = {d0['nut']:.8f} deg.\n")
        fh.write(f"# Self-check: max rel drift of inertial H vector = {mx['dH']:.2e};"
                 f" of T + V_spring + E_dissipated = {mx['dE']:.2e}.\n")
        fh.write("# Columns: t [s]; omega_x,omega_y,omega_z = hub angular velocity in hub body axes [rad/s];\n")
        fh.write("#   h_norm = |H| about system CM [N m s]; kinetic_energy = T in CM frame [J].\n")
        fh.write("t,omega_x,omega_y,omega_z,h_norm,kinetic_energy\n")
        for r in rows:
            fh.write(f"{r[0]:g}," + ",".join(f"{x:.15e}" for x in r[1:]) + "\n")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
