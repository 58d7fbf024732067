#!/usr/bin/env python3
"""Fly a formation with Bitcraze's cflib: simulated (host-sim serve) or real drones.

    swarm.py uris SCENARIO (--sim [--port 19850] | --radio radio://0/80/2M)
    swarm.py fly  SCENARIO (--sim ... | --radio ...) [--log flight.csv] [--seconds S]
    swarm.py step SCENARIO (--sim ... | --radio ...) --agent ID [--log step.csv]
                  [--speed 0.3] [--step-s 3]
    swarm.py compare-step STEP_LOG VEHICLE_STEP_CSV --speed 0.3 [--tolerance 0.03]

The drones are the scenario's agents, in file order: simulated, agent k at
udp://127.0.0.1:PORT+k (host-sim serve); real, at RADIO/E7E7E7E7NN with NN the agent's
wire id in hex (docs/crazyflie.md "Addresses") and `?rate_limit=100`, which the
firmware's P2P documentation asks for when the Crazyradio and P2P share the air
(crazyflie-firmware docs/functional-areas/p2p_api.md:17-22).

`fly`: pre-flight checks (every neighbour heard, positioning locked, on the ground,
idle), take off (0.5 m), enable the formation, show a line per drone and the
formation's worst angle error once a second, then disable and land on Ctrl-C, on a
fault (a drone holding or landing by policy, or stopped by its supervisor) or after
--seconds; the flight log is written to --log (docs/crazyflie.md "The flight log").

`step`: one drone takes off, hovers 1 s, flies the velocity step `--speed` m/s along
x for `--step-s` s (the client's hover setpoints, the app idle), stops, hovers 1 s and
lands; its log is the same format, to hold against `host-sim vehicle step`.

`compare-step`: the logged velocity along x from the step's first setpoint, for 2 s,
against `host-sim vehicle step --speed V --out DIR`'s DIR/step.csv (`v_along`),
aligned by the shift within +-200 ms (four log periods: the setpoint column is the
second block's latest value) that fits best; prints the RMS
and largest difference and exits 0 when the RMS is within --tolerance m/s.
`host-sim compare DIR STEP_LOG --speed V` is the same check in Rust (and
`host-sim compare RUN_DIR FLIGHT_LOG` holds a `fly` log against a run:
docs/crazyflie.md "Flights beside simulations"); this one stays for a ground station
without host-sim.
"""
import argparse
import csv
import math
import signal
import sys
import threading
import time
import tomllib

import cflib.crtp
from cflib.crazyflie import Crazyflie
from cflib.crazyflie.log import LogConfig
from cflib.crazyflie.syncCrazyflie import SyncCrazyflie

STATES = {0: "idle", 1: "formation", 2: "hold", 3: "landing"}
FAULT_SUPERVISOR = 5
# Two log blocks per drone (26 bytes each at most, log.c:88).
BLOCKS = [
    [("stateEstimate.x", "float"), ("stateEstimate.y", "float"), ("stateEstimate.z", "float"),
     ("stateEstimate.vx", "float"), ("stateEstimate.vy", "float"),
     ("formation.state", "uint8_t"), ("formation.fault", "uint8_t"), ("formation.heard", "uint8_t")],
    [("ctrltarget.vx", "float"), ("ctrltarget.vy", "float"),
     ("formation.neighbours", "uint8_t"), ("formation.holdTicks", "uint32_t"),
     ("formation.landings", "uint32_t"), ("kalman.varPX", "float")],
]
# The flight log's columns (docs/crazyflie.md "The flight log").
COLUMNS = ["t_s", "agent", "drone_ms", "x", "y", "z", "vx", "vy", "setpoint_vx",
           "setpoint_vy", "state", "fault", "heard", "neighbours", "hold_ticks", "landings"]


def scenario_agents(path):
    with open(path, "rb") as f:
        s = tomllib.load(f)
    return s, [str(a["id"]) for a in s["agents"]]


