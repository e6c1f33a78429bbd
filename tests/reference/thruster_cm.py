#!/usr/bin/env python3
"""Independent reference model: a rigid hub and one thruster draining its tank, written about
the system's instantaneous centre of mass C with the translation eliminated, integrated for
three scenes whose tank and nozzle are off the spin axis (tests/thruster_reference.rs).

Modelling assumptions (those of docs/effectors.md, "thruster"; nothing else is taken from
polhode): a rigid dry hub (mass m_h, inertia I_h about its centre of mass B, the origin of the
body axes); the propellant left, mass m(t), centre r(t), inertia J_F(t) about its centre (the
tank model), at rest in the body except for the motion r' of its centre; a steady internal
flow of negligible mass from r to the nozzle exit r_e with the mass flux mdot uniform along
the segment (relative to the body: momentum p_f = mdot (r_e - r), angular momentum about B
h_f = mdot r x r_e); mass leaves only through the exit disc (centre r_e, radius a, normal d),
uniformly, at u = -(F/mdot) d relative to the body; no external loads.  Body axes throughout;
' is the rate of a body-axes component, P(x) = |x|^2 1 - x x^T, m' = -mdot.

Derivation.
 1. Centre of mass: M = m_h + m, M c = m r (c from B), so c' = (m r' - mdot (r - c)) / M.
    (Continuity: the spacecraft's linear momentum is M v_C + mdot (r_e - c), i.e. mass
    leaving at r_e; the internal flow's p_f is exactly what makes the model satisfy it.)
 2. Angular momentum about C with velocities relative to the point C itself,
    H_C = sum (x - x_C) x (v - v_C) dm over the contents.  A point at rho (body axes, from B)
    moving at rho' in the body has v - v_C = w x (rho - c) + rho' - c', and
    sum (rho - c) dm = 0 (the flow carries momentum but no mass), so
        H_C = I_C w + g,   I_C = I_h + J_F + m P(r) - M P(c),
        g   = m (r - c) x r' + mdot (r - c) x (r_e - r)      (the propellant's and the flow's).
 3. The material system that fills the spacecraft at t: d/dt of its sum (x - x_C) x (v - v_C)
    dm is the external moment about C (zero) minus (sum (x - x_C) dm) x a_C, which is zero
    because C is its centre of mass at t.  Reynolds' transport theorem for the control volume
    fixed in the body then leaves only the outflow through the exit:
        dH_C/dt|inertial = -Phi,
        Phi = mdot <(x - x_C) x (v - v_C)>_exit
            = mdot (r_e - c) x (w x (r_e - c) - c') - (r_e - c) x F d + mdot (a^2/4)(w + d d.w)
    (v - v_C = w x (r_e + s - c) + u - c' at the exit point r_e + s; the disc average of s is
    0, of s x (w x s) (a^2/4)(w + d d.w); mdot u = -F d).
 4. In body axes:
        I_C w' = -w x (I_C w + g) - I_C' w - g' - Phi,
    with I_C', g', c' the exact time derivatives of the expressions above (taken by sympy from
    m, m', m'', r, r', r'', J_F, J_F'), and the attitude q (w, x, y, z; body -> inertial)
    from q' = q (x) (0, w) / 2.  The translation never enters.

Self-checks (recorded in the JSON):
  * "fixed_origin": the same physics written the other way round (linear momentum and angular
    momentum about a fixed inertial point O, with B's velocity as an unknown, differentiated
    by sympy.physics.vector and solved for B's acceleration and w', at 40 digits) gives the
    same w' at 15 states (random hubs, nozzles and mass properties, and the scenes' own at
    t = 0.5, 31.5 and 59.5 s, each with B far from O and moving);
  * "momentum_audit": along each trajectory, the inertial H_C (summed body by body: hub,
    propellant, flow, with c' and r' by finite differences of c(t) and r(t)) differentiated by
    an 8th-order central difference against -Phi rotated to inertial axes;
  * "tanks": each tank's rates against central differences of its quantities, the emptying
    sphere full (a sphere) and half full (a hemisphere: centre 3R/8 below, moments 2/5 and
    83/320 m R^2), the grain against a thick-walled tube;
  * sensitivity ("variant_without_internal_flow_momentum"): the same run with the flow's term
    left out of g moves w and the attitude by this much;
  * convergence: DOP853 at rtol 1e-12, atol 1e-14 ("samples") against rtol 1e-13, atol 1e-15
    ("samples_check"; their difference is "error_estimate"), and the rtol 1e-13 run against
    rtol 3e-14, atol 3e-16 ("error_estimate_check").

Usage: python thruster_cm.py    writes ../data/thruster_reference.json (tests/data/).
"""
import json
import math
import os
import time

import numpy as np
import sympy as sp
import sympy.physics.vector as spv
from sympy.physics.mechanics import msubs
from scipy.integrate import solve_ivp

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "..", "data", "thruster_reference.json")
G0 = 9.80665                       # m/s^2, standard gravity (I_sp to exhaust velocity)
HUB = {"mass": 600.0, "principal": [500.0, 450.0, 300.0]}
DURATION = 60.0
SAMPLE_EVERY = 1.0
RTOL, ATOL = 1e-12, 1e-14
RTOL_CHECK, ATOL_CHECK = 1e-13, 1e-15
RTOL_FINEST, ATOL_FINEST = 3e-14, 3e-16     # near SciPy's floor (100 eps)

