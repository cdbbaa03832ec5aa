//! What a scene's frames must spend whatever their budget, measured on the scene's own
//! frames: the stages that cannot be interrupted (the broad phase, and the daemon's writing
//! and publishing of the result), and the *tail* of a cut-short frame (each pair left when
//! the frame's clock stops still gets its conservative answer, and every record is then
//! published). The plan reads it before and during the work:
//! - a frame whose budget cannot hold the uninterruptible work is not started, and says so
//!   with the smallest budget measured ([`FrameCosts::mandatory_ns`]);
//! - a frame with more candidate pairs than its budget can answer even conservatively
//!   answers a sample of them ([`FrameCosts::pairs_that_fit`]);
//! - the frontier and the pair loop stop early enough for the tail
//!   ([`FrameCosts::tail_ns`]).
//!
//! Each estimate is the typical cost, a running mean moving an eighth of the way to each
//! sample, a sample counting at most twice the estimate. The tail per pair also keeps its
//! mean deviation and is reserved at the mean plus four of them: a deadline is kept by the
//! slow frames, not the typical one. A frame is refused only when the scene's usual
//! uninterruptible work cannot fit, never for one frame the OS descheduled (a frame whose
//! broad phase runs long is late instead, and its stage times say why).
//! Only broad phases that synced the kept one count (a rebuild, after a new scene or a
//! frame not started, costs more than the frames that follow). A frame not started lowers
//! the broad phase and publish estimates by a sixty-fourth, so an estimate grown stale
//! (the scene got cheaper) lets a frame run and be measured again after a few dozen
//! refusals. A scene whose body count changed by more than an eighth since the estimates
//! were taken is measured afresh.

use std::time::Instant;

/// The cost of one pair in a frame's tail until the scene's own is measured, picoseconds:
/// a conservative answer from separating axes or world boxes and its record. Warm, tens to
/// hundreds of nanoseconds on the 2-core VM (`benches/narrow_phase.rs`'s `proxima-bound`);
/// but the first tails of a scene run cold (a tail runs only when a clock stops, so its
/// code, its pairs' memory records and the result lists are not in cache, and lists grow):
/// 0.6–1.1 µs a pair on the demo's first frame, which a 250 ns prior made 35–240 µs late.
pub const DEFAULT_TAIL_PS_PER_PAIR: u64 = 1_500_000;

/// The cost of one entry left waiting on the frontier until the scene's own is measured,
/// picoseconds: its share of the answer pass and of at most one round's sort (tens of
/// nanoseconds each on the 2-core VM).
pub const DEFAULT_PENDING_ENTRY_PS: u64 = 100_000;

/// A waiting entry's cost over its share of the answer pass (the part measured): the
/// answer pass reads it once, and the sort of the round it would start compares it about
/// `log₂ n` times, about as much again.
const PENDING_ENTRY_PER_ANSWER: u64 = 2;

/// The cost of publishing one record until the scene's own is measured, picoseconds: a
/// 120-byte record written into shared memory (tens of nanoseconds), with room to spare.
pub const DEFAULT_PUBLISH_PS_PER_RECORD: u64 = 100_000;

/// The time a caller that publishes ([`FrameCosts::publishing`]) is taken to need for its
/// first result frame, beyond its records, until one is timed, nanoseconds: the daemon's
/// first results of a scene are written to shared memory not touched yet, 18–48 µs for
/// 116–280 records on the demo's first frame (2-core VM).
pub const COLD_PUBLISH_NS: u64 = 30_000;

/// The least a further record is taken to cost, picoseconds, whatever the fit says: writing
/// 120 bytes to memory another process maps.
const MIN_PUBLISH_PS_PER_RECORD: u64 = 10_000;

/// Frames a publish fit needs before its slope counts.
const MIN_FIT_FRAMES: u32 = 8;

/// Fewest entries in an answer pass for its time to be a sample of the per-entry cost.
const MIN_ANSWER_SAMPLE_ENTRIES: usize = 1024;

/// Fewest pairs in a tail for its time to be a sample of the per-pair cost (fewer are
/// dominated by the clock's reads and the cache misses of the first).
const MIN_TAIL_SAMPLE_PAIRS: usize = 16;

/// Records a conservative pair adds at most: its pair record and one contact.
const RECORDS_PER_TAIL_PAIR: u64 = 2;

