//! A hostile client against the real `proximad`, over real shared memory (issue #31's
//! attacks): each test asserts that the daemon stays up, the victim keeps being served,
//! the attacker gets its code, and nothing of the victim's changes.
//!
//! The attacker runs as another process where the attack is a client's: this test binary
//! re-executed with [`ATTACKER_ROLE`] set runs only `attacker_role`, which attacks the scene
//! named in the variable and prints one line per step (`CODE <step> <error code>`,
//! `SENT <step>`), then `DONE`; with [`DOOMED_ROLE`] set it runs only `doomed_client_role`,
//! a client whose long frame is cut short: it is killed, or drops its scene, mid-frame; with
//! [`OUTSIDER_ROLE`] set, run as another OS user, only `outsider_role`; with [`HOARDER_ROLE`]
//! set, only `hoarder_role`, which takes all it can over many control ports.
//!
//! | attack (issue #31's table) | test |
//! |---|---|
//! | 1 services set up ahead of a scene | unit test in `src/daemon/frame_loop.rs` (ids are random, names secret) |
//! | 2 a subscriber that never reads | `a_subscriber_that_never_reads_never_holds_the_daemon_up` |
//! | 3 commands and frames on another's scene | `another_clients_commands_and_frames_are_refused_and_change_nothing` |
//! | 4 an impostor on the control service | `a_control_service_served_or_set_up_by_another_process_stops_the_daemon_at_start` |
//! | 5 nodes held on the control service | `nodes_held_on_the_control_service_do_not_lock_new_clients_out` |
//! | 6 a restarted daemon | `a_restarted_daemon_answers_no_old_frame_and_old_clients_learn_it_is_lost` |
//! | 7, 11 oversized headers, reserved fields, far coordinates | `reserved_fields_bad_coordinates_and_oversized_headers_get_their_codes_before_any_work` |
//! | 8 endless add/remove | `endless_add_remove_cycles_reuse_body_slots_so_the_scene_stays_its_size` |
//! | 9 a client killed mid-frame | `a_client_killed_mid_frame_has_its_frame_abandoned_and_its_release_seen_by_a_monitor`, `a_scene_dropped_mid_frame_stops_the_frame_and_its_release_is_seen_by_a_monitor` |
//! | 10 another OS user's `global_mgmt` | `another_os_user_can_neither_use_the_daemon_nor_stop_new_clients`, `a_node_counter_another_user_set_up_first_stops_the_daemon_at_start` (run as root, which can start a process as `nobody`; otherwise they say they did not run) |
//! | (not in the table) a frame of seconds, then a request on its scene | `a_clients_long_frame_holds_up_no_other_clients_requests_or_frames` |
//! | (not in the table) one process taking every scene and body over many ports | `a_process_with_many_ports_holds_one_quota_and_leaves_the_rest_to_others` |
//!
//! Same-user limits (README "Who can use the daemon"): iceoryx2 0.10 lets any process of
//! the daemon's user list services, so the attacker here learns the victim's scene token
//! that way, as a real one could. What it cannot learn is the frame key, and ownership does
//! not depend on either.

#[path = "support/daemon.rs"]
mod daemon_harness;

use daemon_harness::{ConfigFile, Daemon, body, pose_at, register_trimesh};
use iceoryx2::prelude::*;
use proxima::daemon::node_counter;
use proxima::geometry::TriMesh;
use proxima_ipc::client::{Client, ClientBuilder, Motion, Primitive};
use proxima_ipc::error::{ClientConnectError, ControlError, FrameReceiveError};
use proxima_ipc::result_feed::ResultFeed;
use proxima_ipc::scene_link::SceneLink;
use proxima_ipc::wire::{
    BroadPhaseCode, Completeness, ErrorCode, PoseFrameHeader, PoseRecord, ResultFrameHeader,
    ResultRecord, frame_flags, query,
};
use proxima_ipc::{EVENT_POSES_SENT, PROTOCOL_VERSION, SceneToken};
use std::io::{BufRead, BufReader, Write};
use std::os::unix::fs::MetadataExt;
use std::os::unix::process::CommandExt;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const TIMEOUT: Duration = Duration::from_secs(10);
/// Environment variable that turns this binary into the attacker (its value: the daemon's
/// root and prefix and the victim's scene id, separated by spaces).
const ATTACKER_ROLE: &str = "PROXIMA_HOSTILE_ATTACKER";
/// Environment variable that turns this binary into a client whose long frame is cut short
/// (its value: the daemon's root and prefix).
const DOOMED_ROLE: &str = "PROXIMA_HOSTILE_DOOMED";
/// Environment variable that turns this binary into another OS user's process (its value:
/// the daemon's root and prefix).
const OUTSIDER_ROLE: &str = "PROXIMA_HOSTILE_OUTSIDER";
/// Environment variable that turns this binary into a client taking all it can over many
/// control ports (its value: the daemon's root and prefix).
const HOARDER_ROLE: &str = "PROXIMA_HOSTILE_HOARDER";

/// The victim: a scene of two unit spheres (bodies 0 and 1) overlapping by 0.1 m, and its
/// frame link.
struct Victim {
    client: Client<ipc::Service>,
    scene: u32,
    link: SceneLink<ipc::Service>,
    seq: u64,
}

