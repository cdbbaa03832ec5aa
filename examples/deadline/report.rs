//! What the bench records per frame ([`FrameRecord`]) and per (scene, budget) row
//! ([`Row`]), the table it prints and the CSV it writes.

use proxima_ipc::tools::latency::{LatencyRecorder, LatencySummary};
use proxima_ipc::wire::{Completeness, ResultFrameHeader, stage};
use std::fmt::Write as _;
use std::time::Duration;

/// One frame as the client saw it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameRecord {
    /// Its `frame_seq`.
    pub frame: u64,
    /// The answer, `None` when none arrived within the frame timeout (lost).
    pub answer: Option<Answer>,
    /// Missed collisions against the oracle; `None` when the frame was not checked.
    pub missed: Option<u32>,
}

/// The figures of an answered frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Answer {
    /// Receipt to publish, measured in the daemon (the header's `elapsed_ns`).
    pub elapsed_ns: u64,
    /// Publish to results received, measured here.
    pub round_trip_ns: u64,
    /// Whether the header says `Exact` (else `Truncated`).
    pub exact: bool,
    /// The header's per-stage times, indexed by [`stage`].
    pub stage_ns: [u64; stage::COUNT],
    /// Pair records.
    pub pairs: u32,
    /// Contact records.
    pub contacts: u32,
    /// The header's `flags`: a frame with `PAIRS_CAPPED` or `BUDGET_TOO_SMALL` declares
    /// itself partial (its pairs a sample, or none), and is not checked by the oracle.
    pub flags: u32,
}

impl Answer {
    /// The figures of a frame with `header`, received `round_trip` after it was sent.
    #[must_use]
    pub fn new(header: &ResultFrameHeader, round_trip: Duration) -> Self {
        Self {
            elapsed_ns: header.elapsed_ns,
            round_trip_ns: u64::try_from(round_trip.as_nanos()).unwrap_or(u64::MAX),
            exact: header.completeness == Completeness::Exact as u32,
            stage_ns: header.stage_ns,
            pairs: header.pair_count,
            contacts: header.contact_count,
            flags: header.flags,
        }
    }
}

/// The frames of one scene at one budget, with or without the hostile client.
#[derive(Debug, Clone)]
pub struct Row {
    /// Scene class name.
    pub scene: &'static str,
    /// The frames' budget, µs.
    pub budget_us: u64,
    /// Whether the hostile registration client ran meanwhile.
    pub hostile: bool,
    /// Every frame, in order.
    pub frames: Vec<FrameRecord>,
    /// The scene's state after the last frame, if it has one to tell.
    pub end_state: Option<String>,
}

/// The row's figures, as printed.
#[derive(Debug, Clone, Copy)]
pub struct RowFigures {
    /// Frames sent.
    pub sent: usize,
    /// Frames never answered.
    pub lost: usize,
    /// Share of sent frames answered within the budget in the daemon, %.
    pub met_percent: f64,
    /// Overrun of the late answered frames (elapsed − budget); `None` when none was late.
    pub overrun: Option<LatencySummary>,
    /// Shares of answered frames that were exact and truncated, %.
    pub exact_percent: f64,
    /// See `exact_percent`.
    pub truncated_percent: f64,
    /// Round trips of the answered frames.
    pub round_trip: Option<LatencySummary>,
    /// Missed collisions over the checked frames, and how many frames were checked.
    pub missed: u64,
    /// See `missed`.
    pub checked: usize,
    /// Answered frames whose header declared them partial (`flags` not 0).
    pub partial: usize,
}

impl Row {
    /// The row's figures.
    #[must_use]
    pub fn figures(&self) -> RowFigures {
        let budget_ns = self.budget_us * 1000;
        let answers: Vec<&Answer> = self
            .frames
            .iter()
            .filter_map(|f| f.answer.as_ref())
            .collect();
        let (mut overruns, mut round_trips) = (
            LatencyRecorder::with_capacity(answers.len()),
            LatencyRecorder::with_capacity(answers.len()),
        );
        for a in &answers {
            if a.elapsed_ns > budget_ns {
                overruns.record_ns(a.elapsed_ns - budget_ns);
            }
            round_trips.record_ns(a.round_trip_ns);
        }
        let share = |n: usize, of: usize| 100.0 * n as f64 / of.max(1) as f64;
        let exact = answers.iter().filter(|a| a.exact).count();
        let met = answers.len() - overruns.len();
        RowFigures {
            sent: self.frames.len(),
            lost: self.frames.len() - answers.len(),
            met_percent: share(met, self.frames.len()),
            overrun: overruns.summary(),
            exact_percent: share(exact, answers.len()),
            truncated_percent: share(answers.len() - exact, answers.len()),
            round_trip: round_trips.summary(),
            missed: self
                .frames
                .iter()
                .filter_map(|f| f.missed)
                .map(u64::from)
                .sum(),
            checked: self.frames.iter().filter(|f| f.missed.is_some()).count(),
            partial: answers.iter().filter(|a| a.flags != 0).count(),
        }
    }

