//! The broad phase of a frame: one stateful [`BroadPhase`] of the scene's bodies kept in
//! sync with the scene between frames, and a [`SortAndSweep`] over the swept boxes for time
//! of impact.
//!
//! # The kind
//! The scene names it ([`Scene::broad_phase`]): a fixed kind, or with
//! [`BroadPhaseChoice::Auto`] the kind [`choose`] picks from [`BroadPhaseStats`] measured
//! on the scene at its first frame and again every [`AUTO_REMEASURE_FRAMES`] frames. The
//! share of far moves and the mean shift come from the kept broad phase's counts since the
//! last measurement ([`BroadPhase::take_move_counts`]): none at the first, which therefore
//! picks for a scene at rest. A different pick rebuilds the broad phase.
//!
//! A build is uninterruptible work: under a deadline a new broad phase is built only when
//! its estimated time (per body, timed per kind on earlier builds) fits in half the time
//! left. Otherwise the kept one goes on and the switch waits for a frame with room; a
//! scene's first frame then builds the kind quickest to build (a sort and sweep).
//!
//! # Sync
//! Each frame re-reads only the bodies in the scene's change log
//! ([`Scene::changes_since`]): a body that did not change is never touched, static bodies
//! included. When the log cannot bridge the gap on the same scene and kind (after a
//! skipped frame, a frame asking only `TOI`, which does not sync, or changes made between
//! its last frame's step and [`Scene::end_frame`]) it re-reads every body into the kept
//! broad phase, removing those gone; it builds afresh from every body on a scene it was
//! not synced to and when the kind changes.
//! Stepping twice in one frame re-reads the same log and answers the same. The frame's
//! [`StepReport`](super::StepReport) says which kind ran, how many bodies it re-read and,
//! on the frames that measured, the statistics. The swept boxes of `TOI` go through a
//! [`SortAndSweep`] over every body each frame.

use super::Query;
use crate::broad::{
    BroadPhase, BroadPhaseChoice, BroadPhaseKind, BroadPhaseStats, CandidatePair, Proxy,
    SortAndSweep, choose,
};
use crate::scene::{BodyId, Scene, SyncPoint};
use std::time::{Duration, Instant};

/// Frames between two measurements of a [`BroadPhaseChoice::Auto`] scene's statistics.
pub const AUTO_REMEASURE_FRAMES: u64 = 256;

/// What building a broad phase costs per body until a build of that kind was timed,
/// picoseconds: a sort and sweep about 60 ns (305 bodies in 18 µs, warm), the kinds that
/// keep state more (a skin grid of the same bodies 1.2 µs each), with room to spare.
const DEFAULT_BUILD_PS_PER_BODY: [u64; 5] = [200_000, 3_000_000, 3_000_000, 3_000_000, 3_000_000];

/// The automatic choice made for one scene.
#[derive(Debug, Clone, Copy)]
struct AutoChoice {
    /// [`Scene::uid`] of the scene measured.
    scene: u64,
    kind: BroadPhaseKind,
    /// The frame of the measurement.
    measured_at: u64,
}

/// The broad phases a workspace keeps between frames.
#[derive(Debug, Default)]
pub(super) struct BroadSync {
    /// Every body's proxy, when the broad phase is rebuilt or the scene measured; the
    /// changed bodies' proxies, when it is synced.
    proxies: Vec<Proxy>,
    /// The broad phase over the current boxes, kept in sync with the scene (module docs).
    broad: Option<BroadPhase>,
    /// Where `broad` was last synced to its scene.
    synced: Option<SyncPoint>,
    /// The last automatic choice, when the scene's choice is `Auto`.
    auto: Option<AutoChoice>,
    /// Bodies of the kept broad phase no longer in the scene, when it catches up.
    gone: Vec<u32>,
    /// A build's time per body, by kind ([`BroadPhaseKind::ALL`] order), picoseconds, a
    /// running mean moving an eighth of the way to each build (0: not timed yet).
    build_ps_per_body: [u64; 5],
    /// Swept boxes of the bodies (time of impact).
    swept: Vec<Proxy>,
    /// The broad phase over the swept boxes, with its own order kept between frames.
    swept_sweep: SortAndSweep,
}

/// What the broad phase of one frame did, for the frame's report.
#[derive(Debug, Clone, Copy)]
pub(super) struct BroadOutcome {
    /// The kind that ran (`None` when the frame asked only `TOI`).
    pub(super) kind: Option<BroadPhaseKind>,
    /// Bodies it re-read.
    pub(super) updates: usize,
    /// Whether it read every body (built the broad phase afresh for a new scene or kind,
    /// or caught the kept one up after a frame the log cannot bridge) instead of syncing
    /// the changed ones: such a frame's time is not the scene's typical broad phase.
    pub(super) rebuilt: bool,
    /// The scene's statistics, on the frames that measured them.
    pub(super) stats: Option<BroadPhaseStats>,
    /// Candidates found beyond the scene's [`SceneLimits::max_pairs_per_frame`](crate::scene::SceneLimits::max_pairs_per_frame) and
    /// dropped, both lists together.
    pub(super) dropped: usize,
}

