#!/usr/bin/env python3
"""The sizes table of docs/world.md from finished one-point sweep folders (no axes).

Usage: python3 scripts/world_sizes_table.py out/sweeps/world-size-<a> out/sweeps/world-size-<b> ...

One row per folder, in the order given: the sweep's description (the formation), runs,
converged fraction with its 95 % Wilson interval (points.csv, as `host-sim sweep`
computed it), the median settle time of the converged runs, the median final angle
error, and the outcomes of the runs that did not converge. The last line names the sizes
where at least 95 % converged.
"""

import json
import sys
from pathlib import Path

from sweep_rows import load, row_cells


def main() -> int:
    if len(sys.argv) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    print(
        "| formation | runs | converged (95 % interval) | settle median (s) "
        "| final angle error median (°) | other outcomes |"
    )
    print("|---|---|---|---|---|---|")
    inside = []
    for arg in sys.argv[1:]:
        d = Path(arg)
        sweep = json.load(open(d / "sweep.json"))
        label = sweep.get("description") or sweep["name"]
        points, by_point = load(d)
        if len(points) != 1:
            print(f"{d}: {len(points)} points, expected one", file=sys.stderr)
            return 1
        p = points[0]
        frac, cells = row_cells(p, by_point.get(p["point"], []))
        print(f"| {label} | {cells}")
        if frac >= 0.95:
            inside.append(label)
    print()
    print(f"≥ 95 % converged: {'; '.join(inside) if inside else 'none'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
