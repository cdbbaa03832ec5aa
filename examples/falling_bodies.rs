//! A simulation process that uses `proximad` for its collisions: a few hundred spheres,
//! capsules, boxes and tori dropped into a bin, integrated here (gravity, velocities) and
//! bounced with the contacts the daemon returns.
//!
//! ```text
//! cargo run --release -- &                                   # a daemon under the root "proxima"
//! cargo run --release --example falling_bodies               # connects to it
//! cargo run --release --example falling_bodies -- --spawn-daemon --bodies 400 --seconds 10
//! ```
//!
//! `--spawn-daemon` starts a private `proximad` (its path from `--daemon`, by default
//! `target/release/proximad` next to this example) under a root of its own. Each frame
//! publishes every body's pose straight into shared memory with `CLOSE | CONTACTS`, waits
//! for the result frame, and for each touching pair applies an impulse along the contact
//! normal at its deepest point (restitution 0.4, bodies as point masses: no spin response),
//! then pushes the bodies apart by the depth. A body slow for half a second falls asleep,
//! as in any rigid-body engine: it stops moving until a hard hit wakes it, so its pose, and
//! with it the daemon's answers for its pairs with other sleepers, stay the same (the
//! daemon reuses them). Once a second it prints the frame's pairs, contacts, round trip and
//! how many bodies have come to rest.
//!
//! Every pair is answered exactly (closed forms for spheres, capsules and boxes, the tori's
//! BVHs against everything else), so the frames say `exact`.

use clap::Parser;
use glam::{DQuat, DVec3};
use iceoryx2::prelude::{LogLevel, ipc, set_log_level_from_env_or};
use proxima::geometry::TriMesh;
use proxima_ipc::client::{BodySpec, Client, ClientBuilder, Motion, Primitive};
use proxima_ipc::tools::daemon_process::{ChildProcess, Isolation};
use proxima_ipc::tools::latency::LatencyRecorder;
use proxima_ipc::wire::{Completeness, ErrorCode, PoseRecord, ResultRecord, query};
use std::error::Error;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Gravity, m/s², along −Z.
const GRAVITY: f64 = 9.81;
/// Fraction of the approach speed kept after a bounce.
const RESTITUTION: f64 = 0.4;
/// Bin: floor half extent and wall height, metres.
const BIN_HALF: f64 = 4.0;
const WALL_HEIGHT: f64 = 3.0;
/// Close-pair margin of every body, metres.
const MARGIN: f64 = 0.02;
/// A body whose speed stays under this for 30 frames counts as resting, m/s (a body at
/// rest on the floor still gains g·dt ≈ 0.08 m/s each frame before its contact stops it).
const REST_SPEED: f64 = 0.15;
/// A body resting this many frames falls asleep: it is no longer integrated, so its pose
/// stays bit for bit the same and the daemon reuses the answers of its pairs with other
/// sleepers. An awake body hitting it faster than [`WAKE_SPEED`] wakes it; slower contact
/// (a body settling on it) treats it as immovable.
const SLEEP_FRAMES: u32 = 60;
/// Approach speed along the contact normal that wakes a sleeper, m/s.
const WAKE_SPEED: f64 = 0.3;

#[derive(Debug, Parser)]
#[command(about = "Bodies falling into a bin, bounced with proximad's contacts")]
struct Args {
    /// Number of falling bodies.
    #[arg(long, default_value_t = 300)]
    bodies: usize,
    /// Simulated (and wall-clock) seconds.
    #[arg(long, default_value_t = 10.0)]
    seconds: f64,
    /// Frames per second.
    #[arg(long, default_value_t = 120)]
    rate_hz: u32,
    /// Frame budget, microseconds.
    #[arg(long, default_value_t = 2000)]
    budget_us: u64,
    /// Service root of the daemon to use.
    #[arg(long, default_value = proxima_ipc::DEFAULT_ROOT)]
    root: String,
    /// iceoryx2 prefix of the daemon to use.
    #[arg(long)]
    iceoryx_prefix: Option<String>,
    /// Start a private daemon instead of using a running one.
    #[arg(long)]
    spawn_daemon: bool,
    /// The `proximad` executable for `--spawn-daemon`.
    #[arg(long)]
    daemon: Option<PathBuf>,
}

