//! Watches a scene's result frames and prints per-frame statistics, without driving the
//! scene: a second subscriber on the scene's result service.
//!
//! ```text
//! cargo run --release                                          # terminal 1: the daemon
//! cargo run --release --example falling_bodies                 # terminal 2: prints its scene's token
//! cargo run --release --example monitor -- --token TOKEN       # terminal 3: one line per second
//! cargo run --release --example monitor -- --token TOKEN --each-frame
//! ```
//!
//! The token (32 hex digits) is the capability to read a scene's results: only its owner
//! has it, and hands it to the monitors it trusts (DESIGN §10). The monitor stops when the
//! daemon releases the scene (its owner dropped it or is gone), saying which.
//!
//! Each line aggregates the frames seen since the last: frames per second, frames missed
//! (gaps in `frame_seq`: the monitor fell behind, or frames the daemon never answered),
//! refused and truncated frames, budget misses, mean pairs and contacts, the daemon's own
//! time from receipt to publication (p50 / max) and its mean split by stage.

use clap::Parser;
use iceoryx2::prelude::{LogLevel, ipc, set_log_level_from_env_or};
use proxima_ipc::client::ClientBuilder;
use proxima_ipc::error::FrameReceiveError;
use proxima_ipc::result_feed::ResultFeed;
use proxima_ipc::tools::latency::LatencyRecorder;
use proxima_ipc::wire::{Completeness, ErrorCode, ResultFrameHeader, stage};
use std::error::Error;
use std::time::{Duration, Instant};

#[derive(Debug, Parser)]
#[command(about = "Print statistics of a scene's result frames")]
struct Args {
    /// The token of the scene to watch (32 hex digits, from its owner).
    #[arg(long)]
    token: proxima_ipc::SceneToken,
    /// Service root of the daemon.
    #[arg(long, default_value = proxima_ipc::DEFAULT_ROOT)]
    root: String,
    /// iceoryx2 prefix of the daemon.
    #[arg(long)]
    iceoryx_prefix: Option<String>,
    /// Print every frame instead of one line per second.
    #[arg(long)]
    each_frame: bool,
    /// Stop after this many seconds (default: until Ctrl-C).
    #[arg(long)]
    seconds: Option<f64>,
}

fn main() -> Result<(), Box<dyn Error>> {
    let args = Args::parse();
    set_log_level_from_env_or(LogLevel::Error);
    let mut builder = ClientBuilder::new()
        .root(&args.root)
        .reply_timeout(Duration::from_secs(5));
    if let Some(prefix) = &args.iceoryx_prefix {
        builder = builder.iceoryx_prefix(prefix);
    }
    // A client connection checks the protocol version; the feed needs only its node.
    let client = builder.connect::<ipc::Service>()?;
    let feed = ResultFeed::open(client.node(), &args.root, args.token)?;
    println!(
        "monitor: watching a scene under {:?} (Ctrl-C to stop)",
        args.root
    );
    let stop_at = args
        .seconds
        .map(|s| Instant::now() + Duration::from_secs_f64(s));
    let mut window = Window::default();
    let mut last_seq: Option<u64> = None;
    let mut last_print = Instant::now();
    while stop_at.is_none_or(|t| Instant::now() < t) {
        let received = match feed.receive(Duration::from_millis(100)) {
            Err(released @ FrameReceiveError::SceneReleased { .. }) => {
                println!("monitor: {released}");
                break;
            }
            received => received?,
        };
        if let Some(frame) = received {
            let header = *frame.header();
            drop(frame);
            if let Some(last) = last_seq {
                window.missed += header.frame_seq.saturating_sub(last + 1);
            }
            last_seq = Some(header.frame_seq);
            if args.each_frame {
                println!("{}", frame_line(&header));
            }
            window.add(&header);
        }
        if !args.each_frame && last_print.elapsed() >= Duration::from_secs(1) {
            window.print(last_print.elapsed());
            window = Window::default();
            last_print = Instant::now();
        }
    }
    Ok(())
}

fn frame_line(h: &ResultFrameHeader) -> String {
    let us = |ns: u64| ns as f64 / 1e3;
    format!(
        "frame {:8}  {:16}  pairs {:5}  contacts {:5}  candidates {:6}  in daemon {:8.1} µs  \
         (ingest {:.1}, broad {:.1}, narrow {:.1}, publish {:.1})  {}{}",
        h.frame_seq,
        status_name(h.status),
        h.pair_count,
        h.contact_count,
        h.candidate_count,
        us(h.elapsed_ns),
        us(h.stage_ns[stage::INGEST]),
        us(h.stage_ns[stage::BROAD]),
        us(h.stage_ns[stage::NARROW]),
        us(h.stage_ns[stage::PUBLISH]),
        if h.completeness == Completeness::Exact as u32 {
            "exact"
        } else {
            "truncated"
        },
        if h.budget_met == 0 {
            "  BUDGET MISSED"
        } else {
            ""
        },
    )
}

fn status_name(status: u32) -> String {
    match ErrorCode::from_u32(status) {
        Some(code) => format!("{code:?}"),
        None => format!("status {status}"),
    }
}

/// Frames seen in one printing window.
#[derive(Default)]
struct Window {
    frames: u64,
    missed: u64,
    refused: u64,
    truncated: u64,
    over_budget: u64,
    pairs: u64,
    contacts: u64,
    stage_ns: [u64; stage::COUNT],
    in_daemon: LatencyRecorder,
}

impl Window {
    fn add(&mut self, h: &ResultFrameHeader) {
        self.frames += 1;
        if h.status != ErrorCode::Ok as u32 {
            self.refused += 1;
            return;
        }
        self.truncated += u64::from(h.completeness != Completeness::Exact as u32);
        self.over_budget += u64::from(h.budget_met == 0);
        self.pairs += u64::from(h.pair_count);
        self.contacts += u64::from(h.contact_count);
        for (sum, ns) in self.stage_ns.iter_mut().zip(h.stage_ns) {
            *sum += ns;
        }
        self.in_daemon.record_ns(h.elapsed_ns);
    }

    fn print(&self, span: Duration) {
        let answered = (self.frames - self.refused).max(1);
        let mean = |n: u64| n as f64 / answered as f64;
        let stage_us = |s: usize| self.stage_ns[s] as f64 / answered as f64 / 1e3;
        let (p50, max) = self.in_daemon.summary().map_or((0.0, 0.0), |s| {
            (s.p50_ns as f64 / 1e3, s.max_ns as f64 / 1e3)
        });
        println!(
            "{:6.0} frames/s  missed {:3}  refused {:3}  truncated {:4}  over budget {:3}  \
             pairs {:7.1}  contacts {:7.1}  in daemon p50 {:7.1} max {:7.1} µs  \
             (mean ingest {:.1}, broad {:.1}, narrow {:.1}, publish {:.1} µs)",
            self.frames as f64 / span.as_secs_f64(),
            self.missed,
            self.refused,
            self.truncated,
            self.over_budget,
            mean(self.pairs),
            mean(self.contacts),
            p50,
            max,
            stage_us(stage::INGEST),
            stage_us(stage::BROAD),
            stage_us(stage::NARROW),
            stage_us(stage::PUBLISH),
        );
    }
}
