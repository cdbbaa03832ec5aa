//! What a heavy shape registration costs another scene's frames: one client runs frames of a
//! small scene of spheres at a fixed rate while a second client registers a large flat grid
//! mesh in a scene of its own. Prints the first client's round trips while the registration
//! runs and outside it, how many frames missed their budget, and when the worst came (from
//! the registration's start); and when the registration was accepted and the shape built.
//!
//! ```text
//! cargo build --release && \
//!   cargo run --release --example registration_stall -- --spawn-daemon --triangles 1000000
//! ```
//!
//! `--spawn-daemon` starts a private `proximad` (its path from `--daemon`, by default
//! `target/release/proximad` next to this example) under a root of its own.

use clap::Parser;
use iceoryx2::prelude::{LogLevel, ipc, set_log_level_from_env_or};
use proxima_ipc::client::{BodySpec, ClientBuilder, Motion, Primitive};
use proxima_ipc::tools::daemon_process::{ChildProcess, Isolation, sibling_daemon};
use proxima_ipc::tools::latency::LatencyRecorder;
use proxima_ipc::wire::{PoseRecord, query};
use std::error::Error;
use std::path::PathBuf;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Distance between neighbouring spheres (radius 0.5: each touches the next), metres.
const SPACING: f64 = 0.9;
/// The unrotated orientation `[x, y, z, w]`.
const IDENTITY: [f64; 4] = [0.0, 0.0, 0.0, 1.0];

#[derive(Debug, Parser)]
#[command(about = "Another scene's frame round trips while a large mesh registers")]
struct Args {
    /// Triangles of the registered grid mesh (rounded to a square grid).
    #[arg(long, default_value_t = 1_000_000)]
    triangles: usize,
    /// Spheres in the framed scene.
    #[arg(long, default_value_t = 64)]
    bodies: u32,
    /// Frames per second of the framed scene.
    #[arg(long, default_value_t = 500)]
    rate_hz: u32,
    /// Frame budget, microseconds.
    #[arg(long, default_value_t = 2000)]
    budget_us: u64,
    /// Seconds of frames before the registration starts and after it ends.
    #[arg(long, default_value_t = 1.0)]
    settle_s: f64,
    /// The `proximad` executable.
    #[arg(long)]
    daemon: Option<PathBuf>,
}

