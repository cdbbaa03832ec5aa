//! What a candidate pair keeps between frames, in one record per pair
//! ([`PairMemory`]): its last exact answer, the separation and hull test that may prove it
//! apart without a traversal, the budgeted frontier's seed and the exact mesh query's warm
//! start.
//!
//! # The one rule
//! A pair's record lives while the pair is a candidate. Every frame visits each of its
//! candidates once ([`PairMemories::visit`]) and, at its end, forgets the records it did not
//! visit ([`PairMemories::forget_unvisited`]): by a stamp, not a search of the candidates
//! for each record, so forgetting costs one pass over the records. A frame asking only
//! `TOI` has no candidates and so forgets every record.
//!
//! # Allocation
//! One record when a pair first becomes a candidate (hash-map growth), and a kept answer's
//! contact list while it grows to the pair's largest manifold.

use super::answer::Answer;
use super::separation::Separation;
use super::{ContactPoint, Query, body};
use crate::broad::{CandidatePair, PairMap};
use crate::math::Pose;
use crate::narrow::gjk::GjkCache;
use crate::narrow::mesh_mesh::DistanceCache;
use crate::scene::{Body, Scene};

/// Everything one candidate pair keeps between frames.
#[derive(Debug, Default)]
pub(super) struct PairMemory {
    /// Its last exact answer, reused while neither body changes.
    pub(super) answer: Option<KeptAnswer>,
    /// The last separation proved for a mesh–mesh pair found apart.
    pub(super) separation: Option<Separation>,
    /// The hull test's memory of a mesh–mesh pair.
    pub(super) hull: HullCache,
    /// The triangle ids of the closest triangle pair a budgeted frame's frontier found
    /// within the pair's threshold, kept until the pair is proven apart: next frame's seed
    /// ([`FrontierPair::seed`](crate::narrow::mesh_mesh::frontier::FrontierPair::seed)),
    /// and first upper bound under `DISTANCE`.
    pub(super) seed: Option<[u32; 2]>,
    /// The exact mesh–mesh query's warm start: the closest triangle pair it last found.
    pub(super) mesh_cache: DistanceCache,
    /// The frame that last visited it.
    stamp: u64,
}

/// The records of every candidate pair (module docs).
#[derive(Debug, Default)]
pub(super) struct PairMemories {
    records: PairMap<PairMemory>,
    /// Frames begun so far: the stamp of the records a frame visits.
    frame: u64,
}

impl PairMemories {
    /// Starts a frame: records visited from now on carry its stamp.
    pub(super) fn begin_frame(&mut self) {
        self.frame += 1;
    }

    /// Marks `pair` a candidate of this frame (its record, if any, is kept), and gives its
    /// kept answer when that answers `pair` of `scene` under `query` now: one look-up.
    pub(super) fn visit(
        &mut self,
        scene: &Scene,
        pair: &CandidatePair,
        query: Query,
    ) -> Option<&KeptAnswer> {
        let record = self.records.get_mut(pair)?;
        record.stamp = self.frame;
        let kept = record.answer.as_ref()?;
        kept.fits(scene, pair, query).then_some(kept)
    }

    /// Forgets the records of the pairs this frame did not visit.
    pub(super) fn forget_unvisited(&mut self) {
        let frame = self.frame;
        self.records.retain(|_, record| record.stamp == frame);
    }

    /// The record of `pair`, if it has one.
    pub(super) fn get(&self, pair: &CandidatePair) -> Option<&PairMemory> {
        self.records.get(pair)
    }

    /// The record of `pair`, if it has one, to change.
    pub(super) fn get_mut(&mut self, pair: &CandidatePair) -> Option<&mut PairMemory> {
        self.records.get_mut(pair)
    }

    /// The record of `pair`, made empty if it has none; visited by this frame.
    pub(super) fn entry(&mut self, pair: &CandidatePair) -> &mut PairMemory {
        let record = self.records.entry(*pair).or_default();
        record.stamp = self.frame;
        record
    }

    /// The pairs whose record holds a kept answer (for tests).
    #[cfg(test)]
    pub(super) fn kept_pairs(&self) -> impl Iterator<Item = &CandidatePair> {
        self.records
            .iter()
            .filter(|(_, record)| record.answer.is_some())
            .map(|(pair, _)| pair)
    }

