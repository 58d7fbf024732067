"""What the docs' sweep tables read of a finished sweep folder (scripts/sensors_table.py,
scripts/world_table.py): its points (points.csv, as `host-sim sweep` computed them) and,
per point, its runs' settle times and final angle errors (runs.csv)."""

import csv
import math
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
