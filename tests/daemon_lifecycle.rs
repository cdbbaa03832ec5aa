//! The daemon's life around its clients, through the real `proximad` over shared memory: a
//! client killed mid-frame loses its scene only after the grace period while others keep
//! being served; a restarted daemon is noticed by old clients as a typed error and serves
//! new ones; SIGTERM stops it cleanly under load; idle, it sleeps.
//!
//! The killed client is this test binary re-executed with [`CHILD_ROLE`] set: it runs only
//! `child_client_role`, which builds a scene, publishes a pose frame it never reads the
//! answer of, prints `READY <scene>` and waits to be killed.

#[path = "support/daemon.rs"]
mod daemon_harness;

use daemon_harness::{Daemon, body, pose_at};
use iceoryx2::prelude::ipc;
use proxima_ipc::client::{Client, Primitive};
use proxima_ipc::error::{ControlError, FrameReceiveError};
use proxima_ipc::scene_link::SceneLink;
use proxima_ipc::wire::{ErrorCode, query};
use std::io::{BufRead, BufReader, Write};
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

const TIMEOUT: Duration = Duration::from_secs(10);
/// Environment variable that turns this binary into the child client (its value: the
/// daemon's root and prefix, separated by a space).
const CHILD_ROLE: &str = "PROXIMA_LIFECYCLE_CHILD";
/// The grace period of the dead-client test's daemon.
const GRACE: Duration = Duration::from_millis(1500);

/// A scene of two spheres of radius 0.5 (bodies 0 and 1, at x = 0 and x = 3), its id and
/// frame link.
fn two_spheres(client: &Client<ipc::Service>) -> (u32, SceneLink<ipc::Service>) {
    let scene = client.create_scene().unwrap();
    let sphere = client
        .register_primitive(scene, Primitive::Sphere { radius: 0.5 })
        .unwrap();
    for x in [0.0, 3.0] {
        client.add_body(scene, &body(sphere, x)).unwrap();
    }
    let link = client.open_scene(scene).unwrap();
    (scene, link)
}

/// Moves body 1 to `x` in frame `seq` and checks the answer: one overlapping pair at
/// distance `x − 1` (the spheres overlap for every `x` used here).
fn assert_frame_answered(link: &SceneLink<ipc::Service>, seq: u64, x: f64) {
    link.publish_poses(seq, 0, query::CLOSE, &[pose_at(1, x)])
        .unwrap();
    let answer = link
        .receive_results_for(seq, TIMEOUT)
        .unwrap()
        .unwrap_or_else(|| panic!("frame {seq} answered"));
    assert_eq!(
        ErrorCode::from_u32(answer.header().status),
        Some(ErrorCode::Ok),
        "frame {seq}"
    );
    let pairs = answer.pairs();
    assert_eq!(pairs.len(), 1, "frame {seq}");
    assert_eq!((pairs[0].body_a, pairs[0].body_b), (0, 1));
    assert!(
        (pairs[0].distance - (x - 1.0)).abs() < 1e-12,
        "frame {seq}: {}",
        pairs[0].distance
    );
}

/// Whether scene `scene` still lives, asked through the protocol: registering a shape in it
/// succeeds (or, from a client that does not own it, is refused with `NotOwner`), or fails
/// with `UnknownScene` once it is gone.
fn scene_lives(client: &Client<ipc::Service>, scene: u32) -> bool {
    match client.register_primitive(scene, Primitive::Sphere { radius: 0.1 }) {
        Ok(_)
        | Err(ControlError::Rejected {
            code: ErrorCode::NotOwner,
            ..
        }) => true,
        Err(ControlError::Rejected {
            code: ErrorCode::UnknownScene,
            ..
        }) => false,
        Err(e) => panic!("unexpected answer about scene {scene}: {e}"),
    }
}

/// The child client (only when spawned with [`CHILD_ROLE`]; otherwise it returns at once).
#[test]
fn child_client_role() {
    let Ok(spec) = std::env::var(CHILD_ROLE) else {
        return;
    };
    let (root, prefix) = spec.split_once(' ').expect("root and prefix");
    let client = proxima_ipc::client::ClientBuilder::new()
        .root(root)
        .iceoryx_prefix(prefix)
        .reply_timeout(TIMEOUT)
        .connect::<ipc::Service>()
        .expect("the child connects");
    let (scene, link) = two_spheres(&client);
    // Mid-frame: a pose frame is out, its results are never read.
    link.publish_poses(1, 0, query::CLOSE, &[pose_at(1, 0.5)])
        .unwrap();
    let mut out = std::io::stdout().lock();
    writeln!(out, "READY {scene}").unwrap();
    out.flush().unwrap();
    std::thread::sleep(Duration::from_secs(60));
    panic!("the child client was not killed");
}

