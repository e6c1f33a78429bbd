#!/usr/bin/env python3
"""Independent reference solution: the linearised spinning stage with two slosh pendulums
(scenarios/spinning-stage-slosh.yaml), its eigenvalues and its nutation time constant.

Model (free system, no external loads):
  * Hub: rigid, mass M, inertia about its own CM diag(A, A, C) in hub axes, CM at the hub
    origin.  The hub translates freely: its CM is placed at -(sum m_i r_i)/M_tot from the
    system CM O, which is fixed in N (zero total linear momentum), so no translational
    speeds are needed.
  * Two spherical pendulums: point mass m_i on a massless rod of length l_i from a hub-fixed
    pivot d_i, bob at r_i = d_i + l_i (cos phi cos theta p1 + sin phi cos theta p2
    - sin theta p3), p1 = rest direction, p3 = pole, p2 = p3 x p1 (hub axes).
  * Dashpot: force -c v_rel on the bob (v_rel = d r_i/dt in the hub frame) and +c v_rel on
    the hub point coincident with the bob.

Equations of motion: sympy.physics.mechanics.KanesMethod, q = [phi_a, theta_a, phi_b,
theta_b], u = [w1, w2, w3 (hub body rates, hub axes), phi_a', theta_a', phi_b', theta_b'].
The attitude does not enter (no external loads) and is left out.

Linearisation: about the steady spin w = (0, 0, Omega), q = 0, u_pendulums = 0 (the rods
radially outward).  M(q) u' = F(q, u) with F = 0 at the equilibrium (checked), so
A = [[0, dq'/du], [M^-1 dF/dq, M^-1 dF/du]] with the Jacobians taken symbolically, then
evaluated with the scenario's numbers; eigenvalues by numpy.  The nutation pair is the one
nearest the rigid body's nutation frequency in body axes.

Self-checks:
  * equilibrium residual |F| = 0 at the operating point;
  * undamped (c = 0): every eigenvalue but the spin's zero is purely imaginary and nonzero
    (|Re| <= 1e-10 |lambda|);
  * rigid limit (pendulum speeds and angles held at zero, i.e. the w rows and columns of
    Kane's equations): the nonzero eigenvalues are +-i Omega sqrt((A1-C)(A2-C)/(A1 A2)) of
    the composite inertia about the system CM (computed here by hand with the parallel axis
    theorem; A1 = A2 = A_total gives Omega (C_total - A_total)/A_total), to 1e-12 relative;
  * the pendulums on a 1e11 kg, 1e11 kg m^2 hub (the spin held constant) have the roots of
    s^2 + (c/m) s + Omega^2 b/l and Omega^2 (b + l)/l (b = pivot's distance from the spin
    axis), to 1e-8 relative.

Usage: python slosh_stage_linear.py      Writes ../data/slosh_stage_linear.json (tests/data/).
"""
import json
import os
import time

import numpy as np
import sympy as sp
import sympy.physics.mechanics as me

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.basename(__file__)

# scenarios/spinning-stage-slosh.yaml (copied by hand: body, effectors, initial spin about z).
P = dict(
    M=800.0, A=900.0, C=250.0, spin=5.0,
    tanks=[
        dict(name="tank_a", m=25.0, l=0.3, pivot=(0.45, 0.0, 0.2), rest=(1.0, 0.0, 0.0),
             pole=(0.0, 1.0, 0.0), c=100.0),
        dict(name="tank_b", m=25.0, l=0.3, pivot=(-0.45, 0.0, 0.2), rest=(-1.0, 0.0, 0.0),
             pole=(0.0, 1.0, 0.0), c=100.0),
    ],
)
NQ, NU = 4, 7
UNDAMPED_TOL = 1e-10
RIGID_TOL = 1e-12
CLOSED_FORM_TOL = 1e-8


