#!/usr/bin/env python3
"""Fit the surface layer's calibration maps (src/surface_calibration.cpp) from evaluation runs.

The surface layer's P, and its pool with the separators, is off inside the contact band, by
scene: on the fit scenes below it under-states collisions there, on W1's piano and room it
over-states them (docs/SURFACE.md, "Calibration"; the maps are off by default for that reason,
CollisionRequest::surface_calibrated). Each of the two gets a map of the band
[free_below, collision_above] = [0.1, 0.9] onto itself,

    P' = 0.1 + 0.8 u^gamma,   u = (P - 0.1) / 0.8,

pinned at both ends (no verdict at the default thresholds changes), strictly increasing (every
ranking kept: ROC AUC unchanged) and the identity outside the band. gamma is the one that
minimises the Brier score of the near-band poses (|d| <= 2.8 sigma_eff), searched on a grid of
0.05 from 0.5 to 4 (below 1 the map raises P in the band, above 1 it lowers it).

Fit on scenes the evaluation never reports: the procedural furnished floors and box-built
objects of `evaluate_collision --fit-scene` (evaluation/fit_scenes.h; workloads F1 and
F1-sparse), never W1's piano and room, W2's primitives or W3's scans. The committed values come
from these runs (the seed draws the scene as well as its samples):

    for s in 1 2 3 4 5 6 7 8 9 10 11 12; do
      build/evaluation/evaluate_collision --out runs/s$s --data ../shared/data --quick \\
          --ours-only --fit-scene --seed $s
    done
    python3 scripts/fit-surface-calibration.py runs/s*

Rows of any other workload are refused. The runs must give the raw P
(CollisionRequest::surface_calibrated off, the default; not --surface-calibrated): nothing in
queries.csv says which one a run wrote. Standard library only.

Exit status 0 after the fit, 2 on a usage error, 1 on a run it cannot use (a missing or malformed
queries.csv, another workload, too few answers); each message names the file.
"""
import csv
import sys

LOW, HIGH = 0.1, 0.9       # CollisionRequest's default free_below and collision_above
GRID = [0.5 + 0.05 * k for k in range(71)]
SETTINGS = (("surface", "kSurfaceLayerGamma"), ("pooled", "kPooledGamma"))
FIT_WORKLOAD = "F1"        # evaluate_collision --fit-scene: F1 and F1-sparse
COLUMNS = ("workload", "method", "setting", "noise_pct", "near_sigma", "score", "exact_collision")


def fail(message):
    sys.exit(f"fit-surface-calibration.py: {message}")


def read_rows(path):
    """queries.csv's rows, each with its file and line ("_where"): a missing column or a short row
    is named with them (a missing column ended in a KeyError traceback)."""
    try:
        with open(path, newline="") as f:
            reader = csv.DictReader(f)
            missing = [c for c in COLUMNS if c not in (reader.fieldnames or [])]
            if missing:
                fail(f"{path}: not an evaluate_collision queries.csv (no column {', '.join(missing)})")
            rows = []
            for row in reader:
                if None in row.values() or None in row:
                    fail(f"{path}:{reader.line_num}: {len(reader.fieldnames)} columns expected")
                row["_where"] = f"{path}:{reader.line_num}"
                rows.append(row)
            return rows
    except OSError as e:
        fail(f"cannot read {path}: {e.strerror}")


def answer(row):
    """(score, exact_collision) of a row the fit uses, or a failure naming its file and line (a
    value that is not a number ended in a ValueError traceback)."""
    try:
        return float(row["score"]), int(row["exact_collision"])
    except ValueError:
        fail(f"{row['_where']}: score {row['score']!r} or exact_collision {row['exact_collision']!r} is not a number")


def mapped(p, gamma):
    if not LOW <= p <= HIGH:
        return p
    return LOW + (HIGH - LOW) * ((p - LOW) / (HIGH - LOW)) ** gamma


def brier(points, gamma):
    return sum((mapped(p, gamma) - y) ** 2 for p, y in points) / len(points)


def main(dirs):
    if dirs in (["-h"], ["--help"]):
        print(__doc__)
        return
    if not dirs or any(d.startswith("-") for d in dirs):
        print("usage: fit-surface-calibration.py RUN_DIR... (each holding a queries.csv)", file=sys.stderr)
        sys.exit(2)
    rows = []
    for d in dirs:
        rows.extend(read_rows(d.rstrip("/") + "/queries.csv"))
    reported = sorted({r["workload"] for r in rows if not r["workload"].startswith(FIT_WORKLOAD)})
    if reported:
        sys.exit(f"fit-surface-calibration.py: the runs hold workload(s) {', '.join(reported)}; fit only on "
                 f"evaluate_collision --fit-scene runs ({FIT_WORKLOAD}), never on what the evaluation reports")
    for setting, name in SETTINGS:
        points = [answer(r) for r in rows
                  if r["method"] == "ours" and r["setting"] == setting
                  and r["noise_pct"] == "0.5" and r["near_sigma"] == "1"]
        if len(points) < 100:
            sys.exit(f"fit-surface-calibration.py: only {len(points)} near-band '{setting}' answers at 0.5 %")
        gamma = min(GRID, key=lambda g: (brier(points, g), g))
        print(f"// {setting}: {len(points)} near-band answers from {len(dirs)} runs, "
              f"Brier {brier(points, 1.0):.4f} raw, {brier(points, gamma):.4f} mapped")
        print(f"constexpr double {name} = {gamma:.2f};")


if __name__ == "__main__":
    main(sys.argv[1:])