/// A child process, killed with SIGKILL when dropped (also when a test fails).
struct ChildClient(std::process::Child);

impl ChildClient {
    /// SIGKILL, then reap.
    fn kill(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

impl Drop for ChildClient {
    fn drop(&mut self) {
        self.kill();
    }
}

/// Spawns the child client against `daemon`; returns it and the scene it created.
fn spawn_child_client(daemon: &Daemon) -> (ChildClient, u32) {
    let mut child = Command::new(std::env::current_exe().unwrap())
        .args([
            "child_client_role",
            "--exact",
            "--nocapture",
            "--test-threads=1",
        ])
        .env(CHILD_ROLE, format!("{} {}", daemon.root(), daemon.prefix()))
        .stdout(Stdio::piped())
        .spawn()
        .expect("the child client starts");
    let stdout = child.stdout.take().unwrap();
    let child = ChildClient(child);
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            // libtest may have printed `test child_client_role ... ` on the same line.
            if let Some((_, scene)) = line.split_once("READY ") {
                let _ = tx.send(scene.trim().parse::<u32>().unwrap());
            }
        }
    });
    let scene = rx
        .recv_timeout(Duration::from_secs(30))
        .expect("the child client reports its scene");
    (child, scene)
}

#[test]
fn a_killed_clients_scene_is_released_after_the_grace_period_while_others_keep_being_served() {
    let grace = GRACE.as_millis().to_string();
    let daemon = Daemon::start_with(&["--grace-ms", &grace]);
    let survivor = daemon.client();
    let (_, link) = two_spheres(&survivor);
    let mut seq = 0;
    let mut frame = |x: f64| {
        seq += 1;
        assert_frame_answered(&link, seq, x);
    };
    frame(0.6);
    let (mut child, orphan) = spawn_child_client(&daemon);
    frame(0.7);
    assert!(scene_lives(&survivor, orphan));

    child.kill();
    let killed = Instant::now();
    // Well inside the grace period: the orphan is kept, the survivor served.
    while killed.elapsed() < GRACE / 3 {
        frame(0.8);
    }
    let checked = Instant::now();
    let lives = scene_lives(&survivor, orphan);
    if checked.duration_since(killed) < GRACE {
        assert!(lives, "scene {orphan} released before the grace period");
    }
    // Then it is released (never before the grace period), and the survivor still served.
    let released = loop {
        frame(0.9);
        let asked = Instant::now();
        if !scene_lives(&survivor, orphan) {
            break asked;
        }
        assert!(killed.elapsed() < TIMEOUT, "scene {orphan} never released");
        std::thread::sleep(Duration::from_millis(20));
    };
    assert!(
        released.duration_since(killed) >= GRACE,
        "released after {:?}",
        released.duration_since(killed)
    );
    for _ in 0..10 {
        frame(0.95);
    }
    // The survivor's own scene was never touched.
    assert_eq!(survivor.create_scene().map(|_| ()), Ok(()));
}

#[test]
fn after_a_daemon_restart_old_clients_get_a_typed_error_and_new_clients_are_served() {
    let mut daemon = Daemon::start();
    let reply_timeout = Duration::from_secs(2);
    let old = daemon.client_with_timeout(reply_timeout);
    let (old_scene, old_link) = two_spheres(&old);
    assert_frame_answered(&old_link, 1, 0.5);

    daemon.kill();
    // While no daemon runs: a typed error, no hang past the reply timeout.
    let asked = Instant::now();
    assert_eq!(old.create_scene(), Err(ControlError::DaemonLost));
    assert!(asked.elapsed() < reply_timeout + Duration::from_secs(3));

    daemon.restart();
    let fresh = daemon.client();
    // The restarted daemon does not answer the old client as if nothing had happened.
    let asked = Instant::now();
    assert_eq!(
        old.register_primitive(old_scene, Primitive::Sphere { radius: 1.0 }),
        Err(ControlError::DaemonLost)
    );
    assert!(asked.elapsed() < reply_timeout + Duration::from_secs(3));
    assert!(!old.daemon_is_alive());
    assert!(fresh.daemon_is_alive());

    // Rejoining: connect again and register anew.
    let rejoined = daemon.client();
    let (_, link) = two_spheres(&rejoined);
    for seq in 1..=5 {
        assert_frame_answered(&link, seq, 0.5 + 0.05 * seq as f64);
    }
    let (_, fresh_link) = two_spheres(&fresh);
    assert_frame_answered(&fresh_link, 1, 0.4);
}

