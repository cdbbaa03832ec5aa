//! A scene as the daemon's threads share it: the frame thread answers its frames, the control
//! thread edits its bodies, the builder thread hands it the shapes it has built.
//!
//! One mutex per scene. The frame thread holds it for one frame; the control thread and the
//! builder hold it only for O(1) edits (a body added, removed or updated, a shape id handed
//! out, a built shape registered), never to decode or build. So a frame waits for control
//! work at most one such edit; the control thread never waits for a frame (it tries the
//! lock, and asks again later). A dropped scene is marked [`dropped`](SceneCell::dropped):
//! a thread that still holds it (a frame taken before the drop, a build finishing after it)
//! leaves it alone. What must reach a frame in progress without the lock goes through the
//! scene's [`SceneSignals`].

use super::shape_table::ShapeTable;
use crate::pipeline::Abandon;
use crate::scene::Scene;
use std::sync::atomic::{AtomicBool, Ordering};
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

/// What the control thread tells a scene's frames at any moment, without the scene's lock
/// (which a frame in progress holds). Clones share the signals.
#[derive(Debug, Clone, Default)]
pub struct SceneSignals {
    /// Stops the frame in progress at its next poll (its answers then conservative).
    abandon: Abandon,
    /// Frames answered from now on say `OWNER_GONE`, and so does the release frame.
    owner_gone: Arc<AtomicBool>,
}

impl SceneSignals {
    /// Fresh signals, none raised.
    #[must_use]
    pub fn new() -> Self {
        Self {
            abandon: Abandon::new(),
            owner_gone: Arc::default(),
        }
    }

    /// The scene's owner is gone: its frames' work is abandoned from now on, and they say so.
    pub fn owner_gone(&self) {
        self.owner_gone.store(true, Ordering::Relaxed);
        self.abandon.raise();
    }

    /// The scene is being let go of: the frame in progress, if any, stops at its next poll.
    pub fn releasing(&self) {
        self.abandon.raise();
    }

    /// The flag the scene's frame work polls.
    #[must_use]
    pub fn abandon(&self) -> &Abandon {
        &self.abandon
    }

    /// Whether the owner is gone.
    #[must_use]
    pub fn is_owner_gone(&self) -> bool {
        self.owner_gone.load(Ordering::Relaxed)
    }
}