fn main() -> Result<(), Box<dyn Error>> {
    let args = Args::parse();
    set_log_level_from_env_or(LogLevel::Error);
    let Isolation { root, prefix } = Isolation::unique("stall");
    let exe = match &args.daemon {
        Some(path) => path.clone(),
        None => sibling_daemon()?,
    };
    let _daemon = ChildProcess::spawn(
        &exe,
        ["--root", &root, "--iceoryx-prefix", &prefix],
        &prefix,
    )?;
    let builder = ClientBuilder::new()
        .root(&root)
        .iceoryx_prefix(&prefix)
        .reply_timeout(Duration::from_secs(600));
    let client = builder.clone().connect::<ipc::Service>()?;
    let scene = client.create_scene()?;
    let ball = client.register_primitive(scene, Primitive::Sphere { radius: 0.5 })?;
    let spec = BodySpec {
        shape: ball,
        position: [0.0; 3],
        orientation: IDENTITY,
        motion: Motion::Kinematic,
        group: 1,
        mask: 1,
        margin: Some(0.01),
    };
    for i in 0..args.bodies {
        let position = [f64::from(i) * SPACING, 0.0, 0.0];
        client.add_body(scene, &BodySpec { position, ..spec })?;
    }
    let link = client.open_scene(scene)?;
    // When the registration started and ended (`None` while it runs), from `start`.
    let span = Mutex::new((None::<Duration>, None::<Duration>));
    let accepted = Mutex::new(Duration::ZERO);
    let start = Instant::now();
    let (during, outside) = std::thread::scope(|s| -> Result<_, Box<dyn Error + Send + Sync>> {
        let registrar = s.spawn(|| -> Result<(), String> {
            let other = builder
                .connect::<ipc::Service>()
                .map_err(|e| e.to_string())?;
            let own = other.create_scene().map_err(|e| e.to_string())?;
            let (vertices, triangles) = grid(args.triangles);
            std::thread::sleep(Duration::from_secs_f64(args.settle_s));
            let began = start.elapsed();
            span.lock().unwrap().0 = Some(began);
            let registration = other
                .register_mesh_no_wait(own, &vertices, &triangles)
                .map_err(|e| e.to_string())?;
            *accepted.lock().unwrap() = start.elapsed() - began;
            other
                .wait_shape(own, registration.shape)
                .map_err(|e| e.to_string())?;
            span.lock().unwrap().1 = Some(start.elapsed());
            Ok(())
        });
        let period = Duration::from_secs(1) / args.rate_hz;
        let (mut during, mut outside) = (Phase::default(), Phase::default());
        for seq in 1u64.. {
            std::thread::sleep(period.saturating_sub(Duration::from_micros(60)));
            let sent = Instant::now();
            let at = sent - start;
            link.publish_poses_with(
                seq,
                args.budget_us * 1000,
                query::CLOSE,
                args.bodies as usize,
                |i| PoseRecord {
                    body: i as u32,
                    position: [i as f64 * SPACING, 0.0, 0.0],
                    orientation: IDENTITY,
                    ..PoseRecord::default()
                },
            )?;
            let frame = link
                .receive_results_for(seq, Duration::from_secs(600))?
                .ok_or("a frame went unanswered")?;
            let (rtt, met) = (sent.elapsed(), frame.header().budget_met != 0);
            drop(frame);
            let (began, ended) = *span.lock().unwrap();
            let since = at.saturating_sub(began.unwrap_or_default());
            match (began, ended) {
                (Some(b), None) if at >= b => during.record(rtt, met, since),
                (Some(b), Some(e)) if at >= b && at <= e => during.record(rtt, met, since),
                _ => outside.record(rtt, met, since),
            }
            if ended.is_some_and(|e| (sent - start).saturating_sub(e).as_secs_f64() > args.settle_s)
            {
                break;
            }
        }
        registrar.join().expect("the registrar does not panic")?;
        Ok((during, outside))
    })
    .map_err(|e| e.to_string())?;
    let (began, ended) = *span.lock().unwrap();
    println!(
        "registration of a {}-triangle grid: accepted after {:.3} s, built after {:.2} s",
        args.triangles,
        accepted.lock().unwrap().as_secs_f64(),
        (ended.unwrap_or_default() - began.unwrap_or_default()).as_secs_f64()
    );
    println!("during it:  {during}");
    println!("outside it: {outside}");
    Ok(())
}

/// The frames of one phase: round trips, how many missed their budget, the worst and when
/// it was sent (from the registration's start).
#[derive(Default)]
struct Phase {
    round_trips: LatencyRecorder,
    over_budget: u64,
    worst: (Duration, Duration),
}

impl Phase {
    fn record(&mut self, rtt: Duration, met: bool, since: Duration) {
        self.round_trips.record(rtt);
        self.over_budget += u64::from(!met);
        self.worst = self.worst.max((rtt, since));
    }
}

impl std::fmt::Display for Phase {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let Some(summary) = self.round_trips.summary() else {
            return f.write_str("no frames");
        };
        write!(
            f,
            "{summary}; {} over budget; worst sent at {:.3} s",
            self.over_budget,
            self.worst.1.as_secs_f64()
        )
    }
}

/// A flat square grid in the z = 0 plane with about `triangles` triangles.
fn grid(triangles: usize) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let n = ((triangles as f64 / 2.0).sqrt().ceil() as u32).max(1);
    let vertices = (0..=n)
        .flat_map(|i| (0..=n).map(move |j| [f64::from(i), f64::from(j), 0.0]))
        .collect();
    let at = |i: u32, j: u32| i * (n + 1) + j;
    let faces = (0..n)
        .flat_map(|i| {
            (0..n).flat_map(move |j| {
                [
                    [at(i, j), at(i + 1, j), at(i, j + 1)],
                    [at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)],
                ]
            })
        })
        .collect();
    (vertices, faces)
}
