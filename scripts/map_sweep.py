#!/usr/bin/env python3
"""A map-building sweep: `lampnav map build` on each drive of a localization sweep (carried three
times, one lamp in twelve failed, on buildings the builder was not tuned on), each map compared
with the true lamps. docs/mapping.md, "Carried parts in regular buildings".

    scripts/map_sweep.py --sweep DIR [--logs DIR] [--out DIR] [--lampnav BIN] [--only TEXT]

DIR is a finished `scripts/localization_sweep.py --out DIR`: its maps/ (the true buildings),
replays/<drive>/truth.tum (the true poses) and logs/ (or --logs, where that sweep read them).
Each built map is placed by the true pose where its frame starts (the drive's start, or the
ceiling frame of the carry after which it is built), refined by the best rigid fit of the lamps
within 0.5 m of a true lamp, then counted: lamps half a metre or more from any true lamp
(`false`), true lamps taken twice, lamps on a failed (dark) lamp. Each part joined after a carry
is checked too: where the note says it was put down, against the true pose then (`wrong` when
more than 0.5 m off). Prints one row a drive with a fault and the totals; writes
OUT/summary.json. Maps already built in OUT are kept. A developer tool: about 20 minutes on one
core for 64 drives.
"""
import argparse
import json
import math
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import localization_sweep as sweep  # noqa: E402  (the buildings, routes and failed lamps)


def lamps_of(path):
    out = {}
    with open(path) as f:
        for feat in json.load(f)["features"]:
            for lamp in feat["properties"].get("lampnav", {}).get("lamps", []):
                out[lamp["id"]] = tuple(lamp["xyz"][:3])
    return out


def read_truth(path):
    rows = []
    with open(path) as f:
        for line in f:
            if line.startswith("#") or not line.strip():
                continue
            v = line.split()
            rows.append((float(v[0]), float(v[1]), float(v[2]),
                         2 * math.atan2(float(v[6]), float(v[7]))))
    return rows


def truth_at(rows, t):
    return min(rows, key=lambda r: abs(r[0] - t))[1:]


def apply(pose, p):
    x, y, yaw = pose
    c, s = math.cos(yaw), math.sin(yaw)
    return (x + c * p[0] - s * p[1], y + s * p[0] + c * p[1])


