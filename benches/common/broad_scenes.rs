//! Broad-phase workloads: `n` boxes laid out as one scene class, then moved frame by frame.
//!
//! Shared by `benches/broad_phase.rs` and `examples/broad_bench.rs`, so both time exactly the
//! same inputs. Every body is a box with a margin of [`MARGIN`] already added (the broad
//! phase's input, a [`Proxy`]); body ids are `0 .. n`.
//!
//! # Layouts
//! - [`Layout::Uniform`]: half-extents uniform in 0.25–0.75 m, centres uniform in a cube of
//!   8 m³ per body, so a body overlaps about one other on average.
//! - [`Layout::Clustered`]: half-extents log-uniform over 0.1–1 m (a tenfold size spread),
//!   centres in 64 Gaussian clusters about 1 body per m³ dense, the clusters scattered in a
//!   cube 8 times the uniform one's volume: most of space empty, a few dense spots.
//! - [`Layout::Stack`]: "dice on a table": columns of 8 unit cubes stacked face to face on a
//!   square grid of 1.25 m, on one static floor slab under all of them. Every box shares the
//!   floor's pairs and its column neighbours', and all bodies share 8 z ranges.
//!
//! # Motion
//! A fixed subset of the dynamic bodies moves every frame (the fraction `moving`, picked at
//! random once: the bodies a simulation keeps awake); the others never move and are never
//! handed to the broad phase again.
//! - [`Motion::Coherent`]: each moving body keeps a velocity (3 cm per frame for the
//!   scattered layouts, 5 mm per frame for the stack) and bounces off the walls of its
//!   region (the layout's cube; for a stacked die, 5 cm around where it was placed).
//! - [`Motion::Teleport`]: each moving body jumps to a fresh random place in its region
//!   every frame.

use proxima::bounding::Aabb;
use proxima::broad::{CollisionFilter, Proxy};
use proxima::math::DVec3;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// Margin already added to every box, metres.
pub const MARGIN: f64 = 0.01;

/// Dice per column in [`Layout::Stack`].
const STACK_HEIGHT: usize = 8;
/// Distance between stack columns, metres.
const STACK_SPACING: f64 = 1.25;

/// How the bodies are laid out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layout {
    /// Scattered uniformly.
    Uniform,
    /// Dense clusters in empty space, tenfold size spread.
    Clustered,
    /// Stacked dice on a floor.
    Stack,
}

impl Layout {
    /// Every layout, in bench order.
    pub const ALL: [Self; 3] = [Self::Uniform, Self::Clustered, Self::Stack];

    /// Name used on the command line and in bench ids.
    pub fn name(self) -> &'static str {
        match self {
            Self::Uniform => "uniform",
            Self::Clustered => "clustered",
            Self::Stack => "stack",
        }
    }

    /// The layout called `name`, if any.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|l| l.name() == name)
    }
}

/// How the moving bodies move.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Motion {
    /// Small steps, bouncing off their region's walls.
    Coherent,
    /// A fresh random place every frame.
    Teleport,
}

impl Motion {
    /// Name used on the command line and in bench ids.
    pub fn name(self) -> &'static str {
        match self {
            Self::Coherent => "coherent",
            Self::Teleport => "teleport",
        }
    }

    /// The motion called `name`, if any.
    pub fn from_name(name: &str) -> Option<Self> {
        [Self::Coherent, Self::Teleport]
            .into_iter()
            .find(|m| m.name() == name)
    }
}

/// One moving body's state.
#[derive(Debug, Clone, Copy)]
struct Mover {
    body: u32,
    centre: DVec3,
    velocity: DVec3,
    half: DVec3,
    /// Region its centre stays in.
    low: DVec3,
    high: DVec3,
}

/// A layout of boxes and the generator that moves its moving subset.
pub struct BroadScene {
    /// Every body as the broad phase sees it, indexed by id; kept current by
    /// [`next_frame`](Self::next_frame).
    pub proxies: Vec<Proxy>,
    movers: Vec<Mover>,
    motion: Motion,
    rng: Pcg64Mcg,
}

