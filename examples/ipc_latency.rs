//! Round-trip latency of `proximad` against a raw iceoryx2 ping-pong of the same payload,
//! measured in the same run.
//!
//! ```text
//! cargo run --release --example ipc_latency                      # back-to-back, 1,000 bodies
//! cargo run --release --example ipc_latency -- --rate-hz 1000 --seconds 60   # paced, moving
//! ```
//!
//! The example starts two helper processes (itself, with a hidden `--role`): the daemon's
//! real service loop, and an echo server that receives the same pose frame over the same
//! kind of services, reads every record and answers with an empty result frame. The client
//! alternates blocks of round trips to each, so machine drift hits both alike, and prints:
//! - `raw`: the echo round trip (publish poses → receive the answer), i.e. what iceoryx2 and
//!   the two processes' wake-ups cost;
//! - `daemon`: the daemon's round trip, its engine time (plan, broad, mid and narrow stages
//!   from the result header) and the overhead = round trip − engine time;
//! - the ratio overhead / raw at p50 and p99 (issue #4's target: ≤ 1.5).
//!
//! With `--rate-hz`, only the daemon is measured: frames are published on a fixed schedule
//! with every body moving, and a frame misses its deadline when its answer is not back
//! within the budget after publication, or the daemon says it missed the budget.
//!
//! The bodies are spheres of radius 0.5 m on a 3 m grid with 0.1 m margins, each moving on
//! a small circle (every pose changes every frame, raw and daemon alike): nothing is
//! close, so the round trip is the frame path itself.

use clap::{Parser, ValueEnum};
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use proxima::daemon::{Daemon, DaemonConfig};
use proxima_ipc::client::ClientBuilder;
use proxima_ipc::scene_link::SceneLink;
use proxima_ipc::tools::daemon_process::{ChildProcess, Isolation};
use proxima_ipc::tools::latency::LatencyRecorder;
use proxima_ipc::tools::latency_scene;
use proxima_ipc::wire::{
    ErrorCode, PoseFrameHeader, PoseRecord, ResultFrameHeader, ResultRecord, query, stage,
};
use std::error::Error;
use std::time::{Duration, Instant};

/// How long the echo server polls before it blocks on its event listener (as the daemon).
const SPIN: Duration = Duration::from_micros(50);
/// Round trips per block before switching between raw and daemon.
const BLOCK: usize = 500;

#[derive(Debug, Parser)]
#[command(about = "proximad round trip against a raw iceoryx2 ping-pong of the same payload")]
struct Args {
    /// Bodies per frame (every one sent every frame).
    #[arg(long, default_value_t = 1000)]
    bodies: usize,
    /// Measured round trips per mode (back-to-back run).
    #[arg(long, default_value_t = 10_000)]
    iterations: usize,
    /// Unmeasured round trips per mode first.
    #[arg(long, default_value_t = 1000)]
    warmup: usize,
    /// Frame budget, nanoseconds.
    #[arg(long, default_value_t = 1_000_000)]
    budget_ns: u64,
    /// Paced run at this many frames per second, bodies moving (0: back-to-back, raw vs daemon).
    #[arg(long, default_value_t = 0)]
    rate_hz: u32,
    /// Length of a paced run, seconds.
    #[arg(long, default_value_t = 10.0)]
    seconds: f64,
    /// Pin this client to CPU 0 and the daemon and echo processes to CPU 1 (with `taskset`),
    /// so the client's spinning never shares a core with the daemon.
    #[arg(long)]
    pin: bool,
    /// How long the client polls for an answer before it blocks, microseconds, for both
    /// the daemon and the raw ping-pong (a long spin needs `--pin`).
    #[arg(long, default_value_t = 50)]
    client_spin_us: u64,
    #[arg(long, hide = true)]
    role: Option<Role>,
    #[arg(long, hide = true)]
    root: Option<String>,
    #[arg(long, hide = true)]
    prefix: Option<String>,
}

#[derive(Debug, Clone, Copy, ValueEnum)]
enum Role {
    Daemon,
    Echo,
}

fn main() -> Result<(), Box<dyn Error>> {
    let args = Args::parse();
    set_log_level_from_env_or(LogLevel::Error);
    match (args.role, &args.root, &args.prefix) {
        (Some(Role::Daemon), Some(root), Some(prefix)) => run_daemon(root, prefix),
        (Some(Role::Echo), Some(root), Some(prefix)) => run_echo(root, prefix),
        (Some(_), _, _) => Err("a role needs --root and --prefix".into()),
        (None, _, _) => measure(&args),
    }
}

// ---------------------------------------------------------------------------------------
// The measuring client.

