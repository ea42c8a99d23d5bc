#!/usr/bin/env python3
"""Writes the bundled maps, maps/office_floor.geojson and maps/domus_museum.geojson.

The maps are data; this script is how they were made, kept so that a change to them is a change
to a few numbers here. Run from the repository root:  python3 scripts/make_maps.py
"""
import csv
import json
import math
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


class MapBuilder:
    def __init__(self, name):
        self.name = name
        self.features = []
        self.next_node = 1
        self.next_edge = 1000
        self.ids = {}
        self.points = {}

    def node(self, name, place, point, region, axis=None, width=None, doors=None, lamps=None):
        """A place. Format 2: what Nav2 can read in `metadata`, lamps and doors in `lampnav`."""
        fid = self.next_node
        self.next_node += 1
        self.ids[name] = fid
        self.points[fid] = (float(point[0]), float(point[1]))
        xs = [float(p[0]) for p in region]
        ys = [float(p[1]) for p in region]
        md = {"name": name, "place": place}
        if axis is not None:
            md["axis"] = {"x_values": [float(axis[0][0]), float(axis[1][0])],
                          "y_values": [float(axis[0][1]), float(axis[1][1])]}
        if width is not None:
            md["width"] = width
        md["region"] = {"x_values": xs, "y_values": ys}
        own = {}
        if doors:
            own["doors"] = doors
        own["lamps"] = lamps or []
        self.features.append({
            "type": "Feature",
            "geometry": {"type": "Point", "coordinates": list(self.points[fid])},
            "properties": {"id": fid, "frame": "map", "metadata": md, "lampnav": own},
        })
        return own

    def edge(self, a, b, line):
        """A two-way passage: two one-way edges, as Nav2 does.

        The cost is the polyline's length; it is written (with "overridable": false, or Nav2
        ignores it) only where it is not the straight line between the node points, which is
        what Nav2 scores an edge without a cost by.
        """
        for s, e, pts in ((a, b, line), (b, a, list(reversed(line)))):
            pts = [[round(p[0], 4), round(p[1], 4)] for p in pts]
            props = {"id": self.next_edge, "startid": self.ids[s], "endid": self.ids[e]}
            length = sum(math.dist(p, q) for p, q in zip(pts, pts[1:]))
            straight = math.dist(self.points[self.ids[s]], self.points[self.ids[e]])
            if abs(length - straight) > 1e-3:  # the points are rounded to 0.1 mm
                props["cost"] = length
                props["overridable"] = False
            props["metadata"] = {}
            self.features.append({
                "type": "Feature",
                "geometry": {"type": "MultiLineString", "coordinates": [pts]},
                "properties": props,
            })
            self.next_edge += 1

    def write(self, path):
        doc = {"type": "FeatureCollection", "name": self.name,
               "lampnav": {"format": 2, "units": "m", "frame": "map"},
               "features": self.features}
        with open(path, "w") as f:
            json.dump(doc, f, indent=1)
            f.write("\n")


def rect(x0, y0, x1, y1):
    return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]