impl BroadScene {
    /// About `bodies` bodies (the stack rounds to whole columns, plus the floor) laid out as
    /// `layout`, of which the fraction `moving` of the dynamic ones moves as `motion`; the
    /// same arguments and `seed` give the same scene and frames.
    pub fn new(layout: Layout, bodies: usize, moving: f64, motion: Motion, seed: u64) -> Self {
        let mut rng = Pcg64Mcg::seed_from_u64(seed);
        let mut boxes: Vec<(DVec3, DVec3, DVec3, DVec3)> = Vec::with_capacity(bodies); // centre, half, region low, high
        let mut floor = None;
        match layout {
            Layout::Uniform => {
                let side = (8.0 * bodies as f64).cbrt();
                let (low, high) = (DVec3::ZERO, DVec3::splat(side));
                for _ in 0..bodies {
                    let half =
                        DVec3::from_array(std::array::from_fn(|_| rng.random_range(0.25..0.75)));
                    boxes.push((uniform_in(&mut rng, low, high), half, low, high));
                }
            }
            Layout::Clustered => {
                let side = 2.0 * (8.0 * bodies as f64).cbrt();
                let (low, high) = (DVec3::ZERO, DVec3::splat(side));
                let clusters: Vec<DVec3> =
                    (0..64).map(|_| uniform_in(&mut rng, low, high)).collect();
                let sigma = 0.5 * (bodies as f64 / 64.0).cbrt();
                for i in 0..bodies {
                    let centre = clusters[i % clusters.len()] + sigma * gaussian3(&mut rng);
                    let half = DVec3::splat((rng.random_range(0.1f64.ln()..1.0f64.ln())).exp());
                    boxes.push((centre, half, low, high));
                }
            }
            Layout::Stack => {
                let columns = (bodies.saturating_sub(1) / STACK_HEIGHT).max(1);
                let per_row = (columns as f64).sqrt().ceil() as usize;
                let half = DVec3::splat(0.5);
                for c in 0..columns {
                    let (x, y) = ((c % per_row) as f64, (c / per_row) as f64);
                    for level in 0..STACK_HEIGHT {
                        let centre =
                            DVec3::new(x * STACK_SPACING, y * STACK_SPACING, 0.5 + level as f64);
                        let roam = DVec3::splat(0.05);
                        boxes.push((centre, half, centre - roam, centre + roam));
                    }
                }
                let extent = per_row as f64 * STACK_SPACING;
                floor = Some(Aabb::new(
                    DVec3::new(-1.0, -1.0, -1.0),
                    DVec3::new(extent, extent, 0.0),
                ));
            }
        }
        let speed = if layout == Layout::Stack { 0.005 } else { 0.03 };
        let mut proxies: Vec<Proxy> = boxes
            .iter()
            .enumerate()
            .map(|(i, &(centre, half, _, _))| proxy(i as u32, centre, half, false))
            .collect();
        let mut movers = Vec::new();
        for (i, &(centre, half, low, high)) in boxes.iter().enumerate() {
            if rng.random_bool(moving.clamp(0.0, 1.0)) {
                let direction = gaussian3(&mut rng).normalize_or(DVec3::X);
                movers.push(Mover {
                    body: i as u32,
                    centre,
                    velocity: speed * direction,
                    half,
                    low,
                    high,
                });
            }
        }
        if let Some(floor) = floor {
            proxies.push(Proxy {
                body: proxies.len() as u32,
                bounds: floor.grown(MARGIN),
                is_static: true,
                filter: CollisionFilter::ALL,
            });
        }
        Self {
            proxies,
            movers,
            motion,
            rng,
        }
    }

    /// Multiplies every coherent mover's speed by `factor` (the layouts' speeds are in the
    /// module docs); teleports are unchanged.
    pub fn scale_speed(&mut self, factor: f64) {
        for m in &mut self.movers {
            m.velocity *= factor;
        }
    }

    /// Number of bodies that move every frame.
    pub fn moving_count(&self) -> usize {
        self.movers.len()
    }

    /// Moves the moving bodies one frame and writes their new boxes to `out` (cleared
    /// first), also updating [`proxies`](Self::proxies).
    pub fn next_frame(&mut self, out: &mut Vec<(u32, Aabb)>) {
        out.clear();
        for m in &mut self.movers {
            match self.motion {
                Motion::Coherent => {
                    m.centre += m.velocity;
                    for axis in 0..3 {
                        let (c, lo, hi) = (m.centre[axis], m.low[axis], m.high[axis]);
                        if c < lo || c > hi {
                            m.velocity[axis] = -m.velocity[axis];
                            m.centre[axis] = c.clamp(lo, hi);
                        }
                    }
                }
                Motion::Teleport => m.centre = uniform_in(&mut self.rng, m.low, m.high),
            }
            let p = proxy(m.body, m.centre, m.half, false);
            self.proxies[m.body as usize] = p;
            out.push((m.body, p.bounds));
        }
    }
}

/// A dynamic (or static) body `body` with box `centre ± half` grown by [`MARGIN`].
fn proxy(body: u32, centre: DVec3, half: DVec3, is_static: bool) -> Proxy {
    Proxy {
        body,
        bounds: Aabb::from_center_half_extents(centre, half).grown(MARGIN),
        is_static,
        filter: CollisionFilter::ALL,
    }
}

fn uniform_in(rng: &mut Pcg64Mcg, low: DVec3, high: DVec3) -> DVec3 {
    DVec3::from_array(std::array::from_fn(|i| {
        if low[i] < high[i] {
            rng.random_range(low[i]..high[i])
        } else {
            low[i]
        }
    }))
}

/// Three independent standard normal samples (Box–Muller).
fn gaussian3(rng: &mut Pcg64Mcg) -> DVec3 {
    DVec3::from_array(std::array::from_fn(|_| {
        let (u, v): (f64, f64) = (rng.random_range(f64::EPSILON..1.0), rng.random());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }))
}
