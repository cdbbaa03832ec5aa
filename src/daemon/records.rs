//! A frame's answers as wire records: what the daemon writes into a result frame (pair
//! records, then contact records, then time-of-impact records), and what in-process
//! drivers of the pipeline (benches, mirrors) need when they feed code that reads records.

use crate::pipeline::{ContactPoint, PairResult, PairToi};
use proxima_ipc::wire::{RecordKind, ResultRecord, record_flags};

/// The record of a pair's answer.
#[must_use]
pub fn pair_record(r: &PairResult) -> ResultRecord {
    ResultRecord {
        kind: RecordKind::Pair as u32,
        body_a: r.a,
        body_b: r.b,
        index: r.first_contact,
        count: r.contact_count,
        flags: approximate_flag(r.exact),
        distance: r.distance,
        error_bound: r.error_bound,
        point_a: r.point_a.to_array(),
        point_b: r.point_b.to_array(),
        normal: r.normal.to_array(),
        time: 0.0,
    }
}

/// [`record_flags::APPROXIMATE`] when a record is not `exact`.
fn approximate_flag(exact: bool) -> u32 {
    if exact { 0 } else { record_flags::APPROXIMATE }
}

/// The record of contact `c`, naming its pair's bodies (from `pairs`).
#[must_use]
pub fn contact_record(pairs: &[PairResult], c: &ContactPoint) -> ResultRecord {
    let pair = &pairs[c.pair as usize];
    ResultRecord {
        kind: RecordKind::Contact as u32,
        body_a: pair.a,
        body_b: pair.b,
        index: c.pair,
        count: 0,
        flags: approximate_flag(pair.exact),
        distance: c.distance,
        error_bound: c.error_bound,
        point_a: c.point_a.to_array(),
        point_b: c.point_b.to_array(),
        normal: c.normal.to_array(),
        time: 0.0,
    }
}

/// The record of a pair's time of impact (`count` 1 when the search reached contact;
/// approximate when the deadline came before its search).
#[must_use]
pub fn toi_record(r: &PairToi) -> ResultRecord {
    ResultRecord {
        kind: RecordKind::Toi as u32,
        body_a: r.a,
        body_b: r.b,
        index: 0,
        count: u32::from(r.reached),
        flags: approximate_flag(r.exact),
        distance: r.distance,
        error_bound: r.error_bound,
        point_a: r.point_a.to_array(),
        point_b: r.point_b.to_array(),
        normal: r.normal.to_array(),
        time: r.time,
    }
}
