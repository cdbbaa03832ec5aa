//! A pile of decomposed meshes: [`COMPOUND_PILE_BODIES`] copies of one closed mesh, scaled
//! to [`COMPOUND_SIZE_M`] across and registered as the compound of its convex
//! decomposition (true penetration depth between them), dropped in layers into the pile's
//! 40 cm box and bounced by the point-mass solver like [`pile`](super::pile)'s bodies.

use super::pile::{add_box, layer_position, random_orientation};
use super::spec::{BodyPlan, SceneSpec, ShapeSpec};
use glam::DVec3;
use proxima::decompose::{Decomposition, Options, decompose};
use proxima::geometry::TriMesh;
use proxima_ipc::client::Motion;
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;

/// Bodies in the pile (the box's five walls come first).
pub const COMPOUND_PILE_BODIES: usize = 50;
/// The largest extent of each body, metres.
pub const COMPOUND_SIZE_M: f64 = 0.07;
/// Close-pair margin of every body, metres.
const MARGIN_M: f64 = 0.005;

/// The decomposition of `mesh` (its default options, at most `max_parts` parts) and the
/// parts' hull vertices scaled and centred so that the body is [`COMPOUND_SIZE_M`] across.
///
/// # Errors
/// The mesh encloses no volume.
pub fn compound_parts(
    mesh: &TriMesh,
    max_parts: usize,
) -> Result<(Decomposition, Vec<Vec<DVec3>>), proxima::decompose::DecomposeError> {
    let options = Options {
        max_parts,
        ..Options::default()
    };
    let parts = decompose(mesh, &options)?;
    let (min, max) = mesh.bounds();
    let (centre, scale) = (
        (min + max) / 2.0,
        COMPOUND_SIZE_M / (max - min).max_element(),
    );
    let points = parts
        .parts
        .iter()
        .map(|p| {
            p.hull
                .vertices()
                .iter()
                .map(|&v| (v - centre) * scale)
                .collect()
        })
        .collect();
    Ok((parts, points))
}

/// The box and [`COMPOUND_PILE_BODIES`] bodies of the compound `parts` (from
/// [`compound_parts`]) above it, at random orientations (the same for the same `seed`).
#[must_use]
pub fn compound_pile_scene(parts: Vec<Vec<DVec3>>, seed: u64) -> SceneSpec {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let mut spec = SceneSpec::default();
    add_box(&mut spec);
    let shape = spec.add_shape(ShapeSpec::Compound(parts));
    for i in 0..COMPOUND_PILE_BODIES {
        spec.add_body(BodyPlan {
            shape,
            position: layer_position(i, &mut rng),
            orientation: random_orientation(&mut rng),
            motion: Motion::Dynamic,
            margin_m: MARGIN_M,
        });
    }
    spec
}