def derive():
    """Kane's equations and their Jacobians at the steady spin, all symbolic."""
    t0 = time.time()
    M, A, C, Om = sp.symbols("M A C Omega")
    m = sp.symbols("m_a m_b")
    l = sp.symbols("l_a l_b")
    c = sp.symbols("c_a c_b")
    d = [sp.symbols(f"d{k}_1:4") for k in "ab"]
    p1 = [sp.symbols(f"p1{k}_1:4") for k in "ab"]
    p3 = [sp.symbols(f"p3{k}_1:4") for k in "ab"]
    q = me.dynamicsymbols("phi_a theta_a phi_b theta_b")
    w = me.dynamicsymbols("w1:4")
    up = me.dynamicsymbols("u_phi_a u_theta_a u_phi_b u_theta_b")

    N = me.ReferenceFrame("N")
    B = me.ReferenceFrame("B")
    B.set_ang_vel(N, w[0] * B.x + w[1] * B.y + w[2] * B.z)
    O = me.Point("O")                       # system CM, fixed in N
    O.set_vel(N, 0)

    def vec(xyz):
        return xyz[0] * B.x + xyz[1] * B.y + xyz[2] * B.z

    r = []
    for i in range(2):
        e1, e3 = vec(p1[i]), vec(p3[i])
        e2 = e3.cross(e1)
        phi, th = q[2 * i], q[2 * i + 1]
        e = sp.cos(phi) * sp.cos(th) * e1 + sp.sin(phi) * sp.cos(th) * e2 - sp.sin(th) * e3
        r.append(vec(d[i]) + l[i] * e)     # bob from the hub CM, hub axes
    Mt = M + m[0] + m[1]
    s = -(m[0] * r[0] + m[1] * r[1]) / Mt   # hub CM from the system CM
    H = O.locatenew("H", s)
    H.set_vel(N, s.dt(N))
    bodies = [me.RigidBody("hub", H, B, M, (me.inertia(B, A, A, C), H))]
    loads = []
    for i, k in enumerate("ab"):
        bob = O.locatenew(f"P{k}", s + r[i])
        bob.set_vel(N, (s + r[i]).dt(N))
        hubpt = H.locatenew(f"Q{k}", r[i])  # hub point coincident with the bob
        hubpt.v2pt_theory(H, N, B)
        vrel = r[i].dt(B)
        bodies.append(me.Particle(f"bob_{k}", bob, m[i]))
        loads += [(bob, -c[i] * vrel), (hubpt, c[i] * vrel)]

    u = list(w) + list(up)
    km = me.KanesMethod(N, q_ind=q, u_ind=u, kd_eqs=[qi.diff() - ui for qi, ui in zip(q, up)])
    km.kanes_equations(bodies, loads)
    Mm, F = km.mass_matrix, km.forcing

    qs = sp.symbols(f"q0:{NQ}")
    us = sp.symbols(f"u0:{NU}")
    plain = dict(zip(q, qs)) | dict(zip(u, us))
    Mm = me.msubs(Mm, plain)
    F = me.msubs(F, plain)
    op = {x: 0 for x in qs} | {x: 0 for x in us} | {us[2]: Om}
    M0 = Mm.subs(op)
    F0 = F.subs(op)
    Fq = F.jacobian(qs).subs(op)
    Fu = F.jacobian(us).subs(op)
    consts = [M, A, C, Om, *m, *l, *c, *d[0], *d[1], *p1[0], *p1[1], *p3[0], *p3[1]]
    fns = {name: sp.lambdify([consts], e, modules="numpy", cse=True)
           for name, e in dict(M0=M0, F0=F0, Fq=Fq, Fu=Fu).items()}
    print(f"[derive] KanesMethod and Jacobians in {time.time() - t0:.1f} s", flush=True)
    return fns


def values(p):
    t = p["tanks"]
    return [p["M"], p["A"], p["C"], p["spin"], t[0]["m"], t[1]["m"], t[0]["l"], t[1]["l"],
            t[0]["c"], t[1]["c"], *t[0]["pivot"], *t[1]["pivot"], *t[0]["rest"],
            *t[1]["rest"], *t[0]["pole"], *t[1]["pole"]]


def state_matrix(fns, p):
    """The 11 x 11 state matrix in x = [q (4), u (7)], and the equilibrium residual."""
    v = values(p)
    M0 = np.array(fns["M0"](v), dtype=float)
    F0 = np.array(fns["F0"](v), dtype=float).ravel()
    Fq = np.array(fns["Fq"](v), dtype=float)
    Fu = np.array(fns["Fu"](v), dtype=float)
    n = NQ + NU
    Amat = np.zeros((n, n))
    Amat[0:NQ, NQ + 3:] = np.eye(NQ)        # q' = pendulum speeds
    Amat[NQ:, 0:NQ] = np.linalg.solve(M0, Fq)
    Amat[NQ:, NQ:] = np.linalg.solve(M0, Fu)
    return Amat, M0, Fq, Fu, np.max(np.abs(F0))


def composite_inertia(p):
    """Inertia of the locked system about its CM (hub axes), by hand."""
    rs = [np.array(t["pivot"]) + t["l"] * np.array(t["rest"]) for t in p["tanks"]]
    ms = [t["m"] for t in p["tanks"]]
    Mt = p["M"] + sum(ms)
    cm = sum(mi * ri for mi, ri in zip(ms, rs)) / Mt
    J = np.diag([p["A"], p["A"], p["C"]]) + p["M"] * (cm @ cm * np.eye(3) - np.outer(cm, cm))
    for mi, ri in zip(ms, rs):
        x = ri - cm
        J += mi * (x @ x * np.eye(3) - np.outer(x, x))
    return J


