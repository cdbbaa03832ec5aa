//! A scene's shape ids as the wire knows them: built and usable, still being built, or
//! failed to build.
//!
//! A convex or mesh shape gets its id when its registration is accepted, before it is built
//! (the reply carries it); the scene ([`Scene`](crate::scene::Scene)) learns the shape only
//! once it is built, under its own [`ShapeId`], in the order builds finish. This table maps
//! the one to the other. Ids are handed out in order and never reused while the scene lives.

use super::convert::Rejection;
use crate::scene::ShapeId;
use proxima_ipc::wire::ErrorCode;

/// What became of one registered shape.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Slot {
    /// Accepted, not built yet.
    Building,
    /// Built: the scene's id of it.
    Ready(ShapeId),
    /// Its build refused the geometry: the code and reason, told to whoever asks.
    Failed(Rejection),
}

/// Wire shape id → [`Slot`] (see the module docs).
#[derive(Debug, Clone, Default)]
pub struct ShapeTable {
    slots: Vec<Slot>,
}

/// Whether a shape may take bodies yet ([`ShapeTable::state`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShapeState {
    /// Still being built.
    Building,
    /// Built; bodies may use it.
    Ready,
}

impl ShapeTable {
    /// Hands out the next id, for a shape about to be built ([`finish`](Self::finish)
    /// tells how that ended).
    ///
    /// # Errors
    /// [`ErrorCode::LimitExceeded`] when `max_shapes` ids are handed out already.
    pub fn reserve(&mut self, max_shapes: u32) -> Result<u32, Rejection> {
        if self.slots.len() >= max_shapes as usize {
            return Err(Rejection::new(
                ErrorCode::LimitExceeded,
                format!("the scene's limit of {max_shapes} shapes is reached"),
            ));
        }
        self.slots.push(Slot::Building);
        Ok(self.slots.len() as u32 - 1)
    }

    /// Records how the build of shape `id` ended: the scene's id of it, or why it failed.
    /// Ids not being built are left as they are.
    pub fn finish(&mut self, id: u32, outcome: Result<ShapeId, Rejection>) {
        if let Some(slot @ Slot::Building) = self.slots.get_mut(id as usize) {
            *slot = match outcome {
                Ok(shape) => Slot::Ready(shape),
                Err(rejection) => Slot::Failed(rejection),
            };
        }
    }

    /// Whether shape `id` is built.
    ///
    /// # Errors
    /// [`ErrorCode::UnknownShape`] for an id never handed out; a failed build's own code
    /// and reason.
    pub fn state(&self, id: u32) -> Result<ShapeState, Rejection> {
        match self.slot(id)? {
            Slot::Building => Ok(ShapeState::Building),
            Slot::Ready(_) => Ok(ShapeState::Ready),
            Slot::Failed(rejection) => Err(rejection.clone()),
        }
    }

    /// The scene's id of shape `id`, for a new body.
    ///
    /// # Errors
    /// [`ErrorCode::ShapeNotReady`] while it is being built; [`ErrorCode::UnknownShape`]
    /// for an id never handed out or whose build failed (the reason says which).
    pub fn usable(&self, id: u32) -> Result<ShapeId, Rejection> {
        match self.slot(id)? {
            Slot::Ready(shape) => Ok(*shape),
            Slot::Building => Err(Rejection::new(
                ErrorCode::ShapeNotReady,
                format!("shape {id} is still being built; wait for it (ShapeState)"),
            )),
            Slot::Failed(rejection) => Err(Rejection::new(
                ErrorCode::UnknownShape,
                format!("shape {id} failed to build: {}", rejection.reason),
            )),
        }
    }

    fn slot(&self, id: u32) -> Result<&Slot, Rejection> {
        self.slots
            .get(id as usize)
            .ok_or_else(|| Rejection::new(ErrorCode::UnknownShape, format!("no shape {id}")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shape_goes_from_building_to_ready_or_to_its_failure() {
        let mut table = ShapeTable::default();
        let primitive = table.reserve(8).unwrap();
        table.finish(primitive, Ok(ShapeId(0)));
        let mesh = table.reserve(8).unwrap();
        let bad = table.reserve(8).unwrap();
        assert_eq!((primitive, mesh, bad), (0, 1, 2));
        assert_eq!(table.state(mesh), Ok(ShapeState::Building));
        assert_eq!(
            table.usable(mesh).unwrap_err().code,
            ErrorCode::ShapeNotReady
        );

        table.finish(mesh, Ok(ShapeId(1)));
        let index_error = Rejection::new(ErrorCode::MeshIndexOutOfRange, "index 9 of 4");
        table.finish(bad, Err(index_error.clone()));
        assert_eq!(table.state(mesh), Ok(ShapeState::Ready));
        assert_eq!(table.usable(mesh), Ok(ShapeId(1)));
        assert_eq!(table.usable(primitive), Ok(ShapeId(0)));
        // Asking again tells the same failure; a body on it is refused as unknown.
        assert_eq!(table.state(bad), Err(index_error.clone()));
        assert_eq!(table.state(bad), Err(index_error));
        let refused = table.usable(bad).unwrap_err();
        assert_eq!(refused.code, ErrorCode::UnknownShape);
        assert!(
            refused.reason.contains("index 9 of 4"),
            "{}",
            refused.reason
        );
        // A finished shape stays as it is.
        table.finish(mesh, Ok(ShapeId(7)));
        assert_eq!(table.usable(mesh), Ok(ShapeId(1)));
    }

    #[test]
    fn ids_stop_at_the_limit_and_unknown_ids_are_refused() {
        let mut table = ShapeTable::default();
        table.reserve(2).unwrap();
        table.reserve(2).unwrap();
        assert_eq!(table.reserve(2).unwrap_err().code, ErrorCode::LimitExceeded);
        assert_eq!(table.state(2).unwrap_err().code, ErrorCode::UnknownShape);
        assert_eq!(
            table.usable(u32::MAX).unwrap_err().code,
            ErrorCode::UnknownShape
        );
    }
}