def office_floor():
    """An office floor in the spirit of paper 2: six corridors 2 m wide on a loop, two
    T-junctions, two corners, two corridor ends, nine doors into rooms; rectangular 1.2 x 0.3 m
    lamps 2.7 m up, about every 2.4 m along each corridor's centreline."""
    m = MapBuilder("office-floor")
    z = 2.7
    node_points = {}
    corridor_axes = {}

    def lamp(lid, x, y, yaw):
        return {"id": lid, "xyz": [round(x, 4), round(y, 4), z], "yaw": round(yaw, 6),
                "shape": "rectangle", "size": [1.2, 0.3]}

    def place(name, kind, cx, cy, with_lamp=True):
        node_points[name] = (cx, cy)
        lamps = [lamp(name + "-L1", cx, cy, 0.0)] if with_lamp else []
        m.node(name, kind, (cx, cy), rect(cx - 1, cy - 1, cx + 1, cy + 1), lamps=lamps)

    def corridor(name, a, b, doors):
        ax, ay = a
        bx, by = b
        length = math.hypot(bx - ax, by - ay)
        dx, dy = (bx - ax) / length, (by - ay) / length
        yaw = math.atan2(dy, dx)
        n = max(1, round(length / 2.4))
        s = length / n
        lamps = [lamp(f"{name}-L{k + 1}", ax + dx * (s / 2 + k * s), ay + dy * (s / 2 + k * s), yaw)
                 for k in range(n)]
        # Region: the axis swept 1 m to each side.
        lx, ly = -dy, dx
        region = [(ax + lx, ay + ly), (ax - lx, ay - ly), (bx - lx, by - ly), (bx + lx, by + ly)]
        xs = [p[0] for p in region]
        ys = [p[1] for p in region]
        region = rect(min(xs), min(ys), max(xs), max(ys))
        mid = ((ax + bx) / 2, (ay + by) / 2)
        node_points[name] = mid
        corridor_axes[name] = (a, b, (dx, dy))
        m.node(name, "corridor", mid, region, axis=[a, b], width=2.0,
               doors=[{"name": d[0], "side": d[1], "at": d[2]} for d in doors], lamps=lamps)

    place("E1", "end", 1, 10)
    corridor("C1", (2, 10), (20, 10), [("D1", "left", 4.0), ("D3", "right", 8.0),
                                       ("D2", "left", 12.0), ("WC", "right", 15.0)])
    place("J1", "junction", 21, 10)
    corridor("C2", (22, 10), (40, 10), [("Store", "right", 3.0), ("D4", "left", 6.0),
                                        ("D5", "right", 10.0)])
    place("K1", "corner", 41, 10)
    corridor("C3", (41, 9), (41, -7), [("D6", "left", 8.0), ("Lab 4 back", "left", 13.0)])
    place("K2", "corner", 41, -8)
    corridor("C4", (40, -8), (22, -8), [("D8", "right", 5.0), ("D7", "left", 9.0)])
    place("J2", "junction", 21, -8)
    corridor("C5", (21, 9), (21, -7), [])
    corridor("C6", (20, -8), (2, -8), [("Archive", "left", 4.0), ("D9", "right", 10.0)])
    place("E2", "end", 1, -8)

    # Doors: 1 m wide, 0.3 m deep, in the wall beside their corridor; rooms behind them.
    rooms = {
        "Lab 1": rect(2, 11.3, 10, 17), "Lab 2": rect(10, 11.3, 20, 17),
        "Office 1": rect(2, 1.5, 20, 8.7), "Lab 3": rect(22, 11.3, 40, 17),
        "Meeting": rect(22, 1.5, 40, 8.7), "Lab 4": rect(42.3, -7, 48, 9),
        "Workshop": rect(22, -15, 40, -9.3), "Kitchen": rect(22, -6.7, 40, 1.5),
        "Office 2": rect(2, -6.7, 20, 1.5),
    }
    doors = [("D1", "C1", "Lab 1"), ("D2", "C1", "Lab 2"), ("D3", "C1", "Office 1"),
             ("D4", "C2", "Lab 3"), ("D5", "C2", "Meeting"), ("D6", "C3", "Lab 4"),
             ("D7", "C4", "Workshop"), ("D8", "C4", "Kitchen"), ("D9", "C6", "Office 2")]
    for room, poly in rooms.items():
        xs = [p[0] for p in poly]
        ys = [p[1] for p in poly]
        cx, cy = (min(xs) + max(xs)) / 2, (min(ys) + max(ys)) / 2
        node_points[room] = (cx, cy)
        m.node(room, "room", (cx, cy), poly,
               lamps=[{"id": room.replace(" ", "") + "-L1", "xyz": [cx, cy, z], "shape": "disc",
                       "size": [0.6]}])
    door_nodes = []
    for door, corr, room in doors:
        (ax, ay), _, (dx, dy) = corridor_axes[corr]
        spec = next(d for d in m.features if d["properties"].get("metadata", {}).get("name") == corr)
        at = next(d["at"] for d in spec["properties"]["lampnav"]["doors"] if d["name"] == door)
        side = next(d["side"] for d in spec["properties"]["lampnav"]["doors"] if d["name"] == door)
        lx, ly = (-dy, dx) if side == "left" else (dy, -dx)
        px, py = ax + dx * at, ay + dy * at          # on the axis
        wx, wy = px + lx * 1.0, py + ly * 1.0          # on the wall
        cx, cy = wx + lx * 0.15, wy + ly * 0.15        # door centre
        corners = [(wx + dx * 0.5, wy + dy * 0.5), (wx - dx * 0.5, wy - dy * 0.5),
                   (wx - dx * 0.5 + lx * 0.3, wy - dy * 0.5 + ly * 0.3),
                   (wx + dx * 0.5 + lx * 0.3, wy + dy * 0.5 + ly * 0.3)]
        xs = [round(p[0], 4) for p in corners]
        ys = [round(p[1], 4) for p in corners]
        node_points[door] = (cx, cy)
        m.node(door, "door", (round(cx, 4), round(cy, 4)), rect(min(xs), min(ys), max(xs), max(ys)))
        door_nodes.append((door, corr, room, (px, py)))

    chain = ["E1", "C1", "J1", "C2", "K1", "C3", "K2", "C4", "J2", "C6", "E2"]
    for a, b in zip(chain, chain[1:]):
        m.edge(a, b, [node_points[a], node_points[b]])
    m.edge("J1", "C5", [node_points["J1"], node_points["C5"]])
    m.edge("C5", "J2", [node_points["C5"], node_points["J2"]])
    for door, corr, room, on_axis in door_nodes:
        m.edge(corr, door, [node_points[corr], on_axis, node_points[door]])
        m.edge(door, room, [node_points[door], node_points[room]])
    return m


