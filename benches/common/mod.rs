//! Helpers shared by the benches: timing over a cyclic sequence of inputs, and the mesh
//! scenes of the mesh–mesh benches.
//!
//! Include with `mod common;` from a bench file; it expects the test support module to be
//! declared at the crate root as `support` (`#[path = "../tests/support/mod.rs"] mod support;`).

pub mod cycle;
pub mod mesh_scenes;