SCENES = [
    {"name": "centrifugal_burn",
     "omega": [0.02, -0.01, 6.283185307179586],
     "thruster": {"nozzle": [0.01, 0.02, -1.0], "direction": [0.005, 0.0, 1.0],
                  "exit_radius": 0.0, "thrust": {"constant": 9000.0}, "isp": 280.0},
     "tank": {"model": "centrifugal_burn", "center": [0.05, -0.03, -0.3], "axis": [0, 0, 1],
              "radius": 0.5, "length": 0.8, "propellant": 400.0}},
    {"name": "constant_volume",
     "omega": [0.05, 0.02, 3.0],
     "thruster": {"nozzle": [0.0, 0.0, -1.0], "direction": [0.0, 0.0, 1.0],
                  "exit_radius": 0.15,
                  "thrust": {"table": [[0.0, 0.0], [2.0, 4000.0], [40.0, 3500.0], [50.0, 0.0]]},
                  "isp": 300.0},
     "tank": {"model": "constant_volume", "center": [0.1, 0.05, -0.3], "radius": 0.4,
              "propellant": 300.0}},
    {"name": "emptying",
     "omega": [0.04, -0.03, 3.0],
     "thruster": {"nozzle": [0.01, -0.02, -1.0], "direction": [0.01, 0.0, 1.0],
                  "exit_radius": 0.0, "thrust": {"constant": 4000.0}, "isp": 300.0},
     "tank": {"model": "emptying", "center": [0.1, 0.05, -0.3], "axis": [0, 0, 1],
              "radius": 0.4, "density": 1000.0, "propellant": 200.0}},
]


# --------------------------------------------------------------------------------------------
# Thrust profile and propellant mass
# --------------------------------------------------------------------------------------------
class Thrust:
    """F(t), F'(t), the integral of F from 0, and the breakpoints: constant, or linear between
    table points and zero outside them."""

    def __init__(self, spec):
        if "constant" in spec:
            self.points = None
            self.value = float(spec["constant"])
        else:
            self.points = [(float(a), float(b)) for a, b in spec["table"]]

    def at(self, t, piece=None):
        """F and F' at t on the piece of the profile that holds the time `piece` (default t):
        an integration segment between breakpoints evaluates its end on its own piece."""
        if self.points is None:
            return self.value, 0.0
        p = self.points
        piece = t if piece is None else piece
        if piece < p[0][0] or piece >= p[-1][0]:
            return 0.0, 0.0
        for (t0, f0), (t1, f1) in zip(p, p[1:]):
            if t0 <= piece < t1:
                s = (f1 - f0) / (t1 - t0)
                return f0 + s * (t - t0), s
        raise AssertionError(piece)

    def integral(self, t):
        if self.points is None:
            return self.value * t
        total = 0.0
        for (t0, f0), (t1, f1) in zip(self.points, self.points[1:]):
            lo, hi = max(t0, 0.0), min(t1, t)
            if hi > lo:
                s = (f1 - f0) / (t1 - t0)
                fa, fb = f0 + s * (lo - t0), f0 + s * (hi - t0)
                total += 0.5 * (fa + fb) * (hi - lo)
        return total

    def breakpoints(self, t_end):
        if self.points is None:
            return []
        return [tp for tp, _ in self.points if 0.0 < tp < t_end]


# --------------------------------------------------------------------------------------------
# Tank models: mass properties as functions of one parameter p (the mass itself, or for the
# emptying sphere the height s of the free surface above the tank's centre)
# --------------------------------------------------------------------------------------------
def tank_expressions(tank):
    """sympy expressions in p: mass, centre offset along the axis, axial and transverse
    moments about the propellant's own centre of mass."""
    p = sp.Symbol("p", real=True)
    model = tank["model"]
    if model == "constant_volume":
        R = sp.Float(tank["radius"])
        m = p
        offset = sp.Integer(0)
        axial = transverse = sp.Rational(2, 5) * p * R**2
    elif model == "centrifugal_burn":
        R, L = sp.Float(tank["radius"]), sp.Float(tank["length"])
        rho = sp.Float(tank["propellant"]) / (sp.pi * R**2 * L)
        b2 = R**2 - p / (rho * sp.pi * L)           # the bore, from m = rho pi L (R^2 - b^2)
        m = p
        offset = sp.Integer(0)
        axial = p * (R**2 + b2) / 2                 # thick-walled tube
        transverse = p * (3 * (R**2 + b2) + L**2) / 12
    elif model == "emptying":
        R, rho = sp.Float(tank["radius"]), sp.Float(tank["density"])
        z = sp.Symbol("z", real=True)
        area = sp.pi * (R**2 - z**2)                # the liquid's cross-section at height z
        # Slices from the outlet pole z = -R up to the free surface z = p: a disc of radius^2
        # R^2 - z^2 has axial moment (1/2) dm rad^2, transverse (1/4) dm rad^2 about its centre.
        m = rho * sp.integrate(area, (z, -R, p))
        first = rho * sp.integrate(z * area, (z, -R, p))
        axial = rho * sp.integrate(area * (R**2 - z**2) / 2, (z, -R, p))
        transverse_centre = rho * sp.integrate(area * ((R**2 - z**2) / 4 + z**2), (z, -R, p))
        offset = first / m
        transverse = transverse_centre - m * offset**2
    else:
        raise ValueError(model)
    return p, [sp.simplify(e) for e in (m, offset, axial, transverse)]


