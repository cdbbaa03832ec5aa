//! Broad-phase timing per frame: Proxima's broad phases and rapier's broad phase (on
//! parry3d-f64's BVH) in lockstep on the same frames of one workload.
//!
//! ```text
//! cargo run --release --example broad_bench -- --bodies 100000 --scene uniform --moving 0.1 --frames 200
//! ```
//!
//! Each frame the workload moves its moving bodies once (not timed); then every broad phase
//! in turn is handed those boxes and produces its pairs, timed on its own. Frames alternate
//! which broad phase goes first, so drift and cache warmth do not favour one. Before any
//! timing, every broad phase is loaded with all bodies (that time is printed as `load ms`).
//!
//! Timed per frame:
//! - `sort_sweep`: [`SortAndSweep::pairs`] over the whole proxy list (its input is the list
//!   itself, so applying the moves costs it nothing);
//! - `incremental_sap`, `hash_grid`: `update` of each moved body, then `pairs` (the sorted
//!   list);
//! - `column_grid`, `skin_grid`: `update_all` of the frame's moves, then `pairs`;
//! - `parry_bvh` (change margin 1 nm, the exact pair set to within 2 nm) and `rapier_bvh` (rapier's 1 cm
//!   change margin): rapier's update loop, its pair map kept current; no list produced.
//!
//! Every frame, every Proxima broad phase's pair list is checked equal to `sort_sweep`'s,
//! and `parry_bvh`'s map to the same set, every `--check-every` frames (not timed); a
//! mismatch stops the run.
//!
//! Prints, per broad phase: mean and p99 µs per frame, pairs per frame, and the ratio of
//! rapier's mean (the faster of its two settings) to this one's.
//!
//! Like `proximad`, the process allocates through [`HugePageAlloc`], so that large tables
//! sit on transparent huge pages where the kernel allows; `--small-pages` turns that off.
//!
//! [`HugePageAlloc`]: proxima::huge_pages::HugePageAlloc

// Shared with benches/broad_phase.rs, which uses the items this one does not.
#[allow(dead_code)]
#[path = "../benches/common/broad_phases.rs"]
mod broad_phases;
// Shared with benches/broad_phase.rs, which uses the items this one does not.
#[allow(dead_code)]
#[path = "../benches/common/broad_scenes.rs"]
mod broad_scenes;
// Shared with benches/broad_phase.rs, which uses the items this one does not.
#[allow(dead_code)]
#[path = "../benches/common/parry_broad.rs"]
mod parry_broad;

use broad_phases::{NAMES, Phase};
use broad_scenes::{BroadScene, Layout, Motion};
use clap::Parser;
use proxima::bounding::Aabb;
use proxima::broad::CandidatePair;
use std::process::ExitCode;
use std::time::Instant;

/// Large tables on transparent huge pages, as in `proximad` (`--small-pages` turns the
/// advice off).
#[global_allocator]
static ALLOC: proxima::huge_pages::HugePageAlloc = proxima::huge_pages::HugePageAlloc;

#[derive(Parser, Debug)]
#[command(about = "Broad-phase time per frame, Proxima against rapier/parry, same frames")]
struct Args {
    /// Number of bodies.
    #[arg(long, default_value_t = 10_000)]
    bodies: usize,
    /// Layout: uniform, clustered or stack.
    #[arg(long, default_value = "uniform")]
    scene: String,
    /// Fraction of the bodies that move every frame.
    #[arg(long, default_value_t = 0.1)]
    moving: f64,
    /// Motion of the moving bodies: coherent or teleport.
    #[arg(long, default_value = "coherent")]
    motion: String,
    /// Frames timed.
    #[arg(long, default_value_t = 100)]
    frames: usize,
    /// Broad phases to run, comma-separated (sort_sweep, incremental_sap, hash_grid,
    /// column_grid, skin_grid, parry_bvh, rapier_bvh).
    #[arg(
        long,
        default_value = "sort_sweep,incremental_sap,hash_grid,column_grid,skin_grid,parry_bvh,rapier_bvh"
    )]
    algos: String,
    /// Check every broad phase's pair set against the others every this many frames
    /// (0: never).
    #[arg(long, default_value_t = 1)]
    check_every: usize,
    /// Factor on the coherent movers' speeds (3 cm per frame scattered, 5 mm stacked).
    #[arg(long, default_value_t = 1.0)]
    speed_scale: f64,
    /// Seed of the layout and the motion.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Leave every table on the 4 KiB pages the system gives (no huge-page advice), to
    /// measure what the advice buys.
    #[arg(long)]
    small_pages: bool,
}

