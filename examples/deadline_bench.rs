//! The daemon's deadline scorecard: every scene class driven through a private `proximad`
//! over the real protocol, budget by budget, each frame checked against the library's
//! exact answer.
//!
//! ```text
//! cargo build --release && cargo run --release --example deadline_bench
//! cargo run --release --example deadline_bench -- --scene pile --scene demo --budgets-us 200,1000 --frames 100
//! cargo run --release --example deadline_bench -- --scene falling --hostile-registration --out target/db
//! cargo run --release --example deadline_bench -- --scene falling --realtime-priority 10
//! ```
//!
//! For each scene class (`--scene`, repeatable; all by default: `demo`, `falling`, `pile`,
//! `pile-primitives`, `compound-pile`, `robot-chain`, `coincident-meshes`, `sphere-swarm`)
//! and budget (`--budgets-us`), a row builds the scene afresh in the daemon and in an
//! in-process mirror, sends one frame without a budget (the daemon's exact answer must
//! equal the mirror's), then `--frames` frames back to back (heavy scenes default to fewer;
//! the output says so), each moving the bodies as the scene's client does (simulations
//! bounce theirs with the returned contacts), publishing every moving body's pose and
//! waiting for the answer; the oracle runs between frames, outside the timed round trip.
//! Rows print as they finish:
//! - `met %`: frames the daemon answered within the budget (header `elapsed_ns`, receipt
//!   to publish, ≤ budget), of the frames sent (a lost frame, unanswered within
//!   `--frame-timeout-ms`, counts as missed);
//! - `over p50/p99/max`: how far the late frames overran the budget, µs (0: none late);
//! - `exact%` / `trunc%`: completeness of the answered frames;
//! - `rt p50/p99`: round trip measured here, publish to results received, µs;
//! - `missed`: collisions the frame missed against the exact answer (see `oracle.rs`; must
//!   be 0), over the `checked` frames (`sphere-swarm` checks every 5th);
//! - `partial`: answered frames whose header declared them partial (`PAIRS_CAPPED`: the
//!   pairs are a sample; `BUDGET_TOO_SMALL`: not started), left out of the check.
//!
//! `--hostile-registration` runs every row a second time with a hostile client registering
//! huge shapes meanwhile (`hostile.rs`): its frames start as the client sends its first
//! registration and stop after `--frames` or `--hostile-seconds`; the row then waits for
//! the registration in flight, so the next row starts on an idle daemon. A daemon whose
//! control work stalls the frame path shows it as lost frames and long round trips (the
//! header's `elapsed_ns` starts when the daemon takes the frame, so it cannot see the wait).
//!
//! Writes `DIR/deadlines.csv` (one line per frame) and `DIR/overrun.svg` (the overruns of
//! each scene and budget), `DIR` from `--out`. `robot-chain` needs FCL's meshes and
//! `compound-pile` Keenan Crane's spot from the data folder (`PROXIMA_DATA`, default
//! `../shared/data`); without them they are skipped.
//! The daemon defaults to `target/release/proximad` next to this example (`--daemon`).

#[path = "scenes/coincident_meshes.rs"]
mod coincident_meshes;
#[path = "scenes/compound_pile.rs"]
mod compound_pile;
#[path = "../src/demo/scene.rs"]
mod demo_scene;
#[path = "scenes/falling.rs"]
mod falling;
#[path = "deadline/hostile.rs"]
mod hostile;
#[path = "deadline/oracle.rs"]
mod oracle;
#[path = "scenes/pile.rs"]
mod pile;
#[path = "deadline/plot.rs"]
mod plot;
#[path = "scenes/point_mass.rs"]
mod point_mass;
#[path = "deadline/report.rs"]
mod report;
#[path = "scenes/robot_chain.rs"]
mod robot_chain;
#[path = "scenes/spec.rs"]
mod spec;
#[path = "scenes/sphere_swarm.rs"]
mod sphere_swarm;
// The data folder's rule and the sphere lattice (the rest is the tests').
#[path = "../tests/support/mod.rs"]
mod support;
#[path = "deadline/workloads.rs"]
mod workloads;

use clap::Parser;
use hostile::{Hostile, HostileReport};
use iceoryx2::prelude::{LogLevel, ipc, set_log_level_from_env_or};
use oracle::{Oracle, possibly_touching};
use proxima_ipc::client::{Client, ClientBuilder};
use proxima_ipc::scene_link::SceneLink;
use proxima_ipc::tools::daemon_process::{ChildProcess, Isolation, sibling_daemon};
use proxima_ipc::tools::latency::LatencySummary;
use proxima_ipc::wire::ErrorCode;
use report::{Answer, FrameRecord, Row};
use std::error::Error;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};
use workloads::{Built, CLASSES, Class, Workload};