fn main() -> Result<(), Box<dyn Error>> {
    let args = Args::parse();
    set_log_level_from_env_or(LogLevel::Error);
    let (_daemon, root, prefix) = if args.spawn_daemon {
        let Isolation { root, prefix } = Isolation::unique("fall");
        let exe = match &args.daemon {
            Some(path) => path.clone(),
            None => sibling_daemon()?,
        };
        let daemon = ChildProcess::spawn(
            &exe,
            ["--root", &root, "--iceoryx-prefix", &prefix],
            &prefix,
        )?;
        (Some(daemon), root, Some(prefix))
    } else {
        (None, args.root.clone(), args.iceoryx_prefix.clone())
    };
    let mut builder = ClientBuilder::new()
        .root(&root)
        .reply_timeout(Duration::from_secs(10));
    if let Some(prefix) = &prefix {
        builder = builder.iceoryx_prefix(prefix);
    }
    let client = builder.connect::<ipc::Service>()?;
    let scene_id = client.create_scene()?;
    let mut world = World::build(&client, scene_id, args.bodies)?;
    let link = client.open_scene(scene_id)?;
    println!(
        "falling_bodies: scene {scene_id}, {} falling bodies in a {:.0} m bin, {} Hz",
        world.bodies.len(),
        2.0 * BIN_HALF,
        args.rate_hz
    );
    let dt = 1.0 / f64::from(args.rate_hz);
    let period = Duration::from_secs_f64(dt);
    let frames = (args.seconds * f64::from(args.rate_hz)).ceil() as u64;
    let mut round_trips = LatencyRecorder::with_capacity(frames as usize);
    let (mut truncated, mut missed, mut lost) = (0u64, 0u64, 0u64);
    let start = Instant::now();
    for seq in 1..=frames {
        let due = start + period * (seq as u32);
        while Instant::now() < due {
            std::thread::sleep(Duration::from_micros(100));
        }
        world.integrate(dt);
        let sent = Instant::now();
        link.publish_poses_with(
            seq,
            args.budget_us * 1000,
            query::CLOSE | query::CONTACTS,
            world.bodies.len(),
            |i| world.pose(i),
        )?;
        let Some(frame) = link.receive_results_for(seq, Duration::from_secs(1))? else {
            lost += 1;
            continue;
        };
        round_trips.record(sent.elapsed());
        let header = *frame.header();
        if header.status != ErrorCode::Ok as u32 {
            return Err(format!("frame {seq} refused: status {}", header.status).into());
        }
        truncated += u64::from(header.completeness != Completeness::Exact as u32);
        missed += u64::from(header.budget_met == 0);
        let bounced = world.resolve(frame.pairs(), frame.contacts());
        drop(frame);
        if seq % u64::from(args.rate_hz) == 0 {
            println!(
                "t {:5.1} s  pairs {:4}  contacts {:4}  bounced {:4}  resting {:4}/{}  \
                 round trip {:6.1} µs",
                seq as f64 * dt,
                header.pair_count,
                header.contact_count,
                bounced,
                world.resting(),
                world.bodies.len(),
                sent.elapsed().as_secs_f64() * 1e6
            );
        }
    }
    if let Some(summary) = round_trips.summary() {
        println!("round trip: {summary}");
    }
    println!(
        "{frames} frames: {truncated} truncated, {missed} over budget, {lost} lost; {} of {} \
         bodies at rest",
        world.resting(),
        world.bodies.len()
    );
    client.drop_scene(scene_id)?;
    Ok(())
}

/// `proximad` in the directory above this example's (`target/<profile>/`).
fn sibling_daemon() -> Result<PathBuf, Box<dyn Error>> {
    let exe = std::env::current_exe()?;
    let path = exe
        .parent()
        .and_then(|examples| examples.parent())
        .map(|profile| profile.join("proximad"))
        .ok_or("cannot locate proximad next to this example")?;
    if !path.exists() {
        return Err(format!(
            "{} does not exist: run `cargo build --release` first, or pass --daemon",
            path.display()
        )
        .into());
    }
    Ok(path)
}

/// A falling body as this simulation integrates it.
#[derive(Debug, Clone, Copy)]
struct Body {
    id: u32,
    position: DVec3,
    orientation: DQuat,
    velocity: DVec3,
    spin: DVec3,
    inverse_mass: f64,
    slow_frames: u32,
    /// Not integrated until an awake body pushes it.
    asleep: bool,
}

