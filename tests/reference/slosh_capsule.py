#!/usr/bin/env python3
"""First lateral slosh mode of a capsule tank (a circular cylinder with hemispherical ends) by
finite elements: an independent solution of the potential problem that
`polhode::effectors::slosh_analog` solves by Rayleigh-Ritz on solid harmonics.

Problem (linear potential flow, flat free surface; Abramson, NASA SP-106, 1966, ch. 2): the
velocity potential psi = Phi(r, z) cos(phi) of azimuthal order 1 satisfies Laplace's equation
in the liquid, d(psi)/dn = 0 on the wetted wall and d(psi)/dz = kappa psi on the free surface,
with omega^2 = g kappa. Its weak form is the Rayleigh quotient

    kappa = min  int_V |grad psi|^2 dV / int_F psi^2 dA,
    int_V |grad psi|^2 dV = pi int int (Phi_r^2 + Phi_z^2 + Phi^2/r^2) r dr dz,
    int_F psi^2 dA       = pi int Phi(r, z_s)^2 r dr,

with Phi = 0 on the axis. Discretised here with linear triangles on a mapped grid
(r = s a(z), s in [0, 1], a(z) the wall radius; the bottom row collapses to the pole), the
interior unknowns condensed onto the free surface (Schur complement, sparse LU), and the
smallest eigenvalue of the condensed problem taken. From the mode, as the Rust module defines
them: C = pi int_F r Phi r dr, N = pi int_F Phi^2 r dr, the slosh mass over rho R^3
kappa C^2/N, and the pivot height z_s + (I_V + C)/(kappa C) with
I_V = pi int int ((z - z_s)(Phi_r + Phi/r) - r Phi_z) r dr dz.

Linear elements converge as h^2 (the polygonal wall too); each case is solved on three grids
(each twice as fine as the last) and Richardson-extrapolated, the error estimate being the
disagreement between the extrapolations from the two coarser and the two finer grids. The method is first checked against the
flat-bottomed cylinder's closed forms (SP-106 Table 6.1; Dodge, SwRI 2000, ch. 2).

Units: the tank radius R = 1; heights from the capsule's geometric centre (mid-barrel), the
Rust module's convention. Writes tests/data/slosh_capsule.json. Runs in about three minutes
(numpy, scipy: tests/reference/requirements.txt).
"""
import json
import math
import os
import sys

import numpy as np
import scipy.linalg
import scipy.sparse
import scipy.sparse.linalg

XI = 1.8411837813406593  # first zero of J1'

# Quadrature on the reference triangle (0,0),(1,0),(0,1): a collapsed (Duffy) Gauss product
# rule, which integrates the 1/r factor near an axis vertex without a node on the axis.
_G, _W = np.polynomial.legendre.leggauss(6)
_U = 0.5 * (_G + 1.0)
_WU = 0.5 * _W
TRI_POINTS = []
for i, u in enumerate(_U):
    for j, v in enumerate(_U):
        # (u, v) in the unit square -> (x, y) = (u (1 - v), u v), Jacobian u.
        TRI_POINTS.append((u * (1.0 - v), u * v, _WU[i] * _WU[j] * u))
TRI_POINTS = np.array(TRI_POINTS)


def capsule_wall(barrel):
    """Wall radius a(z) of a capsule with R = 1 and a barrel of length `barrel`, centred."""
    half = 0.5 * barrel

    def wall(z):
        if z < -half:
            return math.sqrt(max(0.0, 1.0 - (z + half) ** 2))
        if z > half:
            return math.sqrt(max(0.0, 1.0 - (z - half) ** 2))
        return 1.0

    return wall


def z_grid(pieces, per_unit):
    """Grid in z over consecutive pieces (z0, z1, kind, centre). 'dome' pieces lie on a unit
    sphere centred at z = centre and are graded uniformly in its polar angle, so that the wall
    a = sqrt(1 - (z - centre)^2) is resolved near a pole; 'uniform' is uniform in z."""
    zs = []
    for z0, z1, kind, centre in pieces:
        if z1 <= z0:
            continue
        if kind == "dome":
            t0 = math.acos(max(-1.0, min(1.0, centre - z0)))
            t1 = math.acos(max(-1.0, min(1.0, centre - z1)))
            n = max(2, int(math.ceil(per_unit * abs(t1 - t0) * 1.2)))
            pts = centre - np.cos(np.linspace(t0, t1, n + 1))
        else:
            n = max(2, int(math.ceil(per_unit * (z1 - z0))))
            pts = np.linspace(z0, z1, n + 1)
        if zs:
            pts = pts[1:]
        zs.extend(pts.tolist())
    return np.array(zs)


