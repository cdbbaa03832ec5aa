//! What a scene's frames must spend whatever their budget: the stages that cannot be
//! interrupted (the broad phase, and the daemon's writing and publishing of the result),
//! measured on the scene's own frames. The plan reads it before any work starts: a frame
//! whose budget cannot hold this work is not started, and says so with the smallest
//! budget measured ([`FrameCosts::mandatory_ns`]).
//!
//! Each estimate is the typical cost, a running mean moving an eighth of the way to each
//! sample, a sample counting at most twice the estimate: a frame is refused only when the
//! scene's usual uninterruptible work cannot fit, never for one frame the OS descheduled
//! (a frame whose broad phase runs long is late instead, and its stage times say why).
//! Only broad phases that synced the kept one count (a rebuild, after a new scene or a
//! frame not started, costs more than the frames that follow). A frame not started lowers
//! both estimates by a sixty-fourth, so an estimate grown stale (the scene got cheaper)
//! lets a frame run and be measured again after a few dozen refusals. A scene whose body
//! count changed by more than an eighth since the estimates were taken is measured afresh.

/// The uninterruptible stages' typical times for one scene.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FrameCosts {
    /// Broad phase, nanoseconds.
    broad_ns: u64,
    /// Writing and publishing the result frame, nanoseconds (told by the caller).
    publish_ns: u64,
    /// Body count of the scene when the estimates were taken (0: none yet).
    bodies: usize,
}

impl FrameCosts {
    /// Records a frame's broad phase on a scene of `bodies` bodies.
    pub fn note_broad(&mut self, bodies: usize, ns: u64) {
        self.forget_if_changed(bodies);
        self.broad_ns = typical(self.broad_ns, ns);
    }

    /// Records how long the caller took to write and publish a frame's result.
    pub fn note_publish(&mut self, ns: u64) {
        self.publish_ns = typical(self.publish_ns, ns);
    }

    /// Records a frame not started for lack of budget: both estimates fade by a
    /// sixty-fourth.
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

    fn forget_if_changed(&mut self, bodies: usize) {
        if changed(self.bodies, bodies) {
            *self = Self {
                bodies,
                ..Self::default()
            };
        }
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
    fn the_estimate_follows_the_typical_cost_and_one_slow_sample_moves_it_little() {
        let mut costs = FrameCosts::default();
        assert_eq!(costs.mandatory_ns(100), None, "nothing measured yet");
        costs.note_broad(100, 8_000);
        costs.note_publish(800);
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
            costs.note_publish(800);
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
        costs.note_publish(1_000);
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
}