/// The bodies, and which daemon id is which body (`None`: a bin wall).
struct World {
    bodies: Vec<Body>,
    index_of: Vec<Option<usize>>,
}

impl World {
    fn build(
        client: &Client<ipc::Service>,
        scene: u32,
        count: usize,
    ) -> Result<Self, Box<dyn Error>> {
        let mut world = Self {
            bodies: Vec::with_capacity(count),
            index_of: Vec::new(),
        };
        // The bin: a floor and four walls, static boxes.
        let floor = client.register_primitive(
            scene,
            Primitive::Cuboid {
                half_extents: [BIN_HALF, BIN_HALF, 0.25],
            },
        )?;
        let wall_x = client.register_primitive(
            scene,
            Primitive::Cuboid {
                half_extents: [0.25, BIN_HALF, WALL_HEIGHT / 2.0],
            },
        )?;
        let wall_y = client.register_primitive(
            scene,
            Primitive::Cuboid {
                half_extents: [BIN_HALF, 0.25, WALL_HEIGHT / 2.0],
            },
        )?;
        let h = WALL_HEIGHT / 2.0;
        for (shape, at) in [
            (floor, DVec3::new(0.0, 0.0, -0.25)),
            (wall_x, DVec3::new(-BIN_HALF - 0.25, 0.0, h)),
            (wall_x, DVec3::new(BIN_HALF + 0.25, 0.0, h)),
            (wall_y, DVec3::new(0.0, -BIN_HALF - 0.25, h)),
            (wall_y, DVec3::new(0.0, BIN_HALF + 0.25, h)),
        ] {
            let id = client.add_body(scene, &spec(shape, at, DQuat::IDENTITY, Motion::Static))?;
            world.note(id, None);
        }
        // What falls: spheres, capsules, boxes and small tori, a quarter each.
        let torus = TriMesh::torus(0.3, 0.1, 16, 8);
        let vertices: Vec<[f64; 3]> = torus.vertices().iter().map(|v| v.to_array()).collect();
        let shapes = [
            client.register_primitive(scene, Primitive::Sphere { radius: 0.2 })?,
            client.register_primitive(
                scene,
                Primitive::Capsule {
                    radius: 0.12,
                    half_height: 0.2,
                },
            )?,
            client.register_primitive(
                scene,
                Primitive::Cuboid {
                    half_extents: [0.18, 0.18, 0.18],
                },
            )?,
            client.register_mesh(scene, &vertices, torus.triangles())?,
        ];
        let side = (count as f64).sqrt().ceil() as usize;
        let spacing = (2.0 * BIN_HALF - 1.0) / side as f64;
        for i in 0..count {
            let (gx, gy) = (i % side, i / side % side);
            let layer = i / (side * side);
            let position = DVec3::new(
                -BIN_HALF + 0.5 + (gx as f64 + 0.5) * spacing,
                -BIN_HALF + 0.5 + (gy as f64 + 0.5) * spacing,
                2.0 + 1.0 * layer as f64 + 0.37 * ((i * 7) % 5) as f64,
            );
            let orientation =
                DQuat::from_euler(glam::EulerRot::XYZ, i as f64 * 0.7, i as f64 * 1.3, 0.0);
            let id = client.add_body(
                scene,
                &spec(
                    shapes[i % shapes.len()],
                    position,
                    orientation,
                    Motion::Dynamic,
                ),
            )?;
            world.note(id, Some(world.bodies.len()));
            world.bodies.push(Body {
                id,
                position,
                orientation,
                velocity: DVec3::ZERO,
                spin: DVec3::new(0.3, -0.2, 0.5) * ((i % 3) as f64 - 1.0),
                inverse_mass: 1.0,
                slow_frames: 0,
                asleep: false,
            });
        }
        Ok(world)
    }

    fn note(&mut self, id: u32, index: Option<usize>) {
        let id = id as usize;
        if self.index_of.len() <= id {
            self.index_of.resize(id + 1, None);
        }
        self.index_of[id] = index;
    }

    fn pose(&self, i: usize) -> PoseRecord {
        let b = &self.bodies[i];
        PoseRecord {
            body: b.id,
            reserved: 0,
            position: b.position.to_array(),
            orientation: b.orientation.to_array(),
        }
    }

