//! `host-sim serve SCENARIO [--set ...] [--port 19850]`: the scenario's drones as
//! simulated Crazyflies that Bitcraze's client library reaches over `udp://`
//! (docs/crazyflie.md "Simulated Crazyflies over udp://").
//!
//! Each agent is one process of the agent program (`controller-ffi/c/build.sh
//! cfapp-agent`: the app's own C code, `crazyflie-app/src/app.c`, against host
//! stand-ins of the firmware's services, `crazyflie-app/test/serve_*.c`), started with
//! its exported blob and initial position; it owns its vehicle (the Crazyflie cascade
//! of `world = "crazyflie"`), its paced clock and its CRTP port. This process owns the
//! scenario and the radio between the agents:
//!
//! - agent k (scenario order, from 0) answers CRTP on `udp://127.0.0.1:PORT+k`;
//! - the agents' P2P packets go to the relay at `127.0.0.1:PORT+100` from each agent's
//!   own socket `PORT+101+k`, and the relay hands each to every other agent;
//! - the relay keeps one clock for every agent: it grants the next 10 ms tick once
//!   every agent has done the last one and the wall clock (times `--speed`) has
//!   reached it, so a loaded machine slows the whole world down evenly;
//! - standard input takes one command a line: `cut ID` drops every P2P packet to and
//!   from agent ID (its radio to its neighbours is cut; its CRTP link stays up, so the
//!   client still sees it), `restore ID` ends that, `quit` (or the end of input) stops
//!   every agent and exits.
//!
//! Standard output: one `serve: agent ID (wire id N) at udp://127.0.0.1:P` line per
//! agent, then `serve: ready`, then one line per command done.

use crate::exit_code;
use crate::model::{Model, VehicleModel};
use std::io::{BufRead, BufReader, Write as _};
use std::net::UdpSocket;
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// The environment variable naming the agent program when `--agent` is not given.
pub const AGENT_ENV: &str = "PH_CFAPP_AGENT";
/// The relay's port, above the first CRTP port.
pub const RELAY_OFFSET: u16 = 100;

/// Arguments of `host-sim serve`.
#[derive(Debug, clap::Args)]
pub struct ServeArgs {
    /// Scenario file or built-in name.
    pub scenario: String,
    /// Override a field first, e.g. `--set world=crazyflie`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// The first agent's CRTP port (agent k of the scenario: PORT+k).
    #[arg(long, default_value_t = 19850)]
    pub port: u16,
    /// The agent program (`controller-ffi/c/build.sh cfapp-agent OUT_DIR`); default:
    /// the environment variable PH_CFAPP_AGENT.
    #[arg(long, value_name = "PATH")]
    pub agent: Option<PathBuf>,
    /// Simulated seconds per wall-clock second (1: real time; tests may go faster).
    #[arg(long, default_value_t = 1.0)]
    pub speed: f64,
}

/// Why a scenario cannot be served.
fn refusal(model: &Model) -> Option<String> {
    if model.sensors.camera.is_some() {
        return Some(
            "its agents sense bearings with a camera ([sensors.camera]); the Crazyflie app \
             senses its neighbours only through their shared positions (P2P position packets), \
             so a camera world cannot be served"
                .to_owned(),
        );
    }
    if model.sensors.positions.is_none() {
        return Some(
            "its agents do not share positions: the Crazyflie app computes every bearing \
             from its neighbours' position packets; set sensors.bearing_source = \
             \"shared_positions\" (the crazyflie world does: --set world=crazyflie)"
                .to_owned(),
        );
    }
    if !matches!(model.world.vehicle, VehicleModel::CrazyfliePid(_)) {
        return Some(format!(
            "its world is '{}': the served drones fly the Crazyflie's PID cascade; serve it \
             with --set world=crazyflie",
            model.world.preset
        ));
    }
    None
}

struct Agent {
    name: String,
    child: Child,
}