#[derive(Debug, Parser)]
#[command(about = "Deadline scorecard of proximad: every scene class, budget by budget")]
struct Args {
    /// Scene class to run (repeatable): demo, falling, pile, pile-primitives, compound-pile,
    /// robot-chain, coincident-meshes, sphere-swarm; all when none is given.
    #[arg(long)]
    scene: Vec<String>,
    /// Frame budgets, microseconds, comma-separated.
    #[arg(long, default_value = "100,200,300,500,1000,2000")]
    budgets_us: String,
    /// Frames per scene and budget (default: each scene's own, 500 for most).
    #[arg(long)]
    frames: Option<usize>,
    /// Output directory for deadlines.csv and overrun.svg.
    #[arg(long, default_value = "target/deadline_bench")]
    out: PathBuf,
    /// Run every row again with a second client registering huge shapes meanwhile.
    #[arg(long)]
    hostile_registration: bool,
    /// Longest a row with the hostile client sends frames, seconds (its frames may stall);
    /// the row then waits for the registration in flight, so the next starts on an idle
    /// daemon.
    #[arg(long, default_value_t = 30.0)]
    hostile_seconds: f64,
    /// How long a frame's answer is waited for before the frame counts as lost, ms.
    #[arg(long, default_value_t = 10_000)]
    frame_timeout_ms: u64,
    /// The `proximad` executable (default: `proximad` next to this example's directory).
    #[arg(long)]
    daemon: Option<PathBuf>,
    /// Start the daemon with `--realtime-priority N`: its frame thread under SCHED_FIFO.
    #[arg(long, value_parser = proxima::daemon::realtime::parse_priority)]
    realtime_priority: Option<u8>,
}

/// How long the unbudgeted first frame of a row may take (the exact answer of a heavy
/// scene takes seconds).
const FIRST_FRAME_TIMEOUT: Duration = Duration::from_secs(120);

/// The private daemon and this process's connection to it.
struct Session {
    // Dropped first: the client before its daemon.
    client: Client<ipc::Service>,
    daemon: ChildProcess,
    isolation: Isolation,
}

impl Session {
    /// Starts `exe` under a root and prefix of its own, its frame thread at
    /// `realtime_priority` when given, and connects.
    fn start(exe: &Path, realtime_priority: Option<u8>) -> Result<Self, Box<dyn Error>> {
        let isolation = Isolation::unique("dlb");
        let daemon =
            ChildProcess::spawn_quiet_daemon_at_priority(exe, &isolation, realtime_priority)?;
        let Isolation { root, prefix } = &isolation;
        let client = ClientBuilder::new()
            .root(root)
            .iceoryx_prefix(prefix)
            .reply_timeout(Duration::from_secs(60))
            .connect::<ipc::Service>()?;
        Ok(Self {
            client,
            daemon,
            isolation,
        })
    }
}

/// One row's settings.
struct RowPlan<'a> {
    class: &'a Class,
    budget_us: u64,
    hostile: bool,
    frames: usize,
    frame_timeout: Duration,
    hostile_cap: Duration,
}

fn main() -> Result<(), Box<dyn Error>> {
    let args = Args::parse();
    set_log_level_from_env_or(LogLevel::Error);
    let classes = selected_classes(&args.scene)?;
    let budgets_us = parse_budgets(&args.budgets_us)?;
    let exe = match &args.daemon {
        Some(path) => path.clone(),
        None => sibling_daemon()?,
    };
    std::fs::create_dir_all(&args.out)?;
    let mut bench = Bench {
        session: Session::start(&exe, args.realtime_priority)?,
        exe,
        realtime_priority: args.realtime_priority,
        data: support::data::data_dir(),
        rows: Vec::new(),
    };
    for class in classes {
        bench.run_class(class, &budgets_us, &args)?;
    }
    write_outputs(&args.out, &bench.rows)?;
    let missed: u64 = bench.rows.iter().map(|r| r.figures().missed).sum();
    if missed > 0 {
        return Err(format!("{missed} missed collisions").into());
    }
    Ok(())
}

/// The run: the daemon session, where its executable and the data are, the rows so far.
struct Bench {
    session: Session,
    exe: PathBuf,
    /// The daemon's `--realtime-priority`, if any.
    realtime_priority: Option<u8>,
    data: Option<PathBuf>,
    rows: Vec<Row>,
}