impl Victim {
    fn new(daemon: &Daemon) -> Self {
        let client = daemon.client();
        let scene = client.create_scene().unwrap();
        let sphere = client
            .register_primitive(scene, Primitive::Sphere { radius: 0.5 })
            .unwrap();
        for x in [0.0, 0.9] {
            client.add_body(scene, &body(sphere, x)).unwrap();
        }
        let link = client.open_scene(scene).unwrap();
        Self {
            client,
            scene,
            link,
            seq: 0,
        }
    }

    /// One frame (body 1 left where it is): answered Ok, with the one pair at −0.1 m, so
    /// neither its bodies, poses nor masks were changed. A frame the daemon could not start
    /// in its 2 ms (`BUDGET_TOO_SMALL`: the host is loaded by the other tests' daemons) is
    /// sent again, up to [`ATTEMPTS`] times.
    fn assert_untouched(&mut self) {
        const ATTEMPTS: usize = 20;
        for _ in 0..ATTEMPTS {
            self.seq += 1;
            let seq = self.seq;
            self.link
                .publish_poses(seq, 2_000_000, query::CLOSE, &[pose_at(1, 0.9)])
                .unwrap();
            let frame = self
                .link
                .receive_results_for(seq, TIMEOUT)
                .unwrap()
                .unwrap_or_else(|| panic!("victim frame {seq} answered"));
            let header = frame.header();
            assert_eq!(ErrorCode::from_u32(header.status), Some(ErrorCode::Ok));
            assert_eq!(header.instance, self.client.daemon_instance());
            if header.flags & frame_flags::BUDGET_TOO_SMALL != 0 {
                continue;
            }
            let pairs = frame.pairs();
            assert_eq!(pairs.len(), 1, "frame {seq}: the victim's pair");
            assert_eq!((pairs[0].body_a, pairs[0].body_b), (0, 1));
            assert!(
                (pairs[0].distance + 0.1).abs() < 1e-12,
                "{}",
                pairs[0].distance
            );
            return;
        }
        panic!("{ATTEMPTS} victim frames in a row were not started");
    }
}

/// The token of the only scene served under `root`, found the way any process of the
/// daemon's user can: by listing iceoryx2's services.
fn listed_token(root: &str, prefix: &str) -> SceneToken {
    let config = config_with_prefix(prefix);
    let head = format!("{root}/scene-");
    let mut found = None;
    ipc::Service::list(&config, |service| {
        let name = service.static_details.name().to_string();
        if let Some(rest) = name.strip_prefix(&head)
            && let Some((token, _)) = rest.split_once('/')
        {
            found = token.parse().ok();
        }
        CallbackProgression::Continue
    })
    .unwrap();
    found.expect("the victim's services are listed")
}

fn config_with_prefix(prefix: &str) -> iceoryx2::config::Config {
    let mut config = iceoryx2::config::Config::global_config().clone();
    config.global.prefix = FileName::new(prefix.as_bytes()).unwrap();
    config
}

/// This test binary run again as the test `role` alone, which does its work only with the
/// environment variable `var` set: to the daemon's root and prefix, and `extra`.
fn role_process(role: &str, var: &str, daemon: &Daemon, extra: &str) -> Command {
    let mut command = Command::new(std::env::current_exe().unwrap());
    command
        .args([role, "--exact", "--nocapture", "--test-threads=1"])
        .env(
            var,
            format!("{} {} {extra}", daemon.root(), daemon.prefix()),
        );
    command
}

/// What [`role_process`] told a role: the daemon's root and prefix, and the extra word.
struct Role {
    root: String,
    prefix: String,
    extra: String,
}

impl Role {
    /// The role's orders when this process runs as the role of `var`.
    fn from_env(var: &str) -> Option<Self> {
        let spec = std::env::var(var).ok()?;
        let mut words = spec.splitn(3, ' ').map(str::to_owned);
        Some(Self {
            root: words.next()?,
            prefix: words.next()?,
            extra: words.next().unwrap_or_default(),
        })
    }

    /// A client of the role's daemon, waiting `timeout` for each reply.
    fn connect(&self, timeout: Duration) -> Result<Client<ipc::Service>, ClientConnectError> {
        ClientBuilder::new()
            .root(&self.root)
            .iceoryx_prefix(&self.prefix)
            .reply_timeout(timeout)
            .connect::<ipc::Service>()
    }
}

