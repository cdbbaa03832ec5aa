//! Soak: a private `proximad` serving clients that come, go and get killed, for as long as
//! asked; prints the daemon's resident memory, open descriptors and shared-memory files
//! every minute, and at the end whether they came back flat (issue #31).
//!
//! ```text
//! cargo build --release && cargo run --release --example soak -- --minutes 60
//! ```
//!
//! Each client is this binary run again as `--client SECONDS`: it connects, creates a scene
//! (a floor box, 24 spheres, a 200-triangle mesh), sends pose frames at 200 Hz with a 2 ms
//! budget and counts the answers; at its end it drops the scene (or, one in three, just
//! exits and leaves it to the daemon's dead-client sweep) and prints `ANSWERED a SENT s`.
//! The soak keeps up to four clients alive, each living 1–20 s, and kills about a third of
//! them with SIGKILL mid-run. Once the last client is gone it waits for the daemon's grace
//! period and checks that the daemon ended flat: resident memory within 5 % of minute 5's
//! (or the last minute's, in shorter runs), no more descriptors and shared-memory files than
//! when it was idle after one warm-up client had come and gone, and every frame of every
//! client that was not killed answered.

use clap::Parser;
use iceoryx2::prelude::{LogLevel, ipc, set_log_level_from_env_or};
use proxima::geometry::TriMesh;
use proxima_ipc::client::{BodySpec, ClientBuilder, Motion, Primitive};
use proxima_ipc::tools::daemon_process::{ChildProcess, Isolation, sibling_daemon};
use proxima_ipc::wire::{PoseRecord, query};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use std::error::Error;
use std::io::Read;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

#[derive(Debug, Parser)]
#[command(about = "Clients come, go and crash against a private proximad; does it stay flat?")]
struct Args {
    /// How long to run.
    #[arg(long, default_value_t = 60.0)]
    minutes: f64,
    /// Most clients alive at once.
    #[arg(long, default_value_t = 4)]
    clients: usize,
    /// Seed of the clients' lifetimes and kills.
    #[arg(long, default_value_t = 31)]
    seed: u64,
    /// Internal: run as a client for this many seconds (with `--root` and `--prefix`).
    #[arg(long, hide = true)]
    client: Option<f64>,
    #[arg(long, hide = true, default_value = "")]
    root: String,
    #[arg(long, hide = true, default_value = "")]
    prefix: String,
}

fn main() -> Result<(), Box<dyn Error>> {
    let args = Args::parse();
    set_log_level_from_env_or(LogLevel::Error);
    match args.client {
        Some(seconds) => run_client(&args.root, &args.prefix, seconds),
        None => soak(&args),
    }
}

/// How long the soak waits for the daemon to let go of clients that are gone: its
/// dead-client grace (2 s by default) and a few sweeps.
const SETTLE: Duration = Duration::from_secs(4);

/// The daemon's resident memory, descriptors and shared-memory files at one moment.
#[derive(Debug, Clone, Copy)]
struct Sample {
    rss_kib: u64,
    fds: usize,
    shm_files: usize,
}

fn sample(pid: u32, prefix: &str) -> Sample {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap_or_default();
    let rss_kib = status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.split_whitespace().next()?.parse().ok())
        .unwrap_or(0);
    let fds = std::fs::read_dir(format!("/proc/{pid}/fd")).map_or(0, Iterator::count);
    let shm_files = std::fs::read_dir("/dev/shm").map_or(0, |entries| {
        entries
            .flatten()
            .filter(|e| e.file_name().to_string_lossy().starts_with(prefix))
            .count()
    });
    Sample {
        rss_kib,
        fds,
        shm_files,
    }
}

/// A client process and when it is to be killed, if it is.
struct Running {
    child: Child,
    kill_at: Option<Instant>,
}

/// Totals over the clients.
#[derive(Debug, Default)]
struct Tally {
    started: u64,
    killed: u64,
    finished: u64,
    failed: u64,
    sent: u64,
    answered: u64,
}

