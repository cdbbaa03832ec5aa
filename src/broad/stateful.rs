//! The body-level API every stateful broad phase shares, written once over the shared body
//! table ([`Bodies`]: the proxies densely by slot, each id's slot).
//!
//! A kind says where it files a body and how it finds the body's pairs (the required
//! methods of [`StatefulBroadPhase`]); the trait does the rest the same way for every kind:
//! an insertion of a present id replaces that body, a removal moves the last slot into the
//! freed one (the kind renaming it in its listings and per-slot records first), an update
//! looks the body's slot up once. [`stateful_api!`] gives each kind the same public
//! methods, forwarding to the trait.

use super::body_map::Bodies;
use super::{CandidatePair, CollisionFilter, Proxy, debug_assert_valid_bounds};
use crate::bounding::Aabb;

/// A broad phase that keeps its bodies and their overlapping pairs between frames.
///
/// # Invariants
/// The kind's listings and per-slot records follow [`bodies`](Self::bodies) slot for slot.
pub(crate) trait StatefulBroadPhase {
    /// The bodies.
    fn bodies(&self) -> &Bodies;

    /// The bodies, to add and remove them (only the trait's provided methods do).
    fn bodies_mut(&mut self) -> &mut Bodies;

    /// Files the body just added at slot `slot` (the last) and finds its pairs.
    fn file(&mut self, slot: usize);

    /// Takes the body at slot `slot` (its id still mapped) out of the pair set and the
    /// listings.
    fn unfile(&mut self, slot: usize);

    /// Moves the last slot into slot `slot`, already unfiled, in the listings and per-slot
    /// records (as `Vec::swap_remove(slot)`), before the body table does the same.
    fn swap_remove_slot(&mut self, slot: usize);

    /// Moves the body at slot `slot` to box `bounds` and refreshes its pairs.
    fn relocate(&mut self, slot: usize, bounds: Aabb);

    /// Every pair of bodies whose boxes overlap (touching counts) and that may pair, once
    /// each with `a < b`, in increasing `(a, b)` order, written to `out` (cleared first):
    /// exactly the pairs of [`pairs_brute_force`](super::pairs_brute_force) over
    /// [`proxies`](Self::proxies).
    fn pairs(&mut self, out: &mut Vec<CandidatePair>);

    /// Checks every invariant (the kind's docs list them). `O(n²)`: for tests.
    ///
    /// # Errors
    /// A description of the first violated invariant.
    fn validate(&self) -> Result<(), String>;

    /// [`update`](Self::update) of every `(body, bounds)` in `moves`, in order.
    fn update_all(&mut self, moves: &[(u32, Aabb)]) {
        for &(body, bounds) in moves {
            self.update(body, bounds);
        }
    }

    /// Number of bodies.
    fn len(&self) -> usize {
        self.bodies().len()
    }

    /// Whether there are no bodies.
    fn is_empty(&self) -> bool {
        self.bodies().is_empty()
    }

    /// Whether `body` is present.
    fn contains(&self, body: u32) -> bool {
        self.bodies().contains(body)
    }

    /// The bodies as proxies, in slot order (no particular order).
    fn proxies(&self) -> &[Proxy] {
        &self.bodies().proxies
    }

    /// Adds `body` with its margin-grown world box `bounds` (metres; finite, `min <= max`)
    /// and finds its pairs. Inserting an id that is already present replaces that body
    /// (remove, then insert). Static bodies never pair with each other; `filter` decides the
    /// rest ([`Proxy::may_pair`]).
    fn insert(&mut self, body: u32, bounds: Aabb, is_static: bool, filter: CollisionFilter) {
        debug_assert_valid_bounds(&bounds);
        if self.contains(body) {
            self.remove(body);
        }
        let slot = self.bodies_mut().push(Proxy {
            body,
            bounds,
            is_static,
            filter,
        });
        self.file(slot);
    }

    /// Removes `body` and its pairs; `false` when it was not present.
    fn remove(&mut self, body: u32) -> bool {
        let Some(slot) = self.bodies().slot(body) else {
            return false;
        };
        self.unfile(slot);
        self.bodies_mut().unmap(body);
        self.swap_remove_slot(slot);
        self.bodies_mut().swap_remove(slot);
        true
    }