class Tank:
    """m, r, J_F and their time rates from m(t), m'(t), m''(t)."""

    def __init__(self, tank):
        self.spec = tank
        self.center = np.array(tank["center"], float)
        k = np.array(tank.get("axis", [0.0, 0.0, 1.0]), float)
        self.k = k / np.linalg.norm(k)
        p, (m, off, ax, tr) = tank_expressions(tank)
        self.emptying = tank["model"] == "emptying"
        lam = lambda e: sp.lambdify(p, e, "math")
        self.f = {name: (lam(e), lam(sp.diff(e, p)), lam(sp.diff(e, p, 2)))
                  for name, e in dict(m=m, off=off, ax=ax, tr=tr).items()}
        if self.emptying:
            self.R = tank["radius"]

    def parameter(self, mass, dm, ddm):
        """p, p', p'' for the mass and its rates."""
        if not self.emptying:
            return mass, dm, ddm
        fm, fm1, fm2 = self.f["m"]
        # The free surface: fm(s) = mass on [-R, R] (fm increasing), by bisection then Newton.
        lo, hi = -self.R, self.R
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            if fm(mid) < mass:
                lo = mid
            else:
                hi = mid
        s = 0.5 * (lo + hi)
        for _ in range(3):
            s -= (fm(s) - mass) / fm1(s)
        ds = dm / fm1(s)
        dds = (ddm - fm2(s) * ds * ds) / fm1(s)
        return s, ds, dds

    def state(self, mass, dm, ddm):
        p, dp, ddp = self.parameter(mass, dm, ddm)
        out = {}
        for name in ("off", "ax", "tr"):
            f0, f1, f2 = self.f[name]
            out[name] = (f0(p), f1(p) * dp, f2(p) * dp * dp + f1(p) * ddp)
        k = self.k
        kk = np.outer(k, k)
        axisym = lambda t, a: t * np.eye(3) + (a - t) * kk
        return {
            "m": mass, "dm": dm, "ddm": ddm,
            "r": self.center + out["off"][0] * k,
            "dr": out["off"][1] * k,
            "ddr": out["off"][2] * k,
            "J": axisym(out["tr"][0], out["ax"][0]),
            "dJ": axisym(out["tr"][1], out["ax"][1]),
        }


# --------------------------------------------------------------------------------------------
# The equation about C
# --------------------------------------------------------------------------------------------
def centre_of_mass_terms(internal_flow=True):
    """Lambdified I_C, I_C', g, g', c, c' from (m_h, I_h diagonal, r_e, m, m', m'', r, r',
    r'', J_F (6), J_F' (6)); the time derivatives are sympy's, of the definitions.  With
    internal_flow=False, g leaves out the flow's angular momentum about C (a sensitivity
    variant only: the model is then no longer consistent)."""
    t = sp.Symbol("t")
    mh = sp.Symbol("m_h")
    Ih = sp.diag(*sp.symbols("I1:4"))
    re = sp.Matrix(sp.symbols("re1:4"))
    m = sp.Function("m")(t)
    r = sp.Matrix([sp.Function(f"r{i}")(t) for i in range(3)])
    jf = {}
    for i in range(3):
        for j in range(i, 3):
            jf[(i, j)] = jf[(j, i)] = sp.Function(f"J{i}{j}")(t)
    J = sp.Matrix(3, 3, lambda i, j: jf[(i, j)])
    P = lambda x: (x.T * x)[0] * sp.eye(3) - x * x.T
    flow = -m.diff(t)
    M = mh + m
    c = m * r / M
    IC = Ih + J + m * P(r) - M * P(c)
    g = m * (r - c).cross(r.diff(t)) + int(internal_flow) * flow * (r - c).cross(re - r)
    exprs = [IC, IC.diff(t), g, g.diff(t), c, c.diff(t)]
    # Plain symbols for m, r, J_F and their derivatives, highest order first.
    ms = sp.symbols("m0 m1 m2")
    rs = [sp.symbols(f"r{i}_0:3") for i in range(3)]
    pairs = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)]
    Js = [sp.symbols(f"J{i}{j}_0:2") for i, j in pairs]
    sub = {m.diff(t, 2): ms[2], m.diff(t): ms[1]}
    for i in range(3):
        sub[r[i].diff(t, 2)] = rs[i][2]
        sub[r[i].diff(t)] = rs[i][1]
    for n, (i, j) in enumerate(pairs):
        sub[jf[(i, j)].diff(t)] = Js[n][1]
    base = {m: ms[0]} | {r[i]: rs[i][0] for i in range(3)} | {
        jf[(i, j)]: Js[n][0] for n, (i, j) in enumerate(pairs)}
    exprs = [e.xreplace(sub).xreplace(base) for e in exprs]
    args = [mh, *Ih.diagonal(), *re, *ms, *[rs[i][k] for k in range(3) for i in range(3)],
            *[Js[n][0] for n in range(6)], *[Js[n][1] for n in range(6)]]
    f = sp.lambdify(args, exprs, "numpy", cse=True)

    def terms(hub, re_, s):
        J, dJ = s["J"], s["dJ"]
        sym6 = lambda A: [A[i, j] for i, j in pairs]
        IC, dIC, g, dg, c, dc = f(hub["mass"], *hub["principal"], *re_, s["m"], s["dm"],
                                  s["ddm"], *s["r"], *s["dr"], *s["ddr"], *sym6(J), *sym6(dJ))
        col = lambda v: np.asarray(v, float).reshape(3)
        return (np.asarray(IC, float), np.asarray(dIC, float), col(g), col(dg), col(c),
                col(dc))

    return terms


