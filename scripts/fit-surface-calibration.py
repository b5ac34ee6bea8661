#!/usr/bin/env python3
"""Fit the surface layer's calibration maps (src/surface_calibration.cpp) from evaluation runs.

The surface layer's P, and its pool with the separators, over-state collisions inside the
contact band (docs/SURFACE.md, "Calibration"). This script fits, for each of the two settings,
a monotone map of [free_below, collision_above] = [0.1, 0.9] onto itself: isotonic regression
(pool adjacent violators) of the outcome on P over the near-band poses whose P lies in the band,
read at knots 0.05 apart, clipped to the band, made strictly increasing (so that the map keeps
every ranking: ROC AUC unchanged) and pinned at both ends (so that no verdict changes).

Fit on runs that are NOT reported: the committed maps come from the quick evaluation's seeds
2-10 at 0.5 % noise (W1, both rooms), never from seed 1, which docs/RESULTS.md reports:

    for s in 2 3 4 5 6 7 8 9 10; do
      build/evaluation/evaluate_collision --out runs/s$s --data ../shared/data --quick \\
          --ours-only --seed $s
    done
    python3 scripts/fit-surface-calibration.py runs/s*

It prints the knots as C++ initialisers for src/surface_calibration.cpp. Standard library only.
"""
import csv
import sys

LOW, HIGH = 0.1, 0.9       # CollisionRequest's default free_below and collision_above
STEP = 0.05                # knot spacing
MIN_RISE = 0.002           # per knot: strictly increasing
SETTINGS = (("surface", "kSurfaceLayer"), ("pooled", "kPooled"))


def isotonic(points):
    """Pool adjacent violators on (x, y) sorted by x: blocks of (mean y, weight, x_lo, x_hi)."""
    blocks = []
    for x, y in sorted(points):
        blocks.append([float(y), 1.0, x, x])
        while len(blocks) > 1 and blocks[-2][0] / blocks[-2][1] > blocks[-1][0] / blocks[-1][1]:
            last = blocks.pop()
            blocks[-1][0] += last[0]
            blocks[-1][1] += last[1]
            blocks[-1][3] = last[3]
    return [((b[2] + b[3]) / 2.0, b[0] / b[1]) for b in blocks]


def read_at(fit, x):
    """The isotonic fit between its blocks' centres, linearly; flat beyond them."""
    if x <= fit[0][0]:
        return fit[0][1]
    for (x0, y0), (x1, y1) in zip(fit, fit[1:]):
        if x <= x1:
            return y0 if x1 == x0 else y0 + (y1 - y0) * (x - x0) / (x1 - x0)
    return fit[-1][1]


def knots(points):
    fit = isotonic(points)
    count = int(round((HIGH - LOW) / STEP))
    xs = [LOW + k * STEP for k in range(count + 1)]
    ys = [LOW]
    for x in xs[1:-1]:
        ys.append(min(max(read_at(fit, x), ys[-1] + MIN_RISE), HIGH - MIN_RISE * (count - len(ys))))
    ys.append(HIGH)
    return xs, ys


def main(dirs):
    if not dirs:
        sys.exit("usage: fit-surface-calibration.py RUN_DIR... (each holding a queries.csv)")
    rows = []
    for d in dirs:
        path = d.rstrip("/") + "/queries.csv"
        try:
            with open(path, newline="") as f:
                rows.extend(csv.DictReader(f))
        except OSError as e:
            sys.exit(f"fit-surface-calibration.py: cannot read {path}: {e.strerror}")
    for setting, name in SETTINGS:
        points = [(float(r["score"]), int(r["exact_collision"])) for r in rows
                  if r["method"] == "ours" and r["setting"] == setting and r["workload"].startswith("W1")
                  and r["noise_pct"] == "0.5" and r["near_sigma"] == "1" and LOW <= float(r["score"]) <= HIGH]
        if len(points) < 50:
            sys.exit(f"fit-surface-calibration.py: only {len(points)} near-band '{setting}' answers in the band")
        xs, ys = knots(points)
        print(f"// {setting}: {len(points)} near-band answers with P in [{LOW}, {HIGH}] from {len(dirs)} runs")
        print(f"constexpr std::array<double, {len(ys)}> {name} = {{" + ", ".join(f"{y:.4f}" for y in ys) + "};")


if __name__ == "__main__":
    main(sys.argv[1:])