/// The position of `kind` in [`BroadPhaseKind::ALL`].
fn kind_index(kind: BroadPhaseKind) -> usize {
    BroadPhaseKind::ALL
        .iter()
        .position(|&k| k == kind)
        .unwrap_or(0)
}

/// Keeps the first `cap` pairs of `list`; returns how many it dropped.
fn cap_list(list: &mut Vec<CandidatePair>, cap: usize) -> usize {
    let dropped = list.len().saturating_sub(cap);
    list.truncate(cap);
    dropped
}

impl BroadSync {
    /// The frame's candidate pairs at the current poses (when `query` asks anything but
    /// `TOI`) and over the swept boxes (when it asks `TOI`), each list cleared first.
    ///
    /// A build of a new broad phase (a new scene, or another kind) is made only when its
    /// estimated time fits in `room` (`None`: no limit); else the kept one goes on (synced
    /// as usual, the switch tried again next frame) or, on a scene's first frame, the kind
    /// quickest to build serves. Every kind reports the same pairs, so this changes only
    /// the cost.
    pub(super) fn candidates(
        &mut self,
        scene: &Scene,
        query: Query,
        room: Option<Duration>,
        candidates: &mut Vec<CandidatePair>,
        toi_candidates: &mut Vec<CandidatePair>,
    ) -> BroadOutcome {
        let mut stats = None;
        let (kind, updates, rebuilt) = if query.at_current_poses() {
            let (updates, rebuilt) = self.sync(scene, room, &mut stats);
            let broad = self.broad.as_mut().expect("synced");
            broad.pairs(candidates);
            (Some(broad.kind()), updates, rebuilt)
        } else {
            candidates.clear();
            (None, 0, false)
        };
        if query.toi {
            scene.swept_proxies(&mut self.swept);
            self.swept_sweep.pairs(&self.swept, toi_candidates);
        } else {
            toi_candidates.clear();
        }
        let cap = scene.limits().max_pairs_per_frame as usize;
        let dropped = cap_list(candidates, cap) + cap_list(toi_candidates, cap);
        BroadOutcome {
            kind,
            updates,
            rebuilt,
            stats,
            dropped,
        }
    }

    /// Brings the kept broad phase up to date with `scene` (module docs); returns how
    /// many bodies it re-read and whether it rebuilt the broad phase, and sets `measured`
    /// when it measured the scene for the automatic choice.
    fn sync(
        &mut self,
        scene: &Scene,
        room: Option<Duration>,
        measured: &mut Option<BroadPhaseStats>,
    ) -> (usize, bool) {
        let changes = self.synced.and_then(|point| scene.changes_since(point));
        let mut listed = false;
        let wanted = match scene.broad_phase() {
            BroadPhaseChoice::Fixed(kind) => {
                self.auto = None;
                kind
            }
            BroadPhaseChoice::Auto => match self.auto {
                Some(auto)
                    if auto.scene == scene.uid()
                        && (auto.measured_at..auto.measured_at + AUTO_REMEASURE_FRAMES)
                            .contains(&scene.frame()) =>
                {
                    auto.kind
                }
                _ => {
                    scene.proxies(&mut self.proxies);
                    listed = true;
                    let moved = changes.map_or(self.proxies.len(), <[u32]>::len);
                    let mut stats = BroadPhaseStats::measure(&self.proxies, moved);
                    if let Some(broad) = self.broad.as_mut() {
                        stats = stats.with_moves(&broad.take_move_counts());
                    }
                    *measured = Some(stats);
                    let kind = choose(&stats);
                    self.auto = Some(AutoChoice {
                        scene: scene.uid(),
                        kind,
                        measured_at: scene.frame(),
                    });
                    kind
                }
            },
        };
        let previous = self.synced.replace(scene.sync_point());
        let kind = self.kind_that_fits(scene, wanted, previous, room);
        let Self {
            broad,
            proxies,
            gone,
            ..
        } = self;
        if let (Some(broad), Some(changes)) = (broad.as_mut(), changes)
            && broad.kind() == kind
        {
            proxies.clear();
            for &id in changes {
                match scene.proxy(BodyId(id)) {
                    Some(proxy) => proxies.push(proxy),
                    None => {
                        broad.remove(id);
                    }
                }
            }
            broad.set_all(proxies);
            return (changes.len(), false);
        }
        if !listed {
            scene.proxies(proxies);
        }
        // The same scene and kind, but the log cannot tell what changed: every body is set
        // and those gone are removed, as in a frame where everything moved. Far cheaper
        // than building afresh for the kinds that keep state (a skin grid of 300 bodies
        // takes about 360 µs to build; setting every body, tens of µs).
        if let (Some(kept), Some(point)) = (broad.as_mut(), previous)
            && kept.kind() == kind
            && point.scene_uid() == scene.uid()
        {
            gone.clear();
            let live = |id: u32| scene.body(BodyId(id)).is_some();
            gone.extend(
                kept.proxies()
                    .iter()
                    .map(|p| p.body)
                    .filter(|&id| !live(id)),
            );
            for &id in gone.iter() {
                kept.remove(id);
            }
            kept.set_all(proxies);
            return (proxies.len(), true);
        }
        let started = Instant::now();
        *broad = Some(BroadPhase::from_proxies(kind, proxies));
        if let Some(per_body) = u64::try_from(started.elapsed().as_nanos())
            .ok()
            .and_then(|ns| ns.saturating_mul(1000).checked_div(proxies.len() as u64))
        {
            let estimate = &mut self.build_ps_per_body[kind_index(kind)];
            *estimate = match *estimate {
                0 => per_body,
                e => e - e / 8 + per_body / 8,
            };
        }
        (proxies.len(), true)
    }

