//! The frame thread: every scene's pose frames, answered earliest deadline first, and
//! nothing else.
//!
//! Each pass takes the oldest waiting frame of every scene that has none in hand (stamped
//! with its receipt), answers the most urgent one ([`schedule`](super::schedule)) under its
//! scene's lock, and starts over, so a frame that arrives meanwhile competes at once. Scenes
//! come and go by [`FrameCommand`]s from the control thread, read between frames; their ports
//! arrive opened, and a closed scene goes back whole ([`Retired`]) to be let go of on the
//! control thread. A frame of a scene dropped since it was taken is dropped unanswered.
//!
//! # Faults
//! An iceoryx2 failure on one scene's ports (receive, loan, send, notify) quarantines that
//! scene: the frame thread stops serving it and hands it back with the reason, and the
//! control thread frees it and tells its owner (DESIGN §10). Every other scene goes on; the
//! daemon never stops for it.
//!
//! # Waiting (hybrid)
//! After the last frame the thread keeps polling for [`DaemonConfig::spin`], then blocks in
//! its WaitSet on every scene's poses-ready listener and its own wake-up listener (the
//! control thread notifies it after each command) until a notification, a termination
//! signal, or [`DaemonConfig::sweep_interval`] (when it looks at the stop flag again).
//!
//! # Allocation
//! None per frame after a scene's first frames (see [`frame_loop`](super::frame_loop)); the
//! list of scenes is sized for [`DaemonConfig::max_scenes`] up front. A blocking wait
//! allocates its list of attachments, never on the polled path.

use super::Ipc;
use super::config::DaemonConfig;
use super::control_thread::{FrameCommand, Retired};
use super::error::DaemonRunError;
use super::frame_loop::SceneFrames;
use super::log::{Logger, Subject};
use super::schedule::most_urgent;
use super::shared_scene::{SharedScene, lock};
use super::stop::StopHandle;
use super::wait::{Wake, wait_for_events};
use crossbeam::channel::{Receiver, Sender};
use iceoryx2::port::listener::Listener;
use iceoryx2::prelude::*;
use std::time::{Duration, Instant};

/// Scenes whose list is allocated up front; beyond, the list grows when scenes come.
const PRESIZED_SCENES: u32 = 1024;

/// The frame thread's ends of its links to the control thread.
pub struct ControlLinks {
    /// Scenes to serve and to stop serving.
    pub commands: Receiver<FrameCommand>,
    /// Notified after each command.
    pub wake: Listener<Ipc>,
    /// Where a closed scene goes to be let go of.
    pub retire: Sender<Retired>,
}

/// A scene the frame thread serves.
struct LiveScene {
    id: u32,
    scene: SharedScene,
    frames: Box<SceneFrames<Ipc>>,
}

/// The frame thread's state (see the module docs).
pub struct FrameThread {
    scenes: Vec<LiveScene>,
    control: ControlLinks,
    log: Logger,
    spin: Duration,
    max_block: Duration,
}

impl FrameThread {
    /// No scenes yet; they come from `control`.
    #[must_use]
    pub fn new(config: &DaemonConfig, control: ControlLinks) -> Self {
        Self {
            scenes: Vec::with_capacity(config.max_scenes.min(PRESIZED_SCENES) as usize),
            control,
            log: Logger::new(config.log_level),
            spin: config.spin,
            max_block: config.sweep_interval,
        }
    }

    /// Serves frames until `stop` or a termination signal, which it then passes on.
    ///
    /// # Errors
    /// [`DaemonRunError`] when iceoryx2 fails to move a frame or to wait.
    pub fn run(&mut self, stop: &StopHandle) -> Result<(), DaemonRunError> {
        let waitset = WaitSetBuilder::new()
            .create::<Ipc>()
            .map_err(|e| DaemonRunError::Ipc(format!("wait set: {e:?}")))?;
        let mut last_work = Instant::now();
        while !stop.is_stopped() {
            self.follow_commands();
            if self.serve_next() {
                last_work = Instant::now();
                continue;
            }
            if last_work.elapsed() < self.spin {
                std::hint::spin_loop();
                continue;
            }
            let listeners = || {
                let scenes = self.scenes.iter().map(|s| s.frames.poses_ready());
                std::iter::once(&self.control.wake).chain(scenes)
            };
            if wait_for_events(&waitset, listeners, self.max_block)? == Wake::Stop {
                stop.stop();
            }
            last_work = Instant::now();
        }
        for live in &self.scenes {
            log_lateness(&mut self.log, live.id, &live.frames);
        }
        Ok(())
    }

    /// Takes on the scenes the control thread opened and lets go of those it closed.
    fn follow_commands(&mut self) {
        while let Ok(command) = self.control.commands.try_recv() {
            match command {
                FrameCommand::Open { id, scene, frames } => {
                    self.scenes.push(LiveScene { id, scene, frames });
                }
                FrameCommand::Close(id) => {
                    if let Some(index) = self.scenes.iter().position(|s| s.id == id) {
                        self.retire(index, None);
                    }
                }
            }
        }
    }

    /// Stops serving the scene at `index` and hands it back to the control thread, with the
    /// fault that ended it, if any.
    fn retire(&mut self, index: usize, fault: Option<String>) {
        let LiveScene { id, scene, frames } = self.scenes.swap_remove(index);
        log_lateness(&mut self.log, id, &frames);
        if let Some(why) = &fault {
            self.log.error(format_args!(
                "{}: quarantined after a fault on its services: {why}",
                Subject::Scene(id)
            ));
        } else if let Err(why) = frames.publish_release() {
            // Readers of its results then learn it from their waits ending without frames.
            self.log.warn(format_args!(
                "{}: publishing its release failed: {why}",
                Subject::Scene(id)
            ));
        }
        self.log.release(Subject::Scene(id));
        // Should the control thread be gone, the scene is let go of here after all.
        let retired = Retired {
            id,
            scene,
            frames,
            fault,
        };
        let _ = self.control.retire.try_send(retired);
    }

    /// Takes each scene's next frame, answers the most urgent of those waiting; returns
    /// whether there was one. A scene whose ports fail is quarantined.
    fn serve_next(&mut self) -> bool {
        let mut index = 0;
        while index < self.scenes.len() {
            match self.scenes[index].frames.take_next() {
                Ok(()) => index += 1,
                Err(fault) => self.retire(index, Some(fault)),
            }
        }
        let waiting = self.scenes.iter().enumerate();
        let waiting = waiting.filter_map(|(i, live)| Some((i, live.frames.waiting()?)));
        let Some(index) = most_urgent(waiting) else {
            return false;
        };
        let LiveScene { id, scene, frames } = &mut self.scenes[index];
        let mut cell = lock(scene);
        if cell.dropped {
            frames.discard_waiting();
            return true;
        }
        let answered = frames.answer_waiting(*id, &mut cell.scene, &mut self.log);
        drop(cell);
        if let Err(fault) = answered {
            self.retire(index, Some(fault));
        }
        true
    }
}

/// Logs how many of a closing scene's frames were late, and why (a warning: each broke the
/// promise of an answer by the deadline).
fn log_lateness(log: &mut Logger, id: u32, frames: &SceneFrames<Ipc>) {
    if let Some(line) = frames.lateness().summary() {
        log.warn(format_args!("{}: {line}", Subject::Scene(id)));
    }
}