fn soak(args: &Args) -> Result<(), Box<dyn Error>> {
    let isolation = Isolation::unique("soak");
    let mut daemon = ChildProcess::spawn_quiet_daemon(sibling_daemon()?, &isolation)?;
    let Isolation { root, prefix } = isolation;
    let pid = daemon.id().ok_or("the daemon did not start")?;
    let exe = std::env::current_exe()?;
    // One client first, gone before the baseline: what the daemon opens once, at its first
    // client, is not a leak (2 descriptors, measured).
    let status = Command::new(&exe)
        .args(["--client", "1", "--root", &root, "--prefix", &prefix])
        .stdout(Stdio::null())
        .status()?;
    if !status.success() {
        return Err("the warm-up client failed".into());
    }
    std::thread::sleep(SETTLE);
    // Idle and serving: the descriptors and files that must be all that is left at the end.
    let idle = sample(pid, &prefix);
    let mut rng = Pcg64Mcg::seed_from_u64(args.seed);
    let (mut running, mut tally) = (Vec::<Running>::new(), Tally::default());
    let start = Instant::now();
    let end = start + Duration::from_secs_f64(args.minutes * 60.0);
    let mut next_print = start;
    let (mut reference, mut minute) = (None, 0u32);
    println!("minute  rss_MiB  fds  shm_files  clients_started  killed  finished  frames_answered");
    while Instant::now() < end {
        if daemon.has_exited() {
            return Err("the daemon exited".into());
        }
        reap(&mut running, &mut tally);
        while running.len() < args.clients {
            let seconds = rng.random_range(1.0..20.0);
            let child = Command::new(&exe)
                .args([
                    "--client",
                    &seconds.to_string(),
                    "--root",
                    &root,
                    "--prefix",
                    &prefix,
                ])
                .stdout(Stdio::piped())
                .spawn()?;
            let kill_at = rng
                .random_bool(0.33)
                .then(|| Instant::now() + Duration::from_secs_f64(rng.random_range(0.2..seconds)));
            running.push(Running { child, kill_at });
            tally.started += 1;
        }
        if Instant::now() >= next_print {
            let now = sample(pid, &prefix);
            if minute == 5.min(args.minutes as u32) || reference.is_none() {
                reference = Some(now);
            }
            println!(
                "{minute:>6}  {:>7.1}  {:>3}  {:>9}  {:>15}  {:>6}  {:>8}  {}/{}",
                now.rss_kib as f64 / 1024.0,
                now.fds,
                now.shm_files,
                tally.started,
                tally.killed,
                tally.finished,
                tally.answered,
                tally.sent
            );
            minute += 1;
            next_print = start + Duration::from_secs(60 * u64::from(minute));
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    // Let every client end, then the daemon's grace period and a sweep pass.
    for client in &mut running {
        client.kill_at = None;
    }
    while !running.is_empty() {
        reap(&mut running, &mut tally);
        std::thread::sleep(Duration::from_millis(50));
    }
    std::thread::sleep(SETTLE);
    let last = sample(pid, &prefix);
    let reference = reference.unwrap_or(last);
    println!(
        "end     {:>7.1}  {:>3}  {:>9}  {tally:?}",
        last.rss_kib as f64 / 1024.0,
        last.fds,
        last.shm_files
    );
    let rss_change = last.rss_kib as f64 / reference.rss_kib.max(1) as f64 - 1.0;
    let flat = rss_change.abs() <= 0.05 && last.fds <= idle.fds && last.shm_files <= idle.shm_files;
    let all_answered = tally.answered == tally.sent && tally.failed == 0;
    println!(
        "verdict: rss {:+.1} % against minute {}, fds {} idle after warm-up → {}, shm files {} → {}, surviving clients' frames answered {}/{} ({} client failures): {}",
        100.0 * rss_change,
        5.min(args.minutes as u32),
        idle.fds,
        last.fds,
        idle.shm_files,
        last.shm_files,
        tally.answered,
        tally.sent,
        tally.failed,
        if flat && all_answered {
            "FLAT"
        } else {
            "NOT FLAT"
        }
    );
    daemon.stop();
    if flat && all_answered {
        Ok(())
    } else {
        Err("the soak did not end flat".into())
    }
}

/// Kills the clients whose time has come and collects those that ended.
fn reap(running: &mut Vec<Running>, tally: &mut Tally) {
    let now = Instant::now();
    running.retain_mut(|client| {
        if client.kill_at.is_some_and(|at| now >= at) {
            let _ = client.child.kill();
            let _ = client.child.wait();
            tally.killed += 1;
            return false;
        }
        match client.child.try_wait() {
            Ok(Some(status)) => {
                let mut out = String::new();
                if let Some(stdout) = client.child.stdout.as_mut() {
                    let _ = stdout.read_to_string(&mut out);
                }
                match parse_report(&out) {
                    Some((answered, sent)) if status.success() => {
                        tally.finished += 1;
                        tally.answered += answered;
                        tally.sent += sent;
                    }
                    _ => tally.failed += 1,
                }
                false
            }
            _ => true,
        }
    });
}

/// `ANSWERED a SENT s` → `(a, s)`.
fn parse_report(out: &str) -> Option<(u64, u64)> {
    let line = out.lines().find(|l| l.starts_with("ANSWERED "))?;
    let mut words = line.split_whitespace();
    let answered = words.nth(1)?.parse().ok()?;
    let sent = words.nth(1)?.parse().ok()?;
    Some((answered, sent))
}

/// One client: a scene, frames for `seconds`, then drop it or just leave.
fn run_client(root: &str, prefix: &str, seconds: f64) -> Result<(), Box<dyn Error>> {
    let client = ClientBuilder::new()
        .root(root)
        .iceoryx_prefix(prefix)
        .reply_timeout(Duration::from_secs(5))
        .connect::<ipc::Service>()?;
    let scene = client.create_scene()?;
    let floor = client.register_primitive(
        scene,
        Primitive::Cuboid {
            half_extents: [5.0, 5.0, 0.1],
        },
    )?;
    let ball = client.register_primitive(scene, Primitive::Sphere { radius: 0.2 })?;
    // A 200-triangle torus.
    let torus = TriMesh::torus(0.2, 0.05, 10, 10);
    let vertices: Vec<[f64; 3]> = torus.vertices().iter().map(|v| v.to_array()).collect();
    let torus = client.register_mesh(scene, &vertices, torus.triangles())?;
    let spec = |shape, position: [f64; 3], motion| BodySpec {
        shape,
        position,
        orientation: [0.0, 0.0, 0.0, 1.0],
        motion,
        group: 1,
        mask: u32::MAX,
        margin: Some(0.01),
    };
    client.add_body(scene, &spec(floor, [0.0, 0.0, -0.1], Motion::Static))?;
    let mut bodies = Vec::new();
    for i in 0..24 {
        let shape = if i % 6 == 0 { torus } else { ball };
        let x = f64::from(i % 6) * 0.5 - 1.25;
        let y = f64::from(i / 6) * 0.5 - 0.75;
        bodies.push((
            client.add_body(scene, &spec(shape, [x, y, 0.3], Motion::Dynamic))?,
            x,
            y,
        ));
    }
    let link = client.open_scene(scene)?;
    let (mut sent, mut answered) = (0u64, 0u64);
    let start = Instant::now();
    let period = Duration::from_millis(5);
    while start.elapsed().as_secs_f64() < seconds {
        sent += 1;
        let t = start.elapsed().as_secs_f64();
        link.publish_poses_with(
            sent,
            2_000_000,
            query::CLOSE | query::CONTACTS,
            bodies.len(),
            |i| {
                let (body, x, y) = bodies[i];
                PoseRecord {
                    body,
                    reserved: 0,
                    position: [x, y, 0.25 + 0.1 * (t * 3.0 + i as f64).sin()],
                    orientation: [0.0, 0.0, 0.0, 1.0],
                }
            },
        )?;
        if link
            .receive_results_for(sent, Duration::from_secs(1))?
            .is_some()
        {
            answered += 1;
        }
        std::thread::sleep(period);
    }
    if sent % 3 != 0 {
        client.drop_scene(scene)?;
    }
    println!("ANSWERED {answered} SENT {sent}");
    Ok(())
}
