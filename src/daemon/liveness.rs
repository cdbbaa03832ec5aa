//! Which client owns each scene, and which scenes have outlived their owner.
//!
//! Pure bookkeeping, no IPC: the control thread tells [`Liveness`] who created each scene
//! ([`adopt`](Liveness::adopt)) and, at every sweep, which owners are still connected
//! ([`sweep`](Liveness::sweep)). A scene whose owner is no longer connected is *orphaned*;
//! once it has been orphaned for the grace period without its owner coming back, the sweep
//! hands it back to be dropped. Owners are opaque ids (the daemon uses iceoryx2's
//! `UniqueClientId` values); time is injected, so tests need neither iceoryx2 nor a clock.

use std::collections::HashMap;
use std::time::{Duration, Instant};

/// An owner's id: the value of the control client port that created the scene.
pub type OwnerId = u128;

/// Scene id → owner, and since when the owner has been gone.
#[derive(Debug, Clone)]
pub struct Liveness {
    grace: Duration,
    /// The scenes tracked (not dropped), by id.
    scenes: HashMap<u32, Ownership>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Ownership {
    owner: OwnerId,
    /// When a sweep first found the owner gone; `None` while it is connected.
    orphaned_since: Option<Instant>,
}

/// What one [`Liveness::sweep`] found.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct SweepOutcome {
    /// Scenes whose owner this sweep found gone for the first time (log them).
    pub orphaned: Vec<u32>,
    /// Scenes orphaned for at least the grace period: drop them. They are no longer tracked.
    pub expired: Vec<u32>,
}

impl Liveness {
    /// Nothing tracked; orphaned scenes expire after `grace`.
    #[must_use]
    pub fn new(grace: Duration) -> Self {
        Self {
            grace,
            scenes: HashMap::new(),
        }
    }

    /// The grace period an orphaned scene is kept for.
    #[must_use]
    pub fn grace(&self) -> Duration {
        self.grace
    }

    /// Records that `owner` created scene `scene` (replacing any earlier record of that id).
    pub fn adopt(&mut self, scene: u32, owner: OwnerId) {
        let ownership = Ownership {
            owner,
            orphaned_since: None,
        };
        self.scenes.insert(scene, ownership);
    }

    /// Stops tracking scene `scene` (it was dropped by request).
    pub fn forget(&mut self, scene: u32) {
        self.scenes.remove(&scene);
    }

    /// The owner of scene `scene`, if tracked.
    #[must_use]
    pub fn owner(&self, scene: u32) -> Option<OwnerId> {
        self.scenes.get(&scene).map(|o| o.owner)
    }

    /// Whether scene `scene` is tracked and its owner was gone at the last sweep.
    #[must_use]
    pub fn is_orphaned(&self, scene: u32) -> bool {
        self.scenes
            .get(&scene)
            .is_some_and(|o| o.orphaned_since.is_some())
    }

    /// Checks every tracked scene's owner against `is_connected` at time `now`: an owner
    /// that is back clears the orphan mark, a newly missing one sets it to `now`, and a scene
    /// orphaned since at least `now − grace` expires (and is forgotten). The outcome's
    /// lists are in id order.
    pub fn sweep(&mut self, now: Instant, is_connected: impl Fn(OwnerId) -> bool) -> SweepOutcome {
        let mut outcome = SweepOutcome::default();
        for (&id, ownership) in &mut self.scenes {
            if is_connected(ownership.owner) {
                ownership.orphaned_since = None;
                continue;
            }
            let since = *ownership.orphaned_since.get_or_insert_with(|| {
                outcome.orphaned.push(id);
                now
            });
            if now.saturating_duration_since(since) >= self.grace {
                outcome.expired.push(id);
            }
        }
        for id in &outcome.expired {
            self.scenes.remove(id);
        }
        outcome.orphaned.sort_unstable();
        outcome.expired.sort_unstable();
        outcome
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GRACE: Duration = Duration::from_millis(2000);

    fn ms(start: Instant, ms: u64) -> Instant {
        start + Duration::from_millis(ms)
    }

    #[test]
    fn a_scene_whose_owner_stays_connected_never_expires() {
        let start = Instant::now();
        let mut liveness = Liveness::new(GRACE);
        liveness.adopt(0, 7);
        for t in (0..10_000).step_by(100) {
            assert_eq!(
                liveness.sweep(ms(start, t), |o| o == 7),
                SweepOutcome::default()
            );
        }
        assert_eq!(liveness.owner(0), Some(7));
    }

    #[test]
    fn an_orphaned_scene_is_reported_once_and_expires_only_after_the_grace_period() {
        let start = Instant::now();
        let mut liveness = Liveness::new(GRACE);
        liveness.adopt(0, 7);
        liveness.adopt(1, 8);
        let gone = |o: OwnerId| o != 8;
        let first = liveness.sweep(ms(start, 0), gone);
        assert_eq!(first.orphaned, vec![1]);
        assert!(first.expired.is_empty());
        assert!(liveness.is_orphaned(1) && !liveness.is_orphaned(0));
        let before = liveness.sweep(ms(start, 1999), gone);
        assert_eq!(before, SweepOutcome::default());
        assert_eq!(liveness.owner(1), Some(8));
        let after = liveness.sweep(ms(start, 2000), gone);
        assert_eq!(after.expired, vec![1]);
        assert!(after.orphaned.is_empty());
        assert_eq!(liveness.owner(1), None);
        assert_eq!(liveness.owner(0), Some(7));
        assert_eq!(
            liveness.sweep(ms(start, 5000), gone),
            SweepOutcome::default()
        );
    }

    #[test]
    fn an_owner_that_comes_back_within_the_grace_period_keeps_its_scene() {
        let start = Instant::now();
        let mut liveness = Liveness::new(GRACE);
        liveness.adopt(3, 9);
        assert_eq!(liveness.sweep(ms(start, 0), |_| false).orphaned, vec![3]);
        assert_eq!(
            liveness.sweep(ms(start, 1000), |_| true),
            SweepOutcome::default()
        );
        assert!(!liveness.is_orphaned(3));
        // The clock restarts at the next loss.
        assert_eq!(liveness.sweep(ms(start, 2500), |_| false).orphaned, vec![3]);
        assert!(
            liveness
                .sweep(ms(start, 4499), |_| false)
                .expired
                .is_empty()
        );
        assert_eq!(liveness.sweep(ms(start, 4500), |_| false).expired, vec![3]);
    }

    #[test]
    fn forgotten_scenes_are_not_swept_and_ids_may_be_adopted_again() {
        let start = Instant::now();
        let mut liveness = Liveness::new(GRACE);
        liveness.adopt(2, 1);
        liveness.forget(2);
        liveness.forget(40); // never tracked: nothing happens
        assert_eq!(
            liveness.sweep(ms(start, 0), |_| false),
            SweepOutcome::default()
        );
        liveness.adopt(2, 5);
        assert_eq!(liveness.owner(2), Some(5));
        assert_eq!(liveness.owner(0), None);
    }

    #[test]
    fn with_no_grace_an_orphaned_scene_expires_at_the_first_sweep() {
        let start = Instant::now();
        let mut liveness = Liveness::new(Duration::ZERO);
        liveness.adopt(0, 1);
        let outcome = liveness.sweep(ms(start, 0), |_| false);
        assert_eq!(outcome.orphaned, vec![0]);
        assert_eq!(outcome.expired, vec![0]);
        assert_eq!(liveness.owner(0), None);
    }
}
