#!/usr/bin/env python3
"""Buildings off the grid for localization sweeps (docs/hypotheses.md, "A hypothesis off by more
than it knows"): a square ring with a spur out of each side (four-fold symmetric), a hexagon of
corridors with spokes to a hub (six-fold, corridors meeting at 60 and 120 degrees), a comb whose
teeth leave its spine at 60 degrees (alike along the spine), and a 3 x 3 lattice of corridors
crossing at 60 degrees (half-turn symmetric). Lamps are 1.2 x 0.3 m troffers along each
corridor's axis, one over each junction, corner and end.

    scripts/make_look_alike_buildings.py OUT_DIR

writes square_ring.geojson, hexagon_hub.geojson, comb_60.geojson and oblique_lattice.geojson.
Each passes `lampnav map check`.
"""
import json, math, os, sys
OUT = sys.argv[1] if len(sys.argv) > 1 else "."
os.makedirs(OUT, exist_ok=True)


def build(name, nodes, corridors, spacing, height, R=2.5, w=2.0, size=(1.2, 0.3)):
    """A lampnav map (docs: spec map-format.md) of `nodes` (name -> (place kind, (x, y))) joined
    by straight `corridors` (pairs of names). Each place is a 12-gon of radius R with one lamp over
    its point; each corridor a node of its own, its region a rectangle w wide from R past its
    first place to R short of its second (so regions only touch, whatever the angle between
    corridors, down to 45 degrees), its lamps `spacing` apart counted from its first place, along
    its axis. Edges run both ways, place to corridor to place."""
    feats = []; fid = [1]; eid = [5000]
    pos = {n: p for n, (k, p) in nodes.items()}
    ids = {}
    def poly(cx, cy, r, k=12):
        return {"x_values": [round(cx + r*math.cos(2*math.pi*i/k + math.pi/k), 6) for i in range(k)],
                "y_values": [round(cy + r*math.sin(2*math.pi*i/k + math.pi/k), 6) for i in range(k)]}
    yaw_of = {}
    for a, b in corridors:
        for n, m in ((a, b), (b, a)):
            yaw_of.setdefault(n, math.atan2(pos[m][1]-pos[n][1], pos[m][0]-pos[n][0]))
    for n, (k, p) in nodes.items():
        ids[n] = fid[0]; fid[0] += 1
        feats.append({"type": "Feature", "geometry": {"type": "Point", "coordinates": list(p)},
            "properties": {"id": ids[n], "frame": "map", "metadata": {"name": n, "place": k, "region": poly(p[0], p[1], R)},
            "lampnav": {"lamps": [{"id": n+"-L1", "xyz": [p[0], p[1], height], "yaw": round(yaw_of[n] % math.pi, 7), "shape": "rectangle", "size": list(size)}]}}})
    edges = []
    for ci, (a, b) in enumerate(corridors):
        pa, pb = pos[a], pos[b]; L = math.dist(pa, pb)
        ux, uy = (pb[0]-pa[0])/L, (pb[1]-pa[1])/L; nx, ny = -uy, ux
        s0, s1 = R, L - R
        P = lambda t, o=0: (pa[0]+ux*t+nx*o, pa[1]+uy*t+ny*o)
        cn = f"C{ci+1}"; mid = P(L/2)
        region = [P(s0, -w/2), P(s1, -w/2), P(s1, w/2), P(s0, w/2)]
        lamps = []; k = 1
        while k*spacing < s1 - 0.3:
            t = k*spacing
            if t > s0 + 0.3:
                x, y = P(t); lamps.append({"id": f"{cn}-L{len(lamps)+1}", "xyz": [round(x, 6), round(y, 6), height], "yaw": round(math.atan2(uy, ux) % math.pi, 7), "shape": "rectangle", "size": list(size)})
            k += 1
        ids[cn] = fid[0]; fid[0] += 1
        feats.append({"type": "Feature", "geometry": {"type": "Point", "coordinates": [round(mid[0], 6), round(mid[1], 6)]},
            "properties": {"id": ids[cn], "frame": "map", "metadata": {"name": cn, "place": "corridor",
              "region": {"x_values": [round(q[0], 6) for q in region], "y_values": [round(q[1], 6) for q in region]},
              "axis": {"x_values": [round(P(s0)[0], 6), round(P(s1)[0], 6)], "y_values": [round(P(s0)[1], 6), round(P(s1)[1], 6)]}, "width": w},
              "lampnav": {"lamps": lamps}}})
        for u, v in ((a, cn), (cn, b)):
            pu = pos[u] if u in pos else mid; pv = pos[v] if v in pos else mid
            for s, e, ps, pe in ((u, v, pu, pv), (v, u, pv, pu)):
                edges.append({"type": "Feature", "geometry": {"type": "MultiLineString", "coordinates": [[[round(ps[0], 6), round(ps[1], 6)], [round(pe[0], 6), round(pe[1], 6)]]]},
                              "properties": {"id": eid[0], "startid": ids[s], "endid": ids[e], "metadata": {}}}); eid[0] += 1
    return {"type": "FeatureCollection", "name": name, "lampnav": {"format": 2, "units": "m", "frame": "map"}, "features": feats + edges}

def kind(deg):
    return {1: "end", 2: "corner"}.get(deg, "junction")
def finish(name, pts, cors, spacing, height, **kw):
    deg = {}
    for a, b in cors: deg[a] = deg.get(a, 0)+1; deg[b] = deg.get(b, 0)+1
    nodes = {n: (kind(deg[n]), p) for n, p in pts.items()}
    with open(os.path.join(OUT, name + ".geojson"), "w") as f:
        json.dump(build(name.replace("_", " "), nodes, cors, spacing, height, **kw), f, indent=1)
        f.write("\n")

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