/// The scene's measured costs (module docs).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FrameCosts {
    /// Broad phase, nanoseconds.
    broad_ns: u64,
    /// Writing and publishing the result frame, nanoseconds (told by the caller; 0 when it
    /// publishes nothing, as a library caller does).
    publish_ns: u64,
    /// Records (pairs, contacts, times of impact) of the frames `publish_ns` was measured
    /// on, a running mean as `publish_ns`.
    publish_records: u64,
    /// Publishing time against records over recent frames: what a further record costs.
    publish_fit: PublishFit,
    /// A tail pair's answer, picoseconds (mean 0: not measured yet).
    tail_ps_per_pair: Spread,
    /// The visit of one candidate before the pair loop (its kept answer and separation
    /// looked up, its hull test when it is a mesh pair), picoseconds (0: not measured).
    visit_ps_per_pair: u64,
    /// The frontier's answer pass, per entry it read, picoseconds (mean 0: not measured).
    answer_ps_per_entry: Spread,
    /// Body count of the scene when the estimates were taken (0: none yet).
    bodies: usize,
    /// Whether the caller publishes its results (and so tells their time): until it has,
    /// each frame reserves a cold publish ([`COLD_PUBLISH_NS`]).
    publishes: bool,
}

impl FrameCosts {
    /// Costs of a caller that publishes each frame's results (the daemon), and tells how
    /// long that took ([`note_publish`](Self::note_publish)): until it has, a frame
    /// reserves a cold publish for it, 30 µs (`COLD_PUBLISH_NS`) and 100 ns a record
    /// (`DEFAULT_PUBLISH_PS_PER_RECORD`).
    /// Without it, nothing is reserved before a publish is told (a library caller
    /// publishes nothing).
    #[must_use]
    pub fn publishing() -> Self {
        Self {
            publishes: true,
            ..Self::default()
        }
    }

    /// Records a frame's broad phase on a scene of `bodies` bodies.
    pub fn note_broad(&mut self, bodies: usize, ns: u64) {
        self.forget_if_changed(bodies);
        self.broad_ns = typical(self.broad_ns, ns);
    }

    /// Records how long the caller took to write and publish a frame's result of `records`
    /// records.
    pub fn note_publish(&mut self, ns: u64, records: u64) {
        self.publish_ns = typical(self.publish_ns, ns);
        self.publish_records = typical(self.publish_records, records);
        self.publish_fit
            .note(records, ns.min(self.publish_ns.saturating_mul(2)));
    }

    /// Records the time of a frame's tail: `pairs` pairs answered after its clock stopped.
    pub fn note_tail(&mut self, ns: u64, pairs: usize) {
        if pairs >= MIN_TAIL_SAMPLE_PAIRS {
            self.tail_ps_per_pair
                .note(ns.saturating_mul(1000) / pairs as u64);
        }
    }

    /// Records the visits of `pairs` candidates before the pair loop, `ns` in all.
    pub fn note_visits(&mut self, ns: u64, pairs: usize) {
        if pairs >= MIN_TAIL_SAMPLE_PAIRS {
            let sample = ns.saturating_mul(1000) / pairs as u64;
            self.visit_ps_per_pair = typical(self.visit_ps_per_pair, sample);
        }
    }

    /// Records the frontier's answer pass: `entries` waiting entries read, `ns` in all.
    pub fn note_answer_pass(&mut self, ns: u64, entries: usize) {
        if entries >= MIN_ANSWER_SAMPLE_ENTRIES {
            self.answer_ps_per_entry
                .note(ns.saturating_mul(1000) / entries as u64);
        }
    }

    /// What one entry left waiting on the frontier costs the frame after the frontier
    /// stops (its answer and its share of a round's sort), picoseconds: the answer pass's
    /// mean plus four deviations per entry, twice over for the sort.
    #[must_use]
    pub fn pending_entry_ps(&self) -> u64 {
        self.answer_ps_per_entry
            .measured()
            .map_or(DEFAULT_PENDING_ENTRY_PS, |s| {
                s.high().saturating_mul(PENDING_ENTRY_PER_ANSWER)
            })
    }

    /// Records a frame not started for lack of budget: the broad phase and publish
    /// estimates fade by a sixty-fourth.
    pub fn note_skipped(&mut self) {
        self.broad_ns -= self.broad_ns / 64;
        self.publish_ns -= self.publish_ns / 64;
    }

    /// The time a frame of a scene of `bodies` bodies must spend after its ingest,
    /// nanoseconds: `None` before a frame of about that size was measured.
    #[must_use]
    pub fn mandatory_ns(&self, bodies: usize) -> Option<u64> {
        (self.bodies != 0 && !changed(self.bodies, bodies))
            .then(|| self.broad_ns.saturating_add(self.publish_ns))
    }

