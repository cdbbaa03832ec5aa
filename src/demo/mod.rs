//! `proximad demo`: the daemon and a simulation client on the embedded demo scene.
//!
//! The demo is a client of the protocol, like any simulation: it starts `proximad` itself
//! (this same executable, serving under a root and iceoryx2 prefix of its own) as a second
//! process, connects, builds the scene ([`scene`]) and then runs frames at a fixed rate:
//! advance the motion, publish every pose straight into shared memory, wait for the result
//! frame, bounce the spheres that touch, and print a line every so often and a summary at
//! the end ([`report`]). Part of the binary only: the engine library knows nothing of it.

mod report;
mod scene;

use clap::Args;
use iceoryx2::prelude::ipc;
use proxima_ipc::client::ClientBuilder;
use proxima_ipc::tools::daemon_process::{ChildProcess, Isolation};
use proxima_ipc::wire::query;
use report::{FrameLine, Summary};
use scene::DemoScene;
use std::error::Error;
use std::time::{Duration, Instant};

/// Options of `proximad demo`.
#[derive(Debug, Clone, Args)]
pub struct DemoArgs {
    /// How long to run, seconds.
    #[arg(long, default_value_t = 5.0)]
    seconds: f64,
    /// Run until Ctrl-C instead of `--seconds`.
    #[arg(long)]
    keep_running: bool,
    /// Frames per second.
    #[arg(long, default_value_t = 200)]
    rate_hz: u32,
    /// Number of bouncing spheres.
    #[arg(long, default_value_t = 300)]
    spheres: usize,
    /// Budget of each frame, microseconds.
    #[arg(long, default_value_t = 1000)]
    budget_us: u64,
    /// Print one frame line every this many frames.
    #[arg(long, default_value_t = 50)]
    print_every: u64,
    /// Start the demo's daemon with `--realtime-priority N` (its frame thread under
    /// SCHED_FIFO; needs CAP_SYS_NICE).
    #[arg(long, value_parser = proxima::daemon::realtime::parse_priority)]
    realtime_priority: Option<u8>,
}

/// Runs the demo: daemon process, scene, frames, summary.
///
/// # Errors
/// The daemon could not be started or reached, or refused the scene.
pub fn run(args: &DemoArgs) -> Result<(), Box<dyn Error>> {
    let isolation = Isolation::unique("demo");
    let exe = std::env::current_exe()?;
    let mut daemon =
        ChildProcess::spawn_quiet_daemon_at_priority(&exe, &isolation, args.realtime_priority)?;
    let Isolation { root, prefix } = isolation;
    let client = ClientBuilder::new()
        .root(&root)
        .iceoryx_prefix(&prefix)
        .reply_timeout(Duration::from_secs(10))
        .connect::<ipc::Service>()?;
    let scene_id = client.create_scene()?;
    let mut scene = DemoScene::build(&client, scene_id, args.spheres)?;
    let link = client.open_scene(scene_id)?;
    println!(
        "proximad demo: daemon pid {}, scene {scene_id}: {} bodies moving, {} Hz, budget {} µs, \
         queries CLOSE | CONTACTS{}",
        daemon.id().unwrap_or(0),
        scene.body_count(),
        args.rate_hz,
        args.budget_us,
        if args.keep_running {
            ", until Ctrl-C"
        } else {
            ""
        }
    );
    let period = Duration::from_secs_f64(1.0 / f64::from(args.rate_hz.max(1)));
    let frames = if args.keep_running {
        u64::MAX
    } else {
        (args.seconds * f64::from(args.rate_hz)).ceil() as u64
    };
    let budget_ns = args.budget_us * 1000;
    let mut summary = Summary::new(frames.min(1 << 20) as usize, budget_ns);
    let start = Instant::now();
    for seq in 1..=frames {
        wait_until(start + period * (seq as u32));
        if daemon.has_exited() {
            return Err("the daemon exited".into());
        }
        scene.advance(period.as_secs_f64());
        let sent = Instant::now();
        link.publish_poses_with(
            seq,
            budget_ns,
            query::CLOSE | query::CONTACTS,
            scene.body_count(),
            |i| scene.pose(i),
        )?;
        let Some(frame) = link.receive_results_for(seq, Duration::from_secs(1))? else {
            summary.lost();
            continue;
        };
        let round_trip = sent.elapsed();
        let bounced = scene.bounce(frame.pairs(), frame.contacts());
        let line = FrameLine::new(seq, frame.header(), round_trip, bounced);
        drop(frame);
        summary.add(&line);
        // Every late frame is printed, with its stage times.
        if seq % args.print_every.max(1) == 0 || seq == 1 || line.budget_missed() {
            println!("{line}");
        }
    }
    summary.print(start.elapsed());
    drop(link);
    drop(client);
    if !daemon.stop() {
        eprintln!("proximad demo: the daemon did not exit cleanly");
    }
    Ok(())
}

/// Sleeps until shortly before `due`, then spins the rest (a sleep alone overshoots by
/// 50–100 µs on this machine class).
fn wait_until(due: Instant) {
    const SPIN: Duration = Duration::from_micros(200);
    let now = Instant::now();
    if due > now + SPIN {
        std::thread::sleep(due - now - SPIN);
    }
    while Instant::now() < due {
        std::hint::spin_loop();
    }
}
