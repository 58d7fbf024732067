#!/usr/bin/env python3
"""One markdown table of docs/world.md from a finished one-axis sweep folder.

Usage: python3 scripts/world_table.py out/sweeps/world-<name>

Per point: the swept value, runs, converged fraction with its 95 % Wilson interval (from
points.csv, as `host-sim sweep` computed it), the median settle time of the converged
runs, the median final angle error, and the outcomes of the runs that did not converge.
The last line names the deployment envelope: the points where at least 95 % converged.
"""

import statistics
import sys
from collections import Counter
from pathlib import Path

from sweep_rows import angle_errors_deg, converged, load, settle_times


def main() -> int:
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    points, by_point = load(Path(sys.argv[1]))
    axis = [k for k in points[0].keys() if k.startswith("axis:")] or [
        k for k in points[0].keys() if "." in k
    ]
    key = axis[0] if axis else "point"
    name = key.removeprefix("axis:")
    print(
        f"| `{name}` | runs | converged (95 % interval) | settle median (s) "
        "| final angle error median (°) | other outcomes |"
    )
    print("|---|---|---|---|---|---|")
    inside = []
    for p in points:
        rs = by_point.get(p["point"], [])
        settle, err = settle_times(rs), angle_errors_deg(rs)
        frac, lo, hi = converged(p)
        others = Counter(r["outcome"] for r in rs if r["outcome"] != "converged")
        other_s = ", ".join(f"{k} {v}" for k, v in sorted(others.items())) or "–"
        settle_s = f"{statistics.median(settle):.1f}" if settle else "–"
        err_s = f"{statistics.median(err):.3f}" if err else "–"
        print(
            f"| {p[key]} | {len(rs)} | {100 * frac:.0f} % ({100 * lo:.0f}–{100 * hi:.0f} %) "
            f"| {settle_s} | {err_s} | {other_s} |"
        )
        if frac >= 0.95:
            inside.append(p[key])
    print()
    print(f"≥ 95 % converged at `{name}` = {', '.join(inside) if inside else 'none'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