impl Bench {
    /// Runs and prints `class`'s rows, budget by budget (each once more with the hostile
    /// client when asked).
    ///
    /// # Errors
    /// A dead daemon could not be replaced.
    fn run_class(
        &mut self,
        class: &Class,
        budgets_us: &[u64],
        args: &Args,
    ) -> Result<(), Box<dyn Error>> {
        if class.needs_data && self.data.is_none() {
            println!("{}: skipped (no data: set PROXIMA_DATA)", class.name);
            return Ok(());
        }
        let frames = args.frames.unwrap_or(class.default_frames);
        announce(class, frames, args.frames.is_none());
        let hostile_modes: &[bool] = if args.hostile_registration {
            &[false, true]
        } else {
            &[false]
        };
        for &budget_us in budgets_us {
            for &hostile in hostile_modes {
                let plan = RowPlan {
                    class,
                    budget_us,
                    hostile,
                    frames,
                    frame_timeout: Duration::from_millis(args.frame_timeout_ms),
                    hostile_cap: Duration::from_secs_f64(args.hostile_seconds),
                };
                self.run_plan(&plan)?;
            }
        }
        Ok(())
    }

    /// Runs one row and prints it, or why it failed; replaces a daemon that died.
    ///
    /// # Errors
    /// A dead daemon could not be replaced.
    fn run_plan(&mut self, plan: &RowPlan<'_>) -> Result<(), Box<dyn Error>> {
        match run_row(&mut self.session, plan, self.data.as_deref()) {
            Ok((row, hostile_report)) => {
                println!("{}", report::table_line(&row));
                if let Some(h) = hostile_report {
                    print_hostile(&h);
                }
                self.rows.push(row);
            }
            Err(e) => {
                println!("{} at {} µs: FAILED: {e}", plan.class.name, plan.budget_us);
                if self.session.daemon.has_exited() {
                    println!("  the daemon died; starting a new one");
                    self.session = Session::start(&self.exe, self.realtime_priority)?;
                }
            }
        }
        Ok(())
    }
}

/// Prints what a class is, how many frames each of its rows sends (`default`: by its own
/// default) and which the oracle checks, then the table's head.
fn announce(class: &Class, frames: usize, default: bool) {
    let checks = if class.check_every == 1 {
        "every frame".to_owned()
    } else {
        format!("every {}th frame", class.check_every)
    };
    let fewer = if default && frames < 500 {
        " (fewer by default: a heavy scene)"
    } else {
        ""
    };
    println!(
        "\n{}: {}; {frames} frames per budget{fewer}; the oracle checks {checks}",
        class.name, class.about
    );
    println!("{}", report::table_head());
}

/// The classes `names` selects (all when empty), in the order of [`CLASSES`].
fn selected_classes(names: &[String]) -> Result<Vec<&'static Class>, Box<dyn Error>> {
    if let Some(unknown) = names.iter().find(|n| !CLASSES.iter().any(|c| c.name == *n)) {
        let known: Vec<&str> = CLASSES.iter().map(|c| c.name).collect();
        return Err(format!("unknown scene {unknown:?}: one of {}", known.join(", ")).into());
    }
    Ok(CLASSES
        .iter()
        .filter(|c| names.is_empty() || names.iter().any(|n| n == c.name))
        .collect())
}

fn parse_budgets(list: &str) -> Result<Vec<u64>, Box<dyn Error>> {
    list.split(',')
        .map(|b| match b.trim().parse::<u64>() {
            Ok(us) if us > 0 => Ok(us),
            _ => Err(format!("budget {b:?}: a whole number of microseconds > 0").into()),
        })
        .collect()
}

/// Runs one row in a scene of its own, dropped afterwards; `data` is the data folder.
fn run_row(
    session: &mut Session,
    plan: &RowPlan<'_>,
    data: Option<&Path>,
) -> Result<(Row, Option<HostileReport>), Box<dyn Error>> {
    let scene = session.client.create_scene()?;
    let outcome = drive(session, scene, plan, data);
    // A dead daemon cannot drop it; the outcome says why.
    let _ = session.client.drop_scene(scene);
    outcome
}

/// Builds the row's scene in daemon scene `scene`, checks the mirror with one exact frame,
/// then sends the row's frames.
fn drive(
    session: &mut Session,
    scene: u32,
    plan: &RowPlan<'_>,
    data: Option<&Path>,
) -> Result<(Row, Option<HostileReport>), Box<dyn Error>> {
    let class = plan.class;
    let Built { mirror, workload } = (class.build)(&session.client, scene, data)?;
    let mut driver = Driver {
        link: session.client.open_scene(scene)?,
        oracle: Oracle::new(mirror, class.query_flags),
        workload,
        query_flags: class.query_flags,
    };
    driver.first_frame()?;
    let hostile = plan
        .hostile
        .then(|| Hostile::start(&session.isolation.root, &session.isolation.prefix))
        .transpose()?;
    let mut row = Row {
        scene: class.name,
        budget_us: plan.budget_us,
        hostile: plan.hostile,
        frames: Vec::with_capacity(plan.frames),
        end_state: None,
    };
    let started = Instant::now();
    for k in 0..plan.frames {
        if plan.hostile && started.elapsed() > plan.hostile_cap {
            break;
        }
        let seq = k as u64 + 2;
        let check = k % class.check_every == 0;
        let frame = driver.frame(seq, plan.budget_us * 1000, plan.frame_timeout, check)?;
        if frame.answer.is_none() && session.daemon.has_exited() {
            return Err(format!("the daemon exited at frame {seq}").into());
        }
        row.frames.push(frame);
    }
    row.end_state = driver.workload.state();
    let hostile = hostile.map(Hostile::stop).transpose()?;
    Ok((row, hostile))
}

