//! Bottom-up builder: agglomerative clustering (placeholder until implemented below).

use super::{BuildPrimitive, BuildStrategy, Topology};
use crate::bounding::BoundingVolume;
use crate::geometry::Triangle;

/// Builds the topology by agglomerative clustering.
#[expect(
    clippy::extra_unused_type_parameters,
    reason = "placeholder until clustering lands"
)]
pub(super) fn build<B: BoundingVolume>(
    _triangles: &[Triangle],
    primitives: &[BuildPrimitive],
    leaf_size: u32,
) -> Topology {
    // TODO(#3): agglomerative clustering; median split until then.
    super::top_down::build(primitives, BuildStrategy::Median, leaf_size)
}
