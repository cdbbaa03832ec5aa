//! Placeholder: replaced by the foundation work (issue #2).

/// Placeholder.
#[derive(Debug, Clone)]
pub struct TriMesh;
/// Placeholder.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshError {}
/// Placeholder.
#[derive(Debug, Clone, Default)]
pub struct MeshReport;
