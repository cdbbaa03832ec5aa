//! Placeholder: replaced by the foundation work (issue #2).

/// Placeholder.
#[derive(Debug, Clone, Copy)]
pub struct Aabb;
