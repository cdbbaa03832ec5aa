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
//! `--one-at-a-time` runs each broad phase through all the frames before the next starts,
//! on the same frames (the workload regenerated from the seed), so no other broad phase's
//! work evicts its tables between its frames: at 100,000 bodies the peer's 11–13 ms frame
//! reads far more memory than a whole cache, and in lockstep every phase starts its frames
//! cold. The pair sets are then compared by a fingerprint per checked frame.
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
use proxima::broad::{BroadPhaseKind, BroadPhaseStats, CandidatePair, MoveCounts, choose};
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
    /// Each broad phase through all the frames in turn (same frames), instead of all of
    /// them in lockstep, frame by frame.
    #[arg(long)]
    one_at_a_time: bool,
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
    let new_scene = || {
        let mut scene = BroadScene::new(layout, args.bodies, args.moving, motion, args.seed);
        scene.scale_speed(args.speed_scale);
        scene
    };
    let mut names = Vec::new();
    for name in args.algos.split(',').map(str::trim) {
        match NAMES.into_iter().find(|&a| a == name) {
            Some(a) => names.push(a),
            None => {
                eprintln!("unknown broad phase {name:?}");
                return ExitCode::FAILURE;
            }
        }
    }
    let scene = new_scene();
    println!(
        "scene {} ({} motion): {} bodies, {} moving per frame, {} frames{}",
        layout.name(),
        motion.name(),
        scene.proxies.len(),
        scene.moving_count(),
        args.frames,
        if args.one_at_a_time {
            ", one broad phase at a time"
        } else {
            ""
        }
    );
    let (stats, chosen) = automatic_choice(new_scene(), args.frames);
    println!(
        "moving {:.2}, mean relative shift {:.4}, shift for the typical box {:.4}, far moves \
         {:.2} %, size spread {:.1}, sweep overlaps {:.1} per body: the automatic choice is \
         {chosen:?}",
        stats.moving_fraction,
        stats.mean_shift,
        stats.typical_shift,
        100.0 * stats.far_move_fraction,
        stats.size_spread,
        stats.sweep_overlap_ratio
    );
    let outcome = if args.one_at_a_time {
        one_at_a_time(&names, new_scene, &args)
    } else {
        lockstep(&names, scene, &args)
    };
    let runners = match outcome {
        Ok(runners) => runners,
        Err(message) => {
            eprintln!("{message}");
            return ExitCode::FAILURE;
        }
    };
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

/// The statistics the automatic choice reads (`proxima::broad::choose`), measured as the
/// pipeline does (the last frame's boxes, the motion counted over all `frames`), and what
/// it picks.
fn automatic_choice(mut scene: BroadScene, frames: usize) -> (BroadPhaseStats, BroadPhaseKind) {
    let (mut counts, mut moved) = (MoveCounts::default(), Vec::new());
    let mut last_moved = 0;
    let mut before: Vec<Aabb> = Vec::new();
    for _ in 0..frames {
        before.clear();
        before.extend(scene.proxies.iter().map(|p| p.bounds));
        scene.next_frame(&mut moved);
        for &(body, bounds) in &moved {
            counts.add(&before[body as usize], &bounds);
        }
        last_moved = moved.len();
    }
    let stats = BroadPhaseStats::measure(&scene.proxies, last_moved).with_moves(&counts);
    (stats, choose(&stats))
}

/// The runner of `name`, one of [`NAMES`] (checked in `main`), loaded with `scene`.
fn runner(name: &'static str, scene: &BroadScene) -> Runner {
    Runner::new(name, scene).expect("names are checked against NAMES")
}

/// Every broad phase on each frame in turn, the order rotating; the pair sets compared
/// every `--check-every` frames.
fn lockstep(
    names: &[&'static str],
    mut scene: BroadScene,
    args: &Args,
) -> Result<Vec<Runner>, String> {
    let mut runners: Vec<Runner> = names.iter().map(|&name| runner(name, &scene)).collect();
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
                        return Err(format!(
                            "frame {frame}: {} has {} pairs, {name} has {}: the pair sets differ",
                            r.name,
                            pairs.len(),
                            expected.len()
                        ));
                    }
                    Some(_) => {}
                }
            }
        }
    }
    Ok(runners)
}

/// Each broad phase through all the frames before the next one is loaded, on the same
/// frames (`new_scene` regenerates the workload); the pair sets compared by a fingerprint
/// of every `--check-every`th frame's sorted pairs.
fn one_at_a_time(
    names: &[&'static str],
    new_scene: impl Fn() -> BroadScene,
    args: &Args,
) -> Result<Vec<Runner>, String> {
    let mut done = Vec::new();
    let mut reference: Option<(&str, Vec<u64>)> = None;
    let mut moved = Vec::new();
    for &name in names {
        let mut scene = new_scene();
        let mut runner = runner(name, &scene);
        let mut fingerprints = Vec::new();
        for frame in 0..args.frames {
            scene.next_frame(&mut moved);
            runner.frame(&scene, &moved);
            if args.check_every > 0
                && frame % args.check_every == 0
                && let Some(pairs) = runner.phase.exact_pairs(&runner.out)
            {
                fingerprints.push(fingerprint(&pairs));
            }
        }
        if !fingerprints.is_empty() {
            match &reference {
                None => reference = Some((name, fingerprints)),
                Some((first, expected)) => {
                    let differ = expected.iter().zip(&fingerprints).position(|(e, f)| e != f);
                    if let Some(k) = differ {
                        return Err(format!(
                            "checked frame {}: {name} and {first} report different pair sets",
                            k * args.check_every
                        ));
                    }
                }
            }
        }
        done.push(runner);
    }
    Ok(done)
}

/// A hash of a sorted pair list (FNV-1a over the ids).
fn fingerprint(pairs: &[CandidatePair]) -> u64 {
    pairs
        .iter()
        .flat_map(|p| [p.a, p.b])
        .fold(0xcbf2_9ce4_8422_2325, |h, id| {
            (h ^ u64::from(id)).wrapping_mul(0x0100_0000_01b3)
        })
}
