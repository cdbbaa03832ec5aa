//! A scene as plain data: the shapes to register and the bodies to add, in order.
//!
//! One description gives both the daemon's scene, over the protocol ([`SceneSpec::register`]),
//! and an in-process copy built the way the daemon builds it ([`SceneSpec::local_scene`],
//! the shapes as `daemon/convert.rs` makes them). A tool can then check the daemon's
//! answers against the library's on the same shapes and poses, and a bench can run the
//! same scene without a daemon. Registered in a fresh scene, body `i` of the list gets id
//! `i` on both sides.

use glam::{DQuat, DVec3};
use iceoryx2::prelude::ipc;
use proxima::geometry::{
    Capsule, Cone, ConvexPolyhedron, Cuboid, Cylinder, MeshError, Sphere, TriMesh,
};
use proxima::math::Pose;
use proxima::narrow::{CompoundShape, MeshShape, Shape};
use proxima::scene::{BodyDesc, CollisionFilter, Motion as LocalMotion, Scene, SceneLimits};
use proxima_ipc::client::{BodySpec, Client, Motion, Primitive};
use proxima_ipc::error::ControlError;
use std::error::Error;
use std::sync::Arc;

/// A shape to register.
#[derive(Debug, Clone)]
pub enum ShapeSpec {
    /// A closed-form shape.
    Primitive(Primitive),
    /// The convex hull of these points, metres, the shape's local frame.
    Convex(Vec<DVec3>),
    /// A triangle mesh, metres, the shape's local frame.
    Mesh(Arc<TriMesh>),
    /// A solid of convex parts, each the hull of its points (metres, local frame).
    Compound(Vec<Vec<DVec3>>),
}

impl ShapeSpec {
    /// The library's shape, built as the daemon builds it from the wire (the same
    /// constructors, the mesh re-read from its vertices and triangles).
    ///
    /// # Errors
    /// The hull or mesh is invalid (the daemon would refuse it too).
    pub fn library_shape(&self) -> Result<Shape, Box<dyn Error>> {
        Ok(match *self {
            Self::Primitive(Primitive::Sphere { radius }) => Shape::Sphere(Sphere::new(radius)),
            Self::Primitive(Primitive::Capsule {
                radius,
                half_height,
            }) => Shape::Capsule(Capsule::new(half_height, radius)),
            Self::Primitive(Primitive::Cuboid { half_extents }) => {
                Shape::Cuboid(Cuboid::new(DVec3::from_array(half_extents)))
            }
            Self::Primitive(Primitive::Cylinder {
                radius,
                half_height,
            }) => Shape::Cylinder(Cylinder::new(half_height, radius)),
            Self::Primitive(Primitive::Cone {
                radius,
                half_height,
            }) => Shape::Cone(Cone::new(half_height, radius)),
            Self::Convex(ref points) => {
                Shape::Convex(Arc::new(ConvexPolyhedron::try_from_points(points)?))
            }
            Self::Mesh(ref mesh) => {
                let copy: Result<TriMesh, MeshError> =
                    TriMesh::try_new(mesh.vertices().to_vec(), mesh.triangles().to_vec());
                Shape::Mesh(Arc::new(MeshShape::new(copy?)))
            }
            Self::Compound(ref parts) => {
                let hulls = parts
                    .iter()
                    .map(|p| ConvexPolyhedron::try_from_points(p))
                    .collect::<Result<Vec<_>, _>>()?;
                Shape::Compound(Arc::new(CompoundShape::from_hulls(hulls)?))
            }
        })
    }

