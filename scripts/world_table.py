#!/usr/bin/env python3
"""One markdown table of docs/world.md from a finished sweep folder.

Usage: python3 scripts/world_table.py out/sweeps/world-<name>

Per point: the swept value (one column per axis), runs, converged fraction with its 95 % Wilson interval (from
points.csv, as `host-sim sweep` computed it), the median settle time of the converged
runs, the median final angle error, and the outcomes of the runs that did not converge.
The last line names the deployment envelope: the points where at least 95 % converged.
"""

import json
import sys
from pathlib import Path

from sweep_rows import load, row_cells


def main() -> int:
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    d = Path(sys.argv[1])
    points, by_point = load(d)
    # The axes as the sweep names them (sweep.json), else the columns that look like keys.
    named = json.load(open(d / "sweep.json")).get("axes") if (d / "sweep.json").exists() else None
    axis = [k for k in (named or []) if k in points[0]] or [
        k for k in points[0].keys() if k.startswith("axis:") or "." in k
    ]
    keys = axis or ["point"]
    names = [k.removeprefix("axis:") for k in keys]
    head = " | ".join(f"`{n}`" for n in names)
    print(
        f"| {head} | runs | converged (95 % interval) | settle median (s) "
        "| final angle error median (°) | other outcomes |"
    )
    print("|" + "---|" * len(keys) + "---|---|---|---|---|")
    inside = []
    for p in points:
        frac, cells = row_cells(p, by_point.get(p["point"], []))
        values = " | ".join(p[k] for k in keys)
        print(f"| {values} | {cells}")
        if frac >= 0.95:
            inside.append(", ".join(p[k] for k in keys))
    print()
    if len(keys) == 1:
        at, sep = f"`{names[0]}` = ", ", "
    else:
        at, sep = "(" + ", ".join(f"`{n}`" for n in names) + ") = ", "; "
    print(f"≥ 95 % converged at {at}{sep.join(inside) if inside else 'none'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