/// A row's scene in motion: its link to the daemon, its workload and its oracle.
struct Driver {
    link: SceneLink<ipc::Service>,
    workload: Box<dyn Workload>,
    oracle: Oracle,
    query_flags: u32,
}

impl Driver {
    /// Frame 1, at the scene's first poses without a budget: the daemon's exact answer
    /// must be the mirror's (else the oracle would check against another scene).
    ///
    /// # Errors
    /// No answer, a refusal, or the answers differ.
    fn first_frame(&mut self) -> Result<(), Box<dyn Error>> {
        let workload = &mut self.workload;
        let count = workload.pose_count();
        self.link
            .publish_poses_with(1, 0, self.query_flags, count, |i| workload.pose(i))?;
        let first = self
            .link
            .receive_results_for(1, FIRST_FRAME_TIMEOUT)?
            .ok_or("no answer to the first (unbudgeted) frame")?;
        refused(first.header().status, 1)?;
        self.oracle
            .check_mirror(&**workload, first.pairs())
            .map_err(|e| format!("the mirror is not the daemon's scene: {e}"))?;
        workload.respond(first.pairs(), first.contacts());
        Ok(())
    }

    /// Moves the bodies, sends frame `seq` with `budget_ns` and waits up to `timeout` for
    /// its answer; with `check`, counts its missed collisions against the oracle. Then the
    /// workload takes the answer.
    ///
    /// # Errors
    /// The frame could not be sent or was refused, or the oracle failed.
    fn frame(
        &mut self,
        seq: u64,
        budget_ns: u64,
        timeout: Duration,
        check: bool,
    ) -> Result<FrameRecord, Box<dyn Error>> {
        let workload = &mut self.workload;
        workload.advance();
        let count = workload.pose_count();
        let sent = Instant::now();
        self.link
            .publish_poses_with(seq, budget_ns, self.query_flags, count, |i| {
                workload.pose(i)
            })?;
        let received = self.link.receive_results_for(seq, timeout)?;
        let round_trip = sent.elapsed();
        let Some(frame) = received else {
            return Ok(FrameRecord {
                frame: seq,
                answer: None,
                missed: None,
            });
        };
        refused(frame.header().status, seq)?;
        // A frame that declares itself partial (pairs capped, or not started for lack of
        // budget) is counted as such in the table, not judged against the whole answer.
        let missed = if check && frame.header().flags == 0 {
            let touching = possibly_touching(frame.pairs());
            Some(self.oracle.missed(&**workload, &touching)?)
        } else {
            None
        };
        workload.respond(frame.pairs(), frame.contacts());
        Ok(FrameRecord {
            frame: seq,
            answer: Some(Answer::new(frame.header(), round_trip)),
            missed,
        })
    }
}

/// An error when a frame's status is not `Ok`.
fn refused(status: u32, seq: u64) -> Result<(), Box<dyn Error>> {
    if status == ErrorCode::Ok as u32 {
        return Ok(());
    }
    Err(format!("frame {seq} refused: {:?}", ErrorCode::from_u32(status)).into())
}

fn print_hostile(h: &HostileReport) {
    let times = |summary: Option<LatencySummary>| {
        summary.map_or_else(
            || "none finished".to_owned(),
            |s| {
                let seconds = |ns: u64| ns as f64 / 1e9;
                format!(
                    "{} in {:.2}-{:.2} s",
                    s.count,
                    seconds(s.min_ns),
                    seconds(s.max_ns)
                )
            },
        )
    };
    println!(
        "{:<19} hostile client: {} rounds, {} requests failed; 32,768-point hulls registered: {}; \
         1M-triangle meshes registered: {}",
        "",
        h.rounds,
        h.failures,
        times(h.convex),
        times(h.mesh)
    );
}

fn write_outputs(out: &Path, rows: &[Row]) -> Result<(), Box<dyn Error>> {
    std::fs::write(out.join("deadlines.csv"), report::csv(rows))?;
    plot::plot_overruns(&out.join("overrun.svg"), rows)?;
    println!(
        "\nwrote {0}/deadlines.csv and {0}/overrun.svg",
        out.display()
    );
    Ok(())
}