def solve(wall, zs, n_r):
    """The first mode on the mapped grid: returns kappa, C, N, I_V (pi kept)."""
    z_s = zs[-1]
    n_z = len(zs)
    radii = np.array([wall(z) for z in zs])
    s = np.linspace(0.0, 1.0, n_r + 1)
    # Node numbering: (j, i) -> j (n_r + 1) + i; nodes on the axis (i = 0) and at a
    # collapsed pole row (radius 0) are Dirichlet (Phi = 0).
    idx = lambda j, i: j * (n_r + 1) + i
    coords = np.zeros((n_z * (n_r + 1), 2))
    for j in range(n_z):
        coords[j * (n_r + 1):(j + 1) * (n_r + 1), 0] = s * radii[j]
        coords[j * (n_r + 1):(j + 1) * (n_r + 1), 1] = zs[j]
    fixed = np.zeros(len(coords), dtype=bool)
    fixed[coords[:, 0] < 1e-14] = True
    triangles = []
    for j in range(n_z - 1):
        for i in range(n_r):
            a, b, c, d = idx(j, i), idx(j, i + 1), idx(j + 1, i), idx(j + 1, i + 1)
            triangles.append((a, b, d))
            triangles.append((a, d, c))
    rows, cols, vals = [], [], []
    moment = np.zeros(len(coords))
    for tri in triangles:
        p = coords[list(tri)]
        e1, e2 = p[1] - p[0], p[2] - p[0]
        det = e1[0] * e2[1] - e1[1] * e2[0]
        area = 0.5 * abs(det)
        if area < 1e-15:
            continue
        # Gradients of the three linear shape functions (constant).
        inv = np.linalg.inv(np.array([[e1[0], e2[0]], [e1[1], e2[1]]]))
        grads = np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]]) @ inv  # rows: d/dr, d/dz
        local = np.zeros((3, 3))
        local_moment = np.zeros(3)
        for x, y, w in TRI_POINTS:
            n = np.array([1.0 - x - y, x, y])
            r, z = p[0] + x * e1 + y * e2
            weight = w * abs(det)
            local += weight * r * (grads @ grads.T)
            local += weight * np.outer(n, n) / r
            # (z - z_s)(Phi_r + Phi/r) - r Phi_z, times r.
            local_moment += weight * r * ((z - z_s) * (grads[:, 0] + n / r) - r * grads[:, 1])
        for a_ in range(3):
            moment[tri[a_]] += math.pi * local_moment[a_]
            for b_ in range(3):
                rows.append(tri[a_])
                cols.append(tri[b_])
                vals.append(math.pi * local[a_, b_])
    n_nodes = len(coords)
    k = scipy.sparse.csr_matrix((vals, (rows, cols)), shape=(n_nodes, n_nodes))
    # Free-surface matrices on the top row.
    top = [idx(n_z - 1, i) for i in range(n_r + 1)]
    m_surf = np.zeros((n_r + 1, n_r + 1))
    first = np.zeros(n_r + 1)
    g, w = np.polynomial.legendre.leggauss(4)
    r_top = coords[top, 0]
    for i in range(n_r):
        r0, r1 = r_top[i], r_top[i + 1]
        for gq, wq in zip(g, w):
            t = 0.5 * (gq + 1.0)
            r = r0 + t * (r1 - r0)
            n = np.array([1.0 - t, t])
            wt = 0.5 * wq * (r1 - r0) * r
            m_surf[i:i + 2, i:i + 2] += math.pi * wt * np.outer(n, n)
            first[i:i + 2] += math.pi * wt * r * n
    free = ~fixed
    surface = np.zeros(n_nodes, dtype=bool)
    surface[top] = True
    s_nodes = np.where(surface & free)[0]
    i_nodes = np.where(~surface & free)[0]
    k_ii = k[i_nodes][:, i_nodes].tocsc()
    k_is = k[i_nodes][:, s_nodes].toarray()
    k_ss = k[s_nodes][:, s_nodes].toarray()
    lu = scipy.sparse.linalg.splu(k_ii)
    x = lu.solve(k_is)
    schur = k_ss - k_is.T @ x
    schur = 0.5 * (schur + schur.T)
    top_free = [top.index(n) for n in s_nodes]
    m_ss = m_surf[np.ix_(top_free, top_free)]
    eigenvalues, vectors = scipy.linalg.eigh(schur, m_ss)
    kappa = eigenvalues[0]
    phi_s = vectors[:, 0]
    phi = np.zeros(n_nodes)
    phi[s_nodes] = phi_s
    phi[i_nodes] = -x @ phi_s
    c = first[top_free] @ phi_s
    norm = phi_s @ m_ss @ phi_s
    i_v = moment @ phi
    return kappa, c, norm, i_v, z_s


