//! The frame thread: every scene's pose frames, answered earliest deadline first, and
//! nothing else.
//!
//! Each pass takes the oldest waiting frame of every scene that has none in hand (stamped
//! with its receipt), answers the most urgent one ([`schedule`](super::schedule)) under its
//! scene's lock, and starts over, so a frame that arrives meanwhile competes at once. A
//! frame without a deadline (`budget_ns == 0`, exact whatever it costs) is worked on here
//! for at most a short slice; one that takes longer is parked, and its scene goes to the
//! [`lane`](super::lane), a thread of its own, to finish it and come back, so no such frame
//! holds up a frame with a deadline for more than the slice. Scenes
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
//! control thread notifies it after each command, the lane after each frame) until a
//! notification, a termination
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
use super::frame_loop::{Answer, SceneFrames};
use super::lane::{Answered, Lane};
use super::log::{Level, Logger, Subject};
use super::realtime;
use super::schedule::most_urgent;
use super::shared_scene::{SharedScene, lock};
use super::stop::StopHandle;
use super::wait::{Wake, wait_for_events};
use crossbeam::channel::{Receiver, Sender};
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::prelude::*;
use std::time::{Duration, Instant};

/// Scenes whose list is allocated up front; beyond, the list grows when scenes come.
const PRESIZED_SCENES: u32 = 1024;

/// The frame thread's ends of its links to the control thread.
pub struct ControlLinks {
    /// Scenes to serve and to stop serving.
    pub commands: Receiver<FrameCommand>,
    /// Notified after each command (and by the lane after each frame).
    pub wake: Listener<Ipc>,
    /// Where a closed scene goes to be let go of.
    pub retire: Sender<Retired>,
}

/// A scene the frame thread serves.
pub struct LiveScene {
    /// The scene's id.
    pub id: u32,
    scene: SharedScene,
    frames: Box<SceneFrames<Ipc>>,
}

impl LiveScene {
    /// Answers the scene's waiting frame under its lock, one without a deadline within
    /// `slice_end` (else it is parked); drops it unanswered if the scene was dropped since
    /// the frame was taken.
    ///
    /// # Errors
    /// An iceoryx2 failure on the scene's ports, as text.
    fn answer_waiting(
        &mut self,
        log: &mut Logger,
        slice_end: Option<Instant>,
    ) -> Result<Answer, String> {
        let mut cell = lock(&self.scene);
        if cell.dropped {
            self.frames.discard_waiting();
            return Ok(Answer::Nothing);
        }
        self.frames
            .answer_waiting(self.id, &mut cell.scene, log, slice_end)
    }

    /// Finishes the scene's parked frame under its lock (drops it if the scene was
    /// dropped meanwhile).
    ///
    /// # Errors
    /// An iceoryx2 failure on the scene's ports, as text.
    pub fn answer_parked(&mut self, log: &mut Logger) -> Result<(), String> {
        let mut cell = lock(&self.scene);
        if cell.dropped {
            self.frames.discard_waiting();
            return Ok(());
        }
        self.frames
            .answer_parked(self.id, &mut cell.scene, log)
            .map(drop)
    }

    fn is_parked(&self) -> bool {
        self.frames.is_parked()
    }
}

/// How long a frame without a deadline is worked on here before it is parked and handed to
/// the lane: most such frames take less and are answered at once; a longer one holds up
/// frames with a deadline by at most this (plus the step it is in when the slice ends).
const INLINE_SLICE: Duration = Duration::from_micros(250);

/// The frame thread's state (see the module docs).
pub struct FrameThread {
    scenes: Vec<LiveScene>,
    control: ControlLinks,
    /// Handed to the lane when the thread starts.
    lane_wake: Option<Notifier<Ipc>>,
    log: Logger,
    level: Level,
    spin: Duration,
    max_block: Duration,
    /// `SCHED_FIFO` priority to serve at, once the lane has started.
    realtime_priority: Option<u8>,
}

impl FrameThread {
    /// No scenes yet; they come from `control`.
    #[must_use]
    pub fn new(config: &DaemonConfig, control: ControlLinks, lane_wake: Notifier<Ipc>) -> Self {
        Self {
            scenes: Vec::with_capacity(config.max_scenes.min(PRESIZED_SCENES) as usize),
            control,
            lane_wake: Some(lane_wake),
            log: Logger::new(config.log_level),
            level: config.log_level,
            spin: config.spin,
            max_block: config.sweep_interval,
            realtime_priority: config.realtime_priority,
        }
    }

