//! Placeholder.

/// Placeholder.
pub type Pss = super::BoundingSphere;
/// Placeholder.
#[derive(Debug, Clone, Copy)]
pub struct Lss;
/// Placeholder.
#[derive(Debug, Clone, Copy)]
pub struct Rss;