def uris_of(args, agents):
    if args.sim:
        return [f"udp://127.0.0.1:{args.port + k}" for k in range(len(agents))]
    return [f"{args.radio.rstrip('/')}/E7E7E7E7{int(a):02X}?rate_limit=100" for a in agents]


class Drone:
    def __init__(self, agent, uri):
        self.agent, self.uri = agent, uri
        self.scf = SyncCrazyflie(uri, cf=Crazyflie(rw_cache="./cache"))
        self.lock = threading.Lock()
        self.values = {}
        self.rows = []  # (host time, drone ms, values)
        self.offset = math.inf  # host s - drone s, the least delayed packet's

    def connect(self):
        self.scf.open_link()
        for k, block in enumerate(BLOCKS):
            conf = LogConfig(name=f"swarm{k}", period_in_ms=50)
            for name, kind in block:
                conf.add_variable(name, kind)
            self.scf.cf.log.add_config(conf)
            conf.data_received_cb.add_callback(self._on_log)
            conf.start()

    def _on_log(self, t_ms, data, _conf):
        host = time.monotonic()
        with self.lock:
            self.values.update(data)
            self.offset = min(self.offset, host - t_ms / 1000.0)
            if "stateEstimate.x" in data:
                self.rows.append((t_ms, dict(self.values)))

    def get(self, key, default=None):
        with self.lock:
            return self.values.get(key, default)


def worst_angle_error(scenario, drones):
    """The largest |angle - desired| over the scenario's triangles (degrees)."""
    q = {d.agent: (d.get("stateEstimate.x"), d.get("stateEstimate.y")) for d in drones}
    worst = 0.0
    for tri in scenario.get("triangles", []):
        for a in tri.get("angles", []):
            apex = str(a["apex"])
            others = [str(v) for v in tri["vertices"] if str(v) != apex]
            if any(q.get(v, (None,))[0] is None for v in [apex] + others):
                return math.nan
            (ax, ay), (bx, by), (cx, cy) = q[apex], q[others[0]], q[others[1]]
            u, v = (bx - ax, by - ay), (cx - ax, cy - ay)
            nu, nv = math.hypot(*u), math.hypot(*v)
            if nu == 0 or nv == 0:
                return math.nan
            cos = max(-1.0, min(1.0, (u[0] * v[0] + u[1] * v[1]) / (nu * nv)))
            worst = max(worst, abs(math.degrees(math.acos(cos)) - a["desired_deg"]))
    return worst


def wait(what, check, seconds):
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if check():
            return
        time.sleep(0.05)
    raise RuntimeError(f"{what}: not within {seconds} s")


def write_log(path, drones, t0):
    """One row per log packet; t_s on the host's clock from the take-off command."""
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(COLUMNS)
        for d in drones:
            for t_ms, v in d.rows:
                t = t_ms / 1000.0 + d.offset - t0
                w.writerow([f"{t:.3f}", d.agent, t_ms] + [
                    v.get(k) for k in ("stateEstimate.x", "stateEstimate.y", "stateEstimate.z",
                                       "stateEstimate.vx", "stateEstimate.vy", "ctrltarget.vx",
                                       "ctrltarget.vy", "formation.state", "formation.fault",
                                       "formation.heard", "formation.neighbours",
                                       "formation.holdTicks", "formation.landings")])
    print(f"swarm: flight log {path} ({sum(len(d.rows) for d in drones)} rows)")


def preflight(drones):
    wait("log data", lambda: all(d.get("formation.state") is not None for d in drones), 5)
    for d in drones:
        problems = []
        if d.get("formation.heard") != d.get("formation.neighbours"):
            problems.append(f"hears {d.get('formation.heard')} of {d.get('formation.neighbours')} neighbours")
        if not d.get("kalman.varPX", 1.0) < 0.05 ** 2:
            problems.append("positioning not locked")
        if d.get("stateEstimate.z", 1.0) > 0.05:
            problems.append("not on the ground")
        if d.get("formation.state") != 0:
            problems.append(f"state {STATES.get(d.get('formation.state'))}")
        if problems:
            raise RuntimeError(f"pre-flight: drone {d.agent}: " + ", ".join(problems))
    print("swarm: pre-flight passed")