/// The attacker (only when spawned with [`ATTACKER_ROLE`]; otherwise it returns at once):
/// every command on the victim's scene, then a forged pose frame on its pose service.
#[test]
fn attacker_role() {
    let Some(role) = Role::from_env(ATTACKER_ROLE) else {
        return;
    };
    let scene: u32 = role.extra.parse().unwrap();
    let client = role.connect(TIMEOUT).expect("the attacker connects");
    let mut out = std::io::stdout().lock();
    let mut report = |step: &str, result: Result<(), ControlError>| {
        let code = match result {
            Ok(()) => "Ok".to_owned(),
            Err(ControlError::Rejected { code, .. }) => format!("{code:?}"),
            Err(e) => format!("{e:?}"),
        };
        writeln!(out, "CODE {step} {code}").unwrap();
    };
    let sphere = Primitive::Sphere { radius: 9.0 };
    report(
        "register",
        client.register_primitive(scene, sphere).map(drop),
    );
    report("add", client.add_body(scene, &body(0, 5.0)).map(drop));
    report(
        "update",
        client.update_body(scene, 1, Motion::Static, 0, 0, None),
    );
    report("remove", client.remove_body(scene, 1));
    let grid = BroadPhaseCode::HashGrid;
    report("params", client.set_broad_phase(scene, grid));
    report("state", client.shape_state(scene, 0).map(drop));
    report("drop", client.drop_scene(scene));
    let open = client
        .open_scene(scene)
        .map(drop)
        .map_err(|e| format!("{e:?}"));
    writeln!(out, "OPEN {open:?}").unwrap();
    // A forged frame on the victim's own pose service, found by listing: it would move body 1
    // away and, with every flag, cost the daemon work.
    let (root, prefix) = (&role.root, &role.prefix);
    forge_frame(client.node(), root, listed_token(root, prefix), scene);
    writeln!(out, "SENT forged\nDONE").unwrap();
    out.flush().unwrap();
}

/// Coincident sphere meshes in the doomed client's scene: every pair touches all over, so
/// an unbudgeted frame asking their contacts takes seconds (each pair's exact contacts
/// are thousands of triangle pairs).
const DOOMED_SPHERES: u32 = 24;

/// The doomed client (only when spawned with [`DOOMED_ROLE`]; otherwise it returns at
/// once): a scene of [`DOOMED_SPHERES`] coincident sphere meshes, its token on stdout (as an
/// owner hands it to a monitor); then, for each line on stdin, `GO` publishes one
/// unbudgeted frame asking every pair's contacts (answered by no one: it prints `SENT`),
/// `DROP` drops the scene (`DROPPED`), and `ADD` adds a body (`ADDING`, then `ADDED` and
/// the outcome once answered). It waits to be killed.
#[test]
fn doomed_client_role() {
    let Some(role) = Role::from_env(DOOMED_ROLE) else {
        return;
    };
    let client = role.connect(TIMEOUT).expect("the doomed client connects");
    let scene = client.create_scene().unwrap();
    let sphere = TriMesh::uv_sphere(0.5, 48, 24);
    let mesh = register_trimesh(&client, scene, &sphere).unwrap();
    let poses: Vec<PoseRecord> = (0..DOOMED_SPHERES)
        .map(|_| client.add_body(scene, &body(mesh, 0.0)).unwrap())
        .map(|id| pose_at(id, 0.0))
        .collect();
    let link = client.open_scene(scene).unwrap();
    let token = client.scene_access(scene).unwrap().token;
    let mut out = std::io::stdout().lock();
    writeln!(out, "TOKEN {token}").unwrap();
    out.flush().unwrap();
    for line in std::io::stdin().lines().map_while(Result::ok) {
        match line.trim() {
            "GO" => {
                link.publish_poses(1, 0, query::CONTACTS, &poses).unwrap();
                writeln!(out, "SENT").unwrap();
            }
            "DROP" => {
                client.drop_scene(scene).unwrap();
                writeln!(out, "DROPPED").unwrap();
            }
            "ADD" => {
                // Says so first: the reply waits for the frame in progress.
                writeln!(out, "ADDING").unwrap();
                out.flush().unwrap();
                let added = client.add_body(scene, &body(mesh, 0.0));
                writeln!(out, "ADDED {added:?}").unwrap();
            }
            other => panic!("unknown order {other:?}"),
        }
        out.flush().unwrap();
    }
    std::thread::sleep(Duration::from_secs(60));
    panic!("the doomed client was not killed");
}

/// A doomed client (see [`doomed_client_role`]) and its orders.
struct Doomed {
    child: std::process::Child,
    lines: std::io::Lines<BufReader<std::process::ChildStdout>>,
    token: SceneToken,
}

impl Doomed {
    fn start(daemon: &Daemon) -> Self {
        let mut child = role_process("doomed_client_role", DOOMED_ROLE, daemon, "")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .expect("the doomed client starts");
        let mut lines = BufReader::new(child.stdout.take().unwrap()).lines();
        let token = lines
            .by_ref()
            .map_while(Result::ok)
            .find_map(|line| Some(line.split_once("TOKEN ")?.1.trim().parse().unwrap()))
            .expect("the doomed client reports its token");
        Self {
            child,
            lines,
            token,
        }
    }

    /// Sends `order` and waits for the line saying it was done.
    fn order(&mut self, order: &str, done: &str) {
        let stdin = self.child.stdin.as_mut().unwrap();
        writeln!(stdin, "{order}").unwrap();
        stdin.flush().unwrap();
        let line = self.lines.next().expect("an answer").unwrap();
        assert_eq!(line.trim(), done, "the doomed client's answer to {order}");
    }

    fn kill(&mut self) {
        self.child.kill().unwrap();
        self.child.wait().unwrap();
    }
}