def flux(re, d, a, w, F, s, c, dc):
    """Phi: the angular momentum about C that leaves through the exit per second (body axes),
    with the exhaust's velocity taken relative to the point C."""
    mdot = -s["dm"]
    arm = re - c
    spread = 0.25 * a * a * (w + d * (d @ w))
    return mdot * np.cross(arm, np.cross(w, arm) - dc) - np.cross(arm, F * d) + mdot * spread


def omega_dot(hub, re, d, a, terms, w, F, s):
    """w' from I_C w' = -w x (I_C w + g) - I_C' w - g' - Phi."""
    IC, dIC, g, dg, c, dc = terms(hub, re, s)
    rhs = -np.cross(w, IC @ w + g) - dIC @ w - dg - flux(re, d, a, w, F, s, c, dc)
    return np.linalg.solve(IC, rhs)


class Model:
    """One scene: the hub, the thruster and its tank."""

    def __init__(self, scene, terms):
        th = scene["thruster"]
        self.scene = scene
        self.hub = HUB
        self.re = np.array(th["nozzle"], float)
        d = np.array(th["direction"], float)
        self.d = d / np.linalg.norm(d)
        self.a = float(th.get("exit_radius", 0.0))
        self.thrust = Thrust(th["thrust"])
        self.isp = float(th["isp"])
        self.m0 = float(scene["tank"]["propellant"])
        self.tank = Tank(scene["tank"])
        self.terms = terms
        self.piece = 0.0        # a time inside the integration segment under way

    def tank_state(self, t, piece=None):
        F, dF = self.thrust.at(t, piece)
        ve = G0 * self.isp
        mass = self.m0 - self.thrust.integral(t) / ve
        return F, self.tank.state(mass, -F / ve, -dF / ve)

    def omega_dot(self, w, F, s):
        return omega_dot(self.hub, self.re, self.d, self.a, self.terms, w, F, s)

    def rhs(self, t, y):
        w, q = y[:3], y[3:]
        F, s = self.tank_state(t, self.piece)
        dw = self.omega_dot(w, F, s)
        # q' = q (x) (0, w) / 2
        qw, qv = q[0], q[1:]
        dq = 0.5 * np.concatenate(([-qv @ w], qw * w + np.cross(qv, w)))
        return np.concatenate((dw, dq))

    def integrate(self, rtol, atol, dense=False):
        """Samples every SAMPLE_EVERY s; the integration restarts at the thrust's breakpoints
        (where F' jumps), as polhode's does."""
        y = np.array([*self.scene["omega"], 1.0, 0.0, 0.0, 0.0])
        cuts = [0.0, *self.thrust.breakpoints(DURATION), DURATION]
        samples = [k * SAMPLE_EVERY for k in range(int(round(DURATION / SAMPLE_EVERY)) + 1)]
        ts, ys, sols, nfev = [], [], [], 0
        for t0, t1 in zip(cuts, cuts[1:]):
            te = sorted({t for t in samples if t0 <= t <= t1} | {t0, t1})
            self.piece = 0.5 * (t0 + t1)
            sol = solve_ivp(self.rhs, (t0, t1), y, method="DOP853", rtol=rtol, atol=atol,
                            t_eval=te, dense_output=dense)
            assert sol.status == 0, sol.message
            assert sol.t[-1] == t1
            nfev += sol.nfev
            for t, yy in zip(sol.t, sol.y.T):
                if t in samples and (not ts or t > ts[-1]):
                    ts.append(t)
                    ys.append(yy)
            if dense:
                sols.append((t0, t1, sol.sol))
            y = sol.y[:, -1]
        return np.array(ts), np.array(ys), sols, nfev


