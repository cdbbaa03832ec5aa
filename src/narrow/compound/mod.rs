//! Compound shapes: one body made of convex parts, and their queries.
//!
//! A [`CompoundShape`] is a solid: the union of its parts, each a convex shape in the
//! body's frame (a convex hull from [`decompose`](crate::decompose), or any primitive). Its
//! queries answer part by part, through the dispatcher, over the part pairs that the small
//! tree of part boxes ([`PartTree`]) cannot prove farther than what is already known:
//!
//! - apart, the signed distance is the smallest gap over the part pairs;
//! - overlapping, it is minus the depth of the whole compound ([`union_depth`]): the
//!   deepest part pair's (GJK/EPA, or a primitive pair's closed form) when moving B out of
//!   that part frees it from every part, else the shortest move found that does, never
//!   less deep. A decomposition's union is within its stated concavity of the mesh;
//! - the manifold gathers every touching part pair's points and the distance's own
//!   witnesses, and keeps at most four under the compound's normal
//!   (`manifold_reduction::reduce_under_deepest`).
//!
//! Like every query of the dispatcher the distance polls the frame's clock, here before
//! each part pair after the first, and answers bounds when it stops: the best part pair
//! found so far above, the smallest box bound left below. See [`query`].

pub mod query;
mod tree;
pub mod union_depth;

pub use tree::{PartNode, PartTree};

use crate::bounding::{Aabb, BoundingVolume};
use crate::geometry::ConvexPolyhedron;
use crate::geometry::decompose::Decomposition;
use crate::math::DVec3;
use crate::narrow::Shape;
use std::sync::Arc;

/// The most parts a compound shape holds (the decomposition's default is 64).
pub const MAX_PARTS: usize = 1024;

/// Why a compound shape could not be made.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CompoundError {
    /// No part given.
    Empty,
    /// More than [`MAX_PARTS`] parts.
    TooManyParts {
        /// Parts given.
        parts: usize,
    },
    /// Part `index` is a mesh or a compound: parts are convex.
    NotConvex {
        /// Its position in the list.
        index: usize,
    },
}

impl std::fmt::Display for CompoundError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Empty => write!(f, "a compound shape needs at least one part"),
            Self::TooManyParts { parts } => {
                write!(
                    f,
                    "{parts} parts; a compound shape holds at most {MAX_PARTS}"
                )
            }
            Self::NotConvex { index } => {
                write!(f, "part {index} is not convex (a mesh or a compound)")
            }
        }
    }
}

impl std::error::Error for CompoundError {}

/// A solid made of convex parts, in the body's local frame (see the [module docs](self)).
///
/// # Invariants
/// `parts` holds 1 ..= [`MAX_PARTS`] convex shapes (no mesh, no compound); `tree` bounds
/// them, each leaf one part; `bounds` is the union of the parts' local boxes.
#[derive(Debug)]
pub struct CompoundShape {
    parts: Vec<Shape>,
    tree: PartTree,
    bounds: Aabb,
}

impl CompoundShape {
    /// A compound of `parts`, each placed in the body's frame.
    ///
    /// # Errors
    /// [`CompoundError`] when there is no part, too many, or one is not convex.
    pub fn new(parts: Vec<Shape>) -> Result<Self, CompoundError> {
        if parts.is_empty() {
            return Err(CompoundError::Empty);
        }
        if parts.len() > MAX_PARTS {
            return Err(CompoundError::TooManyParts { parts: parts.len() });
        }
        if let Some(index) = parts
            .iter()
            .position(|p| matches!(p, Shape::Mesh(_) | Shape::Compound(_)))
        {
            return Err(CompoundError::NotConvex { index });
        }
        let points: Vec<Vec<DVec3>> = parts.iter().map(part_points).collect();
        let tree = PartTree::new(&points);
        let bounds = parts
            .iter()
            .map(Shape::local_bounds)
            .reduce(|a, b| a.merged(&b))
            .unwrap_or_else(|| unreachable!("checked non-empty above"));
        Ok(Self {
            parts,
            tree,
            bounds,
        })
    }

    /// A compound of convex hulls.
    ///
    /// # Errors
    /// As [`new`](Self::new): none or too many hulls.
    pub fn from_hulls(hulls: Vec<ConvexPolyhedron>) -> Result<Self, CompoundError> {
        Self::new(
            hulls
                .into_iter()
                .map(|h| Shape::Convex(Arc::new(h)))
                .collect(),
        )
    }

    /// The compound of a decomposition's parts' hulls.
    ///
    /// # Errors
    /// As [`new`](Self::new) (a decomposition has 1 ..= its `max_parts` parts, so only when
    /// that was above [`MAX_PARTS`]).
    pub fn from_decomposition(decomposition: &Decomposition) -> Result<Self, CompoundError> {
        Self::from_hulls(decomposition.parts.iter().map(|p| p.hull.clone()).collect())
    }

    /// The parts, body frame; part `i` is the tree's leaf for `i`.
    #[must_use]
    pub fn parts(&self) -> &[Shape] {
        &self.parts
    }

    /// The tree of the parts' boxes.
    #[must_use]
    pub fn tree(&self) -> &PartTree {
        &self.tree
    }

    /// The smallest axis-aligned box of the body's frame containing every part.
    #[must_use]
    pub fn local_bounds(&self) -> Aabb {
        self.bounds
    }
}

/// Points whose hull contains `part` (a convex shape): a hull's vertices, otherwise the
/// corners of its local box.
fn part_points(part: &Shape) -> Vec<DVec3> {
    if let Shape::Convex(hull) = part {
        return hull.vertices().to_vec();
    }
    part.local_bounds().corners().to_vec()
}

#[cfg(test)]
mod tests;