    /// Every answered frame's overrun past the budget, µs (0 for frames on time).
    #[must_use]
    pub fn overruns_us(&self) -> Vec<f64> {
        let budget_ns = self.budget_us * 1000;
        self.frames
            .iter()
            .filter_map(|f| f.answer.as_ref())
            .map(|a| a.elapsed_ns.saturating_sub(budget_ns) as f64 / 1e3)
            .collect()
    }

    /// The row's label in plots: `scene` and, with the hostile client, `+ hostile`.
    #[must_use]
    pub fn scene_label(&self) -> String {
        if self.hostile {
            format!("{} + hostile", self.scene)
        } else {
            self.scene.to_string()
        }
    }
}

/// The table's column heads.
#[must_use]
pub fn table_head() -> String {
    format!(
        "{:<19} {:>7} {:>8} {:>6} {:>6} {:>8} {:>9} {:>9} {:>10} {:>7} {:>7} {:>9} {:>9} {:>7} {:>9} {:>7}",
        "scene",
        "budget",
        "hostile",
        "frames",
        "lost",
        "met %",
        "over p50",
        "over p99",
        "over max",
        "exact%",
        "trunc%",
        "rt p50",
        "rt p99",
        "missed",
        "checked",
        "partial"
    )
}

/// One row of the table: times in µs, overruns over the late frames only (0 when none).
#[must_use]
pub fn table_line(row: &Row) -> String {
    let f = row.figures();
    let us = |ns: u64| ns as f64 / 1e3;
    let overrun =
        |pick: fn(&LatencySummary) -> u64| f.overrun.as_ref().map_or(0.0, |s| us(pick(s)));
    let round_trip =
        |pick: fn(&LatencySummary) -> u64| f.round_trip.as_ref().map_or(0.0, |s| us(pick(s)));
    format!(
        "{:<19} {:>5}µs {:>8} {:>6} {:>6} {:>8.1} {:>9.1} {:>9.1} {:>10.1} {:>7.1} {:>7.1} {:>9.1} {:>9.1} {:>7} {:>9} {:>7}",
        row.scene,
        row.budget_us,
        if row.hostile { "yes" } else { "no" },
        f.sent,
        f.lost,
        f.met_percent,
        overrun(|s| s.p50_ns),
        overrun(|s| s.p99_ns),
        overrun(|s| s.max_ns),
        f.exact_percent,
        f.truncated_percent,
        round_trip(|s| s.p50_ns),
        round_trip(|s| s.p99_ns),
        f.missed,
        format!("{}/{}", f.checked, f.sent),
        f.partial
    ) + &row
        .end_state
        .as_ref()
        .map_or_else(String::new, |s| format!("  {s}"))
}

/// `deadlines.csv`: one line per frame of every row. A lost frame has empty figures; an
/// unchecked frame an empty `missed`.
#[must_use]
pub fn csv(rows: &[Row]) -> String {
    let stages = ["ingest", "plan", "broad", "mid", "narrow", "publish"];
    debug_assert_eq!(stages.len(), stage::COUNT);
    let mut out =
        String::from("scene,budget_us,hostile,frame,elapsed_ns,round_trip_ns,completeness,");
    for name in stages {
        let _ = write!(out, "stage_{name}_ns,");
    }
    out.push_str("pairs,contacts,missed\n");
    for row in rows {
        for f in &row.frames {
            let _ = write!(
                out,
                "{},{},{},{},",
                row.scene, row.budget_us, row.hostile, f.frame
            );
            match &f.answer {
                Some(a) => {
                    let completeness = if a.exact { "exact" } else { "truncated" };
                    let _ = write!(out, "{},{},{completeness},", a.elapsed_ns, a.round_trip_ns);
                    for ns in a.stage_ns {
                        let _ = write!(out, "{ns},");
                    }
                    let _ = write!(out, "{},{},", a.pairs, a.contacts);
                }
                None => out.push_str(&",".repeat(5 + stage::COUNT)),
            }
            if let Some(missed) = f.missed {
                let _ = write!(out, "{missed}");
            }
            out.push('\n');
        }
    }
    out
}