impl Drop for Doomed {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The frame the monitor `feed` sees next, within [`TIMEOUT`].
fn monitored(feed: &ResultFeed<ipc::Service>) -> Result<ResultFrameHeader, FrameReceiveError> {
    let frame = feed.receive(TIMEOUT)?.expect("a frame within the timeout");
    Ok(*frame.header())
}

/// How long the daemon is left on the doomed client's frame before it is killed or drops
/// its scene: long enough that the frame thread has taken it up (the frame takes seconds).
const INTO_THE_FRAME: Duration = Duration::from_millis(300);

#[test]
fn a_client_killed_mid_frame_has_its_frame_abandoned_and_its_release_seen_by_a_monitor() {
    let daemon = Daemon::start_with(&["--grace-ms", "300"]);
    let mut victim = Victim::new(&daemon);
    let mut doomed = Doomed::start(&daemon);
    // The monitor the owner trusted: a client of its own, reading by token.
    let monitor = daemon.client();
    let feed = ResultFeed::open(monitor.node(), daemon.root(), doomed.token).unwrap();
    doomed.order("GO", "SENT");
    std::thread::sleep(INTO_THE_FRAME);
    doomed.kill();
    let killed = Instant::now();
    // The victim's frame waits behind the dead client's only until a sweep finds it dead.
    victim.assert_untouched();
    eprintln!("victim answered {:?} after the kill", killed.elapsed());
    // The dead client's frame: abandoned, so conservative, and saying why.
    let abandoned = monitored(&feed).expect("the killed client's frame is answered");
    assert_eq!(abandoned.frame_seq, 1);
    assert_eq!(ErrorCode::from_u32(abandoned.status), Some(ErrorCode::Ok));
    assert_ne!(
        abandoned.flags & frame_flags::OWNER_GONE,
        0,
        "{abandoned:?}"
    );
    assert_eq!(
        abandoned.completeness,
        Completeness::Truncated as u32,
        "abandoned, not run to its exact end"
    );
    // After the grace period, the release, seen by the monitor.
    assert_eq!(
        monitored(&feed).map(|h| h.frame_seq),
        Err(FrameReceiveError::SceneReleased { owner_gone: true })
    );
    victim.assert_untouched();
}

#[test]
fn a_clients_long_frame_holds_up_no_other_clients_requests_or_frames() {
    let daemon = Daemon::start();
    let mut doomed = Doomed::start(&daemon);
    let monitor = daemon.client();
    let feed = ResultFeed::open(monitor.node(), daemon.root(), doomed.token).unwrap();
    doomed.order("GO", "SENT");
    std::thread::sleep(INTO_THE_FRAME);
    // Its own request on its scene waits for its frame...
    doomed.order("ADD", "ADDING");
    std::thread::sleep(INTO_THE_FRAME);
    // ...and another client's requests do not: each is answered while the frame runs.
    let mut victim = Victim::new(&daemon);
    let shape = victim
        .client
        .register_primitive(victim.scene, Primitive::Sphere { radius: 0.1 })
        .unwrap();
    victim
        .client
        .add_body(victim.scene, &body(shape, 30.0))
        .unwrap();
    // Nor do its frames: frames without a deadline are answered off the frame thread.
    victim.assert_untouched();
    assert!(
        feed.try_receive().unwrap().is_none(),
        "the long frame had ended: the test shows nothing"
    );
}

#[test]
fn a_scene_dropped_mid_frame_stops_the_frame_and_its_release_is_seen_by_a_monitor() {
    let daemon = Daemon::start();
    let mut victim = Victim::new(&daemon);
    let monitor = daemon.client();
    // On a loaded host the daemon may not have taken the frame up by the drop: then the
    // frame is dropped unanswered, and the test is run again.
    for _ in 0..3 {
        let mut doomed = Doomed::start(&daemon);
        let feed = ResultFeed::open(monitor.node(), daemon.root(), doomed.token).unwrap();
        doomed.order("GO", "SENT");
        std::thread::sleep(INTO_THE_FRAME);
        // The drop waits for the frame in progress to stop, not to end.
        doomed.order("DROP", "DROPPED");
        let released = FrameReceiveError::SceneReleased { owner_gone: false };
        let stopped = match monitored(&feed) {
            Ok(stopped) => stopped,
            Err(not_taken) if not_taken == released => {
                eprintln!("the daemon had not taken the frame up by the drop: again");
                continue;
            }
            Err(e) => panic!("monitor: {e}"),
        };
        assert_eq!(stopped.frame_seq, 1);
        assert_eq!(
            stopped.flags & frame_flags::OWNER_GONE,
            0,
            "the owner is alive"
        );
        assert_eq!(stopped.completeness, Completeness::Truncated as u32);
        assert_eq!(monitored(&feed).map(|h| h.frame_seq), Err(released));
        victim.assert_untouched();
        return;
    }
    panic!("three times the daemon had not taken the frame up in {INTO_THE_FRAME:?}");
}

/// Publishes a pose frame on the scene with token `token` without its frame key.
fn forge_frame(node: &Node<ipc::Service>, root: &str, token: SceneToken, scene: u32) {
    let poses = proxima_ipc::poses_service_builder(node, root, token)
        .unwrap()
        .open()
        .unwrap();
    let publisher = poses.publisher_builder().create().unwrap();
    let ready = proxima_ipc::poses_ready_service_builder(node, root, token)
        .unwrap()
        .open()
        .unwrap();
    let notifier = ready.notifier_builder().create().unwrap();
    for guess in [0, 1, u64::MAX] {
        let mut sample = publisher.loan_slice_uninit(1).unwrap();
        *sample.user_header_mut() = PoseFrameHeader {
            protocol_version: PROTOCOL_VERSION,
            scene,
            frame_seq: 1_000_000 + guess % 7,
            budget_ns: 0,
            query_flags: query::ALL,
            count: 1,
            frame_key: guess,
        };
        sample.write_from_fn(|_| pose_at(1, 50.0)).send().unwrap();
        notifier
            .notify_with_custom_event_id(EventId::new(EVENT_POSES_SENT))
            .unwrap();
    }
}

/// Runs the attacker process against `victim`'s scene; returns its output lines.
fn run_attacker(daemon: &Daemon, scene: u32) -> Vec<String> {
    let child = role_process("attacker_role", ATTACKER_ROLE, daemon, &scene.to_string())
        .stdout(Stdio::piped())
        .spawn()
        .expect("the attacker starts");
    let output = child.wait_with_output().expect("the attacker ends");
    assert!(output.status.success(), "the attacker failed");
    BufReader::new(output.stdout.as_slice())
        .lines()
        .map_while(Result::ok)
        .map(|line| match line.find("CODE ").or(line.find("OPEN ")) {
            // libtest may have printed `test attacker_role ... ` on the same line.
            Some(start) => line[start..].to_owned(),
            None => line,
        })
        .collect()
}

#[test]
fn another_clients_commands_and_frames_are_refused_and_change_nothing() {
    let daemon = Daemon::start();
    let mut victim = Victim::new(&daemon);
    victim.assert_untouched();
    let lines = run_attacker(&daemon, victim.scene);
    for step in [
        "register", "add", "update", "remove", "params", "state", "drop",
    ] {
        let expected = format!("CODE {step} NotOwner");
        assert!(lines.contains(&expected), "{expected} not in {lines:?}");
    }
    let open = format!("OPEN Err({:?})", format!("NotOwned({})", victim.scene));
    assert!(lines.contains(&open), "{open} not in {lines:?}");
    assert!(lines.iter().any(|l| l.ends_with("DONE")), "{lines:?}");
    // The forged frames were not answered to the victim and moved nothing; its scene,
    // bodies, shapes and masks are as they were.
    victim.assert_untouched();
    if let Some(frame) = victim.link.try_receive_results().unwrap() {
        panic!("an unasked frame reached the victim: {:?}", frame.header());
    }
    let shape = victim
        .client
        .register_primitive(victim.scene, Primitive::Sphere { radius: 0.1 })
        .unwrap();
    assert_eq!(shape, 1, "the attacker registered no shape");
    assert_eq!(
        victim.client.add_body(victim.scene, &body(shape, 40.0)),
        Ok(2),
        "the attacker added no body"
    );
    victim.assert_untouched();
}

#[test]
fn a_subscriber_that_never_reads_never_holds_the_daemon_up() {
    let daemon = Daemon::start();
    let mut victim = Victim::new(&daemon);
    // Another process of the same user finds the results service and subscribes, with the
    // largest buffer it may, then never reads.
    let config = config_with_prefix(daemon.prefix());
    let node = NodeBuilder::new()
        .config(&config)
        .create::<ipc::Service>()
        .unwrap();
    let token = listed_token(daemon.root(), daemon.prefix());
    let results = node
        .service_builder(
            &proxima_ipc::results_service_name(daemon.root(), token)
                .as_str()
                .try_into()
                .unwrap(),
        )
        .publish_subscribe::<[ResultRecord]>()
        .user_header::<ResultFrameHeader>()
        .open()
        .unwrap();
    assert!(results.static_config().has_safe_overflow());
    let _idle = results
        .subscriber_builder()
        .buffer_size(proxima_ipc::FRAME_BUFFER)
        .create()
        .unwrap();
    // Many more frames than any buffer holds: each is answered (a blocked publisher would
    // answer none past the buffer).
    for _ in 0..200 {
        victim.assert_untouched();
    }
}

#[test]
fn a_control_service_served_or_set_up_by_another_process_stops_the_daemon_at_start() {
    let daemon = Daemon::start();
    // Serving: a client is answered.
    let mut victim = Victim::new(&daemon);
    let config = config_with_prefix(daemon.prefix());
    let impostor = NodeBuilder::new()
        .config(&config)
        .create::<ipc::Service>()
        .unwrap();
    // The real daemon serves `root`; a second one on the same root must refuse, not join.
    let second = Command::new(env!("CARGO_BIN_EXE_proximad"))
        .args(["--root", daemon.root(), "--iceoryx-prefix", daemon.prefix()])
        .output()
        .expect("proximad runs");
    assert!(!second.status.success());
    let stderr = String::from_utf8_lossy(&second.stderr);
    assert!(stderr.contains("already serve"), "{stderr}");
    // A root whose control service someone else created with room for a second server.
    let root = format!("{}-squatted", daemon.root());
    let _squatter = proxima_ipc::control_service_builder(&impostor, &root)
        .unwrap()
        .max_servers(2)
        .create()
        .unwrap();
    let refused = Command::new(env!("CARGO_BIN_EXE_proximad"))
        .args(["--root", &root, "--iceoryx-prefix", daemon.prefix()])
        .output()
        .expect("proximad runs");
    assert!(!refused.status.success());
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(stderr.contains("max_servers 2"), "{stderr}");
    // The running daemon was not disturbed by either.
    victim.assert_untouched();
    Victim::new(&daemon).assert_untouched();
}

#[test]
fn nodes_held_on_the_control_service_do_not_lock_new_clients_out() {
    let daemon = Daemon::start();
    let mut first = Victim::new(&daemon);
    let config = config_with_prefix(daemon.prefix());
    let name = proxima_ipc::control_service_name(daemon.root());
    // Thirty nodes each holding the control service and its event service (iceoryx2's
    // default limit was 20 nodes per service).
    let held: Vec<_> = (0..30)
        .map(|_| {
            let node = NodeBuilder::new()
                .config(&config)
                .create::<ipc::Service>()
                .unwrap();
            let control = proxima_ipc::control_service_builder(&node, daemon.root())
                .unwrap()
                .open()
                .unwrap_or_else(|e| panic!("{name}: {e:?}"));
            let events = proxima_ipc::control_events_service_builder(&node, daemon.root())
                .unwrap()
                .open()
                .unwrap();
            (control, events, node)
        })
        .collect();
    let mut victim = Victim::new(&daemon);
    victim.assert_untouched();
    first.assert_untouched();
    drop(held);
}

#[test]
fn a_restarted_daemon_answers_no_old_frame_and_old_clients_learn_it_is_lost() {
    let mut daemon = Daemon::start();
    let mut old = Victim::new(&daemon);
    old.assert_untouched();
    let old_token = old.client.scene_access(old.scene).unwrap().token;
    daemon.kill();
    daemon.restart();
    let mut new = Victim::new(&daemon);
    new.assert_untouched();
    assert_ne!(new.client.daemon_instance(), old.client.daemon_instance());
    // The old client's frame goes to services no daemon serves: never answered, and the
    // wait ends with a lost daemon, not an answer from the new one.
    old.link
        .publish_poses(99, 0, query::CLOSE, &[pose_at(1, 50.0)])
        .unwrap();
    assert_eq!(
        old.link
            .receive_results_for(99, Duration::from_millis(300))
            .err(),
        Some(FrameReceiveError::DaemonLost)
    );
    assert_eq!(
        old.client.add_body(old.scene, &body(0, 1.0)),
        Err(ControlError::DaemonLost)
    );
    // The new scene has other services and kept its bodies where they were.
    assert_ne!(new.client.scene_access(new.scene).unwrap().token, old_token);
    new.assert_untouched();
}

#[test]
fn reserved_fields_bad_coordinates_and_oversized_headers_get_their_codes_before_any_work() {
    use proxima_ipc::wire::{Command, ControlRequest, ShapeKindCode};
    let daemon = Daemon::start();
    let mut victim = Victim::new(&daemon);
    let attacker = daemon.client();
    let scene = attacker.create_scene().unwrap();
    let code = |reply: proxima_ipc::wire::ControlReply| ErrorCode::from_u32(reply.status);
    // A reserved field set: refused, whatever the command.
    let reserved = ControlRequest {
        protocol_version: PROTOCOL_VERSION,
        command: Command::Hello as u32,
        reserved: 1,
        ..ControlRequest::default()
    };
    let reply = attacker.request(&reserved, &[]).unwrap();
    assert_eq!(code(reply), Some(ErrorCode::MalformedMessage));
    // A mesh header far over the limits (10^7 triangles) with a tiny payload: refused for
    // the limit from the header alone, before its payload is even measured.
    let oversized = ControlRequest {
        protocol_version: PROTOCOL_VERSION,
        command: Command::RegisterShape as u32,
        scene,
        shape_kind: ShapeKindCode::Mesh as u32,
        vertex_count: 3,
        index_count: 30_000_000,
        ..ControlRequest::default()
    };
    let reply = attacker.request(&oversized, &[0; 64]).unwrap();
    assert_eq!(code(reply), Some(ErrorCode::LimitExceeded));
    // A convex point beyond the coordinate limit is a bad shape, not a size limit.
    let far = attacker.register_convex(scene, &[[0.0; 3], [1e300, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    assert!(
        matches!(
            far,
            Err(ControlError::Rejected {
                code: ErrorCode::InvalidShape,
                ..
            })
        ),
        "{far:?}"
    );
    // A pose record whose reserved field is set: the frame is refused, naming the body.
    let link = attacker.open_scene(scene).unwrap();
    let sphere = attacker
        .register_primitive(scene, Primitive::Sphere { radius: 0.5 })
        .unwrap();
    let body_id = attacker.add_body(scene, &body(sphere, 0.0)).unwrap();
    let record = proxima_ipc::wire::PoseRecord {
        reserved: 7,
        ..pose_at(body_id, 3.0)
    };
    link.publish_poses(1, 0, query::CLOSE, &[record]).unwrap();
    let frame = link.receive_results_for(1, TIMEOUT).unwrap().unwrap();
    assert_eq!(
        ErrorCode::from_u32(frame.header().status),
        Some(ErrorCode::MalformedMessage)
    );
    assert_eq!(frame.header().error_body, body_id);
    victim.assert_untouched();
}

#[test]
fn endless_add_remove_cycles_reuse_body_slots_so_the_scene_stays_its_size() {
    let daemon = Daemon::start();
    let mut victim = Victim::new(&daemon);
    let client = daemon.client();
    let scene = client.create_scene().unwrap();
    let sphere = client
        .register_primitive(scene, Primitive::Sphere { radius: 0.1 })
        .unwrap();
    let keep = client.add_body(scene, &body(sphere, 0.0)).unwrap();
    for cycle in 0..10_000 {
        let id = client.add_body(scene, &body(sphere, 1.0)).unwrap();
        assert_eq!(id, keep + 1, "cycle {cycle}: the freed slot is taken again");
        client.remove_body(scene, id).unwrap();
    }
    victim.assert_untouched();
}

/// The user id of `nobody`: the other OS user of the attack-10 tests.
const OUTSIDER_UID: u32 = 65534;

/// The outsider (only when spawned with [`OUTSIDER_ROLE`], as another OS user; otherwise it
/// returns at once): for each file of the daemon's iceoryx2 prefix in `/dev/shm`, whether
/// it can open it for writing (`WRITABLE <name>`) or reading (`READABLE <name>`); then
/// whether it can connect as a client (`CONNECTED`, or `REFUSED <error>`); then `DONE`. It
/// writes nothing: opening is the test.
#[test]
fn outsider_role() {
    let Some(role) = Role::from_env(OUTSIDER_ROLE) else {
        return;
    };
    let mut out = std::io::stdout().lock();
    for entry in std::fs::read_dir(node_counter::SHM_DIR).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        if !name.starts_with(&role.prefix) {
            continue;
        }
        let path = std::path::Path::new(node_counter::SHM_DIR).join(&name);
        if std::fs::OpenOptions::new().write(true).open(&path).is_ok() {
            writeln!(out, "WRITABLE {name}").unwrap();
        }
        if std::fs::File::open(&path).is_ok() {
            writeln!(out, "READABLE {name}").unwrap();
        }
    }
    match role.connect(Duration::from_secs(2)) {
        Ok(_) => writeln!(out, "CONNECTED").unwrap(),
        Err(e) => writeln!(out, "REFUSED {e}").unwrap(),
    }
    writeln!(out, "DONE").unwrap();
}

/// Whether this process may start others as another user.
fn is_root() -> bool {
    std::fs::metadata("/proc/self").is_ok_and(|m| m.uid() == 0)
}

#[test]
fn another_os_user_can_neither_use_the_daemon_nor_stop_new_clients() {
    if !is_root() {
        eprintln!(
            "another_os_user_can_neither_use_the_daemon_nor_stop_new_clients: NOT RUN: starting \
             a process as another OS user needs root"
        );
        return;
    }
    let daemon = Daemon::start();
    let mut victim = Victim::new(&daemon);
    let outsider = role_process("outsider_role", OUTSIDER_ROLE, &daemon, "")
        .uid(OUTSIDER_UID)
        .gid(OUTSIDER_UID)
        .output()
        .expect("the outsider runs");
    let stdout = String::from_utf8_lossy(&outsider.stdout);
    let lines: Vec<&str> = stdout.lines().collect();
    let stderr = String::from_utf8_lossy(&outsider.stderr);
    assert!(lines.contains(&"DONE"), "{stdout}\n{stderr}");
    // Not one of the daemon's files, the node counter included, opens for another user.
    let opened: Vec<&&str> = lines
        .iter()
        .filter(|l| l.contains("WRITABLE ") || l.contains("READABLE "))
        .collect();
    assert!(opened.is_empty(), "another user opened {opened:?}");
    assert!(
        lines.iter().any(|l| l.contains("REFUSED ")),
        "another user connected: {stdout}"
    );
    // The daemon's user is served as before, old clients and new.
    victim.assert_untouched();
    Victim::new(&daemon).assert_untouched();
}

#[test]
fn a_node_counter_another_user_set_up_first_stops_the_daemon_at_start() {
    if !is_root() {
        eprintln!(
            "a_node_counter_another_user_set_up_first_stops_the_daemon_at_start: NOT RUN: \
             files of another OS user need root to make"
        );
        return;
    }
    // The counter of a fresh prefix, made by another user before any daemon ran: named as
    // iceoryx2 names the one of a running daemon's prefix.
    let daemon = Daemon::start();
    let mut victim = Victim::new(&daemon);
    let counter = std::fs::read_dir(node_counter::SHM_DIR)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .find(|name| node_counter::is_node_counter(name, daemon.prefix()))
        .expect("the running daemon's node counter");
    let prefix = format!("{}squat_", daemon.prefix());
    let squatted = std::path::Path::new(node_counter::SHM_DIR).join(counter.replacen(
        daemon.prefix(),
        &prefix,
        1,
    ));
    std::fs::write(&squatted, [0u8; 16]).unwrap();
    std::os::unix::fs::chown(&squatted, Some(OUTSIDER_UID), Some(OUTSIDER_UID)).unwrap();
    let refused = Command::new(env!("CARGO_BIN_EXE_proximad"))
        .args(["--root", daemon.root(), "--iceoryx-prefix", &prefix])
        .output()
        .expect("proximad runs");
    let _ = std::fs::remove_file(&squatted);
    assert!(!refused.status.success());
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(
        stderr.contains("refusing to start") && stderr.contains("belongs to user 65534"),
        "{stderr}"
    );
    victim.assert_untouched();
}

/// Control ports the hoarder opens, each its own node (as many as separate clients).
const HOARDER_PORTS: usize = 4;

/// The hoarder (only when spawned with [`HOARDER_ROLE`]; otherwise it returns at once):
/// over [`HOARDER_PORTS`] control ports it creates scenes until every port is refused, then
/// registers a sphere in each and adds bodies round the scenes until each is refused. It
/// prints `SCENES <n>`, `BODIES <n>` and each refusal's `REFUSED <code> <reason>`, then
/// `READY`, and holds what it took until its stdin closes.
#[test]
fn hoarder_role() {
    let Some(role) = Role::from_env(HOARDER_ROLE) else {
        return;
    };
    let ports: Vec<Client<ipc::Service>> = (0..HOARDER_PORTS)
        .map(|_| role.connect(TIMEOUT).expect("the hoarder connects"))
        .collect();
    let mut out = std::io::stdout().lock();
    // The test harness's `test hoarder_role ... ` has no line end of its own.
    writeln!(out).unwrap();
    let mut refused = |result: Result<u32, ControlError>| match result {
        Ok(id) => Some(id),
        Err(ControlError::Rejected { code, reason }) => {
            writeln!(out, "REFUSED {code:?} {reason}").unwrap();
            None
        }
        Err(e) => panic!("the hoarder's request failed: {e:?}"),
    };
    let mut scenes = Vec::new();
    for (port, client) in ports.iter().enumerate() {
        // One more than a port could ever need, so every port meets its refusal.
        for _ in 0..=HOARDER_PORTS {
            if let Some(scene) = refused(client.create_scene()) {
                scenes.push((port, scene));
            }
        }
    }
    let spheres: Vec<u32> = scenes
        .iter()
        .map(|&(port, scene)| {
            ports[port]
                .register_primitive(scene, Primitive::Sphere { radius: 0.1 })
                .expect("a sphere is registered")
        })
        .collect();
    let mut bodies = 0;
    for attempt in 0..16 {
        let i = attempt % scenes.len();
        let (port, scene) = scenes[i];
        let added = ports[port].add_body(scene, &body(spheres[i], attempt as f64));
        bodies += usize::from(refused(added).is_some());
    }
    let mut out = std::io::stdout().lock();
    writeln!(out, "SCENES {}\nBODIES {bodies}\nREADY", scenes.len()).unwrap();
    out.flush().unwrap();
    drop(out);
    let mut held = String::new();
    let _ = std::io::stdin().read_line(&mut held);
}

/// One process opening several control ports gets one quota (2 scenes, 4 bodies), not one
/// per port: it cannot take the daemon's 5 scenes, and another process still gets its own
/// scenes and bodies and is served.
#[test]
fn a_process_with_many_ports_holds_one_quota_and_leaves_the_rest_to_others() {
    let file = ConfigFile::new(
        "[limits]\n\
         max_scenes = 5\n\
         max_scenes_per_client = 2\n\
         max_bodies_per_client = 4\n",
    );
    let daemon = Daemon::start_plain(&["--config", file.path()]);
    let mut hoarder = role_process("hoarder_role", HOARDER_ROLE, &daemon, "")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("the hoarder starts");
    let mut output = BufReader::new(hoarder.stdout.take().unwrap()).lines();
    let lines: Vec<String> = output
        .by_ref()
        .map_while(Result::ok)
        .take_while(|line| line != "READY")
        .collect();
    let count = |what: &str| -> usize {
        lines
            .iter()
            .find_map(|line| line.strip_prefix(what)?.trim().parse().ok())
            .unwrap_or_else(|| panic!("the hoarder reports {what}: {lines:?}"))
    };
    assert_eq!(count("SCENES "), 2, "{lines:?}");
    assert_eq!(count("BODIES "), 4, "{lines:?}");
    let refusals: Vec<&String> = lines.iter().filter(|l| l.starts_with("REFUSED")).collect();
    // Every port was refused scenes past the first two, then every body past the fourth.
    assert_eq!(
        refusals.len(),
        (HOARDER_PORTS + 1) * HOARDER_PORTS - 2 + 16 - 4,
        "{lines:?}"
    );
    for refusal in &refusals {
        assert!(
            refusal.starts_with("REFUSED LimitExceeded this client process holds its limit of"),
            "{refusal}"
        );
    }
    // Another process: two scenes of its own, each served.
    let mut victims = [Victim::new(&daemon), Victim::new(&daemon)];
    for victim in &mut victims {
        victim.assert_untouched();
    }
    // Its own quota holds too, though the daemon has a scene left.
    let refused = victims[0].client.create_scene().unwrap_err();
    assert!(
        matches!(&refused, ControlError::Rejected { code: ErrorCode::LimitExceeded, reason }
            if reason.contains("this client process")),
        "{refused:?}"
    );
    drop(hoarder.stdin.take());
    let rest: Vec<String> = output.map_while(Result::ok).collect();
    assert!(
        hoarder.wait().unwrap().success(),
        "the hoarder ends well: {rest:?}"
    );
    victims[1].assert_untouched();
}