fn measure(args: &Args) -> Result<(), Box<dyn Error>> {
    let Isolation { root, prefix } = Isolation::unique("lat");
    let pin = args.pin;
    let exe = std::env::current_exe()?;
    let exe = exe.to_string_lossy().into_owned();
    let _children = ["daemon", "echo"]
        .map(|role| {
            let args = ["--role", role, "--root", &root, "--prefix", &prefix];
            if pin {
                let pinned = ["-c", "1", exe.as_str()].into_iter().chain(args);
                ChildProcess::spawn("taskset", pinned, &prefix)
            } else {
                ChildProcess::spawn(&exe, args, &prefix)
            }
        })
        .into_iter()
        .collect::<Result<Vec<_>, _>>()?;
    if pin {
        let me = std::process::id().to_string();
        let status = std::process::Command::new("taskset")
            .args(["-pc", "0", &me])
            .stdout(std::process::Stdio::null())
            .status()?;
        if !status.success() {
            return Err("taskset could not pin the client to CPU 0".into());
        }
    }
    let client = ClientBuilder::new()
        .root(&root)
        .iceoryx_prefix(&prefix)
        .reply_timeout(Duration::from_secs(10))
        .connect::<ipc::Service>()?;
    let scene = client.create_scene()?;
    let mut link = latency_scene::add_bodies(&client, scene, args.bodies)?;
    let client_spin = Duration::from_micros(args.client_spin_us);
    link.set_result_spin(client_spin);
    if args.rate_hz > 0 {
        return paced(args, &link);
    }
    let raw = RawLink::open(client.node(), &raw_root(&root), client_spin)?;
    let mut daemon_trips = DaemonTrips::with_capacity(args.iterations);
    let mut raw_trips = LatencyRecorder::with_capacity(args.iterations);
    let mut seq = 0u64;
    let (mut done, total) = (0, args.warmup + args.iterations);
    while done < total {
        let block = BLOCK.min(total - done);
        let measured = done >= args.warmup;
        for i in 0..block {
            let rtt = raw.round_trip(seq + i as u64, args.bodies)?;
            if measured {
                raw_trips.record(rtt);
            }
        }
        for i in 0..block {
            let (rtt, header) =
                daemon_round_trip(&link, seq + i as u64, args, (seq + i as u64) as f64 * 1e-3)?;
            if measured {
                daemon_trips.record(rtt, &header);
            }
        }
        seq += block as u64;
        done += block;
    }
    report(args, &raw_trips, &daemon_trips);
    Ok(())
}

/// One daemon round trip: publish every body at time `t`, wait for the answer.
fn daemon_round_trip(
    link: &SceneLink<ipc::Service>,
    seq: u64,
    args: &Args,
    t: f64,
) -> Result<(Duration, ResultFrameHeader), Box<dyn Error>> {
    let started = Instant::now();
    link.publish_poses_with(seq, args.budget_ns, query::CLOSE, args.bodies, |i| {
        latency_scene::pose(i, args.bodies, t)
    })?;
    let frame = link
        .receive_results_for(seq, Duration::from_secs(1))?
        .ok_or_else(|| format!("frame {seq}: no answer within 1 s"))?;
    let rtt = started.elapsed();
    let header = *frame.header();
    if header.status != ErrorCode::Ok as u32 || header.pair_count != 0 {
        return Err(format!(
            "frame {seq}: status {}, {} pairs (expected 0, nothing is close)",
            header.status, header.pair_count
        )
        .into());
    }
    Ok((rtt, header))
}

/// The daemon's time inside the engine for one frame: plan, broad, mid and narrow stages.
fn engine_ns(header: &ResultFrameHeader) -> u64 {
    [stage::PLAN, stage::BROAD, stage::MID, stage::NARROW]
        .iter()
        .map(|&s| header.stage_ns[s])
        .sum()
}

/// Daemon round trips split into engine time and overhead.
struct DaemonTrips {
    round_trip: LatencyRecorder,
    engine: LatencyRecorder,
    overhead: LatencyRecorder,
    in_daemon: LatencyRecorder,
    ingest: LatencyRecorder,
    publish: LatencyRecorder,
}

impl DaemonTrips {
    fn with_capacity(n: usize) -> Self {
        Self {
            round_trip: LatencyRecorder::with_capacity(n),
            engine: LatencyRecorder::with_capacity(n),
            overhead: LatencyRecorder::with_capacity(n),
            in_daemon: LatencyRecorder::with_capacity(n),
            ingest: LatencyRecorder::with_capacity(n),
            publish: LatencyRecorder::with_capacity(n),
        }
    }

