#!/usr/bin/env python3
"""End to end: Bitcraze's cflib flies `host-sim serve`'s simulated Crazyflies.

    serve_e2e.py --host-sim PATH --agent PATH [--scenario crazyflie-app/formation.toml]
                 [--port 19850] [--speed 2] [--cut 4]

Starts `host-sim SCENARIO serve --set world=crazyflie`, connects cflib to every drone
(udp://127.0.0.1:PORT+k), and checks, each step polled with a deadline (never a sleep
taken as a result):

  1. pre-flight: every drone hears all its neighbours (log formation.heard =
     formation.neighbours), on the ground, IDLE;
  2. take-off (high-level commander, 0.5 m in 2 s): every drone at 0.45 m or more;
  3. enable (parameter formation.enable = 1): every drone in FORMATION;
  4. convergence: q_i - q_1 within SHAPE_TOL of the square 1-2-4-3 (positions from
     the log group stateEstimate); nobody held or landed before the cut (the control:
     the hold below is the cut's doing);
  5. cut the radio of agent CUT (serve's `cut ID`): its neighbours hold (state HOLD),
     then land by policy (LANDING, fault "lost: landing"), and reach the ground;
  6. restore the radio (serve's `restore ID`): every neighbour heard again;
  7. land the others: enable = 0, then the high-level commander lands them; every
     drone on the ground with its motors off.

Prints one line per step with the simulated time it took; exits 0 when every check
passed, 1 otherwise. Deadlines are in simulated seconds (the drones' log timestamps).
"""
import argparse
import math
import subprocess
import sys
import threading
import time

import cflib.crtp
from cflib.crazyflie import Crazyflie
from cflib.crazyflie.log import LogConfig
from cflib.crazyflie.syncCrazyflie import SyncCrazyflie

# crazyflie-app/src/flight.h
IDLE, FORMATION, HOLD, LANDING = 0, 1, 2, 3
FAULT_LOST_TIMEOUT = 7
# crazyflie-app/formation.toml: the square 1-2-4-3 as q_i - q_1 (z* = q1 - q2 = (1, -1)).
SQUARE = {"1": (0.0, 0.0), "2": (-1.0, 1.0), "3": (1.0, 1.0), "4": (0.0, 2.0)}
SHAPE_TOL = 0.02  # m
VARIABLES = [
    ("stateEstimate.x", "float"),
    ("stateEstimate.y", "float"),
    ("stateEstimate.z", "float"),
    ("formation.state", "uint8_t"),
    ("formation.fault", "uint8_t"),
    ("formation.heard", "uint8_t"),
    ("formation.neighbours", "uint8_t"),
    ("formation.holdTicks", "uint32_t"),
    ("formation.landings", "uint32_t"),
    ("serve.flying", "uint8_t"),
]


class Drone:
    """One drone's link and the latest values of its log block."""

    def __init__(self, name, uri):
        self.name, self.uri = name, uri
        self.scf = SyncCrazyflie(uri, cf=Crazyflie(rw_cache=None))
        self.lock = threading.Lock()
        self.latest = None
        self.t_ms = 0
        self.states = []  # the sequence of formation.state values seen

    def connect(self):
        self.scf.open_link()
        conf = LogConfig(name="e2e", period_in_ms=50)
        for name, kind in VARIABLES:
            conf.add_variable(name, kind)
        self.scf.cf.log.add_config(conf)
        conf.data_received_cb.add_callback(self._on_log)
        conf.start()

    def _on_log(self, t_ms, data, _conf):
        with self.lock:
            self.latest, self.t_ms = dict(data), t_ms
            s = data["formation.state"]
            if not self.states or self.states[-1] != s:
                self.states.append(s)

    def get(self, key):
        with self.lock:
            return None if self.latest is None else self.latest[key]

    def close(self):
        self.scf.close_link()


class Failed(Exception):
    pass


def wait_for(what, check, deadline_s, speed, drones):
    """Polls check() every 20 ms until true; Failed after deadline_s of simulated time
    (the drones' log timestamps: serve's one clock, slower than the wall clock on a
    loaded machine), or 5 times that in wall-clock time (a stalled simulation)."""
    start = time.monotonic()
    t0 = max(d.t_ms for d in drones)
    while True:
        sim = (max(d.t_ms for d in drones) - t0) / 1000.0
        if check():
            print(f"e2e: {what}: yes after {sim:.2f} s (simulated)", flush=True)
            return sim
        if sim > deadline_s or time.monotonic() - start > 5 * deadline_s / speed + 10:
            break
        time.sleep(0.02)
    states = {d.name: (d.latest or {}) for d in drones}
    raise Failed(f"{what}: not within {deadline_s} s (simulated); last values {states}")


def shape_error(drones):
    q = {d.name: (d.get("stateEstimate.x"), d.get("stateEstimate.y")) for d in drones}
    if any(v[0] is None for v in q.values()):
        return math.inf
    x1, y1 = q["1"]
    return max(
        math.hypot(q[n][0] - x1 - SQUARE[n][0], q[n][1] - y1 - SQUARE[n][1]) for n in q
    )