# --------------------------------------------------------------------------------------------
# Check 1: the fixed-origin formulation, differentiated by sympy.physics.vector
# --------------------------------------------------------------------------------------------
def fixed_origin_equations():
    """Linear momentum P and angular momentum about a fixed inertial point O of the same
    contents, dP/dt = -(momentum flux out), dH_O/dt = -(angular momentum flux about O out),
    with B at x (body components) from O, B's velocity v (body components) unknown: six
    equations linear in v' and w'."""
    t = spv.dynamicsymbols._t
    N, Bf = spv.ReferenceFrame("N"), spv.ReferenceFrame("B")
    w = spv.dynamicsymbols("w1:4")
    v = spv.dynamicsymbols("v1:4")
    x = spv.dynamicsymbols("x1:4")
    m = spv.dynamicsymbols("m")
    r = spv.dynamicsymbols("r1:4")
    F = spv.dynamicsymbols("F")
    pairs = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)]
    Jn = {p: spv.dynamicsymbols(f"J{p[0]}{p[1]}") for p in pairs}
    mh, a = sp.symbols("m_h a")
    Ih = sp.symbols("I1:4")
    re = sp.symbols("re1:4")
    d = sp.symbols("d1:4")
    Bf.set_ang_vel(N, w[0] * Bf.x + w[1] * Bf.y + w[2] * Bf.z)
    e = [Bf.x, Bf.y, Bf.z]
    vec = lambda c: c[0] * Bf.x + c[1] * Bf.y + c[2] * Bf.z
    W = Bf.ang_vel_in(N)
    unit = sum((ei | ei for ei in e), spv.Dyadic(0))
    J = sum((Jn[(min(i, j), max(i, j))] * (e[i] | e[j]) for i in range(3) for j in range(3)),
            spv.Dyadic(0))
    I_hub = sum((Ih[i] * (e[i] | e[i]) for i in range(3)), spv.Dyadic(0))
    xB, vB, rv, rev, dv = vec(x), vec(v), vec(r), vec(re), vec(d)
    rdot = vec([ri.diff(t) for ri in r])            # the centre's rate relative to the body
    flow = -m.diff(t)
    P_lin = (mh + m) * vB + m * (W ^ rv) + m * rdot + flow * (rev - rv)
    I_B = I_hub + J + m * ((rv & rv) * unit - (rv | rv))
    H_O = (xB ^ P_lin) + ((m * rv) ^ vB) + (I_B & W) + m * (rv ^ rdot) + flow * (rv ^ rev)
    flux_P = flow * (vB + (W ^ rev)) - F * dv
    flux_H = ((xB + rev) ^ flux_P) + flow * a**2 / 4 * (W + dv * (dv & W))
    eq = [(P_lin.dt(N) + flux_P) & ei for ei in e] + [(H_O.dt(N) + flux_H) & ei for ei in e]
    # B moves with v: x' = v - w x x (body components).
    xdot = vB - (W ^ xB)
    eq = [msubs(q, {x[i].diff(t): xdot & e[i] for i in range(3)}) for q in eq]
    return dict(eq=eq, t=t, w=w, v=v, x=x, m=m, r=r, F=F, J=Jn, mh=mh, a=a, Ih=Ih, re=re, d=d)


def fixed_origin_omega_dot(sym, hub, re, d, a, w, vB, xB, F, s):
    t = sym["t"]
    sub = {}
    m, r = sym["m"], sym["r"]
    sub[m.diff(t, 2)], sub[m.diff(t)], sub[m] = s["ddm"], s["dm"], s["m"]
    for i in range(3):
        sub[r[i].diff(t, 2)], sub[r[i].diff(t)], sub[r[i]] = s["ddr"][i], s["dr"][i], s["r"][i]
        sub[sym["w"][i]], sub[sym["v"][i]], sub[sym["x"][i]] = w[i], vB[i], xB[i]
        sub[sym["Ih"][i]], sub[sym["re"][i]], sub[sym["d"][i]] = (
            hub["principal"][i], re[i], d[i])
    for (i, j), Jij in sym["J"].items():
        sub[Jij.diff(t)], sub[Jij] = s["dJ"][i, j], s["J"][i, j]
    sub[sym["F"]], sub[sym["mh"]], sub[sym["a"]] = F, hub["mass"], a
    unknowns = [q.diff(t) for q in sym["v"]] + [q.diff(t) for q in sym["w"]]
    plain = sp.symbols("z0:6")
    eqs = [msubs(q, dict(zip(unknowns, plain))) for q in sym["eq"]]
    # 40 digits, so that the large x and v (which cancel) leave no rounding behind.
    sub = {k: sp.Float(float(val), 40) for k, val in sub.items()}
    eqs = [msubs(q, sub) for q in eqs]
    A, b = sp.linear_eq_to_matrix(eqs, plain)
    z = A.LUsolve(b)
    return np.array([float(zi) for zi in z[3:]])


def random_state(rng):
    A = rng.normal(size=(3, 3))
    J = A @ A.T * 10 + 20 * np.eye(3)
    dJ = rng.normal(size=(3, 3))
    dJ = -(dJ + dJ.T) * 2
    return {"m": rng.uniform(50, 400), "dm": -rng.uniform(0.5, 5), "ddm": rng.normal(),
            "r": rng.normal(size=3) * 0.4, "dr": rng.normal(size=3) * 0.01,
            "ddr": rng.normal(size=3) * 0.01, "J": J, "dJ": dJ}