def main():
    fns = derive()
    Om = P["spin"]
    Amat, M0, Fq, Fu, resid = state_matrix(fns, P)
    lam = np.linalg.eigvals(Amat)
    lam = lam[np.lexsort((lam.imag, -lam.real))]
    scale = np.max(np.abs(lam))
    print(f"equilibrium residual max |F| = {resid:.3e}")
    ok = resid == 0.0 or resid < 1e-12 * Om ** 2 * P["A"]

    # Rigid limit: the w block with the pendulums locked at rest.
    J = composite_inertia(P)
    assert np.max(np.abs(J - np.diag(np.diag(J)))) < 1e-12 * np.max(J), J
    A1, A2, Ct = np.diag(J)
    w_nut_closed = Om * np.sqrt((A1 - Ct) * (A2 - Ct) / (A1 * A2))
    lam_rigid = np.linalg.eigvals(np.linalg.solve(M0[0:3, 0:3], Fu[0:3, 0:3]))
    w_nut_rigid = np.max(np.abs(lam_rigid.imag))
    rigid_err = abs(w_nut_rigid - w_nut_closed) / w_nut_closed
    rigid_re = np.max(np.abs(lam_rigid.real))
    print(f"composite inertia about the system CM: diag({A1:.12g}, {A2:.12g}, {Ct:.12g}) kg m^2")
    print(f"rigid limit: nutation {w_nut_rigid:.15g} rad/s, closed form {w_nut_closed:.15g} rad/s,"
          f" rel diff {rigid_err:.2e}, max |Re| {rigid_re:.2e}  (limit {RIGID_TOL:g})")
    ok &= rigid_err <= RIGID_TOL and rigid_re <= RIGID_TOL * w_nut_closed

    # Undamped: purely imaginary and, but for the spin's zero, nonzero.
    Pu = json.loads(json.dumps(P))
    for t in Pu["tanks"]:
        t["c"] = 0.0
    lam_u = np.linalg.eigvals(state_matrix(fns, Pu)[0])
    order = np.argsort(np.abs(lam_u))
    zero, rest = lam_u[order[0]], lam_u[order[1:]]
    und_re = np.max(np.abs(rest.real) / np.abs(rest))
    print(f"undamped: spin eigenvalue {abs(zero):.2e}, smallest other |lambda| "
          f"{np.min(np.abs(rest)):.6g}, max |Re|/|lambda| {und_re:.2e}  (limit {UNDAMPED_TOL:g})")
    ok &= abs(zero) <= 1e-12 * scale and und_re <= UNDAMPED_TOL \
        and np.min(np.abs(rest)) > 1e-3 * scale

    # The pendulums alone: a hub of 1e11 kg and kg m^2 holds the spin.
    Ph = json.loads(json.dumps(P))
    Ph.update(M=1e11, A=1e11, C=1e11)
    lam_h = np.linalg.eigvals(state_matrix(fns, Ph)[0])
    cf_err = 0.0
    for t in P["tanks"]:
        b = np.hypot(t["pivot"][0], t["pivot"][1])
        for w0sq in (Om ** 2 * b / t["l"], Om ** 2 * (b + t["l"]) / t["l"]):
            root = np.roots([1.0, t["c"] / t["m"], w0sq])
            for rt in root:
                cf_err = max(cf_err, np.min(np.abs(lam_h - rt)) / abs(rt))
    print(f"pendulums on a 1e11 hub: max rel distance to the closed-form roots {cf_err:.2e}"
          f"  (limit {CLOSED_FORM_TOL:g})")
    ok &= cf_err <= CLOSED_FORM_TOL

    # The nutation pair: nearest the rigid nutation frequency (Im > 0 member).
    up = lam[lam.imag > 0]
    nut = up[np.argmin(np.abs(up.imag - w_nut_closed))]
    print("\neigenvalues (1/s, rad/s):")
    for x in lam:
        print(f"  {x.real: .15e} {x.imag:+.15e} i")
    print(f"\nnutation: rate {nut.real:.15e} 1/s, frequency {nut.imag:.15e} rad/s, "
          f"time constant {1 / abs(nut.real):.10g} s")
    print("SELF-CHECK", "PASSED" if ok else "FAILED")
    if not ok:
        raise SystemExit(1)

    out = os.path.join(HERE, "..", "data", "slosh_stage_linear.json")
    doc = dict(
        description=(
            "Linearised spinning stage with two spherical slosh pendulums "
            "(scenarios/spinning-stage-slosh.yaml) about its steady spin: eigenvalues of the "
            "11 x 11 state matrix (4 pendulum angles, hub body rates, 4 pendulum rates; the "
            "hub translates so the system CM is fixed; attitude left out). Generated by "
            f"{SCRIPT} (sympy.physics.mechanics KanesMethod, symbolic Jacobians at the "
            "operating point, numpy eigenvalues)."),
        parameters=dict(hub_mass=P["M"], hub_principal=[P["A"], P["A"], P["C"]],
                        spin_rate=Om, tanks=P["tanks"]),
        composite_inertia=[A1, A2, Ct],
        rigid_nutation_frequency=w_nut_closed,
        eigenvalues=[[float(x.real), float(x.imag)] for x in lam],
        nutation=dict(rate=float(nut.real), frequency=float(nut.imag),
                      time_constant=float(1 / abs(nut.real))),
        self_checks=dict(equilibrium_residual=float(resid),
                         rigid_limit_relative_difference=float(rigid_err),
                         undamped_max_relative_real_part=float(und_re),
                         pendulum_closed_form_relative_difference=float(cf_err)),
        versions=dict(numpy=np.__version__, sympy=sp.__version__),
    )
    with open(out, "w") as fh:
        json.dump(doc, fh, indent=2)
        fh.write("\n")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