    fn record(&mut self, rtt: Duration, header: &ResultFrameHeader) {
        let rtt_ns = u64::try_from(rtt.as_nanos()).unwrap_or(u64::MAX);
        let engine = engine_ns(header);
        self.round_trip.record_ns(rtt_ns);
        self.engine.record_ns(engine);
        self.overhead.record_ns(rtt_ns.saturating_sub(engine));
        self.in_daemon.record_ns(header.elapsed_ns);
        self.ingest.record_ns(header.stage_ns[stage::INGEST]);
        self.publish.record_ns(header.stage_ns[stage::PUBLISH]);
    }
}

fn report(args: &Args, raw: &LatencyRecorder, daemon: &DaemonTrips) {
    println!(
        "ipc_latency: {} bodies ({} KiB of poses per frame), budget {} µs, {} round trips per mode \
         after {} warm-up, alternating blocks of {BLOCK}; client spin {} µs{}",
        args.bodies,
        args.bodies * size_of::<PoseRecord>() / 1024,
        args.budget_ns / 1000,
        args.iterations,
        args.warmup,
        args.client_spin_us,
        if args.pin {
            ", pinned (client CPU 0, daemon and echo CPU 1)"
        } else {
            ", unpinned"
        }
    );
    let rows = [
        ("raw iceoryx2 round trip", raw),
        ("daemon round trip", &daemon.round_trip),
        ("daemon engine time", &daemon.engine),
        ("daemon receipt → publish", &daemon.in_daemon),
        ("  of which ingest (check, apply)", &daemon.ingest),
        ("  of which publish", &daemon.publish),
        ("daemon overhead (rtt − engine)", &daemon.overhead),
    ];
    for (name, recorder) in rows {
        if let Some(summary) = recorder.summary() {
            println!("  {name:32} {summary}");
        }
    }
    if let (Some(raw), Some(overhead)) = (raw.summary(), daemon.overhead.summary()) {
        let ratio = |a: u64, b: u64| a as f64 / b.max(1) as f64;
        let (p50, p99) = (
            ratio(overhead.p50_ns, raw.p50_ns),
            ratio(overhead.p99_ns, raw.p99_ns),
        );
        let verdict = |r: f64| if r <= 1.5 { "met" } else { "MISSED" };
        println!(
            "  overhead / raw: p50 {p50:.2} ({}), p99 {p99:.2} ({}) — target ≤ 1.5",
            verdict(p50),
            verdict(p99)
        );
    }
}

/// Frames on a fixed schedule at `args.rate_hz`, every body moving, for `args.seconds`.
fn paced(args: &Args, link: &SceneLink<ipc::Service>) -> Result<(), Box<dyn Error>> {
    let period = Duration::from_secs_f64(1.0 / f64::from(args.rate_hz));
    let frames = (args.seconds * f64::from(args.rate_hz)).round() as u64;
    let budget = Duration::from_nanos(args.budget_ns);
    let mut trips = DaemonTrips::with_capacity(frames as usize);
    let (mut late, mut over_budget, mut behind) = (0u64, 0u64, 0u64);
    let mut worst: Vec<(Duration, u64)> = Vec::new();
    let start = Instant::now();
    for seq in 1..=frames {
        let due = start + period * (seq as u32);
        wait_until(due);
        if Instant::now() > due + period {
            behind += 1; // the previous frame ran into this one's slot
        }
        let t = (seq as f64) / f64::from(args.rate_hz);
        let (rtt, header) = daemon_round_trip(link, seq, args, t)?;
        trips.record(rtt, &header);
        late += u64::from(rtt > budget);
        over_budget += u64::from(header.budget_met == 0);
        if rtt > budget {
            worst.push((rtt, seq));
        }
    }
    let wall = start.elapsed();
    println!(
        "ipc_latency paced: {} bodies moving, {frames} frames at {} Hz ({:.1} s wall), budget {} µs, client spin {} µs, {}",
        args.bodies,
        args.rate_hz,
        wall.as_secs_f64(),
        args.budget_ns / 1000,
        args.client_spin_us,
        if args.pin { "pinned" } else { "unpinned" }
    );
    for (name, recorder) in [
        ("round trip", &trips.round_trip),
        ("engine time", &trips.engine),
        ("daemon receipt → publish", &trips.in_daemon),
    ] {
        if let Some(summary) = recorder.summary() {
            println!("  {name:26} {summary}");
        }
    }
    println!(
        "  deadline misses: {late} round trips over budget, {over_budget} frames the daemon \
         itself reported over budget, {behind} frames published more than a period late"
    );
    worst.sort_unstable_by(|a, b| b.cmp(a));
    for (rtt, seq) in worst.iter().take(5) {
        println!("    frame {seq}: {:.1} µs", rtt.as_secs_f64() * 1e6);
    }
    Ok(())
}