    /// Gravity, then velocities (semi-implicit Euler); spin decays.
    fn integrate(&mut self, dt: f64) {
        for b in self.bodies.iter_mut().filter(|b| !b.asleep) {
            b.velocity.z -= GRAVITY * dt;
            b.position += b.velocity * dt;
            let turn = b.spin * dt;
            if turn.length_squared() > 0.0 {
                b.orientation = (DQuat::from_scaled_axis(turn) * b.orientation).normalize();
            }
            b.spin *= 0.995;
            let slow = b.velocity.length() < REST_SPEED;
            b.slow_frames = if slow { b.slow_frames + 1 } else { 0 };
            if b.slow_frames > SLEEP_FRAMES {
                (b.asleep, b.velocity, b.spin) = (true, DVec3::ZERO, DVec3::ZERO);
            }
        }
    }

    /// For each pair with contacts, an impulse at its deepest contact along the normal (A→B)
    /// if the bodies approach, and a push apart by the depth. Returns how many pairs bounced.
    fn resolve(&mut self, pairs: &[ResultRecord], contacts: &[ResultRecord]) -> usize {
        let mut bounced = 0;
        for pair in pairs {
            let first = (pair.index as usize).min(contacts.len());
            let end = (first + pair.count as usize).min(contacts.len());
            let Some(deepest) = contacts[first..end]
                .iter()
                .min_by(|x, y| x.distance.total_cmp(&y.distance))
            else {
                continue;
            };
            bounced += usize::from(self.bounce(pair.body_a, pair.body_b, deepest));
        }
        bounced
    }

    fn bounce(&mut self, a: u32, b: u32, contact: &ResultRecord) -> bool {
        let index = |id: u32| self.index_of.get(id as usize).copied().flatten();
        let (ia, ib) = (index(a), index(b));
        let (inv_a, inv_b) = (
            ia.map_or(0.0, |i| self.bodies[i].inverse_mass),
            ib.map_or(0.0, |i| self.bodies[i].inverse_mass),
        );
        let asleep = |i: Option<usize>| i.is_none_or(|i| self.bodies[i].asleep);
        if asleep(ia) && asleep(ib) {
            // Sleepers (and walls) stay put against each other.
            return false;
        }
        let n = DVec3::from_array(contact.normal);
        let depth = (-contact.distance).max(0.0);
        let velocity = |i: Option<usize>| i.map_or(DVec3::ZERO, |i| self.bodies[i].velocity);
        let approach = (velocity(ib) - velocity(ia)).dot(n);
        // A hard hit wakes a sleeper; a soft one leaves it asleep and immovable.
        let mut immovable = |i: Option<usize>, inv: f64| match i {
            Some(i) if self.bodies[i].asleep && -approach > WAKE_SPEED => {
                (self.bodies[i].asleep, self.bodies[i].slow_frames) = (false, 0);
                inv
            }
            Some(i) if self.bodies[i].asleep => 0.0,
            _ => inv,
        };
        let (inv_a, inv_b) = (immovable(ia, inv_a), immovable(ib, inv_b));
        let total = inv_a + inv_b;
        if total == 0.0 {
            return false;
        }
        let impulse = if approach < 0.0 {
            -(1.0 + RESTITUTION) * approach / total
        } else {
            0.0
        };
        let correction = depth * 0.8 / total;
        if let Some(i) = ia {
            self.bodies[i].velocity -= n * impulse * inv_a;
            self.bodies[i].position -= n * correction * inv_a;
        }
        if let Some(i) = ib {
            self.bodies[i].velocity += n * impulse * inv_b;
            self.bodies[i].position += n * correction * inv_b;
        }
        impulse > 0.0
    }

    fn resting(&self) -> usize {
        self.bodies
            .iter()
            .filter(|b| b.asleep || b.slow_frames > 30)
            .count()
    }
}

fn spec(shape: u32, position: DVec3, orientation: DQuat, motion: Motion) -> BodySpec {
    BodySpec {
        shape,
        position: position.to_array(),
        orientation: orientation.to_array(),
        motion,
        group: u32::MAX,
        mask: u32::MAX,
        margin: Some(MARGIN),
    }
}