    /// The time publishing `records` records takes, nanoseconds: the typical publish time,
    /// plus, for each record beyond the typical count, the cost of a further record: the
    /// slope of publishing time against records over recent frames (at least 10 ns), or
    /// 100 ns (`DEFAULT_PUBLISH_PS_PER_RECORD`) until frames of different sizes were
    /// published. Before any publish was told: a cold publish for a caller that
    /// [publishes](Self::publishing), else 0.
    ///
    /// Not the typical time scaled in proportion: a scene whose frames published no
    /// records (bodies still apart) would then price its first frame of a thousand
    /// contacts at a thousand times its fixed cost, and answer a sample of its pairs under
    /// any budget.
    #[must_use]
    pub fn publish_estimate_ns(&self, records: u64) -> u64 {
        if self.publish_ns == 0 {
            // Nothing published yet, or a caller that publishes nothing (a library user).
            return if self.publishes {
                COLD_PUBLISH_NS
                    .saturating_add(records.saturating_mul(DEFAULT_PUBLISH_PS_PER_RECORD) / 1000)
            } else {
                0
            };
        }
        let per_record = self
            .publish_fit
            .ps_per_record()
            .map_or(DEFAULT_PUBLISH_PS_PER_RECORD, |ps| {
                ps.max(MIN_PUBLISH_PS_PER_RECORD)
            });
        // Polled before every pair: u64 arithmetic, saturating far beyond any real frame.
        let more = records.saturating_sub(self.publish_records);
        self.publish_ns
            .saturating_add(more.saturating_mul(per_record) / 1000)
    }

    /// The time the tail of a frame takes from here, nanoseconds: `pairs_left` pairs
    /// answered conservatively, then `records` records and theirs published. Per pair, the
    /// mean cost plus four times its mean deviation (Jacobson's estimator): a deadline is kept
    /// by the slow frames, not the typical one.
    #[must_use]
    pub fn tail_ns(&self, pairs_left: usize, records: usize) -> u64 {
        let per_pair = self
            .tail_ps_per_pair
            .measured()
            .map_or(DEFAULT_TAIL_PS_PER_PAIR, Spread::high);
        self.tail_at(per_pair, pairs_left, records)
    }

    /// [`tail_ns`](Self::tail_ns) at the mean cost per pair: the typical tail, which the
    /// frontier leaves when it splits the frame with the pair loop (the loop itself keeps
    /// to [`tail_ns`](Self::tail_ns), so the deadline does not rest on this).
    #[must_use]
    pub fn typical_tail_ns(&self, pairs_left: usize, records: usize) -> u64 {
        let per_pair = self
            .tail_ps_per_pair
            .measured()
            .map_or(DEFAULT_TAIL_PS_PER_PAIR, |s| s.mean);
        self.tail_at(per_pair, pairs_left, records)
    }

    /// The tail at `per_pair` picoseconds a pair.
    fn tail_at(&self, per_pair: u64, pairs_left: usize, records: usize) -> u64 {
        let pairs = pairs_left as u64;
        let answers = pairs.saturating_mul(per_pair) / 1000;
        let records = (records as u64).saturating_add(pairs * RECORDS_PER_TAIL_PAIR);
        answers.saturating_add(self.publish_estimate_ns(records))
    }

    /// The most of `candidates` pairs whose visits and tail ([`tail_ns`](Self::tail_ns)
    /// from no records) fit in `left_ns` nanoseconds: all of them when they fit, else a
    /// sample's size (at least 0).
    #[must_use]
    pub fn pairs_that_fit(&self, candidates: usize, left_ns: u64) -> usize {
        let cost = |pairs: usize| {
            let visits = (pairs as u64).saturating_mul(self.visit_ps_per_pair) / 1000;
            visits.saturating_add(self.tail_ns(pairs, 0))
        };
        if cost(candidates) <= left_ns {
            return candidates;
        }
        // The cost grows with the pairs: the largest count that fits, by bisection.
        let (mut fits, mut too_many) = (0, candidates);
        while too_many - fits > 1 {
            let mid = fits + (too_many - fits) / 2;
            if cost(mid) <= left_ns {
                fits = mid;
            } else {
                too_many = mid;
            }
        }
        fits
    }

