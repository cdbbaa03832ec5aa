//! Placeholder: replaced by the foundation work (issue #2).

/// Placeholder.
#[derive(Debug, Clone)]
pub struct ConvexPolyhedron;
/// Placeholder.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ConvexHullError {}