#[test]
fn sigterm_while_frames_flow_stops_the_daemon_with_status_zero() {
    // A spin longer than the test: the loop never blocks, so only its own periodic signal
    // check (not the WaitSet) can see the SIGTERM.
    let mut daemon = Daemon::start_with(&["--spin-us", "30000000"]);
    let client = daemon.client();
    let (_, link) = two_spheres(&client);
    for seq in 1..=20 {
        assert_frame_answered(&link, seq, 0.5);
    }
    // SIGTERM from another thread while this one keeps frames coming.
    let pid = daemon.pid();
    let signaller = std::thread::spawn(move || {
        std::thread::sleep(Duration::from_millis(200));
        daemon_harness::signal(pid, "-TERM");
        Instant::now()
    });
    let started = Instant::now();
    let (mut seq, mut answered) = (20, 0);
    while !daemon.has_exited() && started.elapsed() < TIMEOUT {
        seq += 1;
        link.publish_poses(seq, 0, query::CLOSE, &[pose_at(1, 0.5)])
            .unwrap();
        match link.receive_results_for(seq, Duration::from_millis(5)) {
            Ok(Some(_)) => answered += 1,
            Ok(None) => {}
            // The daemon stopped between two checks of its exit.
            Err(FrameReceiveError::DaemonLost) => break,
            Err(e) => panic!("frame {seq}: {e}"),
        }
    }
    let signalled = signaller.join().unwrap();
    let status = daemon
        .terminate(Duration::from_secs(1))
        .expect("proximad exited after SIGTERM");
    assert!(status.success(), "{status:?}");
    assert!(answered > 0, "frames flowed until the signal");
    // The frames before the signal were served; the daemon stopped within the timeout.
    assert!(signalled.elapsed() < TIMEOUT);
}

#[test]
fn sigint_stops_an_idle_daemon_with_status_zero_and_sigusr1_does_not() {
    let mut daemon = Daemon::start();
    let client = daemon.client();
    let (_, link) = two_spheres(&client);
    // iceoryx2 catches SIGUSR1 too (the daemon answered Hello, so its handler is in place):
    // it interrupts the blocking wait, but must not stop the daemon.
    std::thread::sleep(Duration::from_millis(50));
    daemon_harness::signal(daemon.pid(), "-USR1");
    std::thread::sleep(Duration::from_millis(300));
    assert!(!daemon.has_exited(), "SIGUSR1 stopped the daemon");
    assert_frame_answered(&link, 1, 0.5);
    daemon_harness::signal(daemon.pid(), "-INT");
    let signalled = Instant::now();
    while !daemon.has_exited() && signalled.elapsed() < TIMEOUT {
        std::thread::sleep(Duration::from_millis(5));
    }
    assert!(daemon.has_exited(), "SIGINT did not stop the daemon");
    let status = daemon.terminate(Duration::ZERO).expect("exited");
    assert!(status.success(), "{status:?}");
}

/// User plus system CPU time of process `pid`, in clock ticks (`/proc/<pid>/stat`).
fn cpu_ticks(pid: u32) -> u64 {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap();
    // Fields after the parenthesised command name; utime and stime are fields 14 and 15.
    let rest = &stat[stat.rfind(')').unwrap() + 2..];
    let fields: Vec<&str> = rest.split_whitespace().collect();
    fields[11].parse::<u64>().unwrap() + fields[12].parse::<u64>().unwrap()
}

fn clock_ticks_per_second() -> u64 {
    let out = Command::new("getconf").arg("CLK_TCK").output().unwrap();
    String::from_utf8(out.stdout)
        .unwrap()
        .trim()
        .parse()
        .unwrap()
}

#[test]
fn an_idle_daemon_with_scenes_sleeps_instead_of_spinning() {
    let daemon = Daemon::start();
    let client = daemon.client();
    let (_, link) = two_spheres(&client);
    assert_frame_answered(&link, 1, 0.5);
    std::thread::sleep(Duration::from_millis(200));
    let (before, start) = (cpu_ticks(daemon.pid()), Instant::now());
    std::thread::sleep(Duration::from_secs(1));
    let (used, wall) = (cpu_ticks(daemon.pid()) - before, start.elapsed());
    let share = used as f64 / clock_ticks_per_second() as f64 / wall.as_secs_f64();
    assert!(
        share < 0.3,
        "the idle daemon used {:.0}% of a core",
        share * 100.0
    );
    // Still awake for work after the sleep.
    assert_frame_answered(&link, 2, 0.6);
}