    /// Registers this shape in the daemon's scene `scene`; returns the shape id.
    ///
    /// # Errors
    /// The daemon refused it or did not answer.
    pub fn register(&self, client: &Client<ipc::Service>, scene: u32) -> Result<u32, ControlError> {
        match self {
            Self::Primitive(p) => client.register_primitive(scene, *p),
            Self::Convex(points) => {
                let points: Vec<[f64; 3]> = points.iter().map(|p| p.to_array()).collect();
                client.register_convex(scene, &points)
            }
            Self::Mesh(mesh) => {
                let vertices: Vec<[f64; 3]> =
                    mesh.vertices().iter().map(|v| v.to_array()).collect();
                client.register_mesh(scene, &vertices, mesh.triangles())
            }
            Self::Compound(parts) => {
                let points: Vec<Vec<[f64; 3]>> = parts
                    .iter()
                    .map(|p| p.iter().map(|q| q.to_array()).collect())
                    .collect();
                let slices: Vec<&[[f64; 3]]> = points.iter().map(Vec::as_slice).collect();
                client.register_compound(scene, &slices)
            }
        }
    }
}

/// A body to add: which shape of the list, where, how it moves, its margin. Every body
/// pairs with every other (group and mask all bits).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyPlan {
    /// Index into [`SceneSpec::shapes`].
    pub shape: usize,
    /// Initial position, metres, world frame.
    pub position: DVec3,
    /// Initial orientation, world frame.
    pub orientation: DQuat,
    /// How it moves.
    pub motion: Motion,
    /// Close-pair margin, metres.
    pub margin_m: f64,
}

/// Shapes and bodies, each in registration order.
#[derive(Debug, Clone, Default)]
pub struct SceneSpec {
    /// Shapes; [`BodyPlan::shape`] indexes them.
    pub shapes: Vec<ShapeSpec>,
    /// Bodies; body `i` gets id `i` in a fresh scene.
    pub bodies: Vec<BodyPlan>,
}

impl SceneSpec {
    /// Appends a shape; returns its index.
    pub fn add_shape(&mut self, shape: ShapeSpec) -> usize {
        self.shapes.push(shape);
        self.shapes.len() - 1
    }

    /// Appends a body; returns its index (its id in a fresh scene).
    pub fn add_body(&mut self, body: BodyPlan) -> usize {
        self.bodies.push(body);
        self.bodies.len() - 1
    }

    /// Registers every shape and adds every body to the daemon's scene `scene`; returns
    /// the body ids in list order.
    ///
    /// # Errors
    /// The daemon refused a request or did not answer.
    pub fn register(
        &self,
        client: &Client<ipc::Service>,
        scene: u32,
    ) -> Result<Vec<u32>, ControlError> {
        let shape_ids = self
            .shapes
            .iter()
            .map(|s| s.register(client, scene))
            .collect::<Result<Vec<u32>, _>>()?;
        self.bodies
            .iter()
            .map(|b| {
                client.add_body(
                    scene,
                    &BodySpec {
                        shape: shape_ids[b.shape],
                        position: b.position.to_array(),
                        orientation: b.orientation.to_array(),
                        motion: b.motion,
                        group: u32::MAX,
                        mask: u32::MAX,
                        margin: Some(b.margin_m),
                    },
                )
            })
            .collect()
    }

    /// The same scene in-process, as the daemon holds it (default margin 0 and the
    /// standard limits, the daemon's defaults); body `i` has id `i`.
    ///
    /// # Errors
    /// A shape is invalid, or a body breaks the scene's limits.
    pub fn local_scene(&self) -> Result<Scene, Box<dyn Error>> {
        let mut scene = Scene::try_new(0.0, SceneLimits::STANDARD)?;
        let shape_ids = self
            .shapes
            .iter()
            .map(|s| Ok(scene.register_shape(s.library_shape()?)?))
            .collect::<Result<Vec<_>, Box<dyn Error>>>()?;
        for b in &self.bodies {
            scene.add_body(&BodyDesc {
                shape: shape_ids[b.shape],
                pose: Pose::try_new(b.position, b.orientation)?,
                motion: match b.motion {
                    Motion::Static => LocalMotion::Static,
                    Motion::Kinematic => LocalMotion::Kinematic,
                    Motion::Dynamic => LocalMotion::Dynamic,
                },
                filter: CollisionFilter::ALL,
                margin: Some(b.margin_m),
            })?;
        }
        Ok(scene)
    }
}