    fn forget_if_changed(&mut self, bodies: usize) {
        if changed(self.bodies, bodies) {
            *self = Self {
                bodies,
                // What a pair's answer and visit cost does not depend on the scene's size.
                tail_ps_per_pair: self.tail_ps_per_pair,
                visit_ps_per_pair: self.visit_ps_per_pair,
                answer_ps_per_entry: self.answer_ps_per_entry,
                publish_fit: self.publish_fit,
                publishes: self.publishes,
                ..Self::default()
            };
        }
    }
}

/// Times a frame's tail: from the first pair its clock stopped to the end of its pairs.
#[derive(Debug, Default)]
pub(super) struct TailTimer {
    /// When the tail began, and the pairs left then (that one included).
    began: Option<(Instant, usize)>,
}

impl TailTimer {
    /// Marks a pair answered conservatively because the clock stopped, with `pairs_left`
    /// pairs left (it included); only the first mark counts.
    pub(super) fn begin(&mut self, pairs_left: usize) {
        if self.began.is_none() {
            self.began = Some((Instant::now(), pairs_left));
        }
    }

    /// Ends the frame's pairs: records the tail's time per pair in `costs`, when there was
    /// one.
    pub(super) fn end(self, costs: &mut FrameCosts) {
        if let Some((began, pairs)) = self.began {
            let ns = u64::try_from(began.elapsed().as_nanos()).unwrap_or(u64::MAX);
            costs.note_tail(ns, pairs);
        }
    }
}

/// A straight line through publishing time against records over recent frames: the
/// running means of records, time, records² and records × time, each moving an eighth of
/// the way to each frame's after the first eight (its time counted at most twice the
/// typical, as [`typical`]).
/// Its slope is what a further record costs; the fixed part of a publish (the notify, the
/// loan) does not count in it, as it would in the time over the records.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct PublishFit {
    frames: u32,
    records: f64,
    ns: f64,
    records_sq: f64,
    records_ns: f64,
}

impl PublishFit {
    fn note(&mut self, records: u64, ns: u64) {
        let (r, t) = (records as f64, ns as f64);
        self.frames = self.frames.saturating_add(1);
        // The plain mean of the first eight frames (the first taken whole), then an eighth.
        let weight = 1.0 / f64::from(self.frames.min(8));
        let step = |mean: &mut f64, x: f64| *mean += (x - *mean) * weight;
        step(&mut self.records, r);
        step(&mut self.ns, t);
        step(&mut self.records_sq, r * r);
        step(&mut self.records_ns, r * t);
    }

    /// The slope, picoseconds a record, once [`MIN_FIT_FRAMES`] frames whose record counts
    /// vary by more than a tenth were seen (a fixed count tells no slope).
    fn ps_per_record(&self) -> Option<u64> {
        let spread = self.records_sq - self.records * self.records;
        if self.frames < MIN_FIT_FRAMES || spread <= (0.1 * self.records).powi(2).max(1.0) {
            return None;
        }
        let slope_ns = (self.records_ns - self.records * self.ns) / spread;
        slope_ns
            .is_finite()
            .then(|| (slope_ns.max(0.0) * 1000.0) as u64)
    }
}

/// A running mean and mean deviation (Jacobson's estimator for round-trip times): the mean
/// moves an eighth of the way to each sample (counted at most twice the mean, as
/// [`typical`]), the deviation a quarter of the way to the sample's distance from the mean.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
struct Spread {
    mean: u64,
    deviation: u64,
}

impl Spread {
    fn note(&mut self, sample: u64) {
        if self.mean == 0 {
            *self = Self {
                mean: sample,
                deviation: sample / 2,
            };
            return;
        }
        let off = sample.min(self.mean.saturating_mul(2)).abs_diff(self.mean);
        self.deviation = if off >= self.deviation {
            self.deviation + (off - self.deviation) / 4
        } else {
            self.deviation - (self.deviation - off) / 4
        };
        self.mean = typical(self.mean, sample);
    }

    /// `self`, once a sample was taken.
    fn measured(self) -> Option<Self> {
        (self.mean != 0).then_some(self)
    }

    /// A cost few samples exceed: the mean plus four deviations.
    fn high(self) -> u64 {
        self.mean.saturating_add(self.deviation.saturating_mul(4))
    }
}

/// Whether a body count moved from `then` by more than an eighth.
fn changed(then: usize, now: usize) -> bool {
    then.abs_diff(now) > then / 8
}

