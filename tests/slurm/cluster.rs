//! A private Slurm on localhost for one test: munged, slurmctld and slurmd as children of
//! the test, on free ports, with their state in a temporary folder; stopped by process id
//! (jobs cancelled first: they outlive slurmd) when the test ends, even by a panic.
//!
//! It follows `shared/recipes/slurm-localhost.md`, with three settings of its own for
//! speed: the scheduler looks at pending jobs every second (a requeued task is otherwise
//! started only at the next periodic pass, up to a minute later); a requeued task may start
//! 6 s after its requeue (`cred_expire=5`, Slurm's least; 121 s by default); and a
//! cancelled job is killed 5 s after its SIGTERM (30 s by default). Partition `restricted`
//! admits account `physics` only, and is enforced at submission (`EnforcePartLimits`), so
//! that a wrong account is refused by sbatch as a cluster with accounting refuses it.

use std::os::unix::fs::PermissionsExt;
use std::os::unix::process::CommandExt;
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A running Slurm.
pub struct Slurm {
    dir: tempfile::TempDir,
    /// Its slurm.conf: every client needs it as `SLURM_CONF`.
    pub conf: PathBuf,
    daemons: Vec<Child>,
}

/// A Slurm for the test `test`, or `None` (with the reason on stderr) where none can be
/// started, except under CI (`CI=true`), where that fails the test.
pub fn start_or_skip(test: &str) -> Option<Slurm> {
    match Slurm::start() {
        Ok(s) => Some(s),
        Err(e) if std::env::var("CI").is_ok_and(|v| v == "true") => {
            panic!("{test}: cannot start a Slurm on localhost under CI: {e}")
        }
        Err(e) => {
            // Straight to stderr, past the harness's capture: a skip is seen in every run.
            use std::io::Write;
            let _ = writeln!(std::io::stderr(), "skipped {test}: cannot start a Slurm on localhost: {e}");
            None
        }
    }
}

/// A daemon's path: on the PATH, or in the sbin folders an ordinary user's PATH may lack.
pub fn find(name: &str) -> Result<PathBuf, String> {
    let path = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&path)
        .chain(["/usr/sbin", "/sbin", "/usr/local/sbin"].map(PathBuf::from))
        .map(|d| d.join(name))
        .find(|p| p.is_file())
        .ok_or_else(|| {
            format!("`{name}` not found (Debian: apt-get install slurmctld slurmd slurm-client munge, as .ci/run does)")
        })
}

/// A TCP port free now on 127.0.0.1.
fn free_port() -> Result<u16, String> {
    let l = std::net::TcpListener::bind("127.0.0.1:0").map_err(|e| format!("no free port: {e}"))?;
    Ok(l.local_addr().map_err(|e| e.to_string())?.port())
}