def domus_museum():
    """The exhibition hall of the Domus museum (paper 1, Fig. 2 and Table I): 30 ceiling lights at
    their real positions and heights, in three areas E, A and B as hall nodes whose regions cover
    their lights and touch, so a robot can walk between them. The lights' emitting faces are
    modelled as discs (E and A: 0.5 m, B: 0.25 m): paper 1 uses their centres only."""
    m = MapBuilder("domus-museum")
    lamps = {"E": [], "A": [], "B": []}
    with open(os.path.join(ROOT, "..", "shared", "data", "domus_lamps.csv")) as f:
        rows = [r for r in csv.reader(line for line in f if not line.startswith("#"))]
    header, rows = rows[0], rows[1:]
    assert header == ["label", "area", "x", "y", "z"], header
    for label, area, x, y, z in rows:
        size = 0.25 if area == "B" else 0.5
        lamps[area].append({"id": label, "xyz": [float(x), float(y), float(z)], "shape": "disc",
                            "size": [size]})
    assert sum(len(v) for v in lamps.values()) == 30
    regions = {
        "A": [(-8, -12.5), (23, -12.5), (23, -4.5), (-8, -4.5)],
        "E": [(-8, -4.5), (23, -4.5), (23, -1.6), (14, -1.6), (14, 1.0), (-8, 1.0)],
        "B": [(14, -1.6), (29, -1.6), (29, 4.5), (14, 4.5)],
    }
    points = {"E": (5.0, -2.0), "A": (7.0, -8.5), "B": (21.0, 1.5)}
    for area in ("E", "A", "B"):
        m.node(area, "hall", points[area], regions[area], lamps=lamps[area])
    m.edge("E", "A", [points["E"], points["A"]])
    m.edge("E", "B", [points["E"], (18.0, -1.0), points["B"]])
    return m


def main():
    out = os.path.join(ROOT, "maps")
    os.makedirs(out, exist_ok=True)
    office_floor().write(os.path.join(out, "office_floor.geojson"))
    domus_museum().write(os.path.join(out, "domus_museum.geojson"))
    print("wrote maps/office_floor.geojson and maps/domus_museum.geojson", file=sys.stderr)


if __name__ == "__main__":
    main()