def mode(wall, pieces, base_r, base_z, levels=3):
    """Richardson-extrapolated kappa, slosh volume m_s/(rho R^3) and pivot height."""
    results = []
    for level in range(levels):
        f = 2 ** level
        zs = z_grid(pieces, base_z * f)
        kappa, c, norm, i_v, z_s = solve(wall, zs, base_r * f)
        if c < 0:
            c, i_v = -c, -i_v
        results.append(np.array([kappa, kappa * c * c / norm, z_s + (i_v + c) / (kappa * c)]))
    fine, mid = results[-1], results[-2]
    extrapolated = fine + (fine - mid) / 3.0  # h^2 convergence
    # Error estimate: the disagreement of the two extrapolations available (coarse-mid and
    # mid-fine), which bounds the next order's term of the finer one with margin.
    previous = mid + (mid - results[-3]) / 3.0
    error = np.abs(extrapolated - previous)
    return extrapolated, error, results


def cylinder_closed_form(depth):
    """Flat-bottomed cylinder (R = 1), bottom at z = 0: kappa, m_s/rho, pivot height."""
    x = XI * depth
    kappa = XI * math.tanh(x)
    slosh = math.pi * depth * 2.0 * math.tanh(x) / (XI * (XI * XI - 1.0) * depth)
    pivot = depth + (2.0 / math.sinh(x) - 1.0 / math.tanh(x)) / XI
    return np.array([kappa, slosh, pivot])


def capsule_pieces(barrel, surface):
    """The z pieces of the liquid in a capsule (R = 1, centred) up to the free surface
    `surface`, truncated nowhere (the reference solves the whole liquid)."""
    half = 0.5 * barrel
    bottom = -half - 1.0
    pieces = [(bottom, min(surface, -half), "dome", -half)]
    if surface > -half:
        pieces.append((-half, min(surface, half), "uniform", None))
    if surface > half:
        pieces.append((half, surface, "dome", half))
    return pieces


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    out = os.path.join(here, "..", "data", "slosh_capsule.json")
    base_r, base_z = 12, 12
    # Self-check on the flat-bottomed cylinder (closed forms): depth 0.5 R and 1.5 R.
    checks = []
    for depth in (0.5, 1.5):
        wall = lambda z: 1.0
        value, error, _ = mode(wall, [(0.0, depth, "uniform", None)], base_r, base_z)
        exact = cylinder_closed_form(depth)
        diff = np.abs(value - exact)
        print(f"cylinder h = {depth}: FEM {value}, closed form {exact}, |diff| {diff}, "
              f"estimate {error}")
        # The estimate must cover the true error (within a factor 3), else the reference's
        # error bars are not trustworthy.
        if np.any(diff > 3.0 * error + 1e-12):
            sys.exit(f"cylinder self-check failed at h = {depth}: {diff} vs {error}")
        checks.append({"depth": depth, "fem": value.tolist(), "closed_form": exact.tolist(),
                       "error_estimate": error.tolist()})
    cases = []
    # Capsules (R = 1): barrel lengths, and free-surface heights above the bottom pole.
    for barrel, depths in ((1.0, (0.6, 1.0, 1.3, 1.7, 2.0, 2.3, 2.7)),
                           (3.0, (1.2, 2.0, 3.5))):
        wall = capsule_wall(barrel)
        for depth in depths:
            surface = -0.5 * barrel - 1.0 + depth
            value, error, _ = mode(wall, capsule_pieces(barrel, surface), base_r, base_z)
            print(f"capsule barrel {barrel} depth {depth}: kappa {value[0]:.7f} "
                  f"m_s/rho {value[1]:.7f} pivot {value[2]:.7f}  (+- {error})")
            cases.append({"barrel": barrel, "depth": depth, "kappa": value[0],
                          "slosh_volume": value[1], "pivot_height": value[2],
                          "error_estimate": error.tolist()})
    doc = {
        "description": "First lateral slosh mode of capsule tanks (R = 1) by linear finite "
                       "elements with Richardson extrapolation (tests/reference/slosh_capsule.py)."
                       " kappa = omega^2 R/g; slosh_volume = m_s/(rho R^3); pivot_height from the"
                       " capsule's geometric centre, in R; depth of the free surface above the "
                       "bottom pole, in R.",
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "cylinder_checks": checks,
        "cases": cases,
    }
    with open(out, "w") as f:
        json.dump(doc, f, indent=1)
    print(f"wrote {os.path.normpath(out)}")


if __name__ == "__main__":
    main()