def take_off(cf, height):
    """The high-level commander's take-off, after handing the commander back to it: a
    client's earlier setpoints (cflib's close_link sends a zero one) keep the CRTP
    priority, above the high-level commander's, until a notify-stop relaxes it
    (crazyflie-firmware src/modules/src/commander.c:74-98, crtp_commander.c:91-102)."""
    cf.commander.send_notify_setpoint_stop()
    cf.high_level_commander.takeoff(height, 2.0)


def fly(args, scenario, drones):
    stop = threading.Event()
    signal.signal(signal.SIGINT, lambda *_: stop.set())
    preflight(drones)
    for d in drones:
        take_off(d.scf.cf, args.height)
    wait("take-off", lambda: all(d.get("stateEstimate.z", 0) >= 0.9 * args.height for d in drones), 10)
    for d in drones:
        d.scf.cf.param.set_value("formation.enable", 1)
    start = time.monotonic()
    reason = "time"
    while not stop.is_set() and time.monotonic() - start < args.seconds:
        time.sleep(1.0)
        for d in drones:
            print(f"  {d.agent}: {STATES.get(d.get('formation.state'), '?'):9} fault {d.get('formation.fault')}"
                  f" heard {d.get('formation.heard')}/{d.get('formation.neighbours')}"
                  f" q=({d.get('stateEstimate.x', 0):.2f}, {d.get('stateEstimate.y', 0):.2f},"
                  f" {d.get('stateEstimate.z', 0):.2f})")
        print(f"swarm: worst angle error {worst_angle_error(scenario, drones):.2f} deg", flush=True)
        faulty = [d.agent for d in drones if d.get("formation.state") in (2, 3)
                  or d.get("formation.fault", 0) >= FAULT_SUPERVISOR]
        if faulty:
            reason = f"fault on drones {', '.join(faulty)}"
            break
    if stop.is_set():
        reason = "Ctrl-C"
    print(f"swarm: landing ({reason})")
    for d in drones:
        d.scf.cf.param.set_value("formation.enable", 0)
    time.sleep(1.5)  # the high-level commander takes over and hovers (docs/crazyflie.md)
    for d in drones:
        d.scf.cf.high_level_commander.land(0.0, 3.0)
    wait("landing", lambda: all(d.get("stateEstimate.z", 1) <= 0.05 for d in drones), 10)
    for d in drones:
        d.scf.cf.high_level_commander.stop()  # on the ground: motors off


def step(args, drones):
    d = next((d for d in drones if d.agent == args.agent), None)
    if d is None:
        raise RuntimeError(f"--agent {args.agent}: not in the scenario")
    cf = d.scf.cf
    take_off(cf, args.height)
    wait("take-off", lambda: d.get("stateEstimate.z", 0) >= 0.9 * args.height, 10)
    for vx, seconds in ((0.0, 1.0), (args.speed, args.step_s), (0.0, 1.0)):
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            cf.commander.send_hover_setpoint(vx, 0.0, 0.0, args.height)
            time.sleep(0.02)
    cf.commander.send_notify_setpoint_stop()
    cf.high_level_commander.land(0.0, 2.0)
    wait("landing", lambda: d.get("stateEstimate.z", 1) <= 0.05, 10)


