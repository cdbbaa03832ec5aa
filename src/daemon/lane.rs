//! Frames without a deadline that take long, finished on a thread of their own (the
//! *lane*), so that no such frame, however long, holds up a frame that has one (DESIGN §8).
//!
//! A frame with `budget_ns == 0` asks for exact answers whatever they cost: seconds, for a
//! scene of large meshes in deep contact. The frame thread tries such a frame for a short
//! slice (most finish in it, answered at once); one that does not is *parked*, its poses
//! applied and nothing published. The frame thread then hands its scene (ports, workspace
//! and all) to the lane and goes on serving every other scene; the lane finishes the frame
//! exactly under the scene's lock, hands the scene back and wakes the frame thread. One
//! scene is out at a time; other parked scenes wait their turn. A scene's frames stay in
//! order: while one is parked or out, none of its frames is taken.
//!
//! The price, for the long frames only: the hand-over (one thread wake-up, 60–120 µs on
//! this project's VMs) and the slice's work, done again by the lane (less what the slice
//! kept: exact pair answers are reused).

use super::Ipc;
use super::frame_thread::LiveScene;
use super::log::{Level, Logger};
use crossbeam::channel::{self, Receiver, Sender};
use iceoryx2::port::notifier::Notifier;
use std::thread::{Scope, ScopedJoinHandle};

/// A scene back from the lane, with the outcome of its frame (an iceoryx2 fault on its
/// ports, as text, quarantines it).
pub struct Answered {
    /// The scene, with its ports.
    pub live: LiveScene,
    /// Whether its ports worked.
    pub outcome: Result<(), String>,
}

/// The frame thread's end of the lane.
pub struct Lane<'scope> {
    to: Option<Sender<LiveScene>>,
    back: Receiver<Answered>,
    /// The scene out on the lane, and whether it is to be closed when it comes back.
    out: Option<(u32, bool)>,
    thread: Option<ScopedJoinHandle<'scope, ()>>,
}

impl<'scope> Lane<'scope> {
    /// Starts the lane's thread in `scope`; it notifies `wake` after each frame, logging at
    /// `level`.
    ///
    /// # Errors
    /// The OS's refusal to start a thread.
    pub fn spawn<'env>(
        scope: &'scope Scope<'scope, 'env>,
        wake: Notifier<Ipc>,
        level: Level,
    ) -> std::io::Result<Self> {
        let (to, scenes) = channel::bounded::<LiveScene>(1);
        let (answers, back) = channel::bounded(1);
        let thread = std::thread::Builder::new()
            .name("proximad-lane".to_owned())
            .spawn_scoped(scope, move || {
                let mut log = Logger::new(level);
                for mut live in scenes {
                    let outcome = live.answer_parked(&mut log);
                    if answers.send(Answered { live, outcome }).is_err() {
                        break;
                    }
                    // Should the notification fail, the frame thread finds the scene back
                    // at its next periodic wake-up.
                    let _ = wake.notify();
                }
            })?;
        Ok(Self {
            to: Some(to),
            back,
            out: None,
            thread: Some(thread),
        })
    }

    /// Whether no scene is out on the lane.
    #[must_use]
    pub fn is_free(&self) -> bool {
        self.out.is_none()
    }

    /// Hands `live`, whose frame is parked, to the lane. Gives it back when the lane is busy
    /// or gone.
    ///
    /// # Errors
    /// `live`, not sent.
    pub fn send(&mut self, live: LiveScene) -> Result<(), LiveScene> {
        let Some(to) = self.to.as_ref().filter(|_| self.out.is_none()) else {
            return Err(live);
        };
        let id = live.id;
        match to.try_send(live) {
            Ok(()) => {
                self.out = Some((id, false));
                Ok(())
            }
            Err(e) => Err(e.into_inner()),
        }
    }

    /// Marks scene `id`, if it is out, to be closed when it comes back.
    pub fn close_when_back(&mut self, id: u32) {
        if let Some((out, close)) = &mut self.out
            && *out == id
        {
            *close = true;
        }
    }

    /// The scene back from the lane, if it came back, and whether it is to be closed.
    pub fn take_back(&mut self) -> Option<(Answered, bool)> {
        let answered = self.back.try_recv().ok()?;
        let (_, close) = self.out.take().unwrap_or((answered.live.id, false));
        Some((answered, close))
    }

    /// Stops the lane once its frame in progress, if any, is answered, and waits for it;
    /// returns the scene that was out, if any.
    pub fn stop(&mut self) -> Option<(Answered, bool)> {
        self.to = None;
        if let Some(thread) = self.thread.take() {
            // A panic on the lane surfaces as the scene missing; the daemon is stopping.
            let _ = thread.join();
        }
        self.take_back()
    }
}
