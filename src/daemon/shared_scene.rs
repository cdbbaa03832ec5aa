//! A scene as the daemon's threads share it: the frame thread answers its frames, the control
//! thread edits its bodies, the builder thread hands it the shapes it has built.
//!
//! One mutex per scene. The frame thread holds it for one frame; the control thread and the
//! builder hold it only for O(1) edits (a body added, removed or updated, a shape id handed
//! out, a built shape registered), never to decode or build. So a frame waits for control
//! work at most one such edit, and control work waits at most one frame. A dropped scene is
//! marked [`dropped`](SceneCell::dropped): a thread that still holds it (a frame taken
//! before the drop, a build finishing after it) leaves it alone.

use super::shape_table::ShapeTable;
use crate::scene::Scene;
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

/// A scene, its wire shape ids and whether it was dropped.
#[derive(Debug)]
pub struct SceneCell {
    /// Shapes that are built, and bodies.
    pub scene: Scene,
    /// Every shape id handed out, built or not.
    pub shapes: ShapeTable,
    /// Set once, when the scene is dropped (by request or because its owner is gone).
    pub dropped: bool,
}

/// A scene shared between the daemon's threads.
pub type SharedScene = Arc<Mutex<SceneCell>>;

/// A new shared scene.
#[must_use]
pub fn share(scene: Scene) -> SharedScene {
    Arc::new(Mutex::new(SceneCell {
        scene,
        shapes: ShapeTable::default(),
        dropped: false,
    }))
}

/// Locks `scene`. A lock poisoned by a thread that panicked while holding it is taken over:
/// the daemon stops once any of its threads panics, so nothing builds on that state for long,
/// and no other thread panics on the way out.
pub fn lock(scene: &SharedScene) -> MutexGuard<'_, SceneCell> {
    scene.lock().unwrap_or_else(PoisonError::into_inner)
}
