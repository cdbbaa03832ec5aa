//! What the demo prints: one line per sampled frame, and a summary of the run.

use proxima_ipc::tools::latency::LatencyRecorder;
use proxima_ipc::wire::{Completeness, ErrorCode, ResultFrameHeader, stage};
use std::fmt;
use std::time::Duration;

/// One frame as the demo reports it.
#[derive(Debug, Clone, Copy)]
pub struct FrameLine {
    seq: u64,
    status: u32,
    pairs: u32,
    contacts: u32,
    bounced: usize,
    exact: bool,
    budget_met: bool,
    round_trip: Duration,
    in_daemon_ns: u64,
    stage_ns: [u64; stage::COUNT],
}

impl FrameLine {
    /// The line of frame `seq` from its result header, the measured round trip (publish →
    /// result received) and how many sphere pairs bounced.
    #[must_use]
    pub fn new(seq: u64, header: &ResultFrameHeader, round_trip: Duration, bounced: usize) -> Self {
        Self {
            seq,
            status: header.status,
            pairs: header.pair_count,
            contacts: header.contact_count,
            bounced,
            exact: header.completeness == Completeness::Exact as u32,
            budget_met: header.budget_met != 0,
            round_trip,
            in_daemon_ns: header.elapsed_ns,
            stage_ns: header.stage_ns,
        }
    }
}

impl FrameLine {
    /// Whether the daemon published the frame after its budget.
    #[must_use]
    pub fn budget_missed(&self) -> bool {
        self.status == ErrorCode::Ok as u32 && !self.budget_met
    }
}

impl fmt::Display for FrameLine {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.status != ErrorCode::Ok as u32 {
            let code = ErrorCode::from_u32(self.status);
            return write!(f, "frame {:6}  refused: {code:?}", self.seq);
        }
        write!(
            f,
            "frame {:6}  pairs {:4}  contacts {:4}  bounced {:3}  round trip {:7.1} µs  \
             in daemon {:7.1} µs  {}  {}",
            self.seq,
            self.pairs,
            self.contacts,
            self.bounced,
            self.round_trip.as_secs_f64() * 1e6,
            self.in_daemon_ns as f64 / 1e3,
            if self.budget_met {
                "budget met"
            } else {
                "BUDGET MISSED"
            },
            if self.exact { "exact" } else { "truncated" },
        )?;
        if !self.budget_met {
            // Where the time went, so a late frame can be told from an OS descheduling.
            let us = |i: usize| self.stage_ns[i] as f64 / 1e3;
            write!(
                f,
                "  (µs: ingest {:.1}, plan {:.1}, broad {:.1}, mid {:.1}, narrow {:.1}, \
                 publish {:.1})",
                us(stage::INGEST),
                us(stage::PLAN),
                us(stage::BROAD),
                us(stage::MID),
                us(stage::NARROW),
                us(stage::PUBLISH),
            )?;
        }
        Ok(())
    }
}

/// Totals and latency distributions of a run.
#[derive(Debug)]
pub struct Summary {
    frames: u64,
    refused: u64,
    lost: u64,
    truncated: u64,
    budget_missed: u64,
    round_trip_over_budget: u64,
    pairs: u64,
    contacts: u64,
    bounced: u64,
    round_trips: LatencyRecorder,
    in_daemon: LatencyRecorder,
    budget_ns: u64,
}

impl Summary {
    /// An empty summary with room for `frames` latency samples.
    #[must_use]
    pub fn new(frames: usize, budget_ns: u64) -> Self {
        Self {
            frames: 0,
            refused: 0,
            lost: 0,
            truncated: 0,
            budget_missed: 0,
            round_trip_over_budget: 0,
            pairs: 0,
            contacts: 0,
            bounced: 0,
            round_trips: LatencyRecorder::with_capacity(frames),
            in_daemon: LatencyRecorder::with_capacity(frames),
            budget_ns,
        }
    }

    /// Counts a frame whose answer never arrived.
    pub fn lost(&mut self) {
        self.lost += 1;
    }

    /// Adds a frame.
    pub fn add(&mut self, line: &FrameLine) {
        self.frames += 1;
        if line.status != ErrorCode::Ok as u32 {
            self.refused += 1;
            return;
        }
        self.truncated += u64::from(!line.exact);
        self.budget_missed += u64::from(!line.budget_met);
        self.round_trip_over_budget +=
            u64::from(line.round_trip.as_nanos() > u128::from(self.budget_ns));
        self.pairs += u64::from(line.pairs);
        self.contacts += u64::from(line.contacts);
        self.bounced += line.bounced as u64;
        self.round_trips.record(line.round_trip);
        self.in_daemon.record_ns(line.in_daemon_ns);
    }

    /// Prints the summary of a run that took `wall`.
    pub fn print(&self, wall: Duration) {
        let answered = self.frames - self.refused;
        let per_frame = |n: u64| n as f64 / answered.max(1) as f64;
        println!("--- summary ---");
        println!(
            "{} frames in {:.2} s: {answered} answered ({} exact, {} truncated), {} refused, \
             {} lost",
            self.frames + self.lost,
            wall.as_secs_f64(),
            answered - self.truncated,
            self.truncated,
            self.refused,
            self.lost
        );
        println!(
            "per frame: {:.1} close pairs, {:.1} contacts, {:.1} bounces",
            per_frame(self.pairs),
            per_frame(self.contacts),
            per_frame(self.bounced)
        );
        if let Some(s) = self.round_trips.summary() {
            println!("round trip (publish → results): {s}");
        }
        if let Some(s) = self.in_daemon.summary() {
            println!("in daemon (receipt → publish):  {s}");
        }
        println!(
            "deadline ({} µs): met by the daemon in {} of {answered} frames; round trip within \
             it in {} of {answered}",
            self.budget_ns / 1000,
            answered - self.budget_missed,
            answered - self.round_trip_over_budget
        );
    }
}
