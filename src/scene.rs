//! The scene: registered shapes and the bodies placed with them.
//!
//! A [`Scene`] owns every shape registered for it (primitives, convex hulls, triangle meshes
//! with their BVHs, built once at registration) and every body (a shape at a pose, with a
//! motion kind, a collision filter and a close-pair margin). It is the state the daemon keeps
//! per scene and the pipeline reads each frame; it does no collision work itself beyond
//! keeping each body's world-space bounding box current for the broad phase.
//!
//! Ids are scoped to their scene (DESIGN §9: no assumption that would block splitting
//! scenes across daemons). Shape ids are never reused; a removed body's id is, by the next
//! body added, so a scene's tables stay as large as its most bodies alive at once, however
//! many come and go. Readers that keep answers per body tell a new body in an old slot by
//! its [`Body::version`], which never repeats within a scene.
//!
//! # Frames and motion
//! A scene counts the frames answered over it ([`Scene::end_frame`], called once a frame's
//! results are out). A body's motion over the current frame ([`Scene::frame_motion`]) runs
//! from the pose it had when the last frame was answered to its pose now: a body not moved
//! since is at rest, and a body added since the last answered frame is at rest too (its
//! first pose is not a pose any frame saw, so no sweep is invented from it). Time of impact
//! and swept boxes ([`Scene::swept_proxies`]) read it.
//!
//! # Change log
//! A scene lists the bodies that changed in the current frame ([`Scene::changes`]): added,
//! removed, moved by [`Scene::set_pose`] to a different pose, or changed by
//! [`Scene::update_body`], each id once, cleared by [`Scene::end_frame`]. With the scene's
//! process-unique id ([`Scene::uid`]; a clone gets a new one) and an edit counter, a reader
//! that kept its own state of the bodies (the pipeline's broad phase) learns from
//! [`Scene::changes_since`] which bodies to re-read, or that it must rebuild. The scene also
//! carries which broad phase its frames run ([`Scene::set_broad_phase`]).
//!
//! # Invariants
//! Checked by [`Scene::validate`]: every live body names a registered shape; its world box
//! is its shape's local box moved by its pose; no body's frame stamps are ahead of the
//! scene's frame count; the count of live bodies matches; the free slots are exactly the
//! empty ones.

use crate::bounding::{Aabb, BoundingVolume};
pub use crate::broad::CollisionFilter;
use crate::broad::{BroadPhaseChoice, Proxy};
use crate::math::{DVec3, Pose, conservative_slack};
use crate::narrow::Shape;
use crate::narrow::toi::{FrameMotion, swept_bounds};
use std::fmt;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

/// A shape's id within its scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ShapeId(pub u32);

/// A body's id within its scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct BodyId(pub u32);

/// How a body moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Motion {
    /// Never moves after it is added; two static bodies never pair.
    Static,
    /// Moved by the client, not by physics.
    Kinematic,
    /// Moved by the client's physics.
    Dynamic,
}

/// What a new body is made of.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyDesc {
    /// The shape, registered in the same scene.
    pub shape: ShapeId,
    /// Initial pose, world frame.
    pub pose: Pose,
    /// Motion kind.
    pub motion: Motion,
    /// Collision filter.
    pub filter: CollisionFilter,
    /// Close-pair margin, metres (`None`: the scene's default).
    pub margin: Option<f64>,
}

/// A body in a scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Body {
    /// Its shape.
    pub shape: ShapeId,
    /// Its pose, world frame.
    pub pose: Pose,
    /// Motion kind.
    pub motion: Motion,
    /// Collision filter.
    pub filter: CollisionFilter,
    /// Close-pair margin, metres, `≥ 0`.
    pub margin: f64,
    /// The shape's local box moved by `pose` (world frame), without the margin.
    pub world_bounds: Aabb,
    /// The pose this frame's motion starts from, when `moved_in` is the scene's current
    /// frame (see [`Scene::frame_motion`]).
    frame_start: Pose,
    /// The frame in which `frame_start` was recorded (the body's first move in it).
    moved_in: u64,
    /// The frame in which the body was added (it is at rest during that frame).
    added_in: u64,
    /// The frame in which the body's id was last put in the change log.
    logged_in: u64,
    /// The scene's edit count right after this body's last change ([`Body::version`]).
    version: u64,
}

impl Body {
    /// Changes whenever the body does (added, moved to another pose, motion, filter or
    /// margin updated) and never repeats within its scene: two reads of a body with the
    /// same version saw the same body. Answers that depend only on two bodies can be kept
    /// while both versions stay.
    #[must_use]
    pub fn version(&self) -> u64 {
        self.version
    }
}

/// Limits that keep one client from exhausting the daemon.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SceneLimits {
    /// Most shapes registered in one scene.
    pub max_shapes: u32,
    /// Most live bodies in one scene.
    pub max_bodies: u32,
    /// Most candidate pairs one frame answers (and, with `TOI`, most swept candidates): a
    /// frame whose broad phase finds more answers the first this many in its order and
    /// says how many it dropped ([`StepReport::dropped_candidates`]), so an n² pile-up
    /// costs bounded time and memory past the broad phase.
    ///
    /// [`StepReport::dropped_candidates`]: crate::pipeline::StepReport::dropped_candidates
    pub max_pairs_per_frame: u32,
}

impl SceneLimits {
    /// 4,096 shapes, 100,000 bodies and 16,384 pairs a frame (a result frame of at most
    /// 16,384 pairs with 4 contacts each: 9 MB).
    pub const STANDARD: Self = Self {
        max_shapes: 4_096,
        max_bodies: 100_000,
        max_pairs_per_frame: 16_384,
    };
}