def check_fixed_origin(models, terms):
    t0 = time.time()
    sym = fixed_origin_equations()
    rng = np.random.default_rng(20240601)
    worst = 0.0
    cases = []
    for _ in range(6):
        d = rng.normal(size=3)
        hub = {"mass": rng.uniform(300, 900), "principal": list(rng.uniform(200, 600, 3))}
        cases.append((hub, rng.normal(size=3), d / np.linalg.norm(d), rng.uniform(0, 0.4),
                      rng.normal(size=3) * [0.3, 0.3, 4.0], rng.uniform(0, 9000),
                      random_state(rng)))
    for model in models:
        for tt in (0.5, 31.5, 59.5):
            F, s = model.tank_state(tt)
            cases.append((model.hub, model.re, model.d, model.a,
                          np.array(model.scene["omega"]) + rng.normal(size=3) * 0.05, F, s))
    for hub, re, d, a, w, F, s in cases:
        vB, xB = rng.normal(size=3) * 100, rng.normal(size=3) * 1000
        ours = omega_dot(hub, re, d, a, terms, w, F, s)
        theirs = fixed_origin_omega_dot(sym, hub, re, d, a, w, vB, xB, F, s)
        worst = max(worst, np.linalg.norm(ours - theirs) / np.linalg.norm(theirs))
    print(f"[fixed origin] {len(cases)} states, largest |dw' (C) - dw' (O)| / |w'| "
          f"{worst:.2e} ({time.time() - t0:.0f} s)", flush=True)
    assert worst < 1e-12, worst
    return {"states": len(cases), "max_relative_difference": worst}


# --------------------------------------------------------------------------------------------
# Check 2: H_C summed body by body along the trajectory, finite differences against -Phi
# --------------------------------------------------------------------------------------------
STENCIL = (np.array([1 / 280, -4 / 105, 1 / 5, -4 / 5, 0, 4 / 5, -1 / 5, 4 / 105, -1 / 280]),
           np.arange(-4, 5))


def central(f, t, h):
    return sum(c * f(t + k * h) for c, k in zip(*STENCIL) if c != 0) / h


def rotate(q, v):
    w, u = q[0], q[1:]
    return v + 2 * w * np.cross(u, v) + 2 * np.cross(u, np.cross(u, v))


def momentum_audit(model, sols):
    """max over audit times of |d(R H_C)/dt + R Phi| / max |R Phi| (the flux is zero when
    the motor is off), with H_C summed over the hub, the propellant and the flow, c' and r' by
    finite differences."""
    h = 0.01
    hub = model.hub
    Ih = np.diag(hub["principal"])

    def c_of(t):
        _, s = model.tank_state(t)
        return s["m"] * s["r"] / (hub["mass"] + s["m"])

    def r_of(t):
        return model.tank_state(t)[1]["r"]

    def h_c(t, w):
        F, s = model.tank_state(t)
        c, dc, dr = c_of(t), central(c_of, t, 1e-3), central(r_of, t, 1e-3)
        m, r, mdot = s["m"], s["r"], -s["dm"]
        hub_part = Ih @ w + hub["mass"] * np.cross(-c, np.cross(w, -c) - dc)
        prop = s["J"] @ w + m * np.cross(r - c, np.cross(w, r - c) + dr - dc)
        flow_part = mdot * np.cross(r, model.re) - np.cross(c, mdot * (model.re - r))
        return hub_part + prop + flow_part, flux(model.re, model.d, model.a, w, F, s, c, dc)

    worst = largest = 0.0
    for t0 in np.arange(0.5, DURATION, 5.0):
        sol = next(f for a, b, f in sols if a <= t0 <= b)
        y0 = sol(t0)
        model.piece = t0        # the stencil (+-0.04 s) stays clear of the breakpoints
        grid = t0 + h * np.arange(-4, 5)
        ys = {}
        for side in (grid[grid <= t0][::-1], grid[grid >= t0]):
            r = solve_ivp(model.rhs, (t0, side[-1]), y0, method="DOP853", rtol=1e-13,
                          atol=1e-15, t_eval=side)
            ys.update({round((tt - t0) / h): yy for tt, yy in zip(r.t, r.y.T)})

        def inertial(t):
            y = ys[round((t - t0) / h)]
            q = y[3:] / np.linalg.norm(y[3:])
            return rotate(q, h_c(t, y[:3])[0])

        y = ys[0]
        q = y[3:] / np.linalg.norm(y[3:])
        phi = rotate(q, h_c(t0, y[:3])[1])
        dh = central(inertial, t0, h)
        worst = max(worst, np.linalg.norm(dh + phi))
        largest = max(largest, np.linalg.norm(phi))
    return worst / largest