/// Runs `host-sim serve`; returns the exit code.
pub(super) fn serve_command(args: &ServeArgs) -> u8 {
    let model = match crate::api::load(&args.scenario, &args.set) {
        Ok(m) => m,
        Err(e) => return super::report(&e),
    };
    if let Some(why) = refusal(&model) {
        eprintln!("error: {}: cannot serve: {why}", model.source);
        return exit_code::USAGE;
    }
    if !(args.speed > 0.0 && args.speed <= 100.0) {
        eprintln!("error: --speed {}: must be in (0, 100]", args.speed);
        return exit_code::USAGE;
    }
    let n = model.agents.len();
    if usize::from(args.port) + usize::from(RELAY_OFFSET) + n + 1 > usize::from(u16::MAX) {
        eprintln!(
            "error: --port {}: the ports of {n} agents do not fit",
            args.port
        );
        return exit_code::USAGE;
    }
    let Some(program) = args
        .agent
        .clone()
        .or_else(|| std::env::var_os(AGENT_ENV).map(PathBuf::from))
    else {
        eprintln!(
            "error: no agent program: build it with `controller-ffi/c/build.sh cfapp-agent DIR` \
             and give --agent DIR/cfapp-agent (or set {AGENT_ENV})"
        );
        return exit_code::USAGE;
    };
    if !program.is_file() {
        eprintln!(
            "error: --agent {}: no such file (build it with `controller-ffi/c/build.sh \
             cfapp-agent DIR`)",
            program.display()
        );
        return exit_code::USAGE;
    }
    let relay = match UdpSocket::bind(("127.0.0.1", args.port + RELAY_OFFSET)) {
        Ok(s) => s,
        Err(e) => {
            eprintln!(
                "error: cannot bind the relay at udp 127.0.0.1:{}: {e}",
                args.port + RELAY_OFFSET
            );
            return exit_code::IO;
        }
    };
    let dir = std::env::temp_dir().join(format!("ph-serve-{}", std::process::id()));
    let agents = spawn_all(&model, args, &program, &dir);
    let _ = std::fs::remove_dir_all(&dir);
    let mut agents = match agents {
        Ok(a) => a,
        Err(e) => {
            eprintln!("error: {e}");
            return exit_code::IO;
        }
    };
    let cut = Arc::new(Mutex::new(vec![false; n]));
    let stop = Arc::new(AtomicBool::new(false));
    let relay_thread = {
        let (cut, stop, port, speed) = (Arc::clone(&cut), Arc::clone(&stop), args.port, args.speed);
        std::thread::spawn(move || relay_loop(&relay, port, speed, n, &cut, &stop))
    };
    println!("serve: ready");
    let _ = std::io::stdout().flush();
    let code = command_loop(&model, &cut, &mut agents);
    stop.store(true, Ordering::Relaxed);
    for a in &mut agents {
        let _ = a.child.kill();
        let _ = a.child.wait();
    }
    let _ = relay_thread.join();
    code
}

/// Exports every agent's blob into `dir` and starts its process; waits for each to say
/// it is ready.
fn spawn_all(
    model: &Model,
    args: &ServeArgs,
    program: &std::path::Path,
    dir: &std::path::Path,
) -> Result<Vec<Agent>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let mut agents: Vec<Agent> = Vec::new();
    for (k, a) in model.agents.iter().enumerate() {
        let exported = super::export::export_agent(model, k).map_err(|e| e.to_string())?;
        let blob = dir.join(format!("agent{}.blob", a.name));
        std::fs::write(&blob, &exported.blob)
            .map_err(|e| format!("cannot write {}: {e}", blob.display()))?;
        let port = args.port + k as u16;
        let mut child = Command::new(program)
            .args(["--id", &exported.id.to_string()])
            .args(["--crtp-port", &port.to_string()])
            .args([
                "--p2p-port",
                &(args.port + RELAY_OFFSET + 1 + k as u16).to_string(),
            ])
            .args(["--relay-port", &(args.port + RELAY_OFFSET).to_string()])
            .args(["--x", &a.position[0].to_string()])
            .args(["--y", &a.position[1].to_string()])
            .args(["--relay-clock", "1"])
            .arg("--blob")
            .arg(&blob)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .spawn()
            .map_err(|e| format!("cannot start {}: {e}", program.display()))?;
        let mut line = String::new();
        if let Some(out) = child.stdout.take() {
            let _ = BufReader::new(out).read_line(&mut line);
        }
        if !line.starts_with("CFAGENT ready") {
            let _ = child.kill();
            for mut other in agents {
                let _ = other.child.kill();
                let _ = other.child.wait();
            }
            return Err(format!(
                "agent {} did not start (its stderr says why; it printed {line:?})",
                a.name
            ));
        }
        println!(
            "serve: agent {} (wire id {}) at udp://127.0.0.1:{port}",
            a.name, exported.id
        );
        agents.push(Agent {
            name: a.name.clone(),
            child,
        });
    }
    Ok(agents)
}

