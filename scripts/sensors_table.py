#!/usr/bin/env python3
"""One markdown table of docs/sensors.md from a finished sweep folder.

Usage: python3 scripts/sensors_table.py out/sweeps/sensors-paper

Per point (bearing noise x radio loss): runs, converged fraction with its 95 % Wilson
interval (from points.csv, as `host-sim sweep` computed it), the median settle time of
the converged runs, and the median and largest final angle error (from runs.csv).
"""

import statistics
import sys
from pathlib import Path

from sweep_rows import angle_errors_deg, converged, load, settle_times


def main() -> int:
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    points, by_point = load(Path(sys.argv[1]))
    print(
        "| bearing noise | radio loss | runs | converged (95 % interval) "
        "| settle median (s) | final angle error median / max (°) |"
    )
    print("|---|---|---|---|---|---|")
    for p in points:
        rs = by_point.get(p["point"], [])
        settle, err = settle_times(rs), angle_errors_deg(rs)
        frac, lo, hi = converged(p)
        settle_s = f"{statistics.median(settle):.2f}" if settle else "–"
        err_s = (
            f"{statistics.median(err):.3f} / {max(err):.3f}" if err else "–"
        )
        print(
            f"| {float(p['sensors.bearing_noise_deg']):g}° "
            f"| {100 * float(p['radio.loss']):g} % | {p['runs']} "
            f"| {100 * frac:.0f} % ({100 * lo:.0f}–{100 * hi:.0f} %) "
            f"| {settle_s} | {err_s} |"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
