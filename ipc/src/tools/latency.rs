//! Latency bookkeeping for clients: record round trips, summarise them as percentiles.
//!
//! Tools that measure the daemon (the demo, `ipc_latency`, `monitor`) report the same
//! figures the same way: count, min, p50, p99, p99.9, max and mean, in microseconds.

use std::fmt;
use std::time::Duration;

/// Recorded durations, nanoseconds. Reserve the expected count up front
/// ([`with_capacity`](Self::with_capacity)) so recording never allocates in a timed loop.
#[derive(Debug, Clone, Default)]
pub struct LatencyRecorder {
    samples_ns: Vec<u64>,
}

impl LatencyRecorder {
    /// An empty recorder with room for `capacity` samples.
    #[must_use]
    pub fn with_capacity(capacity: usize) -> Self {
        Self {
            samples_ns: Vec::with_capacity(capacity),
        }
    }

    /// Records one duration (saturating at `u64::MAX` ns, about 584 years).
    pub fn record(&mut self, duration: Duration) {
        self.record_ns(u64::try_from(duration.as_nanos()).unwrap_or(u64::MAX));
    }

    /// Records one duration given in nanoseconds.
    pub fn record_ns(&mut self, ns: u64) {
        self.samples_ns.push(ns);
    }

    /// Number of samples recorded.
    #[must_use]
    pub fn len(&self) -> usize {
        self.samples_ns.len()
    }

    /// Whether nothing was recorded.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.samples_ns.is_empty()
    }

    /// Forgets every sample (keeps the capacity).
    pub fn clear(&mut self) {
        self.samples_ns.clear();
    }

    /// The summary of every sample so far; `None` when there are none.
    #[must_use]
    pub fn summary(&self) -> Option<LatencySummary> {
        let mut sorted = self.samples_ns.clone();
        sorted.sort_unstable();
        let (&min, &max) = (sorted.first()?, sorted.last()?);
        let sum: u128 = sorted.iter().map(|&ns| u128::from(ns)).sum();
        Some(LatencySummary {
            count: sorted.len(),
            min_ns: min,
            p50_ns: percentile(&sorted, 0.5),
            p99_ns: percentile(&sorted, 0.99),
            p999_ns: percentile(&sorted, 0.999),
            max_ns: max,
            mean_ns: u64::try_from(sum / sorted.len() as u128).unwrap_or(u64::MAX),
        })
    }
}

/// The `q`-quantile of ascending `sorted` (nearest rank: the smallest sample with at least
/// `q` of all samples at or below it). `sorted` must not be empty.
fn percentile(sorted: &[u64], q: f64) -> u64 {
    let rank = (q * sorted.len() as f64).ceil() as usize;
    sorted[rank.clamp(1, sorted.len()) - 1]
}

/// Percentiles of a set of durations, nanoseconds. Displays as
/// `n=… min … p50 … p99 … p99.9 … max … mean … µs`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LatencySummary {
    /// Number of samples.
    pub count: usize,
    /// Smallest sample.
    pub min_ns: u64,
    /// Median (nearest rank).
    pub p50_ns: u64,
    /// 99th percentile (nearest rank).
    pub p99_ns: u64,
    /// 99.9th percentile (nearest rank).
    pub p999_ns: u64,
    /// Largest sample.
    pub max_ns: u64,
    /// Arithmetic mean (rounded down).
    pub mean_ns: u64,
}

impl fmt::Display for LatencySummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let us = |ns: u64| ns as f64 / 1e3;
        write!(
            f,
            "n={} min {:.1} p50 {:.1} p99 {:.1} p99.9 {:.1} max {:.1} mean {:.1} µs",
            self.count,
            us(self.min_ns),
            us(self.p50_ns),
            us(self.p99_ns),
            us(self.p999_ns),
            us(self.max_ns),
            us(self.mean_ns)
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_follow_the_nearest_rank_definition() {
        let mut recorder = LatencyRecorder::with_capacity(1000);
        // 1..=1000 ns in a scrambled order.
        for i in 0..1000u64 {
            recorder.record_ns((i * 7919) % 1000 + 1);
        }
        let s = recorder.summary().unwrap();
        assert_eq!(
            (s.count, s.min_ns, s.p50_ns, s.p99_ns, s.p999_ns, s.max_ns),
            (1000, 1, 500, 990, 999, 1000)
        );
        assert_eq!(s.mean_ns, 500); // 500.5 rounded down
    }

    #[test]
    fn one_sample_is_every_percentile_and_none_is_no_summary() {
        let mut recorder = LatencyRecorder::default();
        assert!(recorder.summary().is_none());
        recorder.record(Duration::from_micros(42));
        let s = recorder.summary().unwrap();
        assert!(
            [s.min_ns, s.p50_ns, s.p99_ns, s.p999_ns, s.max_ns, s.mean_ns]
                .iter()
                .all(|&ns| ns == 42_000)
        );
        recorder.clear();
        assert!(recorder.is_empty());
    }
}
