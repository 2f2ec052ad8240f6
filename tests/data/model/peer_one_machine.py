#!/usr/bin/env python3
# Reference values for src/model/monte_carlo.rs `one_machine_matches_the_numpy_peer`:
# run from anywhere with `python3 tests/data/model/peer_one_machine.py` (needs numpy, scipy).
# One deterministic machine through the NumPy peer's model (mc_peer.py), walks given by a formula.
import math, pathlib, sys
import numpy as np
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[3] / "../shared/tools"))
import mc_peer as P

def walk_value(axis, rail, j):
    # rail 0..3 = rail1 normal, rail1 lateral, rail2 normal, rail2 lateral; 4 = positioning
    return 0.5 * math.sin(1.3 * j + 0.7 * rail + 2.1 * axis + 0.4)

straight, positioning = 0.03, 0.01
sq = [30e-6 * 0.8, -30e-6 * 0.35, 30e-6 * 0.6]
grids = {ax: np.arange(lo, hi + 1e-9, P.GRID) for ax, (lo, hi) in P.STROKE.items()}
E = {}
for k, ax in enumerate("XYZ"):
    lo, hi = P.STROKE[ax]
    a, b = P.AB[ax]
    g = grids[ax]
    rk = P.knots_for(lo - b / 2, hi + b / 2)
    pk = P.knots_for(lo, hi)
    Bm, Bp, Bpos = P.basis(rk, g - b / 2), P.basis(rk, g + b / 2), P.basis(pk, g)
    w = [np.array([walk_value(k, r, j) for j in range(len(rk))]) * straight for r in range(4)]
    wp = np.array([walk_value(k, 4, j) for j in range(len(pk))]) * positioning
    r1v, r1h, r2v, r2h = w
    dz1, dz2, dz3, dz4 = Bm @ r1v, Bp @ r1v, Bp @ r2v, Bm @ r2v
    dy1, dy2, dy3, dy4 = Bm @ r1h, Bp @ r1h, Bp @ r2h, Bm @ r2h
    E[ax] = dict(pos=Bpos @ wp, z5=(dz1 + dz2 + dz3 + dz4) / 4, y5=(dy1 + dy2 + dy3 + dy4) / 4,
                 roll=((dz3 + dz4) - (dz1 + dz2)) / (2 * a), pitch=((dz2 + dz3) - (dz1 + dz4)) / (2 * b),
                 yaw=((dy1 + dy4) - (dy2 + dy3)) / (2 * b))
X, Y, Z = np.meshgrid(grids["X"], grids["Y"], grids["Z"], indexing="ij")
ex, ey, ez = E["X"], E["Y"], E["Z"]
EXX, EYX, EZX, EAX, EBX, ECX = ex["pos"], ex["y5"], ex["z5"], ex["roll"], ex["pitch"], ex["yaw"]
EYY, EXY, EZY, EBY, EAY, ECY = ey["pos"], ey["y5"], ey["z5"], ey["roll"], ey["pitch"], ey["yaw"]
EZZ, EXZ, EYZ, ECZ, EAZ, EBZ = ez["pos"], ez["y5"], ez["z5"], ez["roll"], ez["pitch"], ez["yaw"]
EXOY, EXOZ, EYOZ = sq
bx = lambda v: v[:, None, None]; by = lambda v: v[None, :, None]; bz = lambda v: v[None, None, :]
Z3, Z4, Y2, YT, ZT = P.Z3, P.Z4, P.Y2, P.YT, P.ZT
Ex = (bx(EXX) + by(EXY) + bz(EXZ) + bx(EBX) * (Z + Z4 + 550) + by(EBY) * (Z + Z3 + Z4 + 550)
      - bz(EBZ) * ZT + bx(ECX) * (Y - 250) + by(ECY) * (Y - Y2 - 250) + bz(ECZ) * YT
      + EXOY * (Y - 250) + EXOZ * (Z - ZT))
Ey = (bx(EYX) + by(EYY) + bz(EYZ) - bx(EAX) * (Z + Z4 + 550) - by(EAY) * (Z + Z3 + Z4 + 550)
      + bz(EAZ) * ZT + EXOY * X + EYOZ * (ZT - Z))
Ez = (bx(EZX) + by(EZY) + bz(EZZ) + bx(EAX) * (250 - Y) + by(EAY) * (Y2 + 250 - Y)
      - bz(EAZ) * YT - EYOZ * YT)
i0 = (0, 0, len(grids["Z"]) - 1)
Ex, Ey, Ez = Ex - Ex[i0], Ey - Ey[i0], Ez - Ez[i0]
n = np.sqrt(Ex**2 + Ey**2 + Ez**2)
idx = np.unravel_index(np.argmax(n), n.shape)
print(repr(float(n.max())), idx, repr(float(Ex[3, 4, 5])), repr(float(Ey[3, 4, 5])), repr(float(Ez[3, 4, 5])))