/// Why a scene operation was refused. The scene is unchanged when one is returned.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum SceneError {
    /// No shape with this id in the scene.
    UnknownShape(ShapeId),
    /// No live body with this id in the scene.
    UnknownBody(BodyId),
    /// The scene already holds the most shapes its limits allow.
    TooManyShapes(u32),
    /// The scene already holds the most bodies its limits allow.
    TooManyBodies(u32),
    /// A margin is negative, NaN or infinite.
    InvalidMargin(f64),
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::UnknownShape(id) => write!(f, "no shape {} in this scene", id.0),
            Self::UnknownBody(id) => write!(f, "no body {} in this scene", id.0),
            Self::TooManyShapes(limit) => {
                write!(f, "the scene's limit of {limit} shapes is reached")
            }
            Self::TooManyBodies(limit) => {
                write!(f, "the scene's limit of {limit} bodies is reached")
            }
            Self::InvalidMargin(m) => write!(f, "margin {m} is not a finite length ≥ 0"),
        }
    }
}

impl std::error::Error for SceneError {}

/// Where a reader of a scene's bodies stood: which scene, which frame, how many edits had
/// been made ([`Scene::sync_point`], [`Scene::changes_since`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SyncPoint {
    uid: u64,
    frame: u64,
    edits: u64,
}

impl SyncPoint {
    /// [`Scene::uid`] of the scene it was taken on.
    #[must_use]
    pub fn scene_uid(&self) -> u64 {
        self.uid
    }
}

/// Source of [`Scene::uid`]s.
static NEXT_SCENE_UID: AtomicU64 = AtomicU64::new(1);

fn next_uid() -> u64 {
    NEXT_SCENE_UID.fetch_add(1, Ordering::Relaxed)
}

/// Shapes and bodies of one scene (see the [module docs](self)).
#[derive(Debug)]
pub struct Scene {
    /// Shared, copied on write: a frame's helper thread reads the table of the frame it
    /// helps ([`Scene::shape_table`]) while a later registration extends the scene's own.
    shapes: Arc<Vec<Shape>>,
    /// Whether any of `shapes` is a triangle mesh ([`Scene::has_mesh_shapes`]).
    any_mesh_shape: bool,
    /// Whether any of `shapes` is a mesh or a compound ([`Scene::has_tree_shapes`]).
    any_tree_shape: bool,
    /// `shape_boxes[i]` is shape `i`'s local box, computed once at registration.
    shape_boxes: Vec<LocalBox>,
    /// Slot `i` holds body `i` while it lives; removed bodies leave `None` until a new body
    /// takes the slot.
    bodies: Vec<Option<Body>>,
    /// The empty slots, most recently freed last, each with the frame it was last put in
    /// the change log (so an id removed and reused within one frame is logged once).
    free: Vec<(u32, u64)>,
    live: u32,
    /// Frames answered so far ([`Scene::end_frame`]): the current frame's number.
    frame: u64,
    default_margin: f64,
    limits: SceneLimits,
    /// Unique among the scenes of this process (clones included).
    uid: u64,
    /// Ids of the bodies changed in the current frame, each once (see the module docs).
    changes: Vec<u32>,
    /// Changes of bodies ever made (every add, remove, update, and move to a new pose).
    edits: u64,
    /// `edits` when the current frame began.
    edits_at_frame_start: u64,
    /// Which broad phase frames over this scene run.
    broad_phase: BroadPhaseChoice,
}

impl Clone for Scene {
    /// A copy with its own [`Scene::uid`]: readers synced to `self` rebuild for the copy.
    fn clone(&self) -> Self {
        Self {
            shapes: self.shapes.clone(),
            any_mesh_shape: self.any_mesh_shape,
            any_tree_shape: self.any_tree_shape,
            shape_boxes: self.shape_boxes.clone(),
            bodies: self.bodies.clone(),
            free: self.free.clone(),
            live: self.live,
            frame: self.frame,
            default_margin: self.default_margin,
            limits: self.limits,
            uid: next_uid(),
            changes: self.changes.clone(),
            edits: self.edits,
            edits_at_frame_start: self.edits_at_frame_start,
            broad_phase: self.broad_phase,
        }
    }
}

impl Scene {
    /// An empty scene whose bodies default to `default_margin` metres (finite, `≥ 0`).
    ///
    /// # Errors
    /// [`SceneError::InvalidMargin`] for a negative or non-finite margin.
    pub fn try_new(default_margin: f64, limits: SceneLimits) -> Result<Self, SceneError> {
        check_margin(default_margin)?;
        Ok(Self {
            shapes: Arc::new(Vec::new()),
            any_mesh_shape: false,
            any_tree_shape: false,
            shape_boxes: Vec::new(),
            bodies: Vec::new(),
            free: Vec::new(),
            live: 0,
            frame: 0,
            default_margin,
            limits,
            uid: next_uid(),
            changes: Vec::new(),
            edits: 0,
            edits_at_frame_start: 0,
            broad_phase: BroadPhaseChoice::Auto,
        })
    }

    /// The scene's limits.
    #[must_use]
    pub fn limits(&self) -> SceneLimits {
        self.limits
    }

    /// Registers `shape` for bodies of this scene.
    ///
    /// # Errors
    /// [`SceneError::TooManyShapes`] at the limit.
    pub fn register_shape(&mut self, shape: Shape) -> Result<ShapeId, SceneError> {
        self.register_prepared(PreparedShape::new(shape))
    }

