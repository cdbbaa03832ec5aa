//! A simulation process that uses `proximad` for its collisions: a few hundred spheres,
//! capsules, boxes and tori dropped into a bin, integrated here (gravity, velocities) and
//! bounced with the contacts the daemon returns.
//!
//! ```text
//! cargo run --release -- &                                   # a daemon under the root "proxima"
//! cargo run --release --example falling_bodies               # connects to it
//! cargo run --release --example falling_bodies -- --spawn-daemon --bodies 400 --seconds 10
//! ```
//!
//! `--spawn-daemon` starts a private `proximad` (its path from `--daemon`, by default
//! `target/release/proximad` next to this example) under a root of its own. Each frame
//! publishes every body's pose straight into shared memory with `CLOSE | CONTACTS`, waits
//! for the result frame, and for each touching pair applies an impulse along the contact
//! normal at its deepest point (restitution 0.4, bodies as point masses: no spin response),
//! then pushes the bodies apart by the depth. A body slow for half a second falls asleep,
//! as in any rigid-body engine: it stops moving until a hard hit wakes it, so its pose, and
//! with it the daemon's answers for its pairs with other sleepers, stay the same (the
//! daemon reuses them). Once a second it prints the frame's pairs, contacts, round trip and
//! how many bodies have come to rest.
//!
//! Every pair is answered exactly (closed forms for spheres, capsules and boxes, the tori's
//! BVHs against everything else), so the frames say `exact`.
//!
//! The scene and its integration live in `examples/scenes/` (`falling.rs`, `point_mass.rs`),
//! shared with `deadline_bench`.

#[path = "scenes/falling.rs"]
mod falling;
#[path = "scenes/point_mass.rs"]
mod point_mass;
// The scene description also builds in-process copies (`deadline_bench` checks against
// one); this program only registers it with the daemon.
#[allow(dead_code)]
#[path = "scenes/spec.rs"]
mod spec;

use clap::Parser;
use falling::{BIN_HALF, falling_scene, falling_world};
use iceoryx2::prelude::{LogLevel, ipc, set_log_level_from_env_or};
use proxima_ipc::client::ClientBuilder;
use proxima_ipc::tools::daemon_process::{ChildProcess, Isolation, sibling_daemon};
use proxima_ipc::tools::latency::LatencyRecorder;
use proxima_ipc::wire::{Completeness, ErrorCode, query};
use std::error::Error;
use std::path::PathBuf;
use std::time::{Duration, Instant};

#[derive(Debug, Parser)]
#[command(about = "Bodies falling into a bin, bounced with proximad's contacts")]
struct Args {
    /// Number of falling bodies.
    #[arg(long, default_value_t = 300)]
    bodies: usize,
    /// Simulated (and wall-clock) seconds.
    #[arg(long, default_value_t = 10.0)]
    seconds: f64,
    /// Frames per second.
    #[arg(long, default_value_t = 120)]
    rate_hz: u32,
    /// Frame budget, microseconds.
    #[arg(long, default_value_t = 2000)]
    budget_us: u64,
    /// Service root of the daemon to use.
    #[arg(long, default_value = proxima_ipc::DEFAULT_ROOT)]
    root: String,
    /// iceoryx2 prefix of the daemon to use.
    #[arg(long)]
    iceoryx_prefix: Option<String>,
    /// Start a private daemon instead of using a running one.
    #[arg(long)]
    spawn_daemon: bool,
    /// The `proximad` executable for `--spawn-daemon`.
    #[arg(long)]
    daemon: Option<PathBuf>,
}

fn main() -> Result<(), Box<dyn Error>> {
    let args = Args::parse();
    set_log_level_from_env_or(LogLevel::Error);
    let (_daemon, root, prefix) = if args.spawn_daemon {
        let Isolation { root, prefix } = Isolation::unique("fall");
        let exe = match &args.daemon {
            Some(path) => path.clone(),
            None => sibling_daemon()?,
        };
        let daemon = ChildProcess::spawn(
            &exe,
            ["--root", &root, "--iceoryx-prefix", &prefix],
            &prefix,
        )?;
        (Some(daemon), root, Some(prefix))
    } else {
        (None, args.root.clone(), args.iceoryx_prefix.clone())
    };
    let mut builder = ClientBuilder::new()
        .root(&root)
        .reply_timeout(Duration::from_secs(10));
    if let Some(prefix) = &prefix {
        builder = builder.iceoryx_prefix(prefix);
    }
    let client = builder.connect::<ipc::Service>()?;
    let scene_id = client.create_scene()?;
    let spec = falling_scene(args.bodies);
    let mut world = falling_world(&spec, &spec.register(&client, scene_id)?);
    let link = client.open_scene(scene_id)?;
    println!(
        "falling_bodies: scene {scene_id}, {} falling bodies in a {:.0} m bin, {} Hz",
        world.moving_count(),
        2.0 * BIN_HALF,
        args.rate_hz
    );
    if let Some(access) = client.scene_access(scene_id) {
        println!(
            "falling_bodies: watch it with `--example monitor -- --token {}`",
            access.token
        );
    }
    let dt = 1.0 / f64::from(args.rate_hz);
    let period = Duration::from_secs_f64(dt);
    let frames = (args.seconds * f64::from(args.rate_hz)).ceil() as u64;
    let mut round_trips = LatencyRecorder::with_capacity(frames as usize);
    let (mut truncated, mut missed, mut lost) = (0u64, 0u64, 0u64);
    let start = Instant::now();
    for seq in 1..=frames {
        let due = start + period * (seq as u32);
        while Instant::now() < due {
            std::thread::sleep(Duration::from_micros(100));
        }
        world.integrate(dt);
        let sent = Instant::now();
        link.publish_poses_with(
            seq,
            args.budget_us * 1000,
            query::CLOSE | query::CONTACTS,
            world.moving_count(),
            |i| world.pose(i),
        )?;
        let Some(frame) = link.receive_results_for(seq, Duration::from_secs(1))? else {
            lost += 1;
            continue;
        };
        round_trips.record(sent.elapsed());
        let header = *frame.header();
        if header.status != ErrorCode::Ok as u32 {
            return Err(format!("frame {seq} refused: status {}", header.status).into());
        }
        truncated += u64::from(header.completeness != Completeness::Exact as u32);
        missed += u64::from(header.budget_met == 0);
        let bounced = world.resolve(frame.pairs(), frame.contacts());
        drop(frame);
        if seq % u64::from(args.rate_hz) == 0 {
            println!(
                "t {:5.1} s  pairs {:4}  contacts {:4}  bounced {:4}  resting {:4}/{}  \
                 round trip {:6.1} µs",
                seq as f64 * dt,
                header.pair_count,
                header.contact_count,
                bounced,
                world.resting(),
                world.moving_count(),
                sent.elapsed().as_secs_f64() * 1e6
            );
        }
    }
    if let Some(summary) = round_trips.summary() {
        println!("round trip: {summary}");
    }
    println!(
        "{frames} frames: {truncated} truncated, {missed} over budget, {lost} lost; {} of {} \
         bodies at rest",
        world.resting(),
        world.moving_count()
    );
    client.drop_scene(scene_id)?;
    Ok(())
}