    /// Serves frames until `stop` or a termination signal, which it then passes on; frames
    /// without a deadline go to the [`lane`](super::lane).
    ///
    /// # Errors
    /// [`DaemonRunError`] when iceoryx2 fails to wait, or the lane cannot start.
    pub fn run(&mut self, stop: &StopHandle) -> Result<(), DaemonRunError> {
        let waitset = WaitSetBuilder::new()
            .create::<Ipc>()
            .map_err(|e| DaemonRunError::Ipc(format!("wait set: {e:?}")))?;
        let lane_wake = self
            .lane_wake
            .take()
            .ok_or_else(|| DaemonRunError::Ipc("the frame thread ran twice".to_owned()))?;
        std::thread::scope(|scope| {
            let lane = Lane::spawn(scope, lane_wake, self.level)
                .map_err(|e| DaemonRunError::Ipc(format!("starting the lane: {e}")))?;
            // Raised only now: the lane, started above, keeps the fair scheduler.
            if let Some(priority) = self.realtime_priority {
                match realtime::raise_current_thread(priority) {
                    Ok(()) => self.log.info(format_args!(
                        "frame thread under SCHED_FIFO, priority {priority}"
                    )),
                    Err(e) => self
                        .log
                        .warn(format_args!("{e}; the frame thread keeps normal priority")),
                }
            }
            let mut running = Running { thread: self, lane };
            let served = running.serve(stop, &waitset);
            if running.thread.realtime_priority.is_some() {
                realtime::lower_current_thread();
            }
            if let Some(back) = running.lane.stop() {
                running.take_back(back);
            }
            for live in &running.thread.scenes {
                log_lateness(&mut running.thread.log, live.id, &live.frames);
            }
            served
        })
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
}

/// The frame thread while it runs: its state, and its end of the lane.
struct Running<'t, 'scope> {
    thread: &'t mut FrameThread,
    lane: Lane<'scope>,
}

impl Running<'_, '_> {
    fn serve(&mut self, stop: &StopHandle, waitset: &WaitSet<Ipc>) -> Result<(), DaemonRunError> {
        let mut last_work = Instant::now();
        while !stop.is_stopped() {
            self.follow_commands();
            if let Some(back) = self.lane.take_back() {
                self.take_back(back);
            }
            if self.serve_next() {
                last_work = Instant::now();
                continue;
            }
            let thread = &*self.thread;
            if last_work.elapsed() < thread.spin {
                std::hint::spin_loop();
                continue;
            }
            let listeners = || {
                let scenes = thread.scenes.iter().map(|s| s.frames.poses_ready());
                std::iter::once(&thread.control.wake).chain(scenes)
            };
            if wait_for_events(waitset, listeners, thread.max_block)? == Wake::Stop {
                stop.stop();
            }
            last_work = Instant::now();
        }
        Ok(())
    }

    /// Takes on the scenes the control thread opened and lets go of those it closed (one
    /// out on the lane when it comes back).
    fn follow_commands(&mut self) {
        while let Ok(command) = self.thread.control.commands.try_recv() {
            match command {
                FrameCommand::Open { id, scene, frames } => {
                    self.thread.scenes.push(LiveScene { id, scene, frames });
                }
                FrameCommand::Close(id) => {
                    if let Some(index) = self.thread.scenes.iter().position(|s| s.id == id) {
                        self.thread.retire(index, None);
                    } else {
                        self.lane.close_when_back(id);
                    }
                }
            }
        }
    }

    /// Serves a scene back from the lane again, or retires it (closed meanwhile, or its
    /// ports failed).
    fn take_back(&mut self, (answered, close): (Answered, bool)) {
        let Answered { live, outcome } = answered;
        self.thread.scenes.push(live);
        let index = self.thread.scenes.len() - 1;
        match outcome {
            Err(fault) => self.thread.retire(index, Some(fault)),
            Ok(()) if close => self.thread.retire(index, None),
            Ok(()) => {}
        }
    }

    /// Takes each scene's next frame and answers the most urgent of those waiting (one
    /// without a deadline for at most [`INLINE_SLICE`], then it is parked), or hands a
    /// parked frame's scene to the lane when the lane is free; returns whether there was
    /// work. A scene whose ports fail is quarantined.
    fn serve_next(&mut self) -> bool {
        let thread = &mut *self.thread;
        let mut index = 0;
        while index < thread.scenes.len() {
            match thread.scenes[index].frames.take_next() {
                Ok(()) => index += 1,
                Err(fault) => thread.retire(index, Some(fault)),
            }
        }
        if self.lane.is_free()
            && let Some(parked) = thread.scenes.iter().position(LiveScene::is_parked)
        {
            self.hand_to_lane(parked);
            return true;
        }
        let waiting = thread.scenes.iter().enumerate();
        let waiting = waiting.filter_map(|(i, live)| Some((i, live.frames.waiting()?)));
        let Some(index) = most_urgent(waiting) else {
            return false;
        };
        let slice_end = Instant::now() + INLINE_SLICE;
        match thread.scenes[index].answer_waiting(&mut thread.log, Some(slice_end)) {
            Err(fault) => thread.retire(index, Some(fault)),
            Ok(Answer::Parked) if self.lane.is_free() => self.hand_to_lane(index),
            Ok(_) => {}
        }
        true
    }

    /// Hands the scene at `index`, whose frame is parked, to the lane; should the lane be
    /// gone (the daemon is stopping), finishes the frame here.
    fn hand_to_lane(&mut self, index: usize) {
        let thread = &mut *self.thread;
        let live = thread.scenes.swap_remove(index);
        if let Err(live) = self.lane.send(live) {
            thread.scenes.push(live);
            let index = thread.scenes.len() - 1;
            if let Err(fault) = thread.scenes[index].answer_parked(&mut thread.log) {
                thread.retire(index, Some(fault));
            }
        }
    }
}

/// Logs how many of a closing scene's frames were late, and why (a warning: each broke the
/// promise of an answer by the deadline).
fn log_lateness(log: &mut Logger, id: u32, frames: &SceneFrames<Ipc>) {
    if let Some(line) = frames.lateness().summary() {
        log.warn(format_args!("{}: {line}", Subject::Scene(id)));
    }
}
