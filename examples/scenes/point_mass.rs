//! The simulations' own integration: bodies as point masses under gravity, bounced with the
//! contacts the daemon returns (an impulse along the contact normal at each touching
//! pair's deepest point, no spin response), pushed apart by the depth, and put to sleep
//! when slow for a while, as in any rigid-body engine: a sleeper stops moving until a hard
//! hit wakes it, so its pose, and with it the daemon's answers for its pairs with other
//! sleepers, stay the same (the daemon reuses them).

use glam::{DQuat, DVec3};
use proxima_ipc::wire::{PoseRecord, ResultRecord};

/// How the bodies move and settle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverParams {
    /// Gravity, m/s², along −Z.
    pub gravity: f64,
    /// Fraction of the approach speed kept after a bounce.
    pub restitution: f64,
    /// A body whose speed stays under this counts as slow, m/s (a body at rest on the
    /// floor still gains g·dt each frame before its contact stops it).
    pub rest_speed: f64,
    /// A body slow for more than this many frames falls asleep; one slow for more than 30
    /// counts as resting.
    pub sleep_frames: u32,
    /// Approach speed along the contact normal that wakes a sleeper, m/s; slower contact
    /// (a body settling on it) treats it as immovable.
    pub wake_speed: f64,
    /// Share of the spin kept each frame.
    pub spin_decay: f64,
}

/// A moving body as the simulation integrates it.
#[derive(Debug, Clone, Copy)]
struct Body {
    id: u32,
    position: DVec3,
    orientation: DQuat,
    velocity: DVec3,
    /// Angular velocity, rad/s, world frame.
    spin: DVec3,
    inverse_mass: f64,
    slow_frames: u32,
    /// Not integrated until an awake body pushes it.
    asleep: bool,
}

/// The moving bodies, and which daemon id is which body (`None`: a static body).
#[derive(Debug, Clone)]
pub struct World {
    params: SolverParams,
    bodies: Vec<Body>,
    index_of: Vec<Option<usize>>,
}

impl World {
    /// No bodies yet.
    #[must_use]
    pub fn new(params: SolverParams) -> Self {
        Self {
            params,
            bodies: Vec::new(),
            index_of: Vec::new(),
        }
    }

    /// Notes body `id` as static: contacts with it push only the other body.
    pub fn add_static(&mut self, id: u32) {
        self.note(id, None);
    }

    /// Adds a moving body (unit mass, at rest) spinning at `spin` rad/s.
    pub fn add_moving(&mut self, id: u32, position: DVec3, orientation: DQuat, spin: DVec3) {
        self.note(id, Some(self.bodies.len()));
        self.bodies.push(Body {
            id,
            position,
            orientation,
            velocity: DVec3::ZERO,
            spin,
            inverse_mass: 1.0,
            slow_frames: 0,
            asleep: false,
        });
    }

    fn note(&mut self, id: u32, index: Option<usize>) {
        let id = id as usize;
        if self.index_of.len() <= id {
            self.index_of.resize(id + 1, None);
        }
        self.index_of[id] = index;
    }

    /// Number of moving bodies.
    #[must_use]
    pub fn moving_count(&self) -> usize {
        self.bodies.len()
    }

    /// The pose record of moving body `i`.
    #[must_use]
    pub fn pose(&self, i: usize) -> PoseRecord {
        let b = &self.bodies[i];
        PoseRecord {
            body: b.id,
            reserved: 0,
            position: b.position.to_array(),
            orientation: b.orientation.to_array(),
        }
    }

    /// Gravity, then velocities (semi-implicit Euler); spin decays.
    pub fn integrate(&mut self, dt: f64) {
        let p = self.params;
        for b in self.bodies.iter_mut().filter(|b| !b.asleep) {
            b.velocity.z -= p.gravity * dt;
            b.position += b.velocity * dt;
            let turn = b.spin * dt;
            if turn.length_squared() > 0.0 {
                b.orientation = (DQuat::from_scaled_axis(turn) * b.orientation).normalize();
            }
            b.spin *= p.spin_decay;
            let slow = b.velocity.length() < p.rest_speed;
            b.slow_frames = if slow { b.slow_frames + 1 } else { 0 };
            if b.slow_frames > p.sleep_frames {
                (b.asleep, b.velocity, b.spin) = (true, DVec3::ZERO, DVec3::ZERO);
            }
        }
    }

    /// For each pair with contacts, an impulse at its deepest contact along the normal (A→B)
    /// if the bodies approach, and a push apart by the depth. Returns how many pairs bounced.
    pub fn resolve(&mut self, pairs: &[ResultRecord], contacts: &[ResultRecord]) -> usize {
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
            // Sleepers (and static bodies) stay put against each other.
            return false;
        }
        let n = DVec3::from_array(contact.normal);
        let depth = (-contact.distance).max(0.0);
        let velocity = |i: Option<usize>| i.map_or(DVec3::ZERO, |i| self.bodies[i].velocity);
        let approach = (velocity(ib) - velocity(ia)).dot(n);
        let wake_speed = self.params.wake_speed;
        // A hard hit wakes a sleeper; a soft one leaves it asleep and immovable.
        let mut immovable = |i: Option<usize>, inv: f64| match i {
            Some(i) if self.bodies[i].asleep && -approach > wake_speed => {
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
            -(1.0 + self.params.restitution) * approach / total
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

    /// Bodies asleep or slow for more than 30 frames.
    #[must_use]
    pub fn resting(&self) -> usize {
        self.bodies
            .iter()
            .filter(|b| b.asleep || b.slow_frames > 30)
            .count()
    }
}
