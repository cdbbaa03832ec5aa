//! The peer broad phase: rapier's `BroadPhaseBvh` loop, on parry3d-f64 0.31's dynamic
//! [`Bvh`], as rapier 0.30 runs it each step (`src/geometry/broad_phase_bvh.rs`):
//!
//! 1. every changed body: `insert_or_update_partially` with rapier's change-detection
//!    margin (a leaf whose new box still fits its stored, enlarged box is left unchanged);
//! 2. `optimize_incremental`, then `refit`;
//! 3. `traverse_bvtt_single_tree::<true>`: the tree against itself, only through changed
//!    subtrees; every leaf pair found is stamped in the pair map (new ones are the "add
//!    pair" events);
//! 4. every pair not stamped this frame whose leaves no longer overlap (and one of them
//!    changed) is dropped (the "delete pair" events).
//!
//! Its output is the pair map and the events, not a sorted list: the peer is timed without
//! producing one, which favours it. With [`EXACT_CHANGE_MARGIN`] its pair set is that of the
//! boxes grown by 1 nm (checked by the example to equal Proxima's on its workloads); with
//! rapier's 1 cm it also keeps pairs whose enlarged leaves overlap.
//!
//! Static and filtered pairs are not modelled (the workloads have neither, except the
//! stack's one static floor, which rapier also pairs with every die).

use parry3d_f64::bounding_volume::Aabb as ParryAabb;
use parry3d_f64::math::Vector as ParryVector;
use parry3d_f64::partitioning::{Bvh, BvhWorkspace};
use parry3d_f64::utils::hashmap::{Entry, HashMap};
use proxima::bounding::Aabb;
use proxima::broad::{CandidatePair, Proxy};

/// The smallest change-detection margin, metres: parry marks a leaf changed only with a
/// positive margin (with 0 its change-detecting traversal skips moved leaves and misses
/// their new pairs), so the exact variant uses 1 nm.
pub const EXACT_CHANGE_MARGIN: f64 = 1.0e-9;
/// Rapier's change-detection margin, metres.
pub const RAPIER_CHANGE_MARGIN: f64 = 1.0e-2;

/// rapier's broad phase over parry's BVH.
pub struct ParryBroadPhase {
    tree: Bvh,
    workspace: BvhWorkspace,
    pairs: HashMap<(u32, u32), u32>,
    frame: u32,
    change_margin: f64,
    /// Pairs added and removed in the last update (rapier's events), counted.
    pub events: usize,
}

impl ParryBroadPhase {
    /// An empty broad phase with change-detection margin `change_margin` metres.
    pub fn new(change_margin: f64) -> Self {
        Self {
            tree: Bvh::new(),
            workspace: BvhWorkspace::default(),
            pairs: HashMap::default(),
            frame: 0,
            change_margin,
            events: 0,
        }
    }

    /// All `proxies` inserted in one update.
    pub fn with_bodies(change_margin: f64, proxies: &[Proxy]) -> Self {
        let mut phase = Self::new(change_margin);
        let all: Vec<(u32, Aabb)> = proxies.iter().map(|p| (p.body, p.bounds)).collect();
        phase.update(&all);
        phase
    }

    /// One step: the boxes of the bodies that changed, then the pair map brought up to date.
    pub fn update(&mut self, changed: &[(u32, Aabb)]) {
        self.frame = self.frame.wrapping_add(1);
        self.events = 0;
        if changed.is_empty() {
            return;
        }
        for &(body, bounds) in changed {
            self.tree
                .insert_or_update_partially(parry_aabb(&bounds), body, self.change_margin);
        }
        self.tree.optimize_incremental(&mut self.workspace);
        self.tree.refit(&mut self.workspace);
        let (pairs, frame, events) = (&mut self.pairs, self.frame, &mut self.events);
        self.tree
            .traverse_bvtt_single_tree::<true>(&mut self.workspace, &mut |a, b| {
                let key = (a.min(b), a.max(b));
                match pairs.entry(key) {
                    Entry::Occupied(e) => *e.into_mut() = frame,
                    Entry::Vacant(e) => {
                        e.insert(frame);
                        *events += 1;
                    }
                }
            });
        let tree = &self.tree;
        self.pairs.retain(|&(a, b), stamp| {
            if *stamp == frame {
                return true;
            }
            let (Some(na), Some(nb)) = (tree.leaf_node(a), tree.leaf_node(b)) else {
                return false;
            };
            let keep = !((na.is_changed() || nb.is_changed()) && !na.intersects(nb));
            if !keep {
                *events += 1;
            }
            keep
        });
    }

    /// Number of pairs in the map.
    pub fn pair_count(&self) -> usize {
        self.pairs.len()
    }

    /// The pair map as a sorted list (for checking; not timed).
    pub fn sorted_pairs(&self) -> Vec<CandidatePair> {
        let mut out: Vec<CandidatePair> = self
            .pairs
            .keys()
            .map(|&(a, b)| CandidatePair { a, b })
            .collect();
        out.sort_unstable();
        out
    }
}

fn parry_aabb(b: &Aabb) -> ParryAabb {
    ParryAabb::new(
        ParryVector::new(b.min.x, b.min.y, b.min.z),
        ParryVector::new(b.max.x, b.max.y, b.max.z),
    )
}