def compare_step(args):
    """RMS of the logged step response against host-sim vehicle step's (m/s)."""
    with open(args.scenario) as f:  # the step log (positional argument)
        rows = [r for r in csv.DictReader(f)]
    start = next((int(r["drone_ms"]) for r in rows
                  if r["setpoint_vx"] and abs(float(r["setpoint_vx"]) - args.speed) < 1e-6), None)
    if start is None:
        raise RuntimeError(f"{args.scenario}: no setpoint of {args.speed} m/s")
    logged = [((int(r["drone_ms"]) - start) / 1000.0, float(r["vx"])) for r in rows
              if r["vx"] and -0.2 <= (int(r["drone_ms"]) - start) / 1000.0 <= 2.0]
    with open(args.vehicle_step) as f:
        model = [(float(r["t"]), float(r["v_along"])) for r in csv.DictReader(f)]

    def at(t):
        if t <= 0.0:
            return 0.0
        k = min(int(t * 1000.0), len(model) - 2)  # step.csv: every ms
        (t0, v0), (t1, v1) = model[k], model[k + 1]
        return v0 + (v1 - v0) * (t - t0) / (t1 - t0)

    best = None
    for shift_ms in range(-200, 201, 5):
        d = [v - at(t + shift_ms / 1000.0) for t, v in logged if t + shift_ms / 1000.0 >= -0.2]
        rms = math.sqrt(sum(x * x for x in d) / len(d))
        if best is None or rms < best[0]:
            best = (rms, max(abs(x) for x in d), shift_ms)
    rms, worst, shift = best
    ok = rms <= args.tolerance
    print(f"swarm: step vs host-sim vehicle step: rms {rms:.4f} m/s, max {worst:.4f} m/s "
          f"(shift {shift} ms, {len(logged)} samples): {'within' if ok else 'beyond'} "
          f"{args.tolerance} m/s")
    return 0 if ok else 1


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("command", choices=["uris", "fly", "step", "compare-step"])
    ap.add_argument("scenario", help="the scenario (compare-step: the step's flight log)")
    ap.add_argument("vehicle_step", nargs="?", help="compare-step: host-sim vehicle step's step.csv")
    ap.add_argument("--tolerance", type=float, default=0.03)
    where = ap.add_mutually_exclusive_group()
    where.add_argument("--sim", action="store_true", help="host-sim serve's drones")
    where.add_argument("--radio", help="real drones: the Crazyradio URI prefix, e.g. radio://0/80/2M")
    ap.add_argument("--port", type=int, default=19850)
    ap.add_argument("--log", default="flight.csv")
    ap.add_argument("--seconds", type=float, default=60.0)
    ap.add_argument("--height", type=float, default=0.5)
    ap.add_argument("--agent", default="1")
    ap.add_argument("--speed", type=float, default=0.3)
    ap.add_argument("--step-s", type=float, default=3.0)
    args = ap.parse_args()
    if args.command == "compare-step":
        try:
            return compare_step(args)
        except (RuntimeError, OSError, KeyError, ValueError) as e:
            print(f"swarm: {e}", file=sys.stderr)
            return 1
    if not (args.sim or args.radio):
        ap.error("give --sim or --radio")
    scenario, agents = scenario_agents(args.scenario)
    uris = uris_of(args, agents)
    if args.command == "uris":
        print("\n".join(uris))
        return 0
    cflib.crtp.init_drivers()
    drones = [Drone(a, u) for a, u in zip(agents, uris)]
    if args.command == "step":
        drones = [d for d in drones if d.agent == args.agent]
    t0 = time.monotonic()
    try:
        for d in drones:
            d.connect()
        print(f"swarm: connected to {len(drones)} drones")
        if args.command == "fly":
            fly(args, scenario, drones)
        else:
            step(args, drones)
        return 0
    except RuntimeError as e:
        print(f"swarm: {e}; landing", file=sys.stderr)
        for d in drones:
            try:
                d.scf.cf.param.set_value("formation.enable", 0)
                d.scf.cf.high_level_commander.land(0.0, 3.0)
            except Exception:  # the link may be down
                pass
        return 1
    finally:
        write_log(args.log, drones, t0)
        for d in drones:
            d.scf.close_link()


if __name__ == "__main__":
    sys.exit(main())
