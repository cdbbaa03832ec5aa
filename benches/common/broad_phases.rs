//! The broad phases the broad-phase bench and example run, behind one frame step, so both
//! time exactly the same calls.

use super::parry_broad::{EXACT_CHANGE_MARGIN, ParryBroadPhase, RAPIER_CHANGE_MARGIN};
use proxima::bounding::Aabb;
use proxima::broad::{
    CandidatePair, ColumnGrid, HashGrid, IncrementalSap, Proxy, SkinGrid, SortAndSweep,
};

/// Every broad phase by name, Proxima's first.
pub const NAMES: [&str; 7] = [
    "sort_sweep",
    "incremental_sap",
    "hash_grid",
    "column_grid",
    "skin_grid",
    "parry_bvh",
    "rapier_bvh",
];

/// One broad phase under test and its latest pair list.
pub enum Phase {
    /// Proxima's sort and sweep over the whole proxy list.
    SortSweep(Box<SortAndSweep>),
    /// Proxima's incremental three-axis sweep and prune.
    Sap(IncrementalSap),
    /// Proxima's hierarchical hash grid.
    Grid(HashGrid),
    /// Proxima's column grid, a frame's moves handed over as one batch (as the pipeline
    /// does).
    Columns(ColumnGrid),
    /// Proxima's skin grid (the column grid over skin-grown boxes, with neighbour lists),
    /// a frame's moves handed over as one batch.
    Skin(Box<SkinGrid>),
    /// rapier's broad phase on parry's BVH; `exact` for the 1 nm change margin.
    Parry { phase: ParryBroadPhase, exact: bool },
}

impl Phase {
    /// Broad phase `name` (one of [`NAMES`]) loaded with every proxy, its first pairs found.
    pub fn new(name: &str, proxies: &[Proxy], out: &mut Vec<CandidatePair>) -> Option<Self> {
        let mut phase = match name {
            "sort_sweep" => Self::SortSweep(Box::default()),
            "incremental_sap" => Self::Sap(IncrementalSap::from_proxies(proxies)),
            "hash_grid" => {
                let mut g = HashGrid::new();
                for p in proxies {
                    g.insert(p.body, p.bounds, p.is_static, p.filter);
                }
                Self::Grid(g)
            }
            "column_grid" => Self::Columns(ColumnGrid::from_proxies(proxies)),
            "skin_grid" => Self::Skin(Box::new(SkinGrid::from_proxies(proxies))),
            "parry_bvh" | "rapier_bvh" => {
                let exact = name == "parry_bvh";
                let margin = if exact {
                    EXACT_CHANGE_MARGIN
                } else {
                    RAPIER_CHANGE_MARGIN
                };
                Self::Parry {
                    phase: ParryBroadPhase::with_bodies(margin, proxies),
                    exact,
                }
            }
            _ => return None,
        };
        phase.step(proxies, &[], out);
        Some(phase)
    }

    /// One frame: the moved bodies' new boxes (`moved`; `proxies` already holds them) handed
    /// over, and the pairs brought up to date: Proxima's written to `out`, rapier's kept in
    /// its pair map (it produces no list).
    #[inline]
    pub fn step(&mut self, proxies: &[Proxy], moved: &[(u32, Aabb)], out: &mut Vec<CandidatePair>) {
        match self {
            Self::SortSweep(s) => s.pairs(proxies, out),
            Self::Sap(s) => {
                for &(body, bounds) in moved {
                    s.update(body, bounds);
                }
                s.pairs(out);
            }
            Self::Grid(g) => {
                for &(body, bounds) in moved {
                    g.update(body, bounds);
                }
                g.pairs(out);
            }
            Self::Columns(c) => {
                c.update_all(moved);
                c.pairs(out);
            }
            Self::Skin(c) => {
                c.update_all(moved);
                c.pairs(out);
            }
            Self::Parry { phase, .. } => phase.update(moved),
        }
    }

    /// Pairs after the last step (`out` as the step left it, for Proxima's).
    pub fn pair_count(&self, out: &[CandidatePair]) -> usize {
        match self {
            Self::Parry { phase, .. } => phase.pair_count(),
            _ => out.len(),
        }
    }

    /// The exact pair set after the last step, sorted; `None` for rapier's margin, whose
    /// set also keeps pairs of enlarged leaves.
    pub fn exact_pairs(&self, out: &[CandidatePair]) -> Option<Vec<CandidatePair>> {
        match self {
            Self::Parry { phase, exact: true } => Some(phase.sorted_pairs()),
            Self::Parry { exact: false, .. } => None,
            _ => Some(out.to_vec()),
        }
    }

    /// Whether this is the peer.
    pub fn is_peer(&self) -> bool {
        matches!(self, Self::Parry { .. })
    }
}