/// Sleeps until shortly before `due`, then spins (a sleep alone overshoots by 50–100 µs).
fn wait_until(due: Instant) {
    let now = Instant::now();
    if due > now + Duration::from_micros(200) {
        std::thread::sleep(due - now - Duration::from_micros(200));
    }
    while Instant::now() < due {
        std::hint::spin_loop();
    }
}

fn iceoryx_config(prefix: &str) -> Result<iceoryx2::config::Config, Box<dyn Error>> {
    let mut config = iceoryx2::config::Config::global_config().clone();
    config.global.prefix = FileName::new(prefix.as_bytes()).map_err(|e| format!("{e:?}"))?;
    Ok(config)
}

// ---------------------------------------------------------------------------------------
// The daemon role: the real service loop.

fn run_daemon(root: &str, prefix: &str) -> Result<(), Box<dyn Error>> {
    let config = DaemonConfig {
        root: root.to_owned(),
        iceoryx_prefix: Some(prefix.to_owned()),
        ..DaemonConfig::default()
    };
    Daemon::new(config)?.run()?;
    Ok(())
}

// ---------------------------------------------------------------------------------------
// The raw ping-pong: the same pose and result services as a scene (the shared builders),
// one event service per direction, and an echo server that reads every pose.

fn raw_root(root: &str) -> String {
    format!("{root}-raw")
}

fn event_name(root: &str, what: &str) -> Result<ServiceName, Box<dyn Error>> {
    Ok(ServiceName::new(&format!("{root}/0/{what}")).map_err(|e| format!("{e:?}"))?)
}

/// The client side of the raw ping-pong.
struct RawLink {
    poses: Publisher<ipc::Service, [PoseRecord], PoseFrameHeader>,
    results: Subscriber<ipc::Service, [ResultRecord], ResultFrameHeader>,
    poses_sent: Notifier<ipc::Service>,
    results_ready: Listener<ipc::Service>,
    /// How long a round trip polls before it blocks.
    spin: Duration,
}

impl RawLink {
    fn open(node: &Node<ipc::Service>, root: &str, spin: Duration) -> Result<Self, Box<dyn Error>> {
        let fail = |what: &str, e: &dyn std::fmt::Debug| format!("raw {what}: {e:?}");
        let poses_service = proxima_ipc::poses_service_builder(node, root, RAW_TOKEN)
            .map_err(|e| fail("name", &e))?
            .open_or_create()
            .map_err(|e| fail("poses service", &e))?;
        let poses = poses_service
            .publisher_builder()
            .initial_max_slice_len(proxima_ipc::scene_link::POSES_INITIAL_MAX_SLICE_LEN)
            .allocation_strategy(AllocationStrategy::PowerOfTwo)
            .create()
            .map_err(|e| fail("poses publisher", &e))?;
        let results = proxima_ipc::results_service_builder(node, root, RAW_TOKEN)
            .map_err(|e| fail("name", &e))?
            .open_or_create()
            .map_err(|e| fail("results service", &e))?
            .subscriber_builder()
            .create()
            .map_err(|e| fail("results subscriber", &e))?;
        let poses_sent = node
            .service_builder(&event_name(root, "poses-sent")?)
            .event()
            .open_or_create()
            .map_err(|e| fail("event service", &e))?
            .notifier_builder()
            .create()
            .map_err(|e| fail("notifier", &e))?;
        let results_ready = node
            .service_builder(&event_name(root, "results-ready")?)
            .event()
            .open_or_create()
            .map_err(|e| fail("event service", &e))?
            .listener_builder()
            .create()
            .map_err(|e| fail("listener", &e))?;
        // A frame sent before the echo server subscribes is lost: wait for it.
        let deadline = Instant::now() + Duration::from_secs(10);
        while poses_service.dynamic_config().number_of_subscribers() == 0 {
            if Instant::now() > deadline {
                return Err("the echo server did not start".into());
            }
            std::thread::sleep(Duration::from_millis(5));
        }
        Ok(Self {
            poses,
            results,
            poses_sent,
            results_ready,
            spin,
        })
    }

