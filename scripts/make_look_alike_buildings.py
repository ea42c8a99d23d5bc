#!/usr/bin/env python3
"""Buildings off the grid for localization sweeps (docs/hypotheses.md, "A hypothesis off by more
than it knows"): a square ring with a spur out of each side (four-fold symmetric), a hexagon of
corridors with spokes to a hub (six-fold, corridors meeting at 60 and 120 degrees), a comb whose
teeth leave its spine at 60 degrees (alike along the spine), and a 3 x 3 lattice of corridors
crossing at 60 degrees (half-turn symmetric). Lamps are 1.2 x 0.3 m troffers along each
corridor's axis, one over each junction, corner and end.

    scripts/make_look_alike_buildings.py OUT_DIR

writes square_ring.geojson, hexagon_hub.geojson, comb_60.geojson and oblique_lattice.geojson,
and two grids whose corridors each have their own lamps (mixed_grid.geojson,
mixed_uneven_grid.geojson; docs/hypotheses.md, "Corridors each of their own").
Each passes `lampnav map check`.
"""
import math
import os
import random
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_maps import MapBuilder  # noqa: E402

OUT = sys.argv[1] if len(sys.argv) > 1 else "."
os.makedirs(OUT, exist_ok=True)


def polygon(cx, cy, r, k=12):
    return [(cx + r * math.cos(2 * math.pi * (i + 0.5) / k),
             cy + r * math.sin(2 * math.pi * (i + 0.5) / k)) for i in range(k)]


def lamp(lid, x, y, height, yaw, size):
    """A rectangle `size` (length, width), or a disc when `size` has one number (its diameter)."""
    if len(size) == 1:
        return {"id": lid, "xyz": [round(x, 6), round(y, 6), height], "shape": "disc",
                "size": list(size)}
    return {"id": lid, "xyz": [round(x, 6), round(y, 6), height], "yaw": round(yaw % math.pi, 7),
            "shape": "rectangle", "size": list(size)}


def build(name, nodes, corridors, spacing, height, R=2.5, w=2.0, size=(1.2, 0.3), style=None,
          place_height=None):
    """A lampnav map (the spec's map-format.md) of `nodes` (name -> (place kind, (x, y))) joined
    by straight `corridors` (pairs of names). Each place is a 12-gon of radius R with one lamp over
    its point; each corridor a node of its own, its region a rectangle w wide from R past its
    first place to R short of its second (so regions only touch, whatever the angle between
    corridors, down to 45 degrees), its lamps `spacing` apart counted from its first place, along
    its axis. Edges run both ways, place to corridor to place. `style(k)`, when given, returns
    corridor k's own (height, spacing, size, offset of its row off the axis, first lamp's
    distance from its first place); `place_height(name)` a place's lamp's height."""
    m = MapBuilder(name)
    pos = {n: p for n, (k, p) in nodes.items()}
    yaw_of = {}
    for a, b in corridors:
        for n, o in ((a, b), (b, a)):
            yaw_of.setdefault(n, math.atan2(pos[o][1] - pos[n][1], pos[o][0] - pos[n][0]))
    for n, (k, p) in nodes.items():
        h = place_height(n) if place_height else height
        m.node(n, k, p, polygon(p[0], p[1], R), lamps=[lamp(n + "-L1", p[0], p[1], h,
                                                           yaw_of[n], size)])
    for ci, (a, b) in enumerate(corridors):
        pa, pb = pos[a], pos[b]
        L = math.dist(pa, pb)
        ux, uy = (pb[0] - pa[0]) / L, (pb[1] - pa[1]) / L

        def at(t, off=0.0):
            return (pa[0] + ux * t - uy * off, pa[1] + uy * t + ux * off)

        cn = f"C{ci + 1}"
        h, sp, sz, off, first = style(ci) if style else (height, spacing, size, 0.0, spacing)
        lamps = [lamp(f"{cn}-L{i + 1}", *at(t, off), h, math.atan2(uy, ux), sz)
                 for i, t in enumerate(t for t in (first + k * sp for k in range(int(L / sp) + 1))
                                       if R + 0.3 < t < L - R - 0.3)]
        mid = at(L / 2)
        m.node(cn, "corridor", mid, [at(R, -w / 2), at(L - R, -w / 2), at(L - R, w / 2), at(R, w / 2)],
               axis=(at(R), at(L - R)), width=w, lamps=lamps)
        m.edge(a, cn, [pa, mid])
        m.edge(cn, b, [mid, pb])
    return m


def kind(deg):
    return {1: "end", 2: "corner"}.get(deg, "junction")
def finish(name, pts, cors, spacing, height, **kw):
    deg = {}
    for a, b in cors: deg[a] = deg.get(a, 0)+1; deg[b] = deg.get(b, 0)+1
    nodes = {n: (kind(deg[n]), p) for n, p in pts.items()}
    build(name.replace("_", " "), nodes, cors, spacing, height, **kw).write(
        os.path.join(OUT, name + ".geojson"))