# --------------------------------------------------------------------------------------------
# Check 3: the tanks
# --------------------------------------------------------------------------------------------
def check_tanks(models):
    out = {}
    for model in models:
        worst = 0.0
        for t in (0.5, 20.5, 45.5):
            _, s = model.tank_state(t)
            h = 1e-3
            st = lambda k: model.tank_state(t + k * h)[1]
            fd = lambda key: sum(c * st(k)[key] for c, k in zip(*STENCIL) if c != 0) / h
            scale = np.linalg.norm(s["J"]) + s["m"] * np.linalg.norm(s["r"]) ** 2
            worst = max(worst, np.linalg.norm(fd("J") - s["dJ"]) / scale,
                        np.linalg.norm(fd("r") - s["dr"]), np.linalg.norm(fd("dr") - s["ddr"]),
                        abs(fd("m") - s["dm"]) / s["m"])
        out[model.scene["name"]] = float(worst)
        assert worst < 1e-8, (model.scene["name"], worst)
    # The emptying sphere full and half full.
    R, rho = 0.5, 800.0
    tank = Tank({"model": "emptying", "center": [0, 0, 0], "axis": [0, 0, 1], "radius": R,
                 "density": rho, "propellant": 1.0})
    full = rho * 4 / 3 * math.pi * R**3
    sf, sh = tank.state(full * (1 - 1e-15), 0.0, 0.0), tank.state(full / 2, 0.0, 0.0)
    mh = full / 2
    errs = [abs(sf["r"][2]), abs(sf["J"][2, 2] / (0.4 * full * R * R) - 1),
            abs(sf["J"][0, 0] / (0.4 * full * R * R) - 1),
            abs(sh["r"][2] / (-3 * R / 8) - 1), abs(sh["J"][2, 2] / (0.4 * mh * R * R) - 1),
            abs(sh["J"][0, 0] / (83 / 320 * mh * R * R) - 1)]
    out["emptying_sphere_and_hemisphere"] = float(max(errs))
    assert max(errs) < 1e-6, errs
    # The grain against a thick-walled tube integrated in cylindrical coordinates.
    Rg, L, b = 0.5, 0.8, 0.2
    rr, th, z = sp.symbols("rho theta z", positive=True)
    dens = 1800.0
    mass = dens * math.pi * (Rg**2 - b**2) * L
    axial = float(sp.integrate(dens * rr**3, (rr, b, Rg), (th, 0, 2 * sp.pi), (z, -L / 2, L / 2)))
    trans = float(sp.integrate(dens * rr * ((rr * sp.cos(th)) ** 2 + z**2), (rr, b, Rg),
                               (th, 0, 2 * sp.pi), (z, -L / 2, L / 2)))
    grain = Tank({"model": "centrifugal_burn", "center": [0, 0, 0], "axis": [0, 0, 1],
                  "radius": Rg, "length": L, "propellant": dens * math.pi * Rg**2 * L})
    sg = grain.state(mass, 0.0, 0.0)
    errs = [abs(sg["J"][2, 2] / axial - 1), abs(sg["J"][0, 0] / trans - 1)]
    out["grain_tube"] = float(max(errs))
    assert max(errs) < 1e-12, errs
    print(f"[tanks] {out}", flush=True)
    return out


# --------------------------------------------------------------------------------------------
# Scenes, runs, JSON
# --------------------------------------------------------------------------------------------
def fmt(v):
    return "[" + ", ".join(repr(float(x)) for x in v) + "]"


def scene_yaml(scene):
    th, tk = scene["thruster"], scene["tank"]
    thrust = th["thrust"]
    if "constant" in thrust:
        thrust_text = f"{{constant: {float(thrust['constant'])!r}}}"
    else:
        thrust_text = "{table: [" + ", ".join(fmt(p) for p in thrust["table"]) + "]}"
    tank = [f"model: {tk['model']}", f"center: {fmt(tk['center'])}"]
    if "axis" in tk:
        tank.append(f"axis: {fmt(tk['axis'])}")
    for key in ("radius", "length", "density", "propellant"):
        if key in tk:
            tank.append(f"{key}: {float(tk[key])!r}")
    lines = [
        f"name: {scene['name']}",
        "description: >",
        "  Reference scene of tests/reference/thruster_cm.py: the hub and one thruster whose",
        "  tank and nozzle are off the spin axis (tests/thruster_reference.rs).",
        f"body: {{mass: {HUB['mass']!r}, principal: {fmt(HUB['principal'])}, "
        "spin_axis: [0, 0, 1]}",
        f"initial: {{omega: {fmt(scene['omega'])}}}",
        "effectors:",
        "  - thruster:",
        f"      nozzle: {fmt(th['nozzle'])}",
        f"      direction: {fmt(th['direction'])}",
    ]
    if th.get("exit_radius"):
        lines.append(f"      exit_radius: {float(th['exit_radius'])!r}")
    lines += [
        f"      thrust: {thrust_text}",
        f"      isp: {float(th['isp'])!r}",
        "      tank: {" + ", ".join(tank) + "}",
        f"duration: {DURATION!r}",
        f"integrator: {{method: dop853, rtol: {RTOL:.1e}, atol: {ATOL:.1e}}}",
        f"output: {{rate: {1 / SAMPLE_EVERY!r}}}",
    ]
    return "\n".join(lines) + "\n"


def unit_quaternions(ys):
    q = ys[:, 3:] / np.linalg.norm(ys[:, 3:], axis=1)[:, None]
    return q * np.where(q[:, :1] < 0, -1.0, 1.0)


def differences(a, b):
    dw = np.linalg.norm(a[:, :3] - b[:, :3], axis=1).max()
    qa, qb = unit_quaternions(a), unit_quaternions(b)
    # Angle of qa^-1 qb: 2 atan2(|vector part|, |scalar part|).
    s = np.abs(np.sum(qa * qb, axis=1))
    v = np.linalg.norm(qa[:, :1] * qb[:, 1:] - qb[:, :1] * qa[:, 1:]
                       - np.cross(qa[:, 1:], qb[:, 1:]), axis=1)
    return float(dw), float((2 * np.arctan2(v, s)).max())