    /// Publishes `bodies` poses as frame `seq` and waits for the echo.
    fn round_trip(&self, seq: u64, bodies: usize) -> Result<Duration, Box<dyn Error>> {
        let started = Instant::now();
        let mut sample = self
            .poses
            .loan_slice_uninit(bodies)
            .map_err(|e| format!("{e:?}"))?;
        *sample.user_header_mut() = PoseFrameHeader {
            protocol_version: proxima_ipc::PROTOCOL_VERSION,
            scene: 0,
            frame_seq: seq,
            budget_ns: 0,
            query_flags: query::CLOSE,
            count: bodies as u32,
            frame_key: 0,
        };
        let t = seq as f64 * 1e-3;
        sample
            .write_from_fn(|i| latency_scene::pose(i, bodies, t))
            .send()
            .map_err(|e| format!("{e:?}"))?;
        self.poses_sent.notify().map_err(|e| format!("{e:?}"))?;
        let spin_end = started + self.spin;
        let deadline = started + Duration::from_secs(1);
        loop {
            while let Some(answer) = self.results.receive().map_err(|e| format!("{e:?}"))? {
                if answer.user_header().frame_seq == seq {
                    return Ok(started.elapsed());
                }
            }
            let now = Instant::now();
            if now > deadline {
                return Err(format!("raw frame {seq}: no echo within 1 s").into());
            }
            if now >= spin_end {
                self.results_ready
                    .timed_wait(|_| {}, deadline - now)
                    .map_err(|e| format!("{e:?}"))?;
            }
        }
    }
}

/// The token of the raw baseline's services: any fixed one, as no daemon is involved.
const RAW_TOKEN: proxima_ipc::SceneToken = proxima_ipc::SceneToken([0, 0]);

/// The echo server: for every pose frame, read every record, publish an empty result frame
/// with the same `frame_seq`, notify. Waits like the daemon: spin, then block.
fn run_echo(root: &str, prefix: &str) -> Result<(), Box<dyn Error>> {
    let node = NodeBuilder::new()
        .config(&iceoryx_config(prefix)?)
        .create::<ipc::Service>()
        .map_err(|e| format!("{e:?}"))?;
    let root = raw_root(root);
    let poses = proxima_ipc::poses_service_builder(&node, &root, RAW_TOKEN)
        .map_err(|e| format!("{e:?}"))?
        .open_or_create()
        .map_err(|e| format!("{e:?}"))?
        .subscriber_builder()
        .create()
        .map_err(|e| format!("{e:?}"))?;
    let results = proxima_ipc::results_service_builder(&node, &root, RAW_TOKEN)
        .map_err(|e| format!("{e:?}"))?
        .open_or_create()
        .map_err(|e| format!("{e:?}"))?
        .publisher_builder()
        .initial_max_slice_len(1)
        .allocation_strategy(AllocationStrategy::PowerOfTwo)
        .create()
        .map_err(|e| format!("{e:?}"))?;
    let poses_sent = node
        .service_builder(&event_name(&root, "poses-sent")?)
        .event()
        .open_or_create()
        .map_err(|e| format!("{e:?}"))?
        .listener_builder()
        .create()
        .map_err(|e| format!("{e:?}"))?;
    let results_ready = node
        .service_builder(&event_name(&root, "results-ready")?)
        .event()
        .open_or_create()
        .map_err(|e| format!("{e:?}"))?
        .notifier_builder()
        .create()
        .map_err(|e| format!("{e:?}"))?;
    let mut checksum = 0.0f64;
    let mut last_work = Instant::now();
    loop {
        while let Some(frame) = poses.receive().map_err(|e| format!("{e:?}"))? {
            let received = Instant::now();
            for pose in frame.payload() {
                checksum += pose.position[0] + pose.orientation[3];
            }
            let header = ResultFrameHeader {
                protocol_version: proxima_ipc::PROTOCOL_VERSION,
                frame_seq: frame.user_header().frame_seq,
                error_body: u32::MAX,
                ..ResultFrameHeader::default()
            };
            drop(frame);
            let mut answer = results
                .loan_slice_uninit(0)
                .map_err(|e| format!("{e:?}"))?
                .write_from_fn(|_| ResultRecord::default());
            *answer.user_header_mut() = ResultFrameHeader {
                elapsed_ns: received.elapsed().as_nanos() as u64,
                ..header
            };
            answer.send().map_err(|e| format!("{e:?}"))?;
            results_ready.notify().map_err(|e| format!("{e:?}"))?;
            last_work = Instant::now();
        }
        if last_work.elapsed() < SPIN {
            std::hint::spin_loop();
            continue;
        }
        // The wait fails when SIGTERM/SIGINT interrupts it; `node.wait` installs iceoryx2's
        // signal handler on first use and errs once a termination was requested.
        let interrupted = poses_sent
            .timed_wait(|_| {}, Duration::from_millis(100))
            .is_err();
        if interrupted || node.wait(Duration::ZERO).is_err() {
            break;
        }
    }
    std::hint::black_box(checksum);
    Ok(())
}