impl Slurm {
    fn start() -> Result<Self, String> {
        let (munged, slurmctld, slurmd) = (find("munged")?, find("slurmctld")?, find("slurmd")?);
        for client in ["sbatch", "squeue", "scancel", "scontrol", "sinfo"] {
            find(client)?;
        }
        let dir = tempfile::tempdir().map_err(|e| e.to_string())?;
        let t = dir.path().to_path_buf();
        let io = |e: std::io::Error| e.to_string();
        // munged: every folder above its socket must be o+x; its key 0600 in a 0700 folder.
        std::fs::set_permissions(&t, std::fs::Permissions::from_mode(0o755)).map_err(io)?;
        for (sub, mode) in
            [("state", 0o755), ("spool", 0o755), ("log", 0o755), ("munge", 0o700), ("run", 0o755)]
        {
            std::fs::create_dir(t.join(sub)).map_err(io)?;
            std::fs::set_permissions(t.join(sub), std::fs::Permissions::from_mode(mode)).map_err(io)?;
        }
        let key = t.join("munge/munge.key");
        let mut bytes = vec![0u8; 1024];
        std::io::Read::read_exact(&mut std::fs::File::open("/dev/urandom").map_err(io)?, &mut bytes)
            .map_err(io)?;
        std::fs::write(&key, &bytes).map_err(io)?;
        std::fs::set_permissions(&key, std::fs::Permissions::from_mode(0o600)).map_err(io)?;
        let mut s = Slurm { conf: t.join("slurm.conf"), dir, daemons: Vec::new() };
        let socket = t.join("run/munge.sock");
        s.spawn(
            Command::new(munged)
                .arg("-F")
                .arg(format!("--socket={}", socket.display()))
                .arg(format!("--key-file={}", key.display()))
                .arg(format!("--pid-file={}", t.join("run/munged.pid").display()))
                .arg(format!("--log-file={}", t.join("munge/munged.log").display()))
                .arg(format!("--seed-file={}", t.join("munge/munged.seed").display())),
            "munged",
        )?;
        s.wait_for("munged's socket", Duration::from_secs(10), |_| socket.exists())?;

        let user = String::from_utf8_lossy(&Command::new("id").arg("-un").output().map_err(io)?.stdout)
            .trim()
            .to_string();
        let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
        let (ctld_port, d_port) = (free_port()?, free_port()?);
        let d = t.display();
        let conf = format!(
            "ClusterName=ci\n\
             SlurmctldHost=localhost\n\
             SlurmctldPort={ctld_port}\n\
             SlurmdPort={d_port}\n\
             SlurmUser={user}\n\
             SlurmdUser={user}\n\
             AuthType=auth/munge\n\
             CredType=cred/munge\n\
             AuthInfo=socket={d}/run/munge.sock,cred_expire=5\n\
             StateSaveLocation={d}/state\n\
             SlurmdSpoolDir={d}/spool\n\
             SlurmctldPidFile={d}/slurmctld.pid\n\
             SlurmdPidFile={d}/slurmd.pid\n\
             SlurmctldLogFile={d}/log/slurmctld.log\n\
             SlurmdLogFile={d}/log/slurmd.log\n\
             ProctrackType=proctrack/linuxproc\n\
             TaskPlugin=task/none\n\
             SelectType=select/cons_tres\n\
             SelectTypeParameters=CR_Core\n\
             SchedulerType=sched/backfill\n\
             SchedulerParameters=batch_sched_delay=0,sched_min_interval=0,sched_interval=1,bf_interval=1\n\
             KillWait=5\n\
             MpiDefault=none\n\
             MailProg=/bin/true\n\
             ReturnToService=2\n\
             EnforcePartLimits=ALL\n\
             JobCompType=jobcomp/filetxt\n\
             JobCompLoc={d}/log/jobcomp.txt\n\
             NodeName=localhost NodeAddr=127.0.0.1 CPUs={cpus} RealMemory=1000 State=UNKNOWN\n\
             PartitionName=debug Nodes=localhost Default=YES MaxTime=INFINITE State=UP\n\
             PartitionName=restricted Nodes=localhost AllowAccounts=physics MaxTime=INFINITE State=UP\n"
        );
        std::fs::write(&s.conf, conf).map_err(io)?;
        let conf = s.conf.clone();
        s.spawn(Command::new(slurmctld).arg("-D").arg("-f").arg(&conf), "slurmctld")?;
        s.spawn(Command::new(slurmd).arg("-D").arg("-f").arg(&conf).args(["-N", "localhost"]), "slurmd")?;
        s.wait_for("the node to be idle", Duration::from_secs(30), |s| {
            let o = s.cmd("sinfo").args(["-h", "-N", "-n", "localhost", "-p", "debug", "-o", "%T"]).output();
            o.is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "idle")
        })?;
        Ok(s)
    }

    /// Starts a daemon as a child of the test, told to stop if the test's thread dies.
    fn spawn(&mut self, cmd: &mut Command, name: &str) -> Result<(), String> {
        let out = std::fs::File::create(self.dir.path().join(format!("log/{name}.out")))
            .map_err(|e| e.to_string())?;
        let err = out.try_clone().map_err(|e| e.to_string())?;
        cmd.env("SLURM_CONF", &self.conf).stdin(Stdio::null()).stdout(out).stderr(err);
        // SAFETY: prctl is async-signal-safe.
        unsafe {
            cmd.pre_exec(|| {
                libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGTERM);
                Ok(())
            });
        }
        let child = cmd.spawn().map_err(|e| format!("cannot start {name}: {e}"))?;
        self.daemons.push(child);
        Ok(())
    }

    /// Polls `ready` every 0.1 s; after `limit`, fails with the daemons' logs.
    fn wait_for(&self, what: &str, limit: Duration, ready: impl Fn(&Self) -> bool) -> Result<(), String> {
        let t0 = Instant::now();
        while !ready(self) {
            if t0.elapsed() > limit {
                return Err(format!("no {what} after {limit:?}:\n{}", self.logs()));
            }
            std::thread::sleep(Duration::from_millis(100));
        }
        Ok(())
    }

    /// The tail of every daemon's log, for a failure message.
    pub fn logs(&self) -> String {
        let mut out = String::new();
        for name in ["munged.out", "slurmctld.out", "slurmd.out", "slurmctld.log", "slurmd.log"] {
            let text = std::fs::read_to_string(self.dir.path().join("log").join(name)).unwrap_or_default();
            let tail: Vec<&str> = text.lines().rev().take(15).collect();
            out += &format!("--- {name}\n{}\n", tail.into_iter().rev().collect::<Vec<_>>().join("\n"));
        }
        out
    }

    /// A Slurm client command (`squeue`, `scancel`, ...) talking to this Slurm.
    pub fn cmd(&self, tool: &str) -> Command {
        let mut c = Command::new(tool);
        c.env("SLURM_CONF", &self.conf);
        c
    }

    /// The ids (`JOB_TASK`) of the array tasks in state `state` (e.g. `running`).
    pub fn tasks(&self, state: &str) -> Vec<String> {
        let o = self.cmd("squeue").args(["-h", "-r", "-t", state, "-o", "%i"]).output().unwrap();
        String::from_utf8_lossy(&o.stdout).split_whitespace().map(String::from).collect()
    }

    /// Whether any job is pending or running.
    pub fn busy(&self) -> bool {
        !self.tasks("pending,running,completing").is_empty()
    }

    /// Waits until no job is pending or running (at most `limit`).
    pub fn wait_idle(&self, limit: Duration) {
        let t0 = Instant::now();
        while self.busy() {
            assert!(t0.elapsed() < limit, "jobs still queued after {limit:?}:\n{}", self.logs());
            std::thread::sleep(Duration::from_millis(200));
        }
    }
}

impl Drop for Slurm {
    fn drop(&mut self) {
        // Jobs outlive slurmd (their slurmstepd is its own daemon): cancel them, wait until
        // they are gone, then stop the daemons by process id, newest first.
        if !self.daemons.is_empty() {
            let _ = self.cmd("scancel").arg("--me").stdout(Stdio::null()).stderr(Stdio::null()).status();
            let t0 = Instant::now();
            while self.busy() && t0.elapsed() < Duration::from_secs(20) {
                std::thread::sleep(Duration::from_millis(100));
            }
        }
        for child in self.daemons.iter_mut().rev() {
            // SAFETY: kill with the pid of our own child, not yet reaped.
            unsafe {
                libc::kill(child.id() as libc::pid_t, libc::SIGTERM);
            }
            let _ = child.wait();
        }
    }
}