    /// Registers a shape whose local box was measured beforehand: O(1), so a scene shared
    /// between threads can take it under a short lock.
    ///
    /// # Errors
    /// [`SceneError::TooManyShapes`] at the limit.
    pub fn register_prepared(&mut self, prepared: PreparedShape) -> Result<ShapeId, SceneError> {
        if self.shapes.len() >= self.limits.max_shapes as usize {
            return Err(SceneError::TooManyShapes(self.limits.max_shapes));
        }
        self.shape_boxes.push(prepared.local);
        self.any_mesh_shape |= matches!(prepared.shape, Shape::Mesh(_));
        self.any_tree_shape |= matches!(prepared.shape, Shape::Mesh(_) | Shape::Compound(_));
        let shapes = Arc::make_mut(&mut self.shapes);
        shapes.push(prepared.shape);
        Ok(ShapeId(shapes.len() as u32 - 1))
    }

    /// Whether any registered shape is a triangle mesh: without one the scene has no
    /// mesh–mesh pairs, and a frame skips looking for them (shapes are never removed).
    #[must_use]
    pub fn has_mesh_shapes(&self) -> bool {
        self.any_mesh_shape
    }

    /// Whether any registered shape is a mesh or a compound: without one no pair walks a
    /// tree, and a frame skips looking for such pairs.
    #[must_use]
    pub fn has_tree_shapes(&self) -> bool {
        self.any_tree_shape
    }

    /// The shape with id `id`, if registered.
    #[must_use]
    pub fn shape(&self, id: ShapeId) -> Option<&Shape> {
        self.shapes.get(id.0 as usize)
    }

    /// Every registered shape, indexed by [`ShapeId`]: a handle that stays as it is when the
    /// scene registers more (for a thread that reads a frame's shapes without borrowing
    /// the scene).
    #[must_use]
    pub fn shape_table(&self) -> Arc<Vec<Shape>> {
        Arc::clone(&self.shapes)
    }

    /// Every body slot, indexed by [`BodyId`] (`None`: no live body).
    #[must_use]
    pub fn body_slots(&self) -> &[Option<Body>] {
        &self.bodies
    }

    /// Adds a body.
    ///
    /// # Errors
    /// [`SceneError::UnknownShape`], [`SceneError::InvalidMargin`] or
    /// [`SceneError::TooManyBodies`]; the scene is then unchanged.
    pub fn add_body(&mut self, desc: &BodyDesc) -> Result<BodyId, SceneError> {
        let local = *self
            .shape_boxes
            .get(desc.shape.0 as usize)
            .ok_or(SceneError::UnknownShape(desc.shape))?;
        let margin = desc.margin.unwrap_or(self.default_margin);
        check_margin(margin)?;
        if self.live >= self.limits.max_bodies || self.bodies.len() >= u32::MAX as usize {
            return Err(SceneError::TooManyBodies(self.limits.max_bodies));
        }
        let world_bounds = local.world(&desc.pose);
        let body = Body {
            shape: desc.shape,
            pose: desc.pose,
            motion: desc.motion,
            filter: desc.filter,
            margin,
            world_bounds,
            frame_start: desc.pose,
            moved_in: self.frame,
            added_in: self.frame,
            logged_in: self.frame,
            version: self.edits + 1,
        };
        let id = match self.free.pop() {
            Some((id, logged_in)) => {
                self.bodies[id as usize] = Some(body);
                if logged_in != self.frame {
                    self.changes.push(id);
                }
                id
            }
            None => {
                self.bodies.push(Some(body));
                let id = self.bodies.len() as u32 - 1;
                self.changes.push(id);
                id
            }
        };
        self.live += 1;
        self.edits += 1;
        Ok(BodyId(id))
    }

    /// Removes a body; the next body added takes its id.
    ///
    /// # Errors
    /// [`SceneError::UnknownBody`] when no such body lives.
    pub fn remove_body(&mut self, id: BodyId) -> Result<Body, SceneError> {
        let body = self
            .bodies
            .get_mut(id.0 as usize)
            .and_then(Option::take)
            .ok_or(SceneError::UnknownBody(id))?;
        self.live -= 1;
        if body.logged_in != self.frame {
            self.changes.push(id.0);
        }
        self.free.push((id.0, self.frame));
        self.edits += 1;
        Ok(body)
    }

    /// Changes a body's motion kind, filter and margin (`None`: the scene's default).
    ///
    /// # Errors
    /// [`SceneError::UnknownBody`] or [`SceneError::InvalidMargin`]; the body is then
    /// unchanged.
    pub fn update_body(
        &mut self,
        id: BodyId,
        motion: Motion,
        filter: CollisionFilter,
        margin: Option<f64>,
    ) -> Result<(), SceneError> {
        let margin = margin.unwrap_or(self.default_margin);
        check_margin(margin)?;
        let frame = self.frame;
        let Some(Some(body)) = self.bodies.get_mut(id.0 as usize) else {
            return Err(SceneError::UnknownBody(id));
        };
        body.motion = motion;
        body.filter = filter;
        body.margin = margin;
        if body.logged_in != frame {
            body.logged_in = frame;
            self.changes.push(id.0);
        }
        self.edits += 1;
        body.version = self.edits;
        Ok(())
    }