    /// The kind this frame runs: `wanted`, unless building it would take longer than
    /// `room` (see [`candidates`](Self::candidates)); then the kept broad phase's kind when
    /// it serves this scene (`previous`: where it was last synced), else the kind quickest
    /// to build.
    fn kind_that_fits(
        &self,
        scene: &Scene,
        wanted: BroadPhaseKind,
        previous: Option<SyncPoint>,
        room: Option<Duration>,
    ) -> BroadPhaseKind {
        let kept = self
            .broad
            .as_ref()
            .filter(|_| previous.is_some_and(|p| p.scene_uid() == scene.uid()))
            .map(BroadPhase::kind);
        let Some(room) = room.filter(|_| kept != Some(wanted)) else {
            return wanted;
        };
        let bodies = scene.body_count() as u64;
        let build = |kind| {
            let index = kind_index(kind);
            let per_body = match self.build_ps_per_body[index] {
                0 => DEFAULT_BUILD_PS_PER_BODY[index],
                timed => timed,
            };
            Duration::from_nanos(bodies.saturating_mul(per_body) / 1000)
        };
        if build(wanted) <= room {
            return wanted;
        }
        kept.unwrap_or_else(|| {
            BroadPhaseKind::ALL
                .into_iter()
                .min_by_key(|&kind| build(kind))
                .unwrap_or(wanted)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::broad::pairs_brute_force;
    use crate::geometry::Sphere;
    use crate::math::{DVec3, Pose};
    use crate::narrow::Shape;
    use crate::scene::{BodyDesc, CollisionFilter, Motion, SceneLimits};

    /// 60 spheres on a line, each touching the next.
    fn spheres() -> Scene {
        let mut scene = Scene::try_new(0.0, SceneLimits::STANDARD).unwrap();
        let ball = scene
            .register_shape(Shape::Sphere(Sphere::new(0.5)))
            .unwrap();
        for i in 0..60 {
            let desc = BodyDesc {
                shape: ball,
                pose: Pose::from_translation(DVec3::new(0.9 * f64::from(i), 0.0, 0.0)),
                motion: Motion::Dynamic,
                filter: CollisionFilter::ALL,
                margin: Some(0.0),
            };
            scene.add_body(&desc).unwrap();
        }
        scene
    }

    /// One frame's kind and candidates with `room`, checked against brute force.
    fn frame(sync: &mut BroadSync, scene: &mut Scene, room: Option<Duration>) -> BroadPhaseKind {
        let (mut pairs, mut swept) = (Vec::new(), Vec::new());
        let outcome = sync.candidates(scene, Query::CLOSE, room, &mut pairs, &mut swept);
        let mut proxies = Vec::new();
        scene.proxies(&mut proxies);
        let mut want = Vec::new();
        pairs_brute_force(&proxies, &mut want);
        assert_eq!(pairs, want, "the same pairs whatever the kind");
        assert_eq!(pairs.len(), 59, "each sphere touches the next");
        scene.end_frame();
        outcome.kind.expect("a broad phase ran")
    }

    #[test]
    fn a_build_that_does_not_fit_the_room_waits_and_the_pairs_stay_the_same() {
        let mut scene = spheres();
        scene.set_broad_phase(BroadPhaseChoice::Fixed(BroadPhaseKind::SkinGrid));
        let mut sync = BroadSync::default();
        let none = Some(Duration::ZERO);
        assert_eq!(
            frame(&mut sync, &mut scene, none),
            BroadPhaseKind::SortAndSweep,
            "no room on the first frame: the kind quickest to build"
        );
        assert_eq!(
            frame(&mut sync, &mut scene, none),
            BroadPhaseKind::SortAndSweep,
            "still no room: the kept one goes on"
        );
        assert_eq!(
            frame(&mut sync, &mut scene, None),
            BroadPhaseKind::SkinGrid,
            "room: the scene's kind is built"
        );
        assert!(
            sync.build_ps_per_body[kind_index(BroadPhaseKind::SkinGrid)] > 0,
            "timed"
        );
        scene.set_broad_phase(BroadPhaseChoice::Fixed(BroadPhaseKind::HashGrid));
        assert_eq!(
            frame(&mut sync, &mut scene, none),
            BroadPhaseKind::SkinGrid,
            "another kind waits for room too"
        );
        let ample = Some(Duration::from_secs(1));
        assert_eq!(
            frame(&mut sync, &mut scene, ample),
            BroadPhaseKind::HashGrid
        );
    }
}
