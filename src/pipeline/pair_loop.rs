//! The per-pair stage of a frame: every candidate pair answered by its plan
//! ([`FramePlan::pair`]) from the source that has its answer (a kept answer, the
//! frontier's, the worker pool's, or its own query on this thread), paced by the frame's
//! clock, and its records written.

use super::answer::{self, Answer, MeshScratch};
use super::costs::TailTimer;
use super::helper::{Helping, MIN_HELPED_PAIRS};
use super::pair_memory::PairMemories;
use super::plan;
use super::plan::{FramePlan, PairPlan};
use super::workers::{PairOutcome, WorkerPool};
use super::{ContactPoint, FrameResults, PipelineWorkspace, Query, body, index, shape};
use crate::broad::CandidatePair;
use crate::budget::Completeness;
use crate::narrow::Shape;
use crate::narrow::contact::Manifold;
use crate::narrow::dispatch::{self, NarrowScratch, Route};
use crate::narrow::mesh_mesh::frontier::FrontierAnswer;
use crate::scene::{Body, Scene};

/// What the per-pair stage counted.
pub(super) struct PairTally {
    /// The shallowest level of the pairs answered short of exact.
    pub(super) completeness: Completeness,
    /// Pairs answered by their kept answer.
    pub(super) reused: u32,
    /// Pairs the helper thread answered.
    pub(super) helped: u32,
    /// Pairs answered apart by a kept separation or their hulls.
    pub(super) separated: u32,
    /// Pairs answered short of exact.
    pub(super) truncated: u32,
}

/// Answers every candidate pair by its plan ([`FramePlan::pair`]), reusing kept answers,
/// and writes the records the query reports to `results`; keeps what each pair remembers
/// ([`pair_memory`](super::pair_memory)).
pub(super) fn answer_candidates(
    scene: &Scene,
    query: Query,
    plan: &FramePlan,
    workspace: &mut PipelineWorkspace,
    results: &mut FrameResults,
) -> PairTally {
    let mut tally = PairTally {
        completeness: Completeness::Exact,
        reused: 0,
        helped: 0,
        separated: 0,
        truncated: 0,
    };
    let PipelineWorkspace {
        candidates,
        toi_candidates,
        memory,
        separated,
        frontier_answers,
        frontier_pairs,
        outcomes,
        narrow,
        manifold,
        mesh,
        costs,
        workers,
        fresh_last_frame,
        abandon,
        ..
    } = workspace;
    let fresh = *fresh_last_frame;
    let mut helping = workers
        .as_deref()
        .filter(|_| !plan.pool && !abandon.is_raised() && fresh >= MIN_HELPED_PAIRS)
        .and_then(|pool| start_helper(pool, scene, query, candidates, separated));
    let mut sources = AnswerSources {
        pooled: outcomes.iter(),
        frontier: frontier_pairs.iter().zip(frontier_answers.iter()),
        narrow,
        manifold,
        mesh,
    };
    let mut tail = TailTimer::default();
    for (slot, pair) in candidates.iter().enumerate() {
        let left = candidates.len() - slot + toi_candidates.len();
        plan.pace(
            &mut sources.narrow.clock,
            costs,
            left,
            results.record_count(),
        );
        let (a, b) = (body(scene, pair.a), body(scene, pair.b));
        let first_contact = results.contacts.len();
        if let Some(k) = memory.visit(scene, pair, query) {
            tally.reused += 1;
            results.contacts.extend_from_slice(&k.contacts);
            debug_assert!(k.answer.result.exact, "only exact answers are kept");
            report(query, k.answer, (a, b), first_contact, results);
            continue;
        }
        let shapes = (shape(scene, a), shape(scene, b));
        let pair_plan = plan.pair(
            shapes.0,
            shapes.1,
            separated[slot],
            &mut sources.narrow.clock,
        );
        if matches!(pair_plan, PairPlan::Conservative) {
            tail.begin(candidates.len() - slot);
        }
        let from_helper = match (&mut helping, &pair_plan) {
            (Some(helping), PairPlan::Direct | PairPlan::Conservative) => helping.take(index(slot)),
            _ => None,
        };
        let (answer, truncated_level) = match from_helper {
            Some(outcome) => {
                tally.helped += 1;
                results.contacts.extend_from_slice(outcome.contacts());
                (outcome.answer, None)
            }
            None => sources.answer(
                query,
                (slot, pair),
                ((a, shapes.0), (b, shapes.1)),
                &pair_plan,
                memory,
                &mut results.contacts,
            ),
        };
        tally.separated += u32::from(matches!(pair_plan, PairPlan::Separated));
        tally.truncated += u32::from(!answer.result.exact);
        if pair_plan.searches_mesh_pair() {
            memory.remember_search(scene, pair, (a, b), answer.apart_by);
        }
        if answer.result.exact {
            let contacts = &results.contacts[first_contact..];
            memory.keep_answer(scene, pair, (a, b), query, answer, contacts);
        } else {
            // A truncated frontier answer, or the worker pool's fallback box answer (level
            // 0: world boxes).
            tally.completeness = tally
                .completeness
                .truncated_at(truncated_level.unwrap_or(0));
            memory.drop_answer(pair);
        }
        report(query, answer, (a, b), first_contact, results);
    }
    if let Some(helping) = helping {
        sources.narrow.paths.add(&helping.end());
    }
    memory.forget_unvisited();
    tail.end(costs);
    *fresh_last_frame = candidates.len() - (tally.reused + tally.separated) as usize;
    tally
}