    /// Moves a body to `pose` (already validated: see [`Pose::try_new`]) and updates its
    /// world box. The first move of a frame also records where the frame's motion starts
    /// (see [`Scene::frame_motion`]).
    ///
    /// # Errors
    /// [`SceneError::UnknownBody`].
    pub fn set_pose(&mut self, id: BodyId, pose: Pose) -> Result<(), SceneError> {
        // Field borrows (not a helper returning `&mut Body`), so the local box is read in place: a copy of it
        // on the stack read back whole stalled store forwarding (20 → 2 ns per body).
        let Some(Some(body)) = self.bodies.get_mut(id.0 as usize) else {
            return Err(SceneError::UnknownBody(id));
        };
        // Unmoved: the world box is still right.
        if body.pose != pose {
            // A plain copy of a pose stored frames ago (no store-forwarding hazard), once
            // per body and frame.
            if body.moved_in != self.frame {
                body.frame_start = body.pose;
                body.moved_in = self.frame;
            }
            body.world_bounds = self.shape_boxes[body.shape.0 as usize].world(&pose);
            body.pose = pose;
            if body.logged_in != self.frame {
                body.logged_in = self.frame;
                self.changes.push(id.0);
            }
            self.edits += 1;
            body.version = self.edits;
        }
        Ok(())
    }

    /// Ends the current frame: every body's pose now is where its motion over the next
    /// frame starts, and the change log starts empty. The daemon calls it once a frame's
    /// results are published; O(1).
    pub fn end_frame(&mut self) {
        self.frame += 1;
        self.changes.clear();
        self.edits_at_frame_start = self.edits;
    }

    /// The current frame's number: frames answered so far ([`Scene::end_frame`]).
    #[must_use]
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// This scene's id, unique among the scenes (and clones) of this process.
    #[must_use]
    pub fn uid(&self) -> u64 {
        self.uid
    }

    /// Ids of the bodies changed in the current frame (added, removed, moved to another
    /// pose, updated), each once, in the order of their first change. Removed bodies stay
    /// listed; a body added and removed in the same frame is listed once.
    #[must_use]
    pub fn changes(&self) -> &[u32] {
        &self.changes
    }

    /// Where a reader that has just read every body stands.
    #[must_use]
    pub fn sync_point(&self) -> SyncPoint {
        SyncPoint {
            uid: self.uid,
            frame: self.frame,
            edits: self.edits,
        }
    }

    /// The bodies to re-read to catch up from `point` (taken with [`Scene::sync_point`]),
    /// or `None` when the log cannot tell and the reader must read every body: another
    /// scene, an older frame than the previous one, or the previous frame changed after
    /// `point` (the log of that frame is gone).
    ///
    /// In the same frame as `point` it is the whole current log: a superset of what changed
    /// since (a body moved twice in one frame is logged once), so re-reading the listed
    /// bodies must be idempotent. Each listed id is a live body (re-read it) or a removed
    /// one (forget it).
    #[must_use]
    pub fn changes_since(&self, point: SyncPoint) -> Option<&[u32]> {
        let current = point.uid == self.uid
            && (point.frame == self.frame
                || (point.frame + 1 == self.frame && point.edits == self.edits_at_frame_start));
        current.then_some(self.changes.as_slice())
    }

    /// Which broad phase frames over this scene run: [`BroadPhaseChoice::Auto`] (the
    /// default) or a fixed one.
    #[must_use]
    pub fn broad_phase(&self) -> BroadPhaseChoice {
        self.broad_phase
    }

    /// Sets which broad phase frames over this scene run (from the next frame on; results
    /// do not depend on it, only their cost).
    pub fn set_broad_phase(&mut self, choice: BroadPhaseChoice) {
        self.broad_phase = choice;
    }

    /// The broad-phase view of one live body: what [`Scene::proxies`] lists for it.
    #[must_use]
    pub fn proxy(&self, id: BodyId) -> Option<Proxy> {
        self.body(id).map(|body| proxy_of(id, body))
    }

    /// The motion of `body` (a live body of this scene) over the current frame: from its
    /// pose when the last frame was answered ([`Scene::end_frame`]) to its pose now, world
    /// frame. At rest when it has not moved since, or was added since.
    #[must_use]
    pub fn frame_motion(&self, body: &Body) -> FrameMotion {
        if body.moved_in == self.frame && body.added_in != self.frame {
            FrameMotion {
                start: body.frame_start,
                end: body.pose,
            }
        } else {
            FrameMotion::at_rest(body.pose)
        }
    }

    /// The largest distance of a point of `body`'s shape from the body's origin that can
    /// move by rotating, metres: 0 for a sphere (rotation about its centre moves nothing),
    /// else the farthest vertex or local box corner. Bounds the speed of a turning shape.
    #[must_use]
    pub fn reach(&self, body: &Body) -> f64 {
        self.shape_boxes[body.shape.0 as usize].reach
    }

    /// The world box of `body`'s shape were the body at `pose` (its
    /// [`world_bounds`](Body::world_bounds) at its own pose).
    #[must_use]
    pub fn bounds_at(&self, body: &Body, pose: &Pose) -> Aabb {
        self.shape_boxes[body.shape.0 as usize].world(pose)
    }

    /// Like [`Scene::proxies`], but each box covers the body's whole motion over the
    /// current frame ([`swept_bounds`] of [`Scene::frame_motion`], merged with the world
    /// box), grown by its margin: the broad-phase input of time of impact. A body at rest
    /// gets exactly its [`Scene::proxies`] box.
    ///
    /// # Allocation
    /// None once `out` holds as many proxies as there are bodies.
    pub fn swept_proxies(&self, out: &mut Vec<Proxy>) {
        out.clear();
        out.extend(self.bodies().map(|(id, body)| {
            let motion = self.frame_motion(body);
            let bounds = if motion.start == motion.end {
                body.world_bounds
            } else {
                let local = &self.shape_boxes[body.shape.0 as usize];
                let local_box = Aabb::from_center_half_extents(local.center, local.half);
                // The end boxes are padded for rounding by `transformed`; the world box
                // (the end pose) keeps the sphere's own padding.
                swept_bounds(&local_box, local.reach, &motion).merged(&body.world_bounds)
            };
            Proxy {
                body: id.0,
                bounds: bounds.grown(body.margin),
                is_static: body.motion == Motion::Static,
                filter: body.filter,
            }
        }));
    }

