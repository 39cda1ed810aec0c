//! `cargo xtask slurm-demo`: photonflow under a real scheduler on this one machine. Installs
//! Slurm from Debian's packages if it is missing (munge, slurmctld, slurmd), writes a
//! one-node `slurm.conf` into a temporary directory, starts munged, slurmctld and slurmd
//! there (directly: no systemd), submits a path-traced render as an array of 4 shards plus
//! the merge with `deploy/slurm/submit.sh`, waits, checks the merged image and layers against
//! a one-machine run byte for byte, and stops the daemons it started, on failure too. Runs
//! as root (the daemons and the package install need it).

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

const SHARDS: u32 = 4;
/// The worksheet scene, path traced: 4 shards of 16 samples per pixel take seconds each.
const SCENE: &str = "scenes/cornell-spheres/analytic.toml";
const RENDER: &[&str] = &["--method", "path", "--spp", "16"];
const NODE: &str = "pfnode";

/// The daemons this run started, stopped (by their pids) when it is dropped.
struct Daemons(Vec<(&'static str, Child)>);

impl Drop for Daemons {
    fn drop(&mut self) {
        for (name, child) in self.0.iter_mut().rev() {
            let _ = Command::new("kill").arg(child.id().to_string()).status();
            let deadline = Instant::now() + Duration::from_secs(10);
            while Instant::now() < deadline {
                if let Ok(Some(_)) = child.try_wait() {
                    break;
                }
                std::thread::sleep(Duration::from_millis(100));
            }
            if let Ok(None) = child.try_wait() {
                let _ = child.kill();
                let _ = child.wait();
            }
            println!("stopped {name} (pid {})", child.id());
        }
    }
}

fn sh(cmd: &mut Command) -> Result<String, String> {
    let out = cmd
        .output()
        .map_err(|e| format!("cannot run {cmd:?}: {e}"))?;
    if !out.status.success() {
        return Err(format!(
            "{cmd:?} failed ({}): {}{}",
            out.status,
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}

fn on_path(bin: &str) -> bool {
    Command::new("sh")
        .args(["-c", &format!("command -v {bin}")])
        .stdout(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// Installs Debian's Slurm and munge packages if a daemon or client is missing.
fn install() -> Result<(), String> {
    let needed = [
        "munged",
        "slurmctld",
        "slurmd",
        "sbatch",
        "squeue",
        "scontrol",
    ];
    if needed.iter().all(|b| on_path(b)) {
        println!("slurm and munge are installed");
        return Ok(());
    }
    println!("installing slurm-wlm and munge from Debian's packages ...");
    let apt = |args: &[&str]| {
        sh(Command::new("apt-get")
            .args(args)
            .env("DEBIAN_FRONTEND", "noninteractive"))
    };
    apt(&["update", "-q"])?;
    apt(&[
        "install",
        "-y",
        "-q",
        "--no-install-recommends",
        "slurm-wlm",
        "munge",
    ])?;
    match needed.iter().find(|b| !on_path(b)) {
        Some(b) => Err(format!(
            "{b} is still missing after installing slurm-wlm and munge"
        )),
        None => Ok(()),
    }
}

fn short_hostname() -> Result<String, String> {
    Ok(sh(Command::new("hostname").arg("-s"))?.trim().to_string())
}

/// Waits until `f` holds, polling every half second, or fails after `limit` naming `what`.
fn wait(what: &str, limit: Duration, mut f: impl FnMut() -> bool) -> Result<(), String> {
    let t0 = Instant::now();
    while t0.elapsed() < limit {
        if f() {
            return Ok(());
        }
        std::thread::sleep(Duration::from_millis(500));
    }
    Err(format!(
        "timed out after {} s waiting for {what}",
        limit.as_secs()
    ))
}

/// Files of a run directory compared byte for byte: the image and its layers.
fn images(dir: &Path) -> Result<Vec<(String, Vec<u8>)>, String> {
    let mut out = Vec::new();
    let read = |p: &Path| std::fs::read(p).map_err(|e| format!("{}: {e}", p.display()));
    out.push(("image.exr".to_string(), read(&dir.join("image.exr"))?));
    let layers = dir.join("layers");
    let mut names: Vec<PathBuf> = std::fs::read_dir(&layers)
        .map_err(|e| format!("{}: {e}", layers.display()))?
        .flatten()
        .map(|e| e.path())
        .collect();
    names.sort();
    for p in names {
        let name = p.strip_prefix(dir).unwrap_or(&p).display().to_string();
        out.push((name, read(&p)?));
    }
    Ok(out)
}

pub fn run(root: &Path, exe: &Path) -> Result<(), String> {
    if sh(Command::new("id").arg("-u"))?.trim() != "0" {
        return Err("slurm-demo installs packages and starts daemons: run it as root".into());
    }
    install()?;
    let tmp = std::env::temp_dir().join(format!("photonflow-slurm-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&tmp);
    for d in ["ctld", "spool", "munge", "log", "shards"] {
        std::fs::create_dir_all(tmp.join(d)).map_err(|e| format!("{}: {e}", tmp.display()))?;
    }
    let result = demo(root, exe, &tmp);
    match &result {
        Ok(()) => {
            let _ = std::fs::remove_dir_all(&tmp);
        }
        Err(_) => println!("logs kept in {}/log", tmp.display()),
    }
    result
}

fn demo(root: &Path, exe: &Path, tmp: &Path) -> Result<(), String> {
    let t = |p: &str| tmp.join(p).display().to_string();
    let host = short_hostname()?;
    let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
    let socket = t("munge/munge.socket");
    let conf = format!(
        "ClusterName=photonflow-demo\n\
         SlurmctldHost={host}(127.0.0.1)\n\
         SlurmctldPort=16817\nSlurmdPort=16818\n\
         SlurmUser=root\nSlurmdUser=root\n\
         AuthType=auth/munge\nCredType=cred/munge\nAuthInfo=socket={socket}\n\
         StateSaveLocation={ctld}\nSlurmdSpoolDir={spool}\n\
         SlurmctldPidFile={ctld}/slurmctld.pid\nSlurmdPidFile={spool}/slurmd.pid\n\
         SlurmctldLogFile={log}/slurmctld.log\nSlurmdLogFile={log}/slurmd.log\n\
         ProctrackType=proctrack/linuxproc\nTaskPlugin=task/none\n\
         JobAcctGatherType=jobacct_gather/none\nAccountingStorageType=accounting_storage/none\n\
         SchedulerType=sched/backfill\nSelectType=select/cons_tres\n\
         SelectTypeParameters=CR_CPU\nReturnToService=2\nMpiDefault=none\n\
         MinJobAge=600\n\
         NodeName={NODE} NodeAddr=127.0.0.1 CPUs={cpus} State=UNKNOWN\n\
         PartitionName=demo Nodes={NODE} Default=YES MaxTime=INFINITE State=UP\n",
        ctld = t("ctld"),
        spool = t("spool"),
        log = t("log"),
    );
    let conf_path = tmp.join("slurm.conf");
    std::fs::write(&conf_path, conf).map_err(|e| format!("{}: {e}", conf_path.display()))?;
    // munged wants a key only its owner can read, in a directory others cannot write.
    let key = tmp.join("munge/munge.key");
    let mut k = vec![0u8; 1024];
    std::fs::File::open("/dev/urandom")
        .and_then(|mut f| std::io::Read::read_exact(&mut f, &mut k))
        .map_err(|e| format!("/dev/urandom: {e}"))?;
    std::fs::write(&key, k).map_err(|e| format!("{}: {e}", key.display()))?;
    sh(Command::new("chmod").args(["0400", &key.display().to_string()]))?;
    sh(Command::new("chmod").args(["0700", &t("munge"), &t("log")]))?;

    let mut daemons = Daemons(Vec::new());
    let spawn = |name: &'static str, cmd: &mut Command, d: &mut Daemons| -> Result<(), String> {
        let log = std::fs::File::create(tmp.join("log").join(format!("{name}.out")))
            .map_err(|e| e.to_string())?;
        let err = log.try_clone().map_err(|e| e.to_string())?;
        let child = cmd
            .stdout(log)
            .stderr(err)
            .spawn()
            .map_err(|e| format!("cannot start {name}: {e}"))?;
        println!("started {name} (pid {})", child.id());
        d.0.push((name, child));
        Ok(())
    };
    spawn(
        "munged",
        Command::new("munged").args([
            "--foreground",
            "--force",
            &format!("--socket={socket}"),
            &format!("--key-file={}", key.display()),
            &format!("--pid-file={}", t("munge/munged.pid")),
            &format!("--log-file={}", t("log/munged.log")),
            &format!("--seed-file={}", t("munge/munged.seed")),
        ]),
        &mut daemons,
    )?;
    wait("munged's socket", Duration::from_secs(20), || {
        Path::new(&socket).exists()
    })?;
    let slurm = |cmd: &str| {
        let mut c = Command::new(cmd);
        c.env("SLURM_CONF", &conf_path);
        c
    };
    spawn(
        "slurmctld",
        slurm("slurmctld").args(["-D", "-i", "-f", &conf_path.display().to_string()]),
        &mut daemons,
    )?;
    spawn(
        "slurmd",
        slurm("slurmd").args(["-D", "-N", NODE, "-f", &conf_path.display().to_string()]),
        &mut daemons,
    )?;
    wait("the node to be idle", Duration::from_secs(60), || {
        sh(slurm("sinfo").args(["-h", "-N", "-o", "%T"])).is_ok_and(|s| s.trim() == "idle")
    })?;
    println!("slurm is up: one node ({NODE}, {cpus} CPUs)");

    let scene = root.join(SCENE).display().to_string();
    let shards = tmp.join("shards");
    let merged = tmp.join("merged");
    let mut command: Vec<String> = vec!["render".into(), scene.clone()];
    command.extend(RENDER.iter().map(|s| s.to_string()));
    let t0 = Instant::now();
    let ids = sh(
        slurm(&root.join("deploy/slurm/submit.sh").display().to_string())
            .arg(SHARDS.to_string())
            .arg(&shards)
            .arg(&merged)
            .arg("--")
            .args(&command)
            .env("PHOTONFLOW", exe)
            .current_dir(root),
    )?;
    let (array, merge) = ids
        .trim()
        .split_once(' ')
        .ok_or_else(|| format!("submit.sh printed `{}`, not two job ids", ids.trim()))?;
    println!("submitted array job {array} ({SHARDS} shards) and merge job {merge} (afterok)");
    let state = |job: &str| -> String {
        sh(slurm("scontrol").args(["show", "job", job, "-o"]))
            .ok()
            .and_then(|s| {
                s.split_whitespace()
                    .find_map(|w| w.strip_prefix("JobState=").map(String::from))
            })
            .unwrap_or_default()
    };
    wait("the merge job", Duration::from_secs(900), || {
        let s = state(merge);
        !(s.is_empty() || s == "PENDING" || s == "RUNNING" || s == "CONFIGURING")
    })?;
    let merge_state = state(merge);
    println!(
        "merge job {merge}: {merge_state} after {:.1} s",
        t0.elapsed().as_secs_f64()
    );
    for i in 0..SHARDS {
        let job = format!("{array}_{i}");
        println!("  shard task {job}: {}", state(&job));
    }
    if merge_state != "COMPLETED" {
        return Err(format!(
            "the merge job ended {merge_state}; see {}",
            shards.display()
        ));
    }

    println!("one-machine run of the same scene, seed and budget ...");
    let one = tmp.join("one");
    let mut args = command.clone();
    args.extend(["--out".into(), one.display().to_string()]);
    sh(Command::new(exe).args(&args).current_dir(root))?;
    let (a, b) = (images(&merged)?, images(&one)?);
    let names: Vec<&str> = a.iter().map(|(n, _)| n.as_str()).collect();
    if a != b {
        return Err(format!(
            "the merged image differs from the one-machine run's ({} files compared)",
            names.len()
        ));
    }
    println!(
        "merged == one-machine, byte for byte: {} ({} bytes)",
        names.join(", "),
        a.iter().map(|(_, b)| b.len()).sum::<usize>()
    );
    drop(daemons);
    println!("slurm-demo passed");
    Ok(())
}