/// The estimate after `sample`: an eighth of the way towards it, the sample counted at
/// most twice the estimate (one frame the OS descheduled must not refuse the frames after
/// it; a scene that really got slower is followed within a few frames).
fn typical(estimate: u64, sample: u64) -> u64 {
    if estimate == 0 {
        return sample;
    }
    let sample = sample.min(estimate.saturating_mul(2));
    if sample >= estimate {
        estimate + (sample - estimate) / 8
    } else {
        estimate - (estimate - sample) / 8
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_waiting_entry_costs_the_default_until_answer_passes_of_enough_entries_are_timed() {
        let mut costs = FrameCosts::default();
        assert_eq!(costs.pending_entry_ps(), DEFAULT_PENDING_ENTRY_PS);
        costs.note_answer_pass(1_000_000, MIN_ANSWER_SAMPLE_ENTRIES - 1);
        assert_eq!(
            costs.pending_entry_ps(),
            DEFAULT_PENDING_ENTRY_PS,
            "too few entries"
        );
        // 20 ns an entry: the reserve is twice the answer's cost (the sort's share).
        for _ in 0..200 {
            costs.note_answer_pass(20_000_000, 1_000_000);
        }
        let ps = costs.pending_entry_ps();
        assert!((40_000..=40_100).contains(&ps), "{ps}");
        // A scene of another size keeps it: what an entry costs does not depend on it.
        costs.note_broad(10, 1_000);
        costs.note_broad(1_000, 1_000);
        assert_eq!(costs.pending_entry_ps(), ps);
    }

    #[test]
    fn the_estimate_follows_the_typical_cost_and_one_slow_sample_moves_it_little() {
        let mut costs = FrameCosts::default();
        assert_eq!(costs.mandatory_ns(100), None, "nothing measured yet");
        costs.note_broad(100, 8_000);
        costs.note_publish(800, 10);
        assert_eq!(
            costs.mandatory_ns(100),
            Some(8_800),
            "the first sample is taken whole"
        );
        costs.note_broad(100, 1_000_000);
        assert_eq!(
            costs.mandatory_ns(100),
            Some(9_000 + 800),
            "one stall counts as 2×"
        );
        for _ in 0..100 {
            costs.note_broad(100, 24_000);
            costs.note_publish(800, 10);
        }
        let settled = costs.mandatory_ns(100).unwrap();
        assert!((24_700..=24_800).contains(&settled), "{settled}");
    }

    #[test]
    fn frames_not_started_let_a_stale_estimate_fade_until_one_runs() {
        let mut costs = FrameCosts::default();
        costs.note_broad(100, 64_000);
        let mut skips = 0;
        while costs.mandatory_ns(100).unwrap() > 32_000 {
            costs.note_skipped();
            skips += 1;
        }
        assert!((40..50).contains(&skips), "{skips} refusals halve it");
    }

    #[test]
    fn a_scene_that_grew_or_shrank_by_more_than_an_eighth_is_measured_afresh() {
        let mut costs = FrameCosts::default();
        costs.note_broad(800, 9_000);
        costs.note_publish(1_000, 10);
        assert_eq!(costs.mandatory_ns(900), Some(10_000), "within an eighth");
        assert_eq!(costs.mandatory_ns(901), None);
        assert_eq!(costs.mandatory_ns(699), None);
        costs.note_broad(1_000, 2_000);
        assert_eq!(
            costs.mandatory_ns(1_000),
            Some(2_000),
            "publish forgotten too"
        );
    }

    #[test]
    fn the_tail_grows_with_its_pairs_and_records_and_bounds_the_sample() {
        let mut costs = FrameCosts::default();
        assert_eq!(
            costs.tail_ns(1000, 0),
            1000 * DEFAULT_TAIL_PS_PER_PAIR / 1000,
            "nothing published: the default per pair"
        );
        costs.note_publish(2_000, 99);
        costs.note_tail(10_000, 100);
        assert_eq!(
            costs.tail_ns(0, 0),
            2_000,
            "typical records: the typical publish"
        );
        // 100 ns a pair, its deviation taken as half of it at first: 300 ns counted; 2
        // records each, 300 in all: the typical 99 records' publish, and 201 more at the
        // default per record (one frame tells no slope).
        assert_eq!(
            costs.tail_ns(100, 100),
            30_000 + 2_000 + 201 * DEFAULT_PUBLISH_PS_PER_RECORD / 1000
        );
        costs.note_tail(1_000_000, 4);
        assert_eq!(
            costs.tail_ns(1, 0),
            300 + 2_000,
            "a tail of 4 pairs is no sample"
        );
        costs.note_visits(5_000, 100);
        let left = 50_000;
        let fits = costs.pairs_that_fit(10_000, left);
        let cost = |pairs: usize| pairs as u64 * 50 + costs.tail_ns(pairs, 0);
        assert!(cost(fits) <= left && cost(fits + 1) > left, "{fits}");
        assert_eq!(costs.pairs_that_fit(10, left), 10, "all of few pairs");
        assert_eq!(costs.pairs_that_fit(10, 0), 0);
    }

    #[test]
    fn a_publishing_caller_reserves_a_cold_publish_until_one_is_timed() {
        let library = FrameCosts::default();
        assert_eq!(library.publish_estimate_ns(1_000), 0, "publishes nothing");
        let mut daemon = FrameCosts::publishing();
        assert_eq!(
            daemon.publish_estimate_ns(1_000),
            COLD_PUBLISH_NS + 1_000 * DEFAULT_PUBLISH_PS_PER_RECORD / 1000
        );
        assert_eq!(
            daemon.tail_ns(10, 0),
            10 * DEFAULT_TAIL_PS_PER_PAIR / 1000
                + daemon.publish_estimate_ns(10 * RECORDS_PER_TAIL_PAIR),
            "the tail reserves the cold publish of its records"
        );
        daemon.note_publish(5_000, 1_000);
        assert_eq!(
            daemon.publish_estimate_ns(1_000),
            5_000,
            "timed: the measure"
        );
        // A scene that changed size is measured afresh, and is still a publisher's.
        daemon.note_broad(100, 1_000);
        daemon.note_broad(1_000, 1_000);
        assert_eq!(daemon.publish_ns, 0);
        assert!(daemon.publish_estimate_ns(0) >= COLD_PUBLISH_NS);
    }

    #[test]
    fn publishing_many_records_after_frames_of_none_costs_their_records_not_a_multiple() {
        let mut costs = FrameCosts::default();
        // Bodies apart: 20 µs to publish nothing, frame after frame.
        for _ in 0..50 {
            costs.note_publish(20_000, 0);
        }
        assert_eq!(costs.publish_estimate_ns(0), 20_000);
        assert_eq!(
            costs.publish_estimate_ns(1_000),
            20_000 + 1_000 * DEFAULT_PUBLISH_PS_PER_RECORD / 1000,
            "the default per record until frames of different sizes were timed"
        );
        // Then frames of 500 to 1,500 records at 20 µs plus 30 ns a record.
        for i in 0..200_u64 {
            let records = 500 + (i % 11) * 100;
            costs.note_publish(20_000 + 30 * records, records);
        }
        let per_record = costs.publish_fit.ps_per_record().expect("a slope");
        assert!((29_000..=31_000).contains(&per_record), "{per_record}");
        let estimate = costs.publish_estimate_ns(3_000);
        let truth = 20_000 + 30 * 3_000;
        assert!(
            (truth..=truth + truth / 10).contains(&estimate),
            "{estimate} ns for 3,000 records; {truth} true"
        );
    }

    #[test]
    fn a_fixed_record_count_tells_no_slope_and_a_flat_one_counts_the_least() {
        let mut fixed = PublishFit::default();
        for _ in 0..50 {
            fixed.note(1_000, 50_000);
        }
        assert_eq!(fixed.ps_per_record(), None);
        let mut costs = FrameCosts::default();
        for i in 0..50_u64 {
            costs.note_publish(20_000, 100 + (i % 5) * 200);
        }
        let records = costs.publish_records;
        assert_eq!(
            costs.publish_estimate_ns(records + 1_000),
            costs.publish_ns + 1_000 * MIN_PUBLISH_PS_PER_RECORD / 1000,
            "a time that does not grow with the records: the least per record"
        );
    }

    #[test]
    fn the_high_estimate_settles_on_steady_costs_and_covers_varying_ones() {
        let mut steady = Spread::default();
        for _ in 0..100 {
            steady.note(1_000);
        }
        // The deviation decays to the integer rounding of its quarter steps (below 4).
        assert_eq!(steady.mean, 1_000);
        assert!(steady.high() < 1_000 + 4 * 4, "{}", steady.high());
        let mut varying = Spread::default();
        for i in 0..100 {
            varying.note(if i % 2 == 0 { 800 } else { 1_200 });
        }
        let (mean, high) = (varying.mean, varying.high());
        assert!((900..=1_100).contains(&mean), "{mean}");
        assert!(
            high >= 1_200 + 300,
            "four deviations above the mean: {high}"
        );
    }
}