    /// Moves `body`'s box to `bounds` (metres; finite, `min <= max`) and refreshes its pairs.
    /// A body that did not move need not be updated. Updating a body that is not present is
    /// a contract violation (`debug_assert!`; ignored in release builds).
    #[inline]
    fn update(&mut self, body: u32, bounds: Aabb) {
        debug_assert_valid_bounds(&bounds);
        let Some(slot) = self.bodies().slot(body) else {
            debug_assert!(false, "update of absent body {body}");
            return;
        };
        self.relocate(slot, bounds);
    }
}

/// The public body-level methods of a stateful broad phase `$kind`, each forwarding to
/// [`StatefulBroadPhase`] (the kinds are used without the crate-private trait in scope).
macro_rules! stateful_api {
    ($kind:ident) => {
        impl $kind {
            /// Number of bodies.
            #[must_use]
            pub fn len(&self) -> usize {
                $crate::broad::stateful::StatefulBroadPhase::len(self)
            }

            /// Whether there are no bodies.
            #[must_use]
            pub fn is_empty(&self) -> bool {
                $crate::broad::stateful::StatefulBroadPhase::is_empty(self)
            }

            /// Whether `body` is present.
            #[must_use]
            pub fn contains(&self, body: u32) -> bool {
                $crate::broad::stateful::StatefulBroadPhase::contains(self, body)
            }

            /// The bodies as proxies, in slot order (no particular order).
            #[must_use]
            pub fn proxies(&self) -> &[$crate::broad::Proxy] {
                $crate::broad::stateful::StatefulBroadPhase::proxies(self)
            }

            /// Adds `body` with its margin-grown world box `bounds` (metres; finite,
            /// `min <= max`) and finds its pairs. Inserting an id that is already present
            /// replaces that body. Static bodies never pair with each other; `filter`
            /// decides the rest ([`Proxy::may_pair`]($crate::broad::Proxy::may_pair)).
            pub fn insert(
                &mut self,
                body: u32,
                bounds: $crate::bounding::Aabb,
                is_static: bool,
                filter: $crate::broad::CollisionFilter,
            ) {
                $crate::broad::stateful::StatefulBroadPhase::insert(
                    self, body, bounds, is_static, filter,
                );
            }

            /// Removes `body` and its pairs; `false` when it was not present.
            pub fn remove(&mut self, body: u32) -> bool {
                $crate::broad::stateful::StatefulBroadPhase::remove(self, body)
            }

            /// Moves `body`'s box to `bounds` (metres; finite, `min <= max`) and refreshes
            /// its pairs. A body that did not move need not be updated. Updating a body that
            /// is not present is a contract violation (`debug_assert!`; ignored in release
            /// builds).
            #[inline]
            pub fn update(&mut self, body: u32, bounds: $crate::bounding::Aabb) {
                $crate::broad::stateful::StatefulBroadPhase::update(self, body, bounds);
            }

            /// Every pair of bodies whose boxes overlap (touching counts) and that may pair,
            /// once each with `a < b`, in increasing `(a, b)` order, written to `out`
            /// (cleared first): exactly the pairs of
            /// [`pairs_brute_force`]($crate::broad::pairs_brute_force) over
            /// [`proxies`](Self::proxies).
            ///
            /// # Cost
            /// `O(k)` for `k` pairs; no allocation once `out` has grown to `k`.
            pub fn pairs(&mut self, out: &mut Vec<$crate::broad::CandidatePair>) {
                $crate::broad::stateful::StatefulBroadPhase::pairs(self, out);
            }

            /// Checks every invariant (the type's or module's docs). `O(n²)`: for tests.
            ///
            /// # Errors
            /// A description of the first violated invariant.
            pub fn validate(&self) -> Result<(), String> {
                $crate::broad::stateful::StatefulBroadPhase::validate(self)
            }
        }
    };
}
pub(crate) use stateful_api;