def fly(args, drones, serve):
    speed = args.speed
    every = lambda f: (lambda: all(f(d) for d in drones))  # noqa: E731
    wait_for("log data from every drone", every(lambda d: d.latest is not None), 5, speed, drones)
    wait_for(
        "pre-flight: every neighbour heard, on the ground, idle",
        every(
            lambda d: d.get("formation.heard") == d.get("formation.neighbours") > 0
            and d.get("stateEstimate.z") == 0.0
            and d.get("formation.state") == IDLE
        ),
        5,
        speed,
        drones,
    )
    for d in drones:
        d.scf.cf.high_level_commander.takeoff(0.5, 2.0)
    wait_for("take-off: every drone at 0.45 m", every(lambda d: d.get("stateEstimate.z") >= 0.45), 6, speed, drones)
    for d in drones:
        d.scf.cf.param.set_value("formation.enable", 1)
    wait_for("enable: every drone in FORMATION", every(lambda d: d.get("formation.state") == FORMATION), 3, speed, drones)
    wait_for(f"convergence: the square within {SHAPE_TOL} m", lambda: shape_error(drones) <= SHAPE_TOL, 40, speed, drones)
    held = [d.name for d in drones if HOLD in d.states or LANDING in d.states or d.get("formation.holdTicks")]
    if held:
        raise Failed(f"control: drones {held} held or landed before any radio was cut")
    print("e2e: control: nobody held or landed before the cut", flush=True)

    serve.stdin.write(f"cut {args.cut}\n")
    serve.stdin.flush()
    cut = [d for d in drones if d.name == args.cut]
    # The neighbours of the cut drone: those that lose a neighbour (formation.toml's
    # triangles {1,2,3} and {2,3,4}: agent 4's are 2 and 3).
    neighbours = [d for d in drones if d.name in args.neighbours.split(",")]
    wait_for(
        f"cut {args.cut}: its neighbours {args.neighbours} and itself hold",
        lambda: all(HOLD in d.states for d in neighbours + cut),
        3,
        speed,
        drones,
    )
    wait_for(
        "then land by policy (lost: landing) and reach the ground",
        lambda: all(
            d.get("formation.fault") == FAULT_LOST_TIMEOUT
            and d.get("formation.landings") >= 1
            and d.get("serve.flying") == 0
            and d.get("stateEstimate.z") == 0.0
            for d in neighbours + cut
        ),
        10,
        speed,
        drones,
    )
    for d in drones:
        if d.states.index(HOLD) > d.states.index(LANDING) if LANDING in d.states and HOLD in d.states else False:
            raise Failed(f"drone {d.name} landed before holding: {d.states}")

    serve.stdin.write(f"restore {args.cut}\n")
    serve.stdin.flush()
    wait_for(
        f"restore {args.cut}: every neighbour heard again",
        every(lambda d: d.get("formation.heard") == d.get("formation.neighbours")),
        1,
        speed,
        drones,
    )
    for d in drones:
        d.scf.cf.param.set_value("formation.enable", 0)
    wait_for("disable: nobody in FORMATION", every(lambda d: d.get("formation.state") != FORMATION), 3, speed, drones)
    for d in drones:
        d.scf.cf.high_level_commander.land(0.0, 2.0)
    wait_for(
        "land all: every drone on the ground, motors off",
        every(lambda d: d.get("stateEstimate.z") == 0.0 and d.get("serve.flying") == 0),
        6,
        speed,
        drones,
    )


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--host-sim", required=True)
    ap.add_argument("--agent", required=True)
    ap.add_argument("--scenario", default="crazyflie-app/formation.toml")
    ap.add_argument("--port", type=int, default=19850)
    ap.add_argument("--speed", type=float, default=2.0)
    ap.add_argument("--cut", default="4")
    ap.add_argument("--neighbours", default="2,3")
    args = ap.parse_args()

    serve = subprocess.Popen(
        [args.host_sim, "serve", args.scenario, "--set", "world=crazyflie",
         "--port", str(args.port), "--speed", str(args.speed), "--agent", args.agent],
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
    )
    uris = {}
    for line in serve.stdout:
        print(line.rstrip(), flush=True)
        if line.startswith("serve: agent "):
            words = line.split()
            uris[words[2]] = words[-1]
        if line.startswith("serve: ready"):
            break
    if not uris:
        serve.kill()
        print("e2e: FAILED: serve did not start", flush=True)
        return 1
    cflib.crtp.init_drivers()
    drones = [Drone(name, uri) for name, uri in uris.items()]
    code = 0
    try:
        for d in drones:
            d.connect()
        print(f"e2e: cflib connected to {len(drones)} drones", flush=True)
        fly(args, drones, serve)
        print("e2e: PASSED", flush=True)
    except Failed as e:
        print(f"e2e: FAILED: {e}", flush=True)
        code = 1
    finally:
        for d in drones:
            try:
                d.close()
            except Exception:  # a link already down
                pass
        try:
            serve.stdin.write("quit\n")
            serve.stdin.flush()
            serve.wait(timeout=10)
        except Exception:
            serve.kill()
    if serve.returncode not in (0, None):
        print(f"e2e: FAILED: serve exited with {serve.returncode}", flush=True)
        code = 1
    return code


if __name__ == "__main__":
    sys.exit(main())
