//! The daemons of `cargo xtask cluster-test`: `munged`, `slurmctld` and `slurmd` of a
//! one-node cluster on localhost, as children, stopped on drop; and the client commands
//! run against it.

use super::{mkdir, write, TIMEOUT};
use crate::tools;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// The daemons of a one-node cluster, stopped on drop.
pub struct Cluster {
    dir: PathBuf,
    conf: PathBuf,
    daemons: Vec<(&'static str, Child)>,
}

impl Cluster {
    pub fn start() -> Result<Self, String> {
        let dir = std::env::temp_dir().join(format!("ph-slurm-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        for d in ["state", "spool", "log"] {
            mkdir(&dir.join(d))?;
        }
        let mut c = Cluster {
            conf: dir.join("slurm.conf"),
            dir,
            daemons: Vec::new(),
        };
        let key = c.dir.join("munge.key");
        tools::run(
            Command::new(sbin("mungekey"))
                .arg("--create")
                .arg(format!("--keyfile={}", key.display())),
        )?;
        let sock = c.dir.join("munge.sock");
        let d = &c.dir;
        c.spawn(
            "munged",
            Command::new(sbin("munged")).args(["-F", "-f"]).args([
                format!("--socket={}", sock.display()),
                format!("--key-file={}", key.display()),
                format!("--pid-file={}", d.join("munged.pid").display()),
                format!("--log-file={}", d.join("log/munged.log").display()),
                format!("--seed-file={}", d.join("munged.seed").display()),
            ]),
        )?;
        let node = tools::output(Command::new(sbin("slurmd")).arg("-C"))?;
        let node = node.lines().next().unwrap_or_default().to_owned();
        let host = node
            .strip_prefix("NodeName=")
            .and_then(|s| s.split_whitespace().next())
            .ok_or_else(|| format!("slurmd -C printed no NodeName: {node}"))?
            .to_owned();
        write(&c.conf, &slurm_conf(&c.dir, &host, &node, &sock))?;
        let conf = c.conf.clone();
        // -D: in the foreground (our child); -i: ignore any saved state.
        c.spawn(
            "slurmctld",
            Command::new(sbin("slurmctld"))
                .args(["-D", "-i", "-f"])
                .arg(&conf),
        )?;
        c.spawn(
            "slurmd",
            Command::new(sbin("slurmd")).args(["-D", "-f"]).arg(&conf),
        )?;
        let deadline = Instant::now() + Duration::from_secs(60);
        loop {
            let state = c.output(Command::new("sinfo").args(["-h", "-o", "%T"]));
            if state.as_deref().map(str::trim) == Ok("idle") {
                return Ok(c);
            }
            if Instant::now() > deadline {
                return Err(format!(
                    "the node is not idle after 60 s ({state:?}); logs in {}",
                    c.dir.join("log").display()
                ));
            }
            std::thread::sleep(Duration::from_millis(200));
        }
    }

    fn spawn(&mut self, name: &'static str, cmd: &mut Command) -> Result<(), String> {
        let log = std::fs::File::create(self.dir.join(format!("log/{name}.out")))
            .map_err(|e| e.to_string())?;
        let err = log.try_clone().map_err(|e| e.to_string())?;
        let child = cmd
            .env("SLURM_CONF", &self.conf)
            .stdin(Stdio::null())
            .stdout(log)
            .stderr(err)
            .spawn()
            .map_err(|e| format!("{}: {e}", tools::show(cmd)))?;
        self.daemons.push((name, child));
        Ok(())
    }

    /// Runs a Slurm client command against this cluster; its stdout.
    pub fn output(&self, cmd: &mut Command) -> Result<String, String> {
        tools::output(cmd.env("SLURM_CONF", &self.conf))
    }

    /// Submits `script` as `--array=ARRAY` for `sweep` into `shards/<task>`; the job id.
    pub fn submit(
        &self,
        script: &Path,
        ph_formation_sim: &Path,
        sweep: &Path,
        shards: &Path,
        array: &str,
        shards_n: Option<u32>,
    ) -> Result<String, String> {
        let dir = script.parent().unwrap_or(Path::new("."));
        let mut c = Command::new("sbatch");
        c.args(["--parsable", &format!("--array={array}")])
            .arg(format!("--chdir={}", dir.display()))
            .arg(script)
            .env("HOST_SIM", ph_formation_sim)
            .env("SWEEP", sweep)
            .env("SHARDS", shards);
        match shards_n {
            Some(n) => c.env("SHARDS_N", n.to_string()),
            None => c.env_remove("SHARDS_N"),
        };
        let id = self.output(&mut c)?.trim().to_owned();
        println!("cluster-test: sbatch --array={array} → job {id}");
        Ok(id)
    }

    /// Waits (polling squeue) until every task of `job` ended; their final states.
    pub fn wait(&self, job: &str) -> Result<Vec<(String, String)>, String> {
        let deadline = Instant::now() + TIMEOUT;
        loop {
            let out = self.output(Command::new("squeue").args([
                "--states=all",
                "-h",
                "-o",
                "%i %T",
                "-j",
                job,
            ]))?;
            let tasks: Vec<(String, String)> = out
                .lines()
                .filter_map(|l| l.split_once(' '))
                .map(|(i, s)| (i.to_owned(), s.trim().to_owned()))
                .collect();
            let live = [
                "PENDING",
                "RUNNING",
                "CONFIGURING",
                "COMPLETING",
                "SUSPENDED",
            ];
            if !tasks.is_empty() && tasks.iter().all(|(_, s)| !live.contains(&s.as_str())) {
                let mut tasks = tasks;
                tasks.sort();
                return Ok(tasks);
            }
            if Instant::now() > deadline {
                return Err(format!("job {job} not done after {TIMEOUT:?}: {tasks:?}"));
            }
            std::thread::sleep(Duration::from_millis(200));
        }
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        // Cancel what still runs (its slurmstepd would outlive slurmd), then the daemons.
        let _ = self.output(Command::new("scancel").args(["--partition=test"]));
        for _ in 0..50 {
            match self.output(Command::new("squeue").args(["-h", "-o", "%i"])) {
                Ok(s) if s.trim().is_empty() => break,
                Err(_) => break,
                _ => std::thread::sleep(Duration::from_millis(200)),
            }
        }
        for (name, child) in self.daemons.iter_mut().rev() {
            let _ = Command::new("kill").arg(child.id().to_string()).status();
            if child.wait().is_err() {
                eprintln!("cluster-test: could not stop {name}");
            }
        }
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// A daemon from /usr/sbin (not on every root PATH).
fn sbin(name: &str) -> PathBuf {
    let p = Path::new("/usr/sbin").join(name);
    if p.is_file() {
        p
    } else {
        PathBuf::from(name)
    }
}

/// One node on localhost, everything in `dir`, no accounting, no cgroups.
fn slurm_conf(dir: &Path, host: &str, node: &str, munge: &Path) -> String {
    let d = dir.display();
    format!(
        "ClusterName=phtest
SlurmctldHost={host}(127.0.0.1)
SlurmctldPort=16817
SlurmdPort=16818
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket={munge}
StateSaveLocation={d}/state
SlurmdSpoolDir={d}/spool
SlurmctldPidFile={d}/slurmctld.pid
SlurmdPidFile={d}/slurmd.pid
SlurmctldLogFile={d}/log/slurmctld.log
SlurmdLogFile={d}/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
KillWait=10
MinJobAge=600
MailProg=/bin/true
{node} NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=test Nodes=ALL Default=YES MaxTime=INFINITE State=UP
",
        munge = munge.display()
    )
}
