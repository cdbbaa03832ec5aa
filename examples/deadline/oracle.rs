//! The exact answer of a frame, computed in this process by the library on the mirror of
//! the daemon's scene (the same shapes, bodies and margins, the frame's poses): one
//! unlimited [`step`] per checked frame.
//!
//! A **missed collision** is a pair the exact answer finds touching (distance ≤ 0; for
//! mesh pairs, intersecting surfaces) that the daemon's frame does not report as possibly
//! touching, i.e. with a lower bound `distance − error_bound ≤ 0`. Truncated answers are
//! conservative (DESIGN §4), so the count must be 0.

use crate::workloads::Workload;
use proxima::math::{DQuat, DVec3, Pose};
use proxima::pipeline::{FrameResults, PipelineWorkspace, Query, step};
use proxima::scene::{BodyId, Scene};
use proxima_ipc::wire::{ResultRecord, query};
use std::error::Error;

/// The mirror scene and the state of its exact frames.
pub struct Oracle {
    mirror: Scene,
    query: Query,
    workspace: PipelineWorkspace,
    results: FrameResults,
}

impl Oracle {
    /// An oracle over `mirror` answering frames that ask `query_flags`.
    #[must_use]
    pub fn new(mirror: Scene, query_flags: u32) -> Self {
        Self {
            mirror,
            query: Query {
                overlap: query_flags & query::OVERLAP != 0,
                close: query_flags & query::CLOSE != 0,
                distance: query_flags & query::DISTANCE != 0,
                contacts: query_flags & query::CONTACTS != 0,
                toi: query_flags & query::TOI != 0,
            },
            workspace: PipelineWorkspace::default(),
            results: FrameResults::default(),
        }
    }

    /// Moves the mirror's bodies to `workload`'s current poses (as the daemon's ingest
    /// does: the same wire arrays, renormalised the same way) and runs the exact frame.
    ///
    /// # Errors
    /// A pose the daemon would have refused, or a body the mirror lacks.
    fn exact_frame(&mut self, workload: &dyn Workload) -> Result<(), Box<dyn Error>> {
        for i in 0..workload.pose_count() {
            let record = workload.pose(i);
            let [x, y, z, w] = record.orientation;
            let pose = Pose::try_new(
                DVec3::from_array(record.position),
                DQuat::from_xyzw(x, y, z, w),
            )?;
            self.mirror.set_pose(BodyId(record.body), pose)?;
        }
        step(
            &self.mirror,
            self.query,
            &mut self.workspace,
            &mut self.results,
        );
        self.mirror.end_frame();
        Ok(())
    }

    /// The pairs touching in the exact answer at `workload`'s current poses that
    /// `possibly_touching` (sorted `(a, b)` pairs of the daemon's frame) lacks.
    ///
    /// # Errors
    /// See [`exact_frame`](Self::exact_frame).
    pub fn missed(
        &mut self,
        workload: &dyn Workload,
        possibly_touching: &[(u32, u32)],
    ) -> Result<u32, Box<dyn Error>> {
        self.exact_frame(workload)?;
        let missed = self
            .results
            .pairs
            .iter()
            .filter(|p| p.distance <= 0.0)
            .filter(|p| possibly_touching.binary_search(&(p.a, p.b)).is_err())
            .count();
        Ok(u32::try_from(missed).unwrap_or(u32::MAX))
    }

    /// Checks that the daemon's exact answer (`pairs`, from a frame without a budget) at
    /// `workload`'s current poses reports the same pairs as the mirror's, at the same
    /// distances (within their error bounds): the mirror is the daemon's scene.
    ///
    /// # Errors
    /// They differ (the first difference), or see [`exact_frame`](Self::exact_frame).
    pub fn check_mirror(
        &mut self,
        workload: &dyn Workload,
        pairs: &[ResultRecord],
    ) -> Result<(), Box<dyn Error>> {
        self.exact_frame(workload)?;
        let ours = &self.results.pairs;
        if ours.len() != pairs.len() {
            return Err(format!(
                "the mirror reports {} pairs, the daemon {}",
                ours.len(),
                pairs.len()
            )
            .into());
        }
        for (mine, theirs) in ours.iter().zip(pairs) {
            let tolerance = 1e-9 + mine.error_bound + theirs.error_bound;
            if (mine.a, mine.b) != (theirs.body_a, theirs.body_b)
                || (mine.distance - theirs.distance).abs() > tolerance
            {
                return Err(format!(
                    "the mirror reports pair ({}, {}) at {} m, the daemon ({}, {}) at {} m",
                    mine.a, mine.b, mine.distance, theirs.body_a, theirs.body_b, theirs.distance
                )
                .into());
            }
        }
        Ok(())
    }
}

/// The `(a, b)` pairs of a frame's `pairs` records that may touch (`distance −
/// error_bound ≤ 0`), sorted.
#[must_use]
pub fn possibly_touching(pairs: &[ResultRecord]) -> Vec<(u32, u32)> {
    let mut touching: Vec<(u32, u32)> = pairs
        .iter()
        .filter(|p| p.distance - p.error_bound <= 0.0)
        .map(|p| (p.body_a, p.body_b))
        .collect();
    touching.sort_unstable();
    touching
}