# r1: a square ring with spurs outward (4-fold symmetric)
pts = {"K1": (0, 0), "J1": (16, 0), "K2": (32, 0), "J2": (32, 16), "K3": (32, 32), "J3": (16, 32), "K4": (0, 32), "J4": (0, 16),
       "E1": (16, -10), "E2": (42, 16), "E3": (16, 42), "E4": (-10, 16)}
cors = [("K1", "J1"), ("J1", "K2"), ("K2", "J2"), ("J2", "K3"), ("K3", "J3"), ("J3", "K4"), ("K4", "J4"), ("J4", "K1"),
        ("J1", "E1"), ("J2", "E2"), ("J3", "E3"), ("J4", "E4")]
finish("square_ring", pts, cors, 2.25, 2.7)
# r2: a hexagon with spokes to a hub (6-fold, corridors at 60 and 120 degrees)
pts = {"H": (0, 0)}
for i in range(6):
    a = math.radians(60*i); pts[f"V{i+1}"] = (round(14*math.cos(a), 6), round(14*math.sin(a), 6))
cors = [("H", f"V{i+1}") for i in range(6)] + [(f"V{i+1}", f"V{(i+1)%6+1}") for i in range(6)]
finish("hexagon_hub", pts, cors, 2.5, 3.0)
# r3: a comb, teeth at 60 degrees off a spine (translation symmetric)
pts = {"E0": (0, 0), "E5": (75, 0)}
cors = []
prev = "E0"
for i in range(1, 5):
    pts[f"J{i}"] = (15*i, 0); pts[f"T{i}"] = (round(15*i + 12*math.cos(math.radians(60)), 6), round(12*math.sin(math.radians(60)), 6))
    cors += [(prev, f"J{i}"), (f"J{i}", f"T{i}")]; prev = f"J{i}"
cors.append((prev, "E5"))
finish("comb_60", pts, cors, 2.25, 2.7)
# r4: an oblique lattice, 3 x 3 junctions, 60/120-degree crossings, ceiling 3.2 m
pts = {}
for i in range(3):
    for j in range(3):
        pts[f"P{i}_{j}"] = (round(16*i + 8*j, 6), round(16*math.sin(math.radians(60))*j, 6))
cors = [(f"P{i}_{j}", f"P{i+1}_{j}") for i in range(2) for j in range(3)] + [(f"P{i}_{j}", f"P{i}_{j+1}") for i in range(3) for j in range(2)]
finish("oblique_lattice", pts, cors, 2.25, 3.2)


# Two grids no corridor of which is like another: each has its own lamp height (2.4 to 3.6 m),
# spacing (2.0 to 3.2 m), kind (troffers 1.2 x 0.3 or 1.5 x 0.2, square panels 0.6 m, discs
# 0.4 m), first lamp, and a row on the axis or off it by 0.4 or 0.5 m; places' lamps 2.5 to 3.4
# m up. The localizer's models take one usual height (the continuity check) and one spacing.
KINDS = [(1.2, 0.3), (1.2, 0.3), (0.6, 0.6), (1.5, 0.2), (0.4,)]


def mixed(name, xs, ys, missing, seed):
    rng = random.Random(seed)
    pts = {f"J{i}_{j}": (x, y) for i, x in enumerate(xs) for j, y in enumerate(ys)}
    cors = [(f"J{i}_{j}", f"J{i + 1}_{j}") for i in range(len(xs) - 1) for j in range(len(ys))] + \
           [(f"J{i}_{j}", f"J{i}_{j + 1}") for i in range(len(xs)) for j in range(len(ys) - 1)]
    cors.remove(missing)
    heights = {n: round(rng.uniform(2.5, 3.4), 2) for n in pts}
    styles = []
    for _ in cors:
        sp = round(rng.uniform(2.0, 3.2), 2)
        styles.append((round(rng.uniform(2.4, 3.6), 2), sp, rng.choice(KINDS),
                       rng.choice([0.0, 0.0, 0.0, 0.4, -0.5]), rng.uniform(0.3, 1.0) * sp))
    finish(name, pts, cors, 0, 0, w=2.2, style=styles.__getitem__, place_height=heights.get)


# x1: 4 x 3 junctions 15 x 13 m apart, a corridor missing
mixed("mixed_grid", [0, 15, 30, 45], [0, 13, 26], ("J1_1", "J2_1"), 111)
# x2: blocks of uneven size (10, 18 and 12 m across, 9 and 16 m up), a corridor missing
mixed("mixed_uneven_grid", [0, 10, 28, 40], [0, 9, 25], ("J3_0", "J3_1"), 222)
