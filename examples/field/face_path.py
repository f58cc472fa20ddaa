#!/usr/bin/env python3
"""The elastic stress path of a tunnel section as the face goes by, for bbm's
excavate stage (support_path; docs/field.md, "The face's stress path").

A circular tunnel of radius a in an infinite elastic rock, its axis along z, its
face at z = 0 (excavated for z < 0): one quarter of it (the planes x = 0 and y = 0
are planes of symmetry for in-situ stresses along the axes), meshed by trilinear
hexahedra on an O-grid, fixed at r = R and held in z at z = +-L. The excavation's
loads are the in-situ tractions taken off the tunnel's wall and face. Three unit
in-situ stresses are solved (sxx, syy, szz = 1); a tunnel along a principal
stress has, by the axial symmetry of its geometry, the in-plane part of every
other in-situ stress as a rotation of these.

What it writes is what a plane section can carry of the three-dimensional path:
the wall's radial displacement in its two Fourier modes (mode 0 from the mean
in-plane stress p and from szz, mode 2 from the in-plane deviator q), as
fractions of the plane-strain values far behind the face, and from them the
fictitious supports a plane-strain section needs to follow them: the mean's and
the deviator's, k0(d) = 1 - u0(d)/u0(-inf) and k2(d) = 1 - u2(d)/u2(-inf)
(Panet's convergence-confinement generalised to the two modes). It also prints
the in-plane and out-of-plane stresses at the wall ahead of the face for a given
in-situ tensor (by default the Mine-by's): how much they rise and turn.

Checks (printed; --check makes a miss the exit status): far behind the face, the
plane-strain wall displacement of the mean against the thick-walled cylinder's
closed form and of the deviator against Kirsch's, and Kirsch's hoop stress; ahead
of it, the hydrostatic longitudinal displacement profile against Vlachopoulos &
Diederichs (2009), whose closed form fits axisymmetric elastic models.

Needs numpy and scipy (Debian: python3-numpy, python3-scipy). About 2 minutes.
Run: python3 examples/field/face_path.py [--szz-over-p 1.29] [--fine]
"""
import argparse
import math
import sys

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla


def graded(first, growth, largest, length):
    """Spacings from `first`, growing by `growth` up to `largest`, that sum to `length`."""
    h, out = first, []
    while sum(out) < length:
        out.append(h)
        h = min(h * growth, largest)
    out = np.array(out)
    return out * (length / out.sum())


def section(m, radii):
    """The quarter section's nodes (x, y) and quads: the core (the quarter disc
    r < 1, an m x m grid mapped onto it) and the ring outside (the same 2m + 1
    angles at every radius). Returns nodes, core quads, ring quads, the ring's
    node index [radius, angle] and the core's [i, j]."""
    nodes = []
    core_id = np.zeros((m + 1, m + 1), dtype=int)
    for i in range(m + 1):
        for j in range(m + 1):
            s, t = i / m, j / m
            # The elliptical square-to-disc map keeps the two symmetry planes.
            nodes.append((s * math.sqrt(1 - t * t / 2), t * math.sqrt(1 - s * s / 2)))
            core_id[i, j] = len(nodes) - 1
    # The disc's edge, from angle 0 to 90 degrees: along s = 1, then t = 1.
    edge = [core_id[m, j] for j in range(m + 1)] + [core_id[i, m] for i in range(m - 1, -1, -1)]
    angles = [math.atan2(nodes[k][1], nodes[k][0]) for k in edge]
    ring_id = np.zeros((len(radii), len(edge)), dtype=int)
    ring_id[0] = edge
    for a, r in enumerate(radii[1:], start=1):
        for b, th in enumerate(angles):
            nodes.append((r * math.cos(th), r * math.sin(th)))
            ring_id[a, b] = len(nodes) - 1
    core = [(core_id[i, j], core_id[i + 1, j], core_id[i + 1, j + 1], core_id[i, j + 1])
            for i in range(m) for j in range(m)]
    ring = [(ring_id[a, b], ring_id[a + 1, b], ring_id[a + 1, b + 1], ring_id[a, b + 1])
            for a in range(len(radii) - 1) for b in range(len(edge) - 1)]
    # Counter-clockwise in (x, y) for positive volumes.
    def ccw(q):
        p = [nodes[k] for k in q]
        area = sum(p[k][0] * p[(k + 1) % 4][1] - p[(k + 1) % 4][0] * p[k][1] for k in range(4))
        return q if area > 0 else q[::-1]
    return np.array(nodes), [ccw(q) for q in core], [ccw(q) for q in ring], ring_id, np.array(angles)


