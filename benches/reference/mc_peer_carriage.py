#!/usr/bin/env python3
"""A copy of ../shared/tools/mc_peer.py (the NumPy peer of `axcomp tolerance`) with the
carriage side added, so that the speed comparison with it is made on the same work (issue 15).
The lines that differ are marked "carriage side"; everything else is the peer as it is.

The carriage side (src/model/guideway.rs, SaddleFaces): each saddle's four carriage mounting
pads are off the plane of its datum face by e_i, which adds to the rail deviation under
carriage i and is the same at every position of the stroke. e = (-A - B + c, -A + B - c,
A + B + c, A - B - c) with A = D_a/2, B = D_b/2: D_a (across the rails) and D_b (along them)
each uniform in +-parallelism/2, the twist c uniform in +-flatness/2. The draws come from a
second generator, so the rail draws are the peer's own: with both tolerances 0 this prints
what mc_peer.py prints.

usage: mc_peer_carriage.py SAMPLES [SEED] [--baseline|--full]
                           [--carriage-parallelism MM] [--carriage-flatness MM]
prints JSON: samples, seconds, max_volumetric_um {mean, median, min, max, p90}"""
import json
import math
import sys
import time

import numpy as np
from scipy.interpolate import CubicSpline

STROKE = {"X": (0.0, 750.0), "Y": (0.0, 500.0), "Z": (-550.0, 0.0)}
AB = {"X": (350.0, 640.0), "Y": (604.0, 480.0), "Z": (316.0, 356.0)}
Z3, Z4, Y2, YT, ZT = 200.0, 80.0, 0.0, 280.0, 250.0
GRID = 50.0
PERIOD, MULT = 100.0, 0.5


def basis(knots, pts):
    """Matrix B (len(pts) x len(knots)): not-a-knot cubic spline through knots, evaluated at pts."""
    B = np.empty((len(pts), len(knots)))
    for j in range(len(knots)):
        e = np.zeros(len(knots))
        e[j] = 1.0
        B[:, j] = CubicSpline(knots, e, bc_type="not-a-knot")(pts)
    return B


def knots_for(lo, hi):
    n = int(math.ceil((hi - lo) / PERIOD)) + 1
    return np.linspace(lo, hi, n)


def walk(rng, n_samples, n_knots, tol):
    """Bounded random walk in the band [-tol/2, tol/2]: start uniform, steps m*U(-tol, tol), clipped."""
    v = np.empty((n_samples, n_knots))
    v[:, 0] = rng.uniform(-tol / 2, tol / 2, n_samples)
    steps = MULT * rng.uniform(-tol, tol, (n_samples, n_knots - 1))
    for j in range(1, n_knots):
        v[:, j] = np.clip(v[:, j - 1] + steps[:, j - 1], -tol / 2, tol / 2)
    return v