def main():
    t_start = time.time()
    terms = centre_of_mass_terms()
    models = [Model(sc, terms) for sc in SCENES]
    tanks = check_tanks(models)
    fixed = check_fixed_origin(models, terms)
    terms_no_flow = centre_of_mass_terms(internal_flow=False)
    out_scenes = []
    for model in models:
        sc = model.scene
        t0 = time.time()
        ts, ys, sols, nfev = model.integrate(RTOL, ATOL, dense=True)
        run_time = time.time() - t0
        ts2, ys2, _, nfev2 = model.integrate(RTOL_CHECK, ATOL_CHECK)
        ts3, ys3, _, _ = model.integrate(RTOL_FINEST, ATOL_FINEST)
        assert np.array_equal(ts, ts2) and np.array_equal(ts, ts3)
        err_w, err_q = differences(ys, ys2)
        err2_w, err2_q = differences(ys2, ys3)
        audit = momentum_audit(model, sols)
        assert audit < 1e-6, audit
        _, ys_nf, _, _ = Model(sc, terms_no_flow).integrate(RTOL, ATOL)
        nf_w, nf_q = differences(ys, ys_nf)
        q = unit_quaternions(ys)
        F_end, s_end = model.tank_state(DURATION)
        wt = np.hypot(ys[:, 0], ys[:, 1])
        print(f"[{sc['name']}] {len(ts)} samples, {nfev} evaluations ({run_time:.1f} s); "
              f"rtol {RTOL:g} against {RTOL_CHECK:g}: |dw| {err_w:.2e} rad/s, attitude "
              f"{err_q:.2e} rad; rtol {RTOL_CHECK:g} against {RTOL_FINEST:g}: {err2_w:.2e}, "
              f"{err2_q:.2e}; momentum audit {audit:.2e}; the flow's momentum left out "
              f"{nf_w:.2e}, {nf_q:.2e}; w_z {ys[0, 2]:.6f} -> "
              f"{ys[-1, 2]:.6f}, |w_t| {wt[0]:.4f} -> {wt[-1]:.4f} rad/s; propellant "
              f"{s_end['m']:.3f} kg at the end", flush=True)
        out_scenes.append({
            "name": sc["name"],
            "yaml": scene_yaml(sc),
            "parameters": {"hub": HUB, "omega0": sc["omega"], "thruster": sc["thruster"],
                           "tank": sc["tank"], "duration": DURATION, "g0": G0},
            "integrator": {"method": "scipy DOP853", "rtol": RTOL, "atol": ATOL,
                           "restarts_at": model.thrust.breakpoints(DURATION),
                           "evaluations": nfev},
            "error_estimate": {"against": {"rtol": RTOL_CHECK, "atol": ATOL_CHECK,
                                           "evaluations": nfev2},
                               "omega": err_w, "attitude": err_q},
            "error_estimate_check": {"against": {"rtol": RTOL_FINEST, "atol": ATOL_FINEST},
                                     "omega": err2_w, "attitude": err2_q},
            "momentum_audit": audit,
            "variant_without_internal_flow_momentum": {"omega": nf_w, "attitude": nf_q},
            "propellant_at_end": s_end["m"],
            "samples": [{"t": float(t), "omega": [float(x) for x in y[:3]],
                         "quaternion": [float(x) for x in qq]}
                        for t, y, qq in zip(ts, ys, q)],
            "samples_check": [{"t": float(t), "omega": [float(x) for x in y[:3]],
                               "quaternion": [float(x) for x in qq]}
                              for t, y, qq in zip(ts2, ys2, unit_quaternions(ys2))],
        })
    doc = {
        "description": "Rigid hub + one thruster and its tank, tank and nozzle off the spin "
                       "axis: w and the attitude every second from an independent model "
                       "written about the system's centre of mass C (translation eliminated): "
                       "I_C w' = -w x (I_C w + g) - I_C' w - g' - Phi. Generated by "
                       "tests/reference/thruster_cm.py; compared with polhode by "
                       "tests/thruster_reference.rs.",
        "equation": "I_C w' = -w x (I_C w + g) - I_C' w - g' - Phi; I_C = I_h + J_F + m P(r) "
                    "- M P(c); g = m (r - c) x r' + mdot (r - c) x (r_e - r); Phi = mdot "
                    "(r_e - c) x (w x (r_e - c) - c') - (r_e - c) x F d + mdot (a^2/4)(w + d "
                    "d.w); M c = m r",
        "quaternion": "w, x, y, z; body -> inertial; w >= 0",
        "versions": {"numpy": np.__version__, "scipy": __import__("scipy").__version__,
                     "sympy": sp.__version__},
        "self_checks": {"fixed_origin": fixed, "tanks": tanks},
        "scenes": out_scenes,
    }
    with open(OUT, "w") as fh:
        json.dump(doc, fh, indent=1)
        fh.write("\n")
    print(f"wrote {os.path.normpath(OUT)} ({time.time() - t_start:.0f} s)")


if __name__ == "__main__":
    main()