/// One broad phase under test with its timings.
struct Runner {
    name: &'static str,
    phase: Phase,
    out: Vec<CandidatePair>,
    load_ms: f64,
    frame_ns: Vec<u64>,
    pairs_total: usize,
}

impl Runner {
    fn new(name: &'static str, scene: &BroadScene) -> Option<Self> {
        let started = Instant::now();
        let mut out = Vec::new();
        let phase = Phase::new(name, &scene.proxies, &mut out)?;
        Some(Self {
            name,
            phase,
            out,
            load_ms: started.elapsed().as_secs_f64() * 1e3,
            frame_ns: Vec::new(),
            pairs_total: 0,
        })
    }

    /// Hands this frame's moves to the broad phase and brings its pairs up to date, timed.
    fn frame(&mut self, scene: &BroadScene, moved: &[(u32, Aabb)]) {
        let started = Instant::now();
        self.phase.step(&scene.proxies, moved, &mut self.out);
        self.frame_ns.push(started.elapsed().as_nanos() as u64);
        self.pairs_total += self.phase.pair_count(&self.out);
    }

    fn mean_us(&self) -> f64 {
        self.frame_ns.iter().sum::<u64>() as f64 / self.frame_ns.len().max(1) as f64 / 1e3
    }

    fn p99_us(&self) -> f64 {
        let mut sorted = self.frame_ns.clone();
        sorted.sort_unstable();
        let at = ((sorted.len() as f64 * 0.99).ceil() as usize).clamp(1, sorted.len().max(1));
        sorted.get(at - 1).copied().unwrap_or(0) as f64 / 1e3
    }
}

fn main() -> ExitCode {
    let args = Args::parse();
    proxima::huge_pages::set_advising(!args.small_pages);
    let (Some(layout), Some(motion)) = (
        Layout::from_name(&args.scene),
        Motion::from_name(&args.motion),
    ) else {
        eprintln!("--scene is uniform|clustered|stack, --motion is coherent|teleport");
        return ExitCode::FAILURE;
    };
    let mut scene = BroadScene::new(layout, args.bodies, args.moving, motion, args.seed);
    scene.scale_speed(args.speed_scale);
    let mut runners = Vec::new();
    for name in args.algos.split(',').map(str::trim) {
        match NAMES
            .into_iter()
            .find(|&a| a == name)
            .and_then(|a| Runner::new(a, &scene))
        {
            Some(r) => runners.push(r),
            None => {
                eprintln!("unknown broad phase {name:?}");
                return ExitCode::FAILURE;
            }
        }
    }
    println!(
        "scene {} ({} motion): {} bodies, {} moving per frame, {} frames",
        layout.name(),
        motion.name(),
        scene.proxies.len(),
        scene.moving_count(),
        args.frames
    );
    let mut moved = Vec::new();
    for frame in 0..args.frames {
        scene.next_frame(&mut moved);
        let n = runners.len();
        for k in 0..n {
            runners[(frame + k) % n].frame(&scene, &moved);
        }
        if args.check_every > 0 && frame % args.check_every == 0 {
            let mut reference: Option<(&str, Vec<CandidatePair>)> = None;
            for r in &runners {
                let Some(pairs) = r.phase.exact_pairs(&r.out) else {
                    continue;
                };
                match &reference {
                    None => reference = Some((r.name, pairs)),
                    Some((name, expected)) if *expected != pairs => {
                        eprintln!(
                            "frame {frame}: {} has {} pairs, {name} has {}: the pair sets differ",
                            r.name,
                            pairs.len(),
                            expected.len()
                        );
                        return ExitCode::FAILURE;
                    }
                    Some(_) => {}
                }
            }
        }
    }
    let peer_mean = runners
        .iter()
        .filter(|r| r.phase.is_peer())
        .map(Runner::mean_us)
        .fold(f64::INFINITY, f64::min);
    println!(
        "{:<16} {:>10} {:>12} {:>12} {:>12} {:>14}",
        "broad phase", "load ms", "mean µs", "p99 µs", "pairs/frame", "rapier/this"
    );
    for r in &runners {
        println!(
            "{:<16} {:>10.1} {:>12.1} {:>12.1} {:>12.0} {:>14}",
            r.name,
            r.load_ms,
            r.mean_us(),
            r.p99_us(),
            r.pairs_total as f64 / args.frames.max(1) as f64,
            if peer_mean.is_finite() {
                format!("{:.2}×", peer_mean / r.mean_us())
            } else {
                "-".into()
            }
        );
    }
    ExitCode::SUCCESS
}