/// The relay's clock messages (first byte of a datagram; P2P packets start with
/// their port, 0 or 1): a grant of time to an agent, an agent's tick done.
const GRANT: u8 = 0xF0;
const DONE: u8 = 0xF1;
/// The firmware's tick (ms).
const TICK_MS: u32 = 10;

/// The relay: hands every P2P packet to every other agent, unless the sender's or
/// the receiver's radio is cut; and keeps one clock for all agents: time `t` is
/// granted (`[GRANT, t]`) once every agent has reported its tick at `t − 10 ms`
/// (`[DONE, t − 10]`) and the wall clock has reached `t / speed`. A loaded machine
/// slows the whole world down rather than letting one drone fall behind the others.
fn relay_loop(
    relay: &UdpSocket,
    port: u16,
    speed: f64,
    n: usize,
    cut: &Mutex<Vec<bool>>,
    stop: &AtomicBool,
) {
    let first = port + RELAY_OFFSET + 1;
    let mut done = vec![false; n];
    let mut granted: u32 = 0;
    let start = Instant::now();
    let mut buf = [0u8; 128];
    let grant = |t: u32| {
        let mut d = [GRANT, 0, 0, 0, 0];
        d[1..].copy_from_slice(&t.to_le_bytes());
        for j in 0..n {
            let _ = relay.send_to(&d, ("127.0.0.1", first + j as u16));
        }
    };
    while !stop.load(Ordering::Relaxed) {
        if done.iter().all(|&d| d) {
            let due = start + Duration::from_secs_f64(f64::from(granted + TICK_MS) / 1e3 / speed);
            let now = Instant::now();
            if now >= due {
                granted += TICK_MS;
                done.iter_mut().for_each(|d| *d = false);
                grant(granted);
                continue;
            }
            let _ = relay.set_read_timeout(Some(due - now));
        } else {
            let _ = relay.set_read_timeout(Some(Duration::from_millis(50)));
        }
        let Ok((len, from)) = relay.recv_from(&mut buf) else {
            continue;
        };
        let k = usize::from(from.port().wrapping_sub(first));
        if k >= n || len == 0 {
            continue;
        }
        if buf[0] == DONE && len == 5 {
            let t = u32::from_le_bytes([buf[1], buf[2], buf[3], buf[4]]);
            if t == granted {
                done[k] = true;
            }
            continue;
        }
        let cut = cut.lock().map(|c| c.clone()).unwrap_or_default();
        if cut.get(k).copied().unwrap_or(false) {
            continue;
        }
        for j in (0..n).filter(|&j| j != k && !cut.get(j).copied().unwrap_or(false)) {
            let _ = relay.send_to(&buf[..len], ("127.0.0.1", first + j as u16));
        }
    }
}

/// Reads commands from standard input until `quit` or its end, or an agent dies.
fn command_loop(model: &Model, cut: &Mutex<Vec<bool>>, agents: &mut [Agent]) -> u8 {
    let stdin = std::io::stdin();
    for line in stdin.lock().lines() {
        let Ok(line) = line else { break };
        let words: Vec<&str> = line.split_whitespace().collect();
        for a in agents.iter_mut() {
            if let Ok(Some(status)) = a.child.try_wait() {
                eprintln!("error: agent {} exited ({status})", a.name);
                return exit_code::IO;
            }
        }
        match words.as_slice() {
            [] => {}
            ["quit"] => break,
            [verb @ ("cut" | "restore"), id] => {
                match model.agents.iter().position(|a| a.name == *id) {
                    Some(k) => {
                        if let Ok(mut c) = cut.lock() {
                            c[k] = *verb == "cut";
                        }
                        println!("serve: {verb} {id}");
                    }
                    None => eprintln!("serve: no agent {id}"),
                }
            }
            _ => eprintln!("serve: unknown command {line:?} (cut ID, restore ID, quit)"),
        }
        let _ = std::io::stdout().flush();
    }
    exit_code::CONVERGED
}