    /// The live body with id `id`.
    #[must_use]
    pub fn body(&self, id: BodyId) -> Option<&Body> {
        self.bodies.get(id.0 as usize).and_then(Option::as_ref)
    }

    /// Every live body with its id, in increasing id order.
    pub fn bodies(&self) -> impl Iterator<Item = (BodyId, &Body)> {
        self.bodies
            .iter()
            .enumerate()
            .filter_map(|(i, b)| b.as_ref().map(|b| (BodyId(i as u32), b)))
    }

    /// The broad-phase view of every live body, in increasing id order, into `out`
    /// (cleared first): world boxes grown by each body's margin.
    ///
    /// # Allocation
    /// None once `out` holds as many proxies as there are bodies.
    pub fn proxies(&self, out: &mut Vec<Proxy>) {
        out.clear();
        out.extend(self.bodies().map(|(id, body)| proxy_of(id, body)));
    }

    /// Number of live bodies.
    #[must_use]
    pub fn body_count(&self) -> usize {
        self.live as usize
    }

    /// Checks the invariants in the [module docs](self).
    ///
    /// # Errors
    /// A description of the first broken invariant.
    pub fn validate(&self) -> Result<(), String> {
        let mut live = 0;
        for (id, body) in self.bodies() {
            live += 1;
            let shape = self
                .shape(body.shape)
                .ok_or_else(|| format!("body {} names unknown shape {}", id.0, body.shape.0))?;
            if body.world_bounds != LocalBox::of(shape).world(&body.pose) {
                return Err(format!("body {} has a stale world box", id.0));
            }
            if body.moved_in > self.frame
                || body.added_in > body.moved_in
                || body.logged_in > self.frame
                || body.added_in > body.logged_in
            {
                return Err(format!("body {} has frame stamps out of order", id.0));
            }
            let logged = self.changes.contains(&id.0);
            if logged != (body.logged_in == self.frame) {
                return Err(format!("body {} logged {logged}, stamp disagrees", id.0));
            }
        }
        if live != self.live {
            return Err(format!("{live} live bodies, {} counted", self.live));
        }
        let mut free: Vec<u32> = self.free.iter().map(|&(id, _)| id).collect();
        free.sort_unstable();
        free.dedup();
        let all_empty = free
            .iter()
            .all(|&id| self.bodies.get(id as usize).is_some_and(Option::is_none));
        if !all_empty || free.len() + live as usize != self.bodies.len() {
            return Err("the free slots are not exactly the empty ones".into());
        }
        let mut ids = self.changes.clone();
        ids.sort_unstable();
        if ids.windows(2).any(|w| w[0] == w[1])
            || ids.last().is_some_and(|&i| i as usize >= self.bodies.len())
        {
            return Err("the change log repeats an id or names an unknown body".into());
        }
        if self.edits < self.edits_at_frame_start {
            return Err("edit count went backwards".into());
        }
        Ok(())
    }
}

/// The broad-phase view of body `id`: its world box grown by its margin.
fn proxy_of(id: BodyId, body: &Body) -> Proxy {
    Proxy {
        body: id.0,
        bounds: body.world_bounds.grown(body.margin),
        is_static: body.motion == Motion::Static,
        filter: body.filter,
    }
}

/// A shape with its local box measured ([`Scene::register_prepared`]): the O(n) part of
/// registering a convex or mesh shape (its farthest vertex), done before the scene is
/// touched.
#[derive(Debug, Clone)]
pub struct PreparedShape {
    shape: Shape,
    local: LocalBox,
}

impl PreparedShape {
    /// Measures `shape`'s local box.
    #[must_use]
    pub fn new(shape: Shape) -> Self {
        let local = LocalBox::of(&shape);
        Self { shape, local }
    }
}

/// A shape's local box (centre and half extents, computed once at registration), and
/// whether every rotation leaves it unchanged (a sphere's), so a new pose only moves it.
#[derive(Debug, Clone, Copy)]
struct LocalBox {
    center: DVec3,
    half: DVec3,
    rotation_invariant: bool,
    /// See [`Scene::reach`].
    reach: f64,
}

impl LocalBox {
    fn of(shape: &Shape) -> Self {
        let aabb = shape.local_bounds();
        let farthest = |points: &[DVec3]| points.iter().map(|p| p.length()).fold(0.0, f64::max);
        let reach = match shape {
            Shape::Sphere(_) => 0.0,
            Shape::Convex(c) => farthest(c.vertices()),
            Shape::Mesh(m) => farthest(m.mesh.vertices()),
            _ => aabb.min.abs().max(aabb.max.abs()).length(),
        };
        Self {
            center: aabb.center(),
            half: aabb.half_extents(),
            rotation_invariant: matches!(shape, Shape::Sphere(_)),
            // Rounding of the lengths: never below the truth.
            reach: reach * (1.0 + 4.0 * f64::EPSILON),
        }
    }