    /// The pairs that have a record, whatever it holds (for tests).
    #[cfg(test)]
    pub(super) fn recorded_pairs(&self) -> impl Iterator<Item = &CandidatePair> {
        self.records.keys()
    }

    /// The kept answer of `pair` when it answers `pair` of `scene` under `query` now.
    pub(super) fn kept_answer(
        &self,
        scene: &Scene,
        pair: &CandidatePair,
        query: Query,
    ) -> Option<&KeptAnswer> {
        let kept = self.records.get(pair)?.answer.as_ref()?;
        kept.fits(scene, pair, query).then_some(kept)
    }

    /// The warm start of the exact mesh–mesh query of `pair` (empty when it has none).
    pub(super) fn mesh_cache(&self, pair: &CandidatePair) -> DistanceCache {
        self.records
            .get(pair)
            .map(|record| record.mesh_cache)
            .unwrap_or_default()
    }

    /// Remembers what this frame's search of mesh pair `pair` (bodies `a`, `b`) found:
    /// `apart_by`, a proven lower bound of its distance beyond its margins, becomes its
    /// separation (and its frontier seed, a proof of closeness, lapses); none lapses the
    /// separation it had.
    pub(super) fn remember_search(
        &mut self,
        scene: &Scene,
        pair: &CandidatePair,
        (a, b): (&Body, &Body),
        apart_by: Option<f64>,
    ) {
        match apart_by {
            Some(bound) => {
                let record = self.entry(pair);
                record.separation = Some(Separation::new(scene, (a, b), bound));
                record.seed = None;
            }
            None => {
                if let Some(record) = self.records.get_mut(pair) {
                    record.separation = None;
                }
            }
        }
    }

    /// Drops the kept answer of `pair` (answered short of exact this frame).
    pub(super) fn drop_answer(&mut self, pair: &CandidatePair) {
        if let Some(record) = self.records.get_mut(pair) {
            record.answer = None;
        }
    }

    /// Keeps `answer`, exact, with its world-frame `contacts`, as the answer of `pair`
    /// (bodies `a` and `b` of `scene`) under `query`.
    pub(super) fn keep_answer(
        &mut self,
        scene: &Scene,
        pair: &CandidatePair,
        (a, b): (&Body, &Body),
        query: Query,
        answer: Answer,
        contacts: &[ContactPoint],
    ) {
        let kept = self.entry(pair).answer.get_or_insert_with(|| KeptAnswer {
            scene: 0,
            versions: [0; 2],
            query,
            answer,
            contacts: Vec::new(),
        });
        kept.scene = scene.uid();
        kept.versions = [a.version(), b.version()];
        kept.query = query;
        kept.answer = answer;
        kept.contacts.clear();
        kept.contacts.extend_from_slice(contacts);
    }
}

/// A candidate pair's answer kept from the frame that computed it ("pairs whose relative
/// pose did not change reuse last frame's answer", DESIGN §6): valid while the scene, the
/// query and both bodies' [`versions`](crate::scene::Body::version) are the same, since an
/// answer depends on nothing else (shapes never change). Both bodies unchanged is stricter
/// than an unchanged relative pose: the answer is in world frame, so a pair moved rigidly
/// together is answered again.
#[derive(Debug, Clone)]
pub(super) struct KeptAnswer {
    scene: u64,
    versions: [u64; 2],
    query: Query,
    pub(super) answer: Answer,
    /// Its contacts, world frame (`pair` rewritten when reused).
    pub(super) contacts: Vec<ContactPoint>,
}

impl KeptAnswer {
    /// Whether it answers `pair` of `scene` under `query` now.
    fn fits(&self, scene: &Scene, pair: &CandidatePair, query: Query) -> bool {
        self.scene == scene.uid()
            && self.query == query
            && self.versions == [body(scene, pair.a).version(), body(scene, pair.b).version()]
    }
}

/// What the hull test (`mark_separated`) keeps of a pair between frames.
#[derive(Debug, Default)]
pub(super) struct HullCache {
    /// GJK's warm start between the two hulls.
    pub(super) gjk: GjkCache,
    /// The relative pose at which the last test gave no proof (the hulls meet, or are not
    /// apart by more than the margins), so a pair at that same pose is not tested again.
    pub(super) met_at: Option<Pose>,
}