def study(n, seed, straight=0.03, positioning=0.0, squareness=0.0, parallelism=0.0, flatness=0.0,
          chunk=5000):
    rng = np.random.default_rng(seed)
    carriage_rng = np.random.default_rng([seed, 1])  # carriage side
    grids = {ax: np.arange(lo, hi + 1e-9, GRID) for ax, (lo, hi) in STROKE.items()}
    pre = {}
    for ax, (lo, hi) in STROKE.items():
        a, b = AB[ax]
        g = grids[ax]
        rk = knots_for(lo - b / 2, hi + b / 2)
        pk = knots_for(lo, hi)
        pre[ax] = (rk, basis(rk, g - b / 2), basis(rk, g + b / 2), pk, basis(pk, g), a, b)
    X, Y, Z = np.meshgrid(grids["X"], grids["Y"], grids["Z"], indexing="ij")
    out = []
    done = 0
    while done < n:
        m = min(chunk, n - done)
        E = {}
        for ax in "XYZ":
            rk, Bm, Bp, pk, Bpos, a, b = pre[ax]
            r1v, r1h, r2v, r2h = (walk(rng, m, len(rk), straight) for _ in range(4))
            dz1, dz2, dz3, dz4 = r1v @ Bm.T, r1v @ Bp.T, r2v @ Bp.T, r2v @ Bm.T
            # carriage side: the saddle's pads, one value per machine, added at every position
            A, B = (carriage_rng.uniform(-parallelism / 2, parallelism / 2, (m, 1)) / 2 for _ in range(2))
            c = carriage_rng.uniform(-flatness / 2, flatness / 2, (m, 1))
            dz1, dz2, dz3, dz4 = dz1 - A - B + c, dz2 - A + B - c, dz3 + A + B + c, dz4 + A - B - c
            dy1, dy2, dy3, dy4 = r1h @ Bm.T, r1h @ Bp.T, r2h @ Bp.T, r2h @ Bm.T
            z5 = (dz1 + dz2 + dz3 + dz4) / 4
            y5 = (dy1 + dy2 + dy3 + dy4) / 4
            roll = ((dz3 + dz4) - (dz1 + dz2)) / (2 * a)
            pitch = ((dz2 + dz3) - (dz1 + dz4)) / (2 * b)
            yaw = ((dy1 + dy4) - (dy2 + dy3)) / (2 * b)
            pos = walk(rng, m, len(pk), positioning) @ Bpos.T if positioning > 0 else np.zeros_like(z5)
            E[ax] = dict(pos=pos, z5=z5, y5=y5, roll=roll, pitch=pitch, yaw=yaw)
        sq = [rng.uniform(-squareness, squareness, m) if squareness > 0 else np.zeros(m) for _ in range(3)]
        EXOY, EXOZ, EYOZ = (s[:, None, None, None] for s in sq)
        ex, ey, ez = E["X"], E["Y"], E["Z"]
        # Tab. 3.2 mapping (signs +1)
        EXX, EYX, EZX, EAX, EBX, ECX = ex["pos"], ex["y5"], ex["z5"], ex["roll"], ex["pitch"], ex["yaw"]
        EYY, EXY, EZY, EBY, EAY, ECY = ey["pos"], ey["y5"], ey["z5"], ey["roll"], ey["pitch"], ey["yaw"]
        EZZ, EXZ, EYZ, ECZ, EAZ, EBZ = ez["pos"], ez["y5"], ez["z5"], ez["roll"], ez["pitch"], ez["yaw"]
        bx = lambda v: v[:, :, None, None]   # noqa: E731  function of X
        by = lambda v: v[:, None, :, None]   # noqa: E731  function of Y
        bz = lambda v: v[:, None, None, :]   # noqa: E731  function of Z
        Xg, Yg, Zg = X[None], Y[None], Z[None]
        Ex = (bx(EXX) + by(EXY) + bz(EXZ) + bx(EBX) * (Zg + Z4 + 550) + by(EBY) * (Zg + Z3 + Z4 + 550)
              - bz(EBZ) * ZT + bx(ECX) * (Yg - 250) + by(ECY) * (Yg - Y2 - 250) + bz(ECZ) * YT
              + EXOY * (Yg - 250) + EXOZ * (Zg - ZT))
        Ey = (bx(EYX) + by(EYY) + bz(EYZ) - bx(EAX) * (Zg + Z4 + 550) - by(EAY) * (Zg + Z3 + Z4 + 550)
              + bz(EAZ) * ZT + EXOY * Xg + EYOZ * (ZT - Zg))
        Ez = (bx(EZX) + by(EZY) + bz(EZZ) + bx(EAX) * (250 - Yg) + by(EAY) * (Y2 + 250 - Yg)
              - bz(EAZ) * YT - EYOZ * YT)
        # origin reference: the grid point X=0, Y=0, Z=0 is the last Z index (Z grid ends at 0)
        i0 = (0, 0, len(grids["Z"]) - 1)
        Ex = Ex - Ex[:, i0[0], i0[1], i0[2]][:, None, None, None]
        Ey = Ey - Ey[:, i0[0], i0[1], i0[2]][:, None, None, None]
        Ez = Ez - Ez[:, i0[0], i0[1], i0[2]][:, None, None, None]
        mx = np.sqrt(Ex * Ex + Ey * Ey + Ez * Ez).reshape(m, -1).max(axis=1)
        out.append(mx)
        done += m
    v = np.concatenate(out) * 1000.0
    return {"mean": float(v.mean()), "median": float(np.median(v)), "min": float(v.min()),
            "max": float(v.max()), "p90": float(np.percentile(v, 90))}


if __name__ == "__main__":
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 50000
    seed = int(sys.argv[2]) if len(sys.argv) > 2 and not sys.argv[2].startswith("--") else 1
    full = "--full" in sys.argv

    def option(name):  # carriage side
        return float(sys.argv[sys.argv.index(name) + 1]) if name in sys.argv else 0.0

    t0 = time.perf_counter()
    r = study(n, seed, positioning=0.01 if full else 0.0, squareness=30e-6 if full else 0.0,
              parallelism=option("--carriage-parallelism"), flatness=option("--carriage-flatness"))
    dt = time.perf_counter() - t0
    print(json.dumps({"samples": n, "seconds": dt, "max_volumetric_um": r}))