/// Hands the pool's helper (when no other frame holds it) the candidates it may answer
/// ([`PairHelper::begin`](super::helper::PairHelper::begin) says when it takes them).
fn start_helper(
    pool: &WorkerPool,
    scene: &Scene,
    query: Query,
    candidates: &[CandidatePair],
    separated: &[bool],
) -> Option<Helping> {
    let pairs = candidates.iter().enumerate().filter_map(|(slot, pair)| {
        let (a, b) = (body(scene, pair.a), body(scene, pair.b));
        let direct = !separated[slot] && helps(shape(scene, a), shape(scene, b));
        direct.then_some((index(slot), *pair))
    });
    // The guard may go once the frame is handed over: the frame's claims are its own.
    pool.helper()?.begin(scene, query, pairs)
}

/// Whether the helper may answer a pair of these shapes: a direct pair between convex
/// shapes (closed forms, GJK/EPA), not a walk of a tree.
fn helps(sa: &Shape, sb: &Shape) -> bool {
    matches!(dispatch::route(sa, sb), Route::Direct) && plan::pool_work(sa, sb).is_none()
}

/// Where a pair's answer comes from besides its own query: the pool's outcomes and the
/// frontier's answers, both in candidate order, and this thread's scratch.
struct AnswerSources<'w> {
    pooled: std::slice::Iter<'w, PairOutcome>,
    frontier:
        std::iter::Zip<std::slice::Iter<'w, CandidatePair>, std::slice::Iter<'w, FrontierAnswer>>,
    narrow: &'w mut NarrowScratch,
    manifold: &'w mut Manifold,
    mesh: &'w mut MeshScratch,
}

impl<'w> AnswerSources<'w> {
    /// The answer of `pair` (candidate `slot`; bodies `a`, `b` with shapes `sa`, `sb`) by
    /// `plan`, its contacts appended to `contacts`, and the level it was truncated at when
    /// the frontier left it unfinished.
    fn answer(
        &mut self,
        query: Query,
        (slot, pair): (usize, &CandidatePair),
        ((a, sa), (b, sb)): ((&Body, &Shape), (&Body, &Shape)),
        plan: &PairPlan<'_>,
        memory: &mut PairMemories,
        contacts: &mut Vec<ContactPoint>,
    ) -> (Answer, Option<u32>) {
        let narrow = &mut *self.narrow;
        let answer = match *plan {
            // Proven apart by a kept separation, which stays as it is (`DISTANCE` frames
            // never come here). Kept as an answer too, so an unchanged pair is reused.
            PairPlan::Separated => answer::apart(pair, None),
            PairPlan::Conservative => {
                answer::conservative(pair, (a, sa), (b, sb), query, narrow, contacts)
            }
            PairPlan::Direct => answer::direct(
                pair,
                (a, sa),
                (b, sb),
                query,
                narrow,
                self.manifold,
                contacts,
            ),
            PairPlan::Frontier(ma, mb) => {
                narrow.paths.mesh_mesh += 1;
                let (_, found) = self
                    .frontier
                    .find(|(p, _)| *p == pair)
                    .expect("a frontier answer for every mesh pair not kept");
                let Completeness::Truncated { level } = found.completeness else {
                    let cache = &mut memory.entry(pair).mesh_cache;
                    let mesh = &mut *self.mesh;
                    return (
                        answer::mesh_mesh_finished(
                            pair,
                            (a, ma),
                            (b, mb),
                            query,
                            found,
                            cache,
                            (mesh, &mut narrow.clock),
                            contacts,
                        ),
                        None,
                    );
                };
                let truncated = answer::mesh_mesh_truncated(pair, (a, b), query, found, contacts);
                return (truncated, Some(level));
            }
            PairPlan::Pooled => {
                narrow.paths.mesh_mesh += 1;
                let outcome = self.pooled(slot, contacts);
                memory.entry(pair).mesh_cache = outcome.cache;
                outcome.answer
            }
            PairPlan::PooledWalk => {
                let outcome = self.pooled(slot, contacts);
                self.narrow.paths.add(&outcome.paths);
                outcome.answer
            }
            PairPlan::MeshMesh(ma, mb) => {
                narrow.paths.mesh_mesh += 1;
                let cache = &mut memory.entry(pair).mesh_cache;
                let mesh = (&mut *self.mesh, &mut narrow.clock);
                answer::mesh_mesh(pair, (a, ma), (b, mb), query, cache, mesh, contacts)
            }
        };
        (answer, None)
    }

    /// The pool's outcome for candidate `slot` (outcomes come in slot order), its contacts
    /// appended to `contacts`.
    fn pooled(&mut self, slot: usize, contacts: &mut Vec<ContactPoint>) -> &'w PairOutcome {
        let outcome = self
            .pooled
            .next()
            .expect("one pool outcome per pooled pair");
        debug_assert_eq!(outcome.slot as usize, slot);
        contacts.extend_from_slice(outcome.contacts());
        outcome
    }
}

/// Adds `answer` (its contacts already at `results.contacts[first_contact..]`) to the
/// frame's records when `query` reports it, linking its contacts; else drops the contacts.
fn report(
    query: Query,
    mut answer: Answer,
    (a, b): (&Body, &Body),
    first_contact: usize,
    results: &mut FrameResults,
) {
    if query.reports(&answer, a.margin + b.margin) {
        let count = results.contacts.len() - first_contact;
        if count > 0 {
            answer.result.first_contact = index(first_contact);
            answer.result.contact_count = index(count);
            let pair = index(results.pairs.len());
            for c in &mut results.contacts[first_contact..] {
                c.pair = pair;
            }
        }
        results.pairs.push(answer.result);
    } else {
        results.contacts.truncate(first_contact);
    }
}
