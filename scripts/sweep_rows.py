"""What the docs' sweep tables read of a finished sweep folder (scripts/sensors_table.py,
scripts/world_table.py): its points (points.csv, as `host-sim sweep` computed them) and,
per point, its runs' settle times and final angle errors (runs.csv)."""

import csv
import math
import statistics
from collections import Counter
from pathlib import Path


def load(d: Path) -> tuple[list[dict], dict[str, list[dict]]]:
    """The points of sweep folder `d`, and its runs grouped by point."""
    points = list(csv.DictReader(open(d / "points.csv", newline="")))
    by_point: dict[str, list[dict]] = {}
    for r in csv.DictReader(open(d / "runs.csv", newline="")):
        by_point.setdefault(r["point"], []).append(r)
    return points, by_point


def settle_times(runs: list[dict]) -> list[float]:
    """The settle times (s) of the converged runs."""
    return [
        float(r["settle_time"])
        for r in runs
        if r["outcome"] == "converged" and r["settle_time"]
    ]


def angle_errors_deg(runs: list[dict]) -> list[float]:
    """The final largest angle errors (degrees) of the runs that have one."""
    return [
        math.degrees(float(r["final_max_angle_error"]))
        for r in runs
        if r["final_max_angle_error"] not in ("", "NaN", "nan")
    ]


def converged(point: dict) -> tuple[float, float, float]:
    """The converged fraction of a point and its 95 % Wilson interval."""
    return (
        float(point["converged"]),
        float(point["converged_lo"]),
        float(point["converged_hi"]),
    )


def row_cells(point: dict, runs: list[dict]) -> tuple[float, str]:
    """A table row's cells after the first, from one point and its runs: runs, converged
    fraction with its 95 % interval, median settle time of the converged runs, median
    final angle error, and the other outcomes; with the converged fraction."""
    settle, err = settle_times(runs), angle_errors_deg(runs)
    frac, lo, hi = converged(point)
    others = Counter(r["outcome"] for r in runs if r["outcome"] != "converged")
    other_s = ", ".join(f"{k} {v}" for k, v in sorted(others.items())) or "–"
    settle_s = f"{statistics.median(settle):.1f}" if settle else "–"
    err_s = f"{statistics.median(err):.3f}" if err else "–"
    cells = (
        f"{len(runs)} | {100 * frac:.0f} % ({100 * lo:.0f}–{100 * hi:.0f} %) "
        f"| {settle_s} | {err_s} | {other_s} |"
    )
    return frac, cells