def relative(a, b):
    """b in a's frame."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    c, s = math.cos(a[2]), math.sin(a[2])
    return (c * dx + s * dy, -s * dx + c * dy)


def rigid_fit(pairs):
    """The rotation and translation that put the first of each pair onto the second."""
    n = len(pairs)
    ax = sum(a[0] for a, _ in pairs) / n
    ay = sum(a[1] for a, _ in pairs) / n
    bx = sum(b[0] for _, b in pairs) / n
    by = sum(b[1] for _, b in pairs) / n
    c = s = 0.0
    for a, b in pairs:
        u, v, p, q = a[0] - ax, a[1] - ay, b[0] - bx, b[1] - by
        c += u * p + v * q
        s += u * q - v * p
    yaw = math.atan2(s, c)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return (bx - (cy * ax - sy * ay), by - (sy * ax + cy * ay), yaw)


def nearest(points, true_xy):
    out = []
    for p in points:
        k = min(range(len(true_xy)),
                key=lambda i: (true_xy[i][0] - p[0]) ** 2 + (true_xy[i][1] - p[1]) ** 2)
        out.append((math.hypot(true_xy[k][0] - p[0], true_xy[k][1] - p[1]), k))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sweep", required=True, help="a finished localization sweep's --out")
    ap.add_argument("--logs", help="its logs (default SWEEP/logs)")
    ap.add_argument("--out", help="maps built here (default SWEEP/built)")
    ap.add_argument("--lampnav", default=os.path.join(os.path.dirname(HERE), "build", "apps",
                                                      "lampnav"), help="program that builds")
    ap.add_argument("--only", default="", help="only drives whose name contains this")
    a = ap.parse_args()
    logs = a.logs or os.path.join(a.sweep, "logs")
    out = a.out or os.path.join(a.sweep, "built")
    os.makedirs(out, exist_ok=True)
    totals = {"drives": 0, "refused": 0, "lamps": 0, "false": 0, "twice": 0, "dark": 0,
              "joins": 0, "wrong_joins": 0}
    rows = []
    for name in sorted(os.listdir(logs)):
        if not name.endswith(".mcap") or a.only not in name:
            continue
        drive = name[:-5]
        building = next((b for b in list(sweep.GRIDS) + sweep.LOOK_ALIKES
                         if drive.startswith(b + "_")), None)
        truth_path = os.path.join(a.sweep, "replays", drive, "truth.tum")
        if building is None or not os.path.exists(truth_path):
            continue
        map_path = os.path.join(a.sweep, "maps", building + ".geojson")
        failed = set(sweep.failed_lamps(map_path, int(drive.rsplit("_s", 1)[1])))
        true = lamps_of(map_path)
        ids = list(true)
        true_xy = [true[k] for k in ids]
        built_path = os.path.join(out, drive + ".geojson")
        notes_path = os.path.join(out, drive + ".txt")
        if not os.path.exists(notes_path):
            p = subprocess.run([a.lampnav, "map", "build", os.path.join(logs, name), "-o",
                                built_path, "--quiet"], capture_output=True, text=True)
            with open(notes_path, "w") as f:
                f.write(p.stderr + f"\nstatus {p.returncode}\n")
        with open(notes_path) as f:
            notes = f.read()
        totals["drives"] += 1
        if int(re.search(r"status (-?\d+)", notes).group(1)) != 0:
            totals["refused"] += 1
            continue
        truth = read_truth(truth_path)
        # Where the map's frame starts: the drive's start, or the carry it is built after.
        start = truth[0][0]
        restart = [float(t) for t in re.findall(
            r"jumped ([\d.]+) s into the drive[^\n]*the map is built from the drive after it",
            notes)]
        if restart:
            start += restart[-1]
        frame = truth_at(truth, start)
        built = list(lamps_of(built_path).values())
        pose = frame
        for _ in range(4):  # placed by the true frame, refined on the lamps within 0.5 m
            pairs = [(b, true_xy[k]) for b, (d, k) in
                     zip(built, nearest([apply(pose, b) for b in built], true_xy)) if d < 0.5]
            if len(pairs) < 2:
                break
            pose = rigid_fit(pairs)
        near = nearest([apply(pose, b) for b in built], true_xy)
        matched = [k for d, k in near if d < 0.5]
        row = {"drive": drive, "lamps": len(built), "false": len(built) - len(matched),
               "twice": len(matched) - len(set(matched)),
               "dark": sum(1 for k in matched if ids[k] in failed), "joins": 0, "wrong_joins": 0}
        for t, x, y in re.findall(r"jumped ([\d.]+) s into the drive[^\n]*is in the map, put "
                                  r"down at \(([-\d.]+), ([-\d.]+)\)", notes):
            expected = relative(frame, truth_at(truth, truth[0][0] + float(t)))
            row["joins"] += 1
            if math.hypot(float(x) - expected[0], float(y) - expected[1]) > 0.5:
                row["wrong_joins"] += 1
        for k in ("lamps", "false", "twice", "dark", "joins", "wrong_joins"):
            totals[k] += row[k]
        rows.append(row)
        if row["false"] or row["twice"] or row["dark"] or row["wrong_joins"]:
            print(f"{drive}: {row['lamps']} lamps, {row['false']} half a metre off, "
                  f"{row['twice']} twice, {row['dark']} on failed lamps, "
                  f"{row['wrong_joins']} of {row['joins']} joins wrong")
    print(f"{totals['drives']} drives ({totals['refused']} refused): {totals['lamps']} lamps, "
          f"{totals['false']} half a metre off, {totals['twice']} twice, {totals['dark']} on "
          f"failed lamps; {totals['wrong_joins']} of {totals['joins']} joins wrong")
    with open(os.path.join(out, "summary.json"), "w") as f:
        json.dump({**totals, "rows": rows}, f, indent=1)


if __name__ == "__main__":
    main()
