"""Reads a run's run.mcap with Foxglove's PyPI `mcap` reader and compares it with the
run's timeseries.csv and summary.json, value for value.

    python mcap_check.py RUN_DIR     exit 0 and one "ok" line, or exit 1 naming the first
                                     difference (or the reader's error)

Run by host-sim/tests/mcap.rs (with the venv of scripts/python-deps.sh). Numbers compare
exactly: the CSV and the JSON messages both hold shortest round-trip decimals of the
same f64 (NaN in the CSV is null in JSON).
"""

import csv
import json
import math
import sys
from collections import defaultdict

from mcap.reader import make_reader

BASE = 13  # t, V, V_kin, ..., frames_rejected (host-sim/src/report/columns.rs)
SCENE_PERIOD = 0.1  # host-sim/src/report/mcap.rs


def fail(msg):
    print(f"mcap_check: FAIL: {msg}")
    sys.exit(1)


def same(csv_value, json_value):
    if json_value is None:
        return math.isnan(csv_value)
    return csv_value == json_value


def main(run_dir):
    with open(f"{run_dir}/timeseries.csv", newline="") as f:
        rows = list(csv.reader(f))
    header, rows = rows[0], [[float(x) for x in r] for r in rows[1:]]
    col = {name: k for k, name in enumerate(header)}
    agents = [h[2:] for h in header if h.startswith("x_")]
    with open(f"{run_dir}/summary.json") as f:
        summary = json.load(f)

    by_topic = defaultdict(list)
    try:
        with open(f"{run_dir}/run.mcap", "rb") as f:
            reader = make_reader(f)
            # Compressed chunks (host-sim/src/report/mcap.rs), read by this reader.
            chunks = reader.get_summary().chunk_indexes
            if not chunks or any(c.compression != "zstd" for c in chunks):
                fail(f"chunks not zstd-compressed: {sorted({c.compression for c in chunks})}")
            for schema, channel, message in reader.iter_messages(log_time_order=True):
                by_topic[channel.topic].append(
                    (schema.name, message.log_time, json.loads(message.data))
                )
    except Exception as e:  # the reader's own errors: bad magic, CRC, truncation
        fail(f"the mcap reader refused run.mcap: {type(e).__name__}: {e}")

    poses = by_topic["/agents/poses"]
    if len(poses) != len(rows):
        fail(f"/agents/poses has {len(poses)} messages, timeseries.csv {len(rows)} rows")
    for i, (row, (schema, log_time, msg)) in enumerate(zip(rows, poses)):
        t = row[0]
        if schema != "foxglove.PosesInFrame" or log_time != round(t * 1e9):
            fail(f"row {i}: schema {schema}, log time {log_time} ns for t = {t}")
        if len(msg["poses"]) != len(agents):
            fail(f"row {i}: {len(msg['poses'])} poses for {len(agents)} agents")
        for a, p in zip(agents, msg["poses"]):
            for axis in "xy":
                if not same(row[col[f"{axis}_{a}"]], p["position"][axis]):
                    fail(f"row {i} (t = {t}): agent {a}'s {axis} differs: "
                         f"{row[col[f'{axis}_{a}']]} in the CSV, {p['position'][axis]} in the MCAP")

    def compare(topic, names):
        msgs = by_topic[topic]
        if len(msgs) != len(rows):
            fail(f"{topic} has {len(msgs)} messages, timeseries.csv {len(rows)} rows")
        for i, (row, (_, _, msg)) in enumerate(zip(rows, msgs)):
            for key, name in names:
                if not same(row[col[name]], msg[key]):
                    fail(f"row {i}: {topic} {key} = {msg[key]}, CSV {name} = {row[col[name]]}")

    for a in agents:
        compare(f"/agents/{a}", [(c, f"{c}_{a}") for c in ("x", "y", "vx", "vy")])
    base = [(h, h) for h in header[1:BASE]]
    compare("/diagnostics", base)
    compare("/angle_errors", [(h, h) for h in header if h.startswith("angle_err_")])
    compare("/estimates", [(h, h) for h in header if h.startswith(("rhat_", "r_"))])

    scenes = by_topic["/formation/scene"]
    if not scenes or scenes[0][0] != "foxglove.SceneUpdate":
        fail("no foxglove.SceneUpdate on /formation/scene")
    ids = {e["id"] for e in scenes[0][2]["entities"]}
    if not {"agents", "edges"} <= ids:
        fail(f"scene entities {sorted(ids)} lack agents or edges")
    # Every scene's edges and leader edge join the agents of summary.json's edges and
    # leaders, at the positions of the CSV row of the same time.
    row_at = {round(r[0] * 1e9): r for r in rows}
    edges = sorted(tuple(sorted(str(v) for v in e)) for e in summary["edges"])
    leaders = [tuple(sorted(str(v) for v in summary["leaders"]))] if summary.get("leaders") else []
    for _, log_time, msg in scenes:
        row = row_at.get(log_time)
        if row is None:
            fail(f"a scene update at {log_time} ns matches no row")
        where = {a: (row[col[f"x_{a}"]], row[col[f"y_{a}"]]) for a in agents}
        entities = {e["id"]: e for e in msg["entities"]}
        for eid, pairs in (("edges", edges), ("leader_edge", leaders)):
            if not pairs:
                if eid in entities:
                    fail(f"a {eid} entity without {eid} in summary.json")
                continue
            pts = entities[eid]["lines"][0]["points"]
            segments = [tuple(sorted([(p["x"], p["y"]) for p in pts[i:i + 2]]))
                        for i in range(0, len(pts), 2)]
            want = [tuple(sorted([where[a], where[b]])) for a, b in pairs]
            if sorted(segments) != sorted(want):
                fail(f"t = {row[0]}: the {eid} entity's segments are not summary.json's "
                     f"{eid} at the CSV's positions")

    # Every SCENE_PERIOD, or every row when the rows are further apart (a thinned run).
    span = rows[-1][0] - rows[0][0]
    if len(scenes) < min(len(rows) - 1, span / SCENE_PERIOD) * 0.99:
        fail(f"{len(scenes)} scene updates over {span} s")

    events = by_topic["/events"]
    if len(events) != len(summary.get("events", [])):
        fail(f"/events has {len(events)} messages, summary.json {len(summary.get('events', []))}")

    print(f"mcap_check: ok: {len(rows)} rows, {len(agents)} agents' poses each, "
          f"{len(scenes)} scene updates, {len(events)} events")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        print(__doc__)
        sys.exit(2)
    main(sys.argv[1])