    /// The world box at `pose`, padded by the rounding slack (conservative).
    // PERF: always inlined: returned through the stack, the box was written in 8-byte and
    // read in 16-byte pieces, a store-forwarding stall per body (see `set_pose`).
    #[inline(always)]
    fn world(&self, pose: &Pose) -> Aabb {
        if self.rotation_invariant {
            // A ball about the local origin: its box about the position.
            let magnitude = pose.position.abs().max_element() + self.half.max_element();
            let half = self.half + DVec3::splat(conservative_slack(magnitude));
            return Aabb::from_center_half_extents(pose.position, half);
        }
        Aabb::from_center_half_extents(self.center, self.half).transformed(&pose.to_isometry())
    }
}

fn check_margin(margin: f64) -> Result<(), SceneError> {
    if margin.is_finite() && margin >= 0.0 {
        Ok(())
    } else {
        Err(SceneError::InvalidMargin(margin))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Capsule, Cone, ConvexPolyhedron, Cuboid, Cylinder, Sphere};
    use crate::narrow::{CompoundShape, MeshShape};
    use crate::test_support::{meshes, pose, rng};
    use std::sync::Arc;

    fn scene() -> Scene {
        Scene::try_new(
            0.01,
            SceneLimits {
                max_shapes: 4,
                max_bodies: 3,
                ..SceneLimits::STANDARD
            },
        )
        .unwrap()
    }

    fn desc(shape: ShapeId, pose: Pose) -> BodyDesc {
        BodyDesc {
            shape,
            pose,
            motion: Motion::Dynamic,
            filter: CollisionFilter::ALL,
            margin: None,
        }
    }

    #[test]
    fn a_scene_knows_whether_it_holds_a_mesh_shape_and_its_clone_too() {
        let mut s = scene();
        assert!(!s.has_mesh_shapes());
        s.register_shape(Shape::Sphere(Sphere::new(0.5))).unwrap();
        s.register_shape(Shape::Cuboid(Cuboid::new(DVec3::splat(0.5))))
            .unwrap();
        assert!(!s.has_mesh_shapes(), "primitives are not meshes");
        let mesh = MeshShape::new(meshes::torus(1.0, 0.25, 12, 6));
        s.register_shape(Shape::Mesh(Arc::new(mesh))).unwrap();
        assert!(s.has_mesh_shapes());
        assert!(s.clone().has_mesh_shapes());
    }

    #[test]
    fn world_boxes_contain_the_shape_at_every_pose_and_follow_set_pose() {
        let mut s = Scene::try_new(0.0, SceneLimits::STANDARD).unwrap();
        let torus = meshes::torus(1.0, 0.25, 24, 12);
        let points: Vec<DVec3> = torus.vertices().to_vec();
        let shifted: Vec<DVec3> = points
            .iter()
            .map(|&p| p + DVec3::new(3.0, 0.0, 1.0))
            .collect();
        let shapes = [
            Shape::Sphere(Sphere::new(0.5)),
            Shape::Capsule(Capsule::new(1.0, 0.25)),
            Shape::Cuboid(Cuboid::new(DVec3::new(0.1, 2.0, 0.3))),
            Shape::Cylinder(Cylinder::new(0.7, 0.2)),
            Shape::Cone(Cone::new(0.7, 0.2)),
            Shape::Convex(Arc::new(
                ConvexPolyhedron::try_from_points(&points).unwrap(),
            )),
            Shape::Mesh(Arc::new(MeshShape::new(torus.clone()))),
            Shape::Compound(Arc::new(
                CompoundShape::from_hulls(vec![
                    ConvexPolyhedron::try_from_points(&points).unwrap(),
                    ConvexPolyhedron::try_from_points(&shifted).unwrap(),
                ])
                .unwrap(),
            )),
        ];
        let ids: Vec<ShapeId> = shapes
            .into_iter()
            .map(|sh| s.register_shape(sh).unwrap())
            .collect();
        let mut rng = rng(41);
        for case in 0..2_000 {
            let id = ids[case % ids.len()];
            let body = s.add_body(&desc(id, pose(&mut rng, 1e3))).unwrap();
            s.set_pose(body, pose(&mut rng, 1e5)).unwrap();
            let b = *s.body(body).unwrap();
            // Surface samples of the shape, moved by the pose, must lie in the world box.
            let local: Vec<DVec3> = match s.shape(id).unwrap() {
                // The ball's world extremes (its box is computed without the rotation).
                Shape::Sphere(sp) => [DVec3::X, DVec3::Y, DVec3::Z]
                    .into_iter()
                    .flat_map(|axis| [axis, -axis])
                    .map(|dir| b.pose.rotation.inverse() * dir * sp.radius)
                    .collect(),
                Shape::Capsule(c) => {
                    vec![DVec3::Z * (c.half_height + c.radius), DVec3::X * c.radius]
                }
                Shape::Cuboid(c) => vec![c.half_extents, -c.half_extents],
                Shape::Cylinder(c) => vec![DVec3::new(c.radius, 0.0, c.half_height)],
                Shape::Cone(c) => vec![
                    DVec3::new(0.0, -c.radius, -c.half_height),
                    DVec3::Z * c.half_height,
                ],
                Shape::Convex(_) | Shape::Mesh(_) => points.clone(),
                Shape::Compound(_) => [points.clone(), shifted.clone()].concat(),
            };
            let iso = b.pose.to_isometry();
            for p in local {
                assert!(
                    b.world_bounds.contains_point(iso.transform_point(p)),
                    "case {case}"
                );
            }
            s.remove_body(body).unwrap();
        }
        assert_eq!(s.validate(), Ok(()));
        assert_eq!(s.body_count(), 0);
    }

    #[test]
    fn bad_requests_are_refused_and_leave_the_scene_unchanged() {
        let mut s = scene();
        let sphere = s.register_shape(Shape::Sphere(Sphere::new(1.0))).unwrap();
        let a = s.add_body(&desc(sphere, Pose::IDENTITY)).unwrap();
        let before = format!("{s:?}");
        assert_eq!(
            s.add_body(&desc(ShapeId(9), Pose::IDENTITY)),
            Err(SceneError::UnknownShape(ShapeId(9)))
        );
        let bad_margin = BodyDesc {
            margin: Some(f64::NAN),
            ..desc(sphere, Pose::IDENTITY)
        };
        assert!(matches!(
            s.add_body(&bad_margin),
            Err(SceneError::InvalidMargin(_))
        ));
        assert!(matches!(
            s.update_body(a, Motion::Static, CollisionFilter::ALL, Some(-1.0)),
            Err(SceneError::InvalidMargin(_))
        ));
        assert_eq!(
            s.set_pose(BodyId(7), Pose::IDENTITY),
            Err(SceneError::UnknownBody(BodyId(7)))
        );
        assert_eq!(format!("{s:?}"), before);
        // Limits, and a removed body's id taken by the next body, with a new version.
        let b = s.add_body(&desc(sphere, Pose::IDENTITY)).unwrap();
        s.add_body(&desc(sphere, Pose::IDENTITY)).unwrap();
        assert_eq!(
            s.add_body(&desc(sphere, Pose::IDENTITY)),
            Err(SceneError::TooManyBodies(3))
        );
        let old_version = s.body(b).unwrap().version();
        s.remove_body(b).unwrap();
        assert_eq!(s.remove_body(b), Err(SceneError::UnknownBody(b)));
        let d = s.add_body(&desc(sphere, Pose::IDENTITY)).unwrap();
        assert_eq!(d, b);
        assert!(s.body(d).unwrap().version() > old_version);
        for _ in 0..3 {
            s.register_shape(Shape::Sphere(Sphere::new(1.0))).unwrap();
        }
        assert!(matches!(
            s.register_shape(Shape::Sphere(Sphere::new(1.0))),
            Err(SceneError::TooManyShapes(4))
        ));
        assert_eq!(s.validate(), Ok(()));
        assert!(Scene::try_new(-0.1, SceneLimits::STANDARD).is_err());
    }

    #[test]
    fn proxies_grow_world_boxes_by_margins_and_mark_static_bodies() {
        let mut s = Scene::try_new(0.1, SceneLimits::STANDARD).unwrap();
        let sphere = s.register_shape(Shape::Sphere(Sphere::new(1.0))).unwrap();
        let a = s.add_body(&desc(sphere, Pose::IDENTITY)).unwrap();
        let wall = BodyDesc {
            motion: Motion::Static,
            margin: Some(0.5),
            ..desc(sphere, Pose::from_translation(DVec3::X * 2.55))
        };
        let b = s.add_body(&wall).unwrap();
        let mut proxies = Vec::new();
        s.proxies(&mut proxies);
        assert_eq!(proxies.len(), 2);
        assert_eq!((proxies[0].body, proxies[1].body), (a.0, b.0));
        // Radius 1 + margin 0.1, plus the world box's rounding pad (conservative, tiny).
        let reach = proxies[0].bounds.max.x;
        assert!((1.1..1.1 + 1e-9).contains(&reach), "{reach}");
        assert!(!proxies[0].is_static && proxies[1].is_static);
        // 0.55 m apart, margins 0.1 + 0.5: a candidate pair.
        let mut pairs = Vec::new();
        crate::broad::pairs_brute_force(&proxies, &mut pairs);
        assert_eq!(pairs, [crate::broad::CandidatePair { a: a.0, b: b.0 }]);
    }

    /// Motion starts where the last answered frame left a body: bodies added since and
    /// bodies not moved since are at rest, a second move in one frame keeps the start, and
    /// each swept box holds the body's world box at every sampled time of its motion (a
    /// resting body's is exactly its proxy box).
    #[test]
    fn frame_motion_starts_at_the_last_answered_pose_and_swept_boxes_cover_it() {
        let mut s = Scene::try_new(0.05, SceneLimits::STANDARD).unwrap();
        let torus = meshes::torus(1.0, 0.25, 12, 6);
        let shapes = [
            Shape::Sphere(Sphere::new(0.5)),
            Shape::Capsule(Capsule::new(1.0, 0.25)),
            Shape::Cuboid(Cuboid::new(DVec3::new(0.1, 2.0, 0.3))),
            Shape::Cone(Cone::new(0.7, 0.2)),
            Shape::Mesh(Arc::new(MeshShape::new(torus))),
        ];
        let ids: Vec<ShapeId> = shapes
            .iter()
            .map(|sh| s.register_shape(sh.clone()).unwrap())
            .collect();
        let mut rng = rng(43);
        let (mut proxies, mut swept) = (Vec::new(), Vec::new());
        for case in 0..300 {
            let shape = ids[case % ids.len()];
            let (p0, p1, p2, p3) = (
                pose(&mut rng, 10.0),
                pose(&mut rng, 10.0),
                pose(&mut rng, 10.0),
                pose(&mut rng, 10.0),
            );
            let id = s.add_body(&desc(shape, p0)).unwrap();
            // Added this frame: at rest even when moved.
            s.set_pose(id, p1).unwrap();
            assert_eq!(
                s.frame_motion(s.body(id).unwrap()),
                FrameMotion::at_rest(p1)
            );
            s.end_frame();
            assert_eq!(
                s.frame_motion(s.body(id).unwrap()),
                FrameMotion::at_rest(p1)
            );
            s.set_pose(id, p2).unwrap();
            s.set_pose(id, p3).unwrap();
            let motion = s.frame_motion(s.body(id).unwrap());
            assert_eq!(motion, FrameMotion { start: p1, end: p3 }, "case {case}");
            s.proxies(&mut proxies);
            s.swept_proxies(&mut swept);
            let body = *s.body(id).unwrap();
            // The swept box without the margin (plus rounding room).
            let sweep = swept.iter().find(|p| p.body == id.0).unwrap().bounds;
            let inner = DVec3::splat(body.margin - 1e-9);
            let sweep = Aabb::new(sweep.min + inner, sweep.max - inner);
            let local = s.shape(shape).unwrap().local_bounds();
            for i in 0..=32 {
                let at = motion.pose_at(f64::from(i) / 32.0);
                // Extreme points of the shape at time t: its vertices, its local box's
                // corners (their distance from the origin is the reach), a ball's poles.
                let points: Vec<DVec3> = match s.shape(shape).unwrap() {
                    Shape::Sphere(b) => [DVec3::X, DVec3::Y, DVec3::Z]
                        .into_iter()
                        .flat_map(|d| [at.position + d * b.radius, at.position - d * b.radius])
                        .collect(),
                    Shape::Mesh(m) => m
                        .mesh
                        .vertices()
                        .iter()
                        .map(|&v| at.transform_point(v))
                        .collect(),
                    _ => (0..8)
                        .map(|c| {
                            let pick =
                                |bit: u32, lo: f64, hi: f64| if c & bit == 0 { lo } else { hi };
                            at.transform_point(DVec3::new(
                                pick(1, local.min.x, local.max.x),
                                pick(2, local.min.y, local.max.y),
                                pick(4, local.min.z, local.max.z),
                            ))
                        })
                        .collect(),
                };
                for p in points {
                    assert!(sweep.contains_point(p), "case {case}: t = {i}/32");
                }
            }
            s.end_frame();
            // Not moved since: at rest, and the swept box is the proxy box.
            s.set_pose(id, p3).unwrap();
            assert_eq!(
                s.frame_motion(s.body(id).unwrap()),
                FrameMotion::at_rest(p3)
            );
            s.proxies(&mut proxies);
            s.swept_proxies(&mut swept);
            assert_eq!(proxies, swept);
            assert_eq!(s.validate(), Ok(()));
            s.remove_body(id).unwrap();
        }
    }

    /// The log covers the gap from a sync point only when nothing it cannot see happened:
    /// same frame (the whole log), the next frame with no edit after the point, never a
    /// frame later, another scene or a clone.
    #[test]
    fn changes_since_a_sync_point_are_given_only_when_the_log_covers_them() {
        let mut s = Scene::try_new(0.0, SceneLimits::STANDARD).unwrap();
        let sphere = s.register_shape(Shape::Sphere(Sphere::new(1.0))).unwrap();
        let a = s.add_body(&desc(sphere, Pose::IDENTITY)).unwrap();
        let b = s.add_body(&desc(sphere, Pose::IDENTITY)).unwrap();
        let at = |x: f64| Pose::from_translation(DVec3::X * x);
        let point = s.sync_point();
        assert_eq!(s.changes_since(point), Some(&[a.0, b.0][..]));
        s.set_pose(a, at(1.0)).unwrap(); // logged already: once
        assert_eq!(s.changes_since(point), Some(&[a.0, b.0][..]));
        let synced = s.sync_point();
        s.end_frame();
        // Nothing after `synced`: the new frame's log is all there is to read; `point`
        // missed the move.
        assert_eq!(s.changes_since(synced), Some(&[][..]));
        assert_eq!(s.changes_since(point), None);
        let point = s.sync_point();
        s.set_pose(b, at(2.0)).unwrap();
        s.set_pose(a, at(1.0)).unwrap(); // unchanged pose: not a change
        s.update_body(a, Motion::Static, CollisionFilter::ALL, None)
            .unwrap();
        s.set_pose(b, at(3.0)).unwrap();
        assert_eq!(s.changes_since(point), Some(&[b.0, a.0][..]));
        let synced = s.sync_point();
        s.remove_body(a).unwrap(); // after the step of this frame
        s.end_frame();
        assert_eq!(
            s.changes_since(synced),
            None,
            "an edit after the point is lost"
        );
        let point = s.sync_point();
        s.end_frame();
        s.end_frame();
        assert_eq!(s.changes_since(point), None, "a skipped frame");
        let point = s.sync_point();
        let copy = s.clone();
        assert_ne!(copy.uid(), s.uid());
        assert_eq!(copy.changes_since(point), None);
        assert_eq!(s.changes_since(point), Some(&[][..]));
        let other = Scene::try_new(0.0, SceneLimits::STANDARD).unwrap();
        assert_eq!(other.changes_since(point), None);
        assert_eq!(s.validate(), Ok(()));
    }

    #[test]
    fn filters_pair_only_when_both_groups_meet_the_other_mask() {
        let (a, b) = (
            CollisionFilter {
                group: 0b01,
                mask: 0b10,
            },
            CollisionFilter {
                group: 0b10,
                mask: 0b01,
            },
        );
        let c = CollisionFilter {
            group: 0b10,
            mask: 0b10,
        };
        assert!(a.allows(&b) && b.allows(&a));
        assert!(!a.allows(&c) && !c.allows(&a));
        assert!(CollisionFilter::ALL.allows(&a));
    }
}