GP = np.array([-1, 1]) / math.sqrt(3)
CORNERS = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                    [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=float)


def shape_derivatives(xi):
    """dN/dxi (8 x 3) of the trilinear hexahedron at xi."""
    d = np.zeros((8, 3))
    for k, c in enumerate(CORNERS):
        f = 1 + c * xi
        d[k, 0] = c[0] * f[1] * f[2] / 8
        d[k, 1] = c[1] * f[0] * f[2] / 8
        d[k, 2] = c[2] * f[0] * f[1] / 8
    return d


def elasticity(E, nu):
    lam, G = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    D = np.zeros((6, 6))
    D[:3, :3] = lam
    D[np.arange(3), np.arange(3)] += 2 * G
    D[np.arange(3, 6), np.arange(3, 6)] = G
    return D


def b_matrices(X, points):
    """B (ne, npts, 6, 24) and det J (ne, npts) at the natural points."""
    ne = X.shape[0]
    Bs, dets = [], []
    for xi in points:
        dN = shape_derivatives(np.array(xi))                     # 8 x 3
        J = np.einsum("kd,ekx->edx", dN, X)                      # ne x 3 x 3: dX/dxi
        dets.append(np.linalg.det(J))
        dNx = np.einsum("kd,exd->ekx", dN, np.linalg.inv(J))     # dN/dx
        B = np.zeros((ne, 6, 24))
        B[:, 0, 0::3] = dNx[:, :, 0]
        B[:, 1, 1::3] = dNx[:, :, 1]
        B[:, 2, 2::3] = dNx[:, :, 2]
        B[:, 3, 0::3], B[:, 3, 1::3] = dNx[:, :, 1], dNx[:, :, 0]   # gamma_xy
        B[:, 4, 1::3], B[:, 4, 2::3] = dNx[:, :, 2], dNx[:, :, 1]   # gamma_yz
        B[:, 5, 0::3], B[:, 5, 2::3] = dNx[:, :, 2], dNx[:, :, 0]   # gamma_xz
        Bs.append(B)
    return np.stack(Bs, axis=1), np.stack(dets, axis=1)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--young", type=float, default=69e9)
    ap.add_argument("--poisson", type=float, default=0.26)
    ap.add_argument("--stress", type=float, nargs=4, default=[-57.13e6, -13.87e6, -11.50e6, -45e6],
                    metavar=("SXX", "SYY", "SXY", "SZZ"),
                    help="in-situ stress in the section's axes and along the tunnel (Pa, tension positive; default the "
                         "Mine-by's)")
    ap.add_argument("--fine", action="store_true", help="a mesh 1.5 times as fine each way (the convergence check; about 10 minutes, 6 GB)")
    ap.add_argument("--coarse", action="store_true", help="a mesh about half as fine each way (a quick look)")
    ap.add_argument("--check", action="store_true",
                    help="exit with status 1 if a check misses its tolerance (the test suite runs --coarse --check)")
    ap.add_argument("--table", type=float, nargs="+",
                    default=[6, 4, 3, 2, 1.5, 1, 0.75, 0.5, 0.25, 0.1, -0.1, -0.25, -0.5, -0.75, -1, -1.5, -2, -3, -4, -5],
                    help="distances ahead of the face, in radii, of the table's rows (negative: behind)")
    args = ap.parse_args()
    E, nu = args.young, args.poisson
    G = E / (2 * (1 + nu))
    f = 1.5 if args.fine else 0.5 if args.coarse else 1
    R, L = 25.0, 10.0
    radii = 1 + np.concatenate([[0], np.cumsum(graded(0.04 / f, 1 + 0.15 / f, 2.0, R - 1))])
    m = int(12 * f)
    xy, core_q, ring_q, ring_id, angles = section(m, radii)
    dz_b = graded(0.04 / f, 1 + 0.12 / f, 0.6, L)
    zs = np.concatenate([-np.cumsum(dz_b)[::-1], [0.0], np.cumsum(dz_b)])
    nxy, nz = len(xy), len(zs)
    coords = np.column_stack([np.tile(xy, (nz, 1)), np.repeat(zs, nxy)])
    nid = lambda k, layer: layer * nxy + k
    hexes = []
    for layer in range(nz - 1):
        zc = 0.5 * (zs[layer] + zs[layer + 1])
        quads = ring_q + (core_q if zc > 0 else [])
        for q in quads:
            hexes.append([nid(k, layer) for k in q] + [nid(k, layer + 1) for k in q])
    hexes = np.array(hexes)
    used = np.unique(hexes)
    renum = -np.ones(len(coords), dtype=int)
    renum[used] = np.arange(len(used))
    coords, hexes = coords[used], renum[hexes]
    nn, ne = len(coords), len(hexes)
    print(f"mesh: {nn} nodes, {ne} hexahedra, {3 * nn} unknowns; wall {len(angles) - 1} x 90 degrees, "
          f"first ring {radii[1] - 1:.3f} a, first slice {dz_b[0]:.3f} a", flush=True)

    D = elasticity(E, nu)
    X = coords[hexes]
    gps = [(a, b, c) for a in GP for b in GP for c in GP]
    B, det = b_matrices(X, gps)
    assert (det > 0).all(), "inverted hexahedron"
    Ke = np.einsum("egji,jk,egkl,eg->eil", B, D, B, det)
    dofs = (3 * hexes[:, :, None] + np.arange(3)).reshape(ne, 24)
    K = sp.coo_matrix((Ke.ravel(), (np.repeat(dofs, 24, axis=1).ravel(), np.tile(dofs, (1, 24)).ravel())),
                      shape=(3 * nn, 3 * nn)).tocsc()

    # Loads: minus the in-situ traction sigma.n on the wall (r = 1, z < 0) and the
    # face (z = 0, r < 1), n the rock's outward normal; per unit stress component.
    r = np.hypot(coords[:, 0], coords[:, 1])
    on_wall = (np.abs(r - 1) < 1e-9) & (coords[:, 2] < 1e-9)
    on_face = (np.abs(coords[:, 2]) < 1e-9) & (r < 1 + 1e-9)
    faces = []  # (4 nodes, outward normal's sign check)
    for h in hexes:
        for quad in ([0, 1, 2, 3], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]):
            ids = h[quad]
            if on_wall[ids].all() or on_face[ids].all():
                faces.append((ids, coords[h].mean(axis=0)))
    unit = {"sxx": np.diag([1.0, 0, 0]), "syy": np.diag([0, 1.0, 0]), "szz": np.diag([0, 0, 1.0])}
    F = {k: np.zeros(3 * nn) for k in unit}
    for ids, inside in faces:
        P = coords[ids]
        for a, b in [(x, y) for x in GP for y in GP]:
            N = np.array([(1 - a) * (1 - b), (1 + a) * (1 - b), (1 + a) * (1 + b), (1 - a) * (1 + b)]) / 4
            dNa = np.array([-(1 - b), (1 - b), (1 + b), -(1 + b)]) / 4
            dNb = np.array([-(1 - a), -(1 + a), (1 + a), (1 - a)]) / 4
            nA = np.cross(dNa @ P, dNb @ P)                      # n dA
            if np.dot(nA, N @ P - inside) < 0:
                nA = -nA                                         # outward from the rock
            for k, S in unit.items():
                t = -S @ nA
                for node, w in zip(ids, N):
                    F[k][3 * node:3 * node + 3] += w * t
    # Supports: x = 0 and y = 0 planes of symmetry, r = R fixed, z = +-L held in z.
    fixed = np.zeros(3 * nn, dtype=bool)
    fixed[3 * np.where(np.abs(coords[:, 0]) < 1e-9)[0]] = True
    fixed[3 * np.where(np.abs(coords[:, 1]) < 1e-9)[0] + 1] = True
    outer = np.where(np.abs(r - R) < 1e-6)[0]
    for c in range(3):
        fixed[3 * outer + c] = True
    fixed[3 * np.where(np.abs(np.abs(coords[:, 2]) - L) < 1e-9)[0] + 2] = True
    free = np.where(~fixed)[0]
    print(f"solving ({len(free)} free unknowns) ...", flush=True)
    Kf = K[free][:, free].tocsr()
    # Conjugate gradients, Jacobi-preconditioned: a direct factorisation of a 3D
    # mesh this size takes scipy's SuperLU far longer.
    Minv = spla.LinearOperator(Kf.shape, matvec=lambda x, d=1 / Kf.diagonal(): d * x)
    U = {}
    for k in unit:
        u = np.zeros(3 * nn)
        b = F[k][free]
        its = [0]
        x, info = spla.cg(Kf, b, tol=1e-10, maxiter=20000, M=Minv, callback=lambda _: its.__setitem__(0, its[0] + 1))
        res = np.linalg.norm(Kf @ x - b) / np.linalg.norm(b)
        print(f"  {k}: {its[0]} iterations, residual {res:.1e}", flush=True)
        if info != 0 or res > 1e-8:
            sys.exit(f"face_path.py: conjugate gradients did not converge for {k} (residual {res:.1e})")
        u[free] = x
        U[k] = u.reshape(nn, 3)

    # The wall's radial displacement by slice, fitted by A0 + A2 cos 2 theta.
    wall_nodes = np.where(np.abs(r - 1) < 1e-9)[0]
    slices = np.unique(np.round(coords[wall_nodes, 2], 9))
    def modes(u, z):
        ids = wall_nodes[np.abs(coords[wall_nodes, 2] - z) < 1e-9]
        th = np.arctan2(coords[ids, 1], coords[ids, 0])
        ur = u[ids, 0] * np.cos(th) + u[ids, 1] * np.sin(th)
        A = np.column_stack([np.ones_like(th), np.cos(2 * th)])
        return np.linalg.lstsq(A, ur, rcond=None)[0]
    # Unit mean p = 1 (sxx = syy = 1), deviator q = 1 (sxx = -syy = 1), szz = 1.
    prof = []
    for z in slices:
        mx, my, mz = modes(U["sxx"], z), modes(U["syy"], z), modes(U["szz"], z)
        prof.append((z, mx[0] + my[0], mx[1] - my[1], mz[0]))
    prof = np.array(prof)
    far = prof[np.argmin(np.abs(prof[:, 0] + L / 2))]
    # Excavation-induced displacement (tension positive: unloading a tensile in-situ
    # stress moves the wall outwards): a unit mean, a / 2G in infinite rock; held at
    # r = R, the thick-walled cylinder's (1 - a²/R²) / (1 + a²/R² / (1 - 2 nu)).
    bounded = (1 - R**-2) / (1 + R**-2 / (1 - 2 * nu))
    print(f"\nplane strain far behind (z = {far[0]:.1f} a): mean mode {far[1] * 2 * G:.4f} x a/2G (closed form, held "
          f"at {R:g} a: {bounded:.4f}); deviator mode {far[2] * 2 * G:.4f} x a/2G (Kirsch in infinite rock: 3 - 4 nu = "
          f"{3 - 4 * nu:.4f}); szz's {far[3] * 2 * G:+.4f} (0)")
    checks = [("the mean's plane-strain wall displacement within 2% of the closed form",
               abs(far[1] * 2 * G / bounded - 1) < 0.02),
              ("the deviator's within 6% of Kirsch's", abs(far[2] * 2 * G / (3 - 4 * nu) - 1) < 0.06)]

    # Hoop stress at the wall far behind the face, from the first two rings'
    # elements extrapolated to r = a, against Kirsch's for a unit sxx: 1 - 2 cos 2 theta.
    centres = X.mean(axis=1)
    cr = np.hypot(centres[:, 0], centres[:, 1])
    B_centre = b_matrices(X, [(0, 0, 0)])[0][:, 0]
    stress_of = lambda u: np.einsum("eij,ej->ei", B_centre, u[hexes].reshape(ne, 24)) @ D.T
    sig = stress_of(U["sxx"])
    def hoop(sv, c):
        th = math.atan2(c[1], c[0])
        ct, st = math.cos(th), math.sin(th)
        return sv[0] * st * st + sv[1] * ct * ct - 2 * sv[3] * st * ct
    rows = []
    zf = -L / 2
    spans = (X[:, :, 2].min(axis=1) < zf) & (X[:, :, 2].max(axis=1) >= zf)
    near = lambda k: np.where(spans & (cr > radii[k]) & (cr < radii[k + 1]))[0]
    first, second = near(0), near(1)
    for e1 in first:
        th = math.atan2(centres[e1, 1], centres[e1, 0])
        e2 = second[np.argmin(np.abs(np.arctan2(centres[second, 1], centres[second, 0]) - th)
                               + np.abs(centres[second, 2] - centres[e1, 2]))]
        h1, h2 = hoop(sig[e1] + [1, 0, 0, 0, 0, 0], centres[e1]), hoop(sig[e2] + [1, 0, 0, 0, 0, 0], centres[e2])
        r1, r2 = cr[e1], cr[e2]
        rows.append((math.degrees(th), h1 + (h1 - h2) * (r1 - 1) / (r2 - r1), 1 - 2 * math.cos(2 * th)))
    rows = np.array(sorted(rows))
    err = np.abs(rows[:, 1] - rows[:, 2]).max()
    print(f"hoop stress at the wall far behind, unit sxx: at 0 deg {rows[0, 1]:+.3f} (Kirsch -1), at 90 deg "
          f"{rows[-1, 1]:+.3f} (3); largest difference over the wall {err:.3f} (of 3)")
    checks.append(("Kirsch's hoop stress within 5% of 3 all round the wall", err < 0.15))

    # The longitudinal profile of the mean mode for szz = p against V&D 2009.
    u_inf_p, u_inf_q = far[1], far[2]
    print("\nd/a (ahead +)   mean p: u/u_inf  [V&D 2009]   szz: u/u_inf(p)   deviator: u/u_inf")
    ldp_off = 0.0
    for d in [3, 2, 1, 0.5, 0, -0.5, -1, -2, -3, -4]:
        row = prof[np.argmin(np.abs(prof[:, 0] - d))]  # ahead of the face: z > 0
        x = -d
        vd = (1 / 3) * math.exp(-0.15) * (math.exp(x) if x < 0 else 1) if x <= 0 else \
            1 - (1 - (1 / 3) * math.exp(-0.15)) * math.exp(-3 * x / 2)
        print(f"{d:+6.2f}          {(row[1] + row[3]) / u_inf_p:7.3f}   [{vd:.3f}]      {row[3] / u_inf_p:+7.3f}"
              f"          {row[2] / u_inf_q:7.3f}")
        if d in (1, 2):
            ldp_off = max(ldp_off, abs((row[1] + row[3]) / u_inf_p - vd))
    checks.append(("the hydrostatic profile 1 and 2 radii ahead of the face within 0.03 of V&D 2009's", ldp_off < 0.03))

    # The stress path at the wall where the notch forms: across the largest in-plane
    # stress (in its principal axes, theta' = 90 degrees: the plane x = 0), by slice,
    # extrapolated from the first two rings to r = a. Tension positive.
    sxx, syy, sxy, szz = args.stress
    mean, half = 0.5 * (sxx + syy), math.hypot(0.5 * (sxx - syy), sxy)
    s_major, s_minor = mean - half, mean + half                  # most compressive first
    insitu = np.array([s_major, s_minor, szz, 0, 0, 0])
    total = s_major * stress_of(U["sxx"]) + s_minor * stress_of(U["syy"]) + szz * stress_of(U["szz"]) + insitu
    at_roof = lambda k: np.where((cr > radii[k]) & (cr < radii[k + 1]) &
                                 (np.arctan2(centres[:, 1], centres[:, 0]) > math.radians(90) - 0.75 * math.pi / 2 / len(angles)))[0]
    ring1, ring2 = at_roof(0), at_roof(1)
    print(f"\nstress at the wall across the largest in-plane stress ({-s_major / 1e6:.1f} MPa; the roof's notch), "
          "compression positive, MPa")
    print("d/a (ahead +)   s1     s2     s3   | in plane: s_tt   s_rr  | s1 out of the section's plane")
    for zc in [3, 2, 1.5, 1, 0.75, 0.5, 0.25, 0.1, -0.1, -0.25, -0.5, -1, -2, -3]:
        e1 = ring1[np.argmin(np.abs(centres[ring1, 2] - zc))]
        e2 = ring2[np.argmin(np.abs(centres[ring2, 2] - centres[e1, 2]))]
        w = (cr[e1] - 1) / (cr[e2] - cr[e1])
        v = total[e1] + (total[e1] - total[e2]) * w
        T = -np.array([[v[0], v[3], v[5]], [v[3], v[1], v[4]], [v[5], v[4], v[2]]]) / 1e6
        vals, vecs = np.linalg.eigh(T)
        tilt = math.degrees(math.asin(min(1.0, abs(vecs[2, 2]))))
        print(f"{centres[e1, 2]:+6.2f}      {vals[2]:6.1f} {vals[1]:6.1f} {vals[0]:6.1f} |     {T[0, 0]:6.1f} {T[1, 1]:6.1f} "
              f"| {tilt:4.0f} degrees")
    print(f"(plane strain, Kirsch, at the wall: s_tt = {-(3 * s_major - s_minor) / 1e6:.1f} MPa)")

    # The wall's hoop stress by element layer, fitted by A0 + A2 cos 2 theta (the
    # first two rings extrapolated to r = a), per unit case: excavation-induced.
    theta_c = np.arctan2(centres[:, 1], centres[:, 0])
    layer_z = np.round(centres[:, 2], 9)
    in1 = (cr > radii[0]) & (cr < radii[1])
    in2 = (cr > radii[1]) & (cr < radii[2])
    def hoop_of(sv):
        c, sn = np.cos(theta_c), np.sin(theta_c)
        return sv[:, 0] * sn * sn + sv[:, 1] * c * c - 2 * sv[:, 3] * sn * c
    hoops = {k: hoop_of(stress_of(U[k])) for k in unit}
    layers = np.unique(layer_z[in1])
    hoop_prof = []
    for z in layers:
        e1 = np.where(in1 & (layer_z == z))[0]
        e2 = np.where(in2 & (layer_z == z))[0]
        e1, e2 = e1[np.argsort(theta_c[e1])], e2[np.argsort(theta_c[e2])]
        w = (cr[e1] - 1) / (cr[e2] - cr[e1])
        A = np.column_stack([np.ones(len(e1)), np.cos(2 * theta_c[e1])])
        fit = {k: np.linalg.lstsq(A, h[e1] + (h[e1] - h[e2]) * w, rcond=None)[0] for k, h in hoops.items()}
        hoop_prof.append((z, fit["sxx"][0] + fit["syy"][0], fit["sxx"][1] - fit["syy"][1], fit["szz"][0]))
    hoop_prof = np.array(hoop_prof)
    hfar = hoop_prof[np.argmin(np.abs(hoop_prof[:, 0] + L / 2))]
    print(f"\nexcavation-induced hoop stress at the wall far behind, per unit: mean mode {hfar[1]:+.4f} (plane strain "
          f"+1: 2p less the in-situ p), deviator mode {hfar[2]:+.4f} (-3: Kirsch's -4q cos 2 theta less the in-situ's "
          f"-q cos 2 theta), "
          f"szz's {hfar[3]:+.4f} (0)")

    # The tables for bbm: for the given in-situ stress, the fictitious supports of
    # the mean (k0) and the deviator (k2) at the distances asked, matched on the
    # wall's hoop stress (the stress path where notches and side walls fail) and,
    # for comparison, on its radial displacement (the convergence-confinement
    # method's longitudinal displacement profile).
    p = 0.5 * (sxx + syy)
    print(f"\nsupport_path for sxx {sxx / 1e6:.2f}, syy {syy / 1e6:.2f}, sxy {sxy / 1e6:.2f}, szz {szz / 1e6:.2f} MPa "
          f"(mean p {p / 1e6:.2f} MPa; k0 counts szz's share in the mean mode)")
    print("d/a     hoop-matched: k_mean  k_deviator   displacement-matched: k_mean  k_deviator")
    tables = {"hoop": [], "displacement": []}
    for d in args.table:
        row = prof[np.argmin(np.abs(prof[:, 0] - d))]
        k0u = 1 - (p * row[1] + szz * row[3]) / (p * u_inf_p)
        k2u = 1 - row[2] / u_inf_q
        hrow = hoop_prof[np.argmin(np.abs(hoop_prof[:, 0] - d))]
        k0h = 1 - (p * hrow[1] + szz * hrow[3]) / (p * hfar[1])
        k2h = 1 - hrow[2] / hfar[2]
        # The first row is the face far ahead: the in-situ support (the mesh's
        # within 0.5% of it at 6 a); the last far behind: none left.
        if d == args.table[0]:
            k0u = k2u = k0h = k2h = 1.0
        if d == args.table[-1]:
            k0u = k2u = k0h = k2h = 0.0
        tables["hoop"].append((d, k0h, k2h))
        tables["displacement"].append((d, k0u, k2u))
        print(f"{d:+5.2f}                {k0h:8.4f}  {k2h:8.4f}                         {k0u:8.4f}  {k2u:8.4f}")
    for name, table in tables.items():
        print(f"\n# {name}-matched; rows equally spaced in the face's advance, from {table[0][0]:+g} a to "
              f"{table[-1][0]:+g} a")
        d0, d1 = table[0][0], table[-1][0]
        print("support_path = [" + ", ".join(f"[{(d0 - d) / (d0 - d1):.4g}, {k0:.4f}, {k2:.4f}]" for d, k0, k2 in table)
              + "]")
    print()
    for what, ok in checks:
        print(("ok      " if ok else "MISSED  ") + what)
    if args.check and not all(ok for _, ok in checks):
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
