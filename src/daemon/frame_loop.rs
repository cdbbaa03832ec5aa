//! The frame path of one scene: take a pose frame (stamped with its receipt; it then waits
//! for its turn, see [`schedule`](super::schedule)), ingest it (poses and query), run the
//! pipeline for that query, write the result frame — pair records, then contact records,
//! then time-of-impact records — straight into a loaned shared-memory sample, publish,
//! notify. An answered frame ends the scene's frame ([`Scene::end_frame`]): its poses are
//! where the next frame's motion starts (refused frames apply no pose and end nothing).
//!
//! A frame with a budget (`budget_ns > 0`) runs [`pipeline::step_within`] with a
//! [`Deadline`] at the frame's receipt plus its budget (the pipeline keeps back the time
//! this publishing takes, measured per record and told it by
//! [`PipelineWorkspace::note_publish`]); `budget_ns == 0` runs the exact [`pipeline::step`].
//!
//! The header carries the pipeline's own [`StepReport`]: its completeness (with
//! `Truncated`, the shallowest level any pair stopped at in `deepest_level`), broad, mid
//! (the budgeted frontier, 0 without a budget) and narrow timings (`stage_ns[BROAD]`,
//! `stage_ns[MID]`, `stage_ns[NARROW]`), candidate, pair and contact counts, and the
//! candidates dropped beyond the scene's pair limit (`flags` says `PAIRS_CAPPED`); ingest
//! and publish are timed here. The plan stage the pipeline does not have yet stays 0.
//!
//! # Allocation
//! After a scene's first frames, none: the pipeline workspace and the result lists are
//! reused, and result records are written into the loaned sample. (A result frame larger
//! than any before makes iceoryx2 map a bigger segment once.)

use super::convert::Rejection;
use super::ingest::{FrameRejection, apply_pose_frame};
use super::lateness::{LateFrame, Lateness, thread_cpu_ns};
use super::log::{Cause, Level, Logger, Subject};
use super::records::{contact_record, pair_record, toi_record};
use super::schedule::FrameKey;
use super::shared_scene::SceneSignals;
use crate::math::Pose;
use crate::pipeline::{
    self, Completeness, Deadline, FrameResults, PipelineWorkspace, Query, StepReport, WorkerPool,
};
use crate::scene::{BodyId, Scene};
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use iceoryx2::sample::Sample;
use iceoryx2::sample_mut::SampleMut;
use proxima_ipc::wire::{
    self, ErrorCode, PoseFrameHeader, PoseRecord, ResultFrameHeader, ResultRecord,
};
use proxima_ipc::{EVENT_RESULTS_READY, PROTOCOL_VERSION, SceneToken};
use std::sync::Arc;
use std::time::Instant;

/// Initial number of result records a result sample can hold (grows by powers of two).
const INITIAL_RESULT_RECORDS: usize = 1024;

/// A received pose frame, still in shared memory.
type PoseSample<S> = Sample<S, [PoseRecord], PoseFrameHeader>;

/// A result frame written in shared memory, not sent yet.
type ResultSample<S> = SampleMut<S, [ResultRecord], ResultFrameHeader>;

/// What [`SceneFrames::answer_waiting`] did with the waiting frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Answer {
    /// There was none, or it was not the owner's (dropped unanswered).
    Nothing,
    /// Answered and published.
    Published,
    /// Its slice ended first: its poses are applied, nothing is published, and
    /// [`SceneFrames::answer_parked`] finishes it.
    Parked,
}

/// A pose frame taken in and applied, with what its answer needs from its receipt.
struct Ingested {
    header: PoseFrameHeader,
    key: FrameKey,
    /// The frame thread's CPU time at the frame's receipt.
    cpu_at_receipt: u64,
    ingest_ns: u64,
}

impl Ingested {
    /// The header of the frame's result, as far as ingest knows it.
    fn result_header(&self, instance: u64) -> ResultFrameHeader {
        let mut result = ResultFrameHeader {
            protocol_version: PROTOCOL_VERSION,
            frame_seq: self.header.frame_seq,
            error_body: u32::MAX,
            instance,
            ..ResultFrameHeader::default()
        };
        result.stage_ns[wire::stage::INGEST] = self.ingest_ns;
        result
    }
}

/// Who a scene's frames are for: the secrets its services and frames carry, the daemon
/// run answering them, and the flag that abandons them.
#[derive(Clone)]
pub struct SceneKeys {
    /// Names the scene's services.
    pub token: SceneToken,
    /// Every pose frame of the scene's owner carries it; other frames are not answered.
    pub frame_key: u64,
    /// This daemon run's instance id, in every result header.
    pub instance: u64,
    /// What the control thread tells the scene's frames while one may be in progress.
    pub signals: SceneSignals,
}

/// A scene's ports, the frame waiting for its turn and per-frame scratch space.
pub struct SceneFrames<S: Service> {
    keys: SceneKeys,
    poses: Subscriber<S, [PoseRecord], PoseFrameHeader>,
    results: Publisher<S, [ResultRecord], ResultFrameHeader>,
    notifier: Notifier<S>,
    /// Wakes the frame path when a client has published a pose frame.
    poses_ready: Listener<S>,
    /// The oldest pose frame taken from `poses` and not answered yet, with its receipt and
    /// the frame thread's CPU time then ([`thread_cpu_ns`]).
    waiting: Option<(PoseSample<S>, FrameKey, u64)>,
    /// The frame whose slice ended before its answer ([`Answer::Parked`]), and its query.
    parked: Option<(Ingested, Query)>,
    /// Its budgeted frames that were late, and why.
    lateness: Lateness,
    workspace: PipelineWorkspace,
    output: FrameResults,
    validated: Vec<(BodyId, Pose)>,
    /// Records a result sample of the publisher's data segment holds now (it grows by
    /// powers of two, [`grow_results_ahead`](Self::grow_results_ahead)).
    results_room: usize,
}

impl<S: Service> SceneFrames<S> {
    /// Creates the services of the scene `keys` names under `root`, with every setting of
    /// the shared builders, and the daemon's ports on them. Services that already exist were
    /// set up by someone else (the token is secret and fresh): refused, not opened.
    ///
    /// # Errors
    /// The iceoryx2 failure, as text.
    pub fn open(
        node: &Node<S>,
        root: &str,
        keys: SceneKeys,
        workers: &Arc<WorkerPool>,
    ) -> Result<Self, String> {
        let token = keys.token;
        let poses = proxima_ipc::poses_service_builder(node, root, token)
            .map_err(|e| format!("{e:?}"))?
            .create()
            .map_err(|e| format!("creating the poses service: {e:?}"))?
            .subscriber_builder()
            .create()
            .map_err(|e| format!("poses subscriber: {e:?}"))?;
        // Never held up by a subscriber that does not read: with safe overflow (set by the
        // builder) its oldest frame is overwritten, and were it off, the frame is dropped.
        let results = proxima_ipc::results_service_builder(node, root, token)
            .map_err(|e| format!("{e:?}"))?
            .create()
            .map_err(|e| format!("creating the results service: {e:?}"))?
            .publisher_builder()
            .initial_max_slice_len(INITIAL_RESULT_RECORDS)
            .allocation_strategy(AllocationStrategy::PowerOfTwo)
            .backpressure_strategy(BackpressureStrategy::DiscardData)
            .create()
            .map_err(|e| format!("results publisher: {e:?}"))?;
        let notifier = proxima_ipc::events_service_builder(node, root, token)
            .map_err(|e| format!("{e:?}"))?
            .create()
            .map_err(|e| format!("creating the results-ready service: {e:?}"))?
            .notifier_builder()
            .create()
            .map_err(|e| format!("events notifier: {e:?}"))?;
        let poses_ready = proxima_ipc::poses_ready_service_builder(node, root, token)
            .map_err(|e| format!("{e:?}"))?
            .create()
            .map_err(|e| format!("creating the poses-ready service: {e:?}"))?
            .listener_builder()
            .create()
            .map_err(|e| format!("poses-ready listener: {e:?}"))?;
        Ok(Self {
            poses,
            results,
            notifier,
            poses_ready,
            waiting: None,
            parked: None,
            lateness: Lateness::default(),
            workspace: PipelineWorkspace::with_workers(Arc::clone(workers))
                .publishing()
                .abandon_on(keys.signals.abandon().clone()),
            output: FrameResults::default(),
            validated: Vec::new(),
            results_room: INITIAL_RESULT_RECORDS,
            keys,
        })
    }

    /// The listener clients notify after publishing a pose frame.
    pub fn poses_ready(&self) -> &Listener<S> {
        &self.poses_ready
    }

    /// Takes the next pose frame from the subscriber, stamped with its receipt, unless one
    /// is already waiting or parked (the scene's frames are answered in order).
    ///
    /// # Errors
    /// The iceoryx2 failure, as text.
    pub fn take_next(&mut self) -> Result<(), String> {
        if self.waiting.is_none()
            && self.parked.is_none()
            && let Some(sample) = self
                .poses
                .receive()
                .map_err(|e| format!("poses receive: {e:?}"))?
        {
            let key = FrameKey {
                received: Instant::now(),
                budget_ns: sample.user_header().budget_ns,
            };
            self.waiting = Some((sample, key, thread_cpu_ns()));
        }
        Ok(())
    }

    /// The receipt and budget of the frame waiting for its turn.
    pub fn waiting(&self) -> Option<FrameKey> {
        self.waiting.as_ref().map(|&(_, key, _)| key)
    }

    /// Answers the waiting frame (see [`take_next`](Self::take_next)) over `scene` (id
    /// `scene_id`). A frame without a deadline is tried until `slice_end`, when given: one
    /// not done by then is [`Answer::Parked`], its poses applied and nothing published, for
    /// [`answer_parked`](Self::answer_parked) to finish (on another thread: the lane).
    ///
    /// # Errors
    /// The iceoryx2 failure, as text (client mistakes are answered in the result header).
    pub fn answer_waiting(
        &mut self,
        scene_id: u32,
        scene: &mut Scene,
        log: &mut Logger,
        slice_end: Option<Instant>,
    ) -> Result<Answer, String> {
        let Some((sample, key, cpu_at_receipt)) = self.waiting.take() else {
            return Ok(Answer::Nothing);
        };
        let header = *sample.user_header();
        if header.frame_key != self.keys.frame_key {
            // Not the owner's: not answered, so the owner's results are untouched.
            drop(sample);
            let cause = Cause {
                what: "foreign pose frame",
                code: ErrorCode::NotOwner as u32,
            };
            log.once(Level::Warn, Subject::Scene(scene_id), cause, || {
                "pose frame without the scene's frame key ignored (not its owner's)".to_owned()
            });
            return Ok(Answer::Nothing);
        }
        let ingest_started = Instant::now();
        let outcome = apply_pose_frame(
            scene_id,
            scene,
            &header,
            sample.payload(),
            &mut self.validated,
        );
        drop(sample);
        let frame = Ingested {
            header,
            key,
            cpu_at_receipt,
            ingest_ns: elapsed_ns(ingest_started),
        };
        let mut result = frame.result_header(self.keys.instance);
        match outcome {
            Err(FrameRejection {
                rejection: Rejection { code, reason },
                body,
            }) => {
                let seq = header.frame_seq;
                log.once(
                    Level::Warn,
                    Subject::Scene(scene_id),
                    Cause {
                        what: "refused pose frame",
                        code: code as u32,
                    },
                    || format!("frame {seq} refused: {reason}"),
                );
                self.output.pairs.clear();
                self.output.contacts.clear();
                self.output.tois.clear();
                result.status = code as u32;
                result.error_body = body.unwrap_or(u32::MAX);
            }
            Ok(query) => {
                let Some(report) = self.step(scene, query, key, slice_end) else {
                    self.parked = Some((frame, query));
                    return Ok(Answer::Parked);
                };
                self.end_frame(scene, &mut result, &report, frame.ingest_ns);
            }
        }
        self.publish_answer(scene_id, result, &frame, log)?;
        Ok(Answer::Published)
    }

    /// Finishes the [parked](Answer::Parked) frame, if any, exactly, and publishes it.
    ///
    /// # Errors
    /// The iceoryx2 failure, as text.
    pub fn answer_parked(
        &mut self,
        scene_id: u32,
        scene: &mut Scene,
        log: &mut Logger,
    ) -> Result<Answer, String> {
        let Some((frame, query)) = self.parked.take() else {
            return Ok(Answer::Nothing);
        };
        let mut result = frame.result_header(self.keys.instance);
        let report = pipeline::step(scene, query, &mut self.workspace, &mut self.output);
        self.end_frame(scene, &mut result, &report, frame.ingest_ns);
        self.publish_answer(scene_id, result, &frame, log)?;
        Ok(Answer::Published)
    }

    /// Whether a frame is parked (its scene then takes no next frame until it is answered).
    pub fn is_parked(&self) -> bool {
        self.parked.is_some()
    }

    /// Ends the scene's frame after the pipeline's `report`: the poses become where the
    /// next frame's motion starts, and the report goes into `result`.
    fn end_frame(
        &self,
        scene: &mut Scene,
        result: &mut ResultFrameHeader,
        report: &StepReport,
        ingest_ns: u64,
    ) {
        scene.end_frame();
        fill_header(result, report);
        if self.keys.signals.is_owner_gone() {
            result.flags |= wire::frame_flags::OWNER_GONE;
        }
        if let Some(needed) = report.budget_too_small {
            result.flags |= wire::frame_flags::BUDGET_TOO_SMALL;
            result.min_budget_ns = ingest_ns.saturating_add(needed);
        }
    }

    /// Publishes `result` and the output of `frame`, and notes its publishing time and
    /// lateness.
    fn publish_answer(
        &mut self,
        scene_id: u32,
        result: ResultFrameHeader,
        frame: &Ingested,
        log: &mut Logger,
    ) -> Result<(), String> {
        let budget_ns = frame.header.budget_ns;
        let published = self.publish(result, frame.key.received, budget_ns)?;
        let records = self.output.record_count();
        self.workspace
            .note_publish(published.publish_ns, records as u64);
        let cpu_ns = published.cpu_ns.saturating_sub(frame.cpu_at_receipt);
        if let Some(late) = self.lateness.note(budget_ns, published.elapsed_ns, cpu_ns) {
            log_late(log, scene_id, frame.header.frame_seq, late);
        }
        self.grow_results_ahead(records, scene_id, log);
        Ok(())
    }

    /// Doubles the results' data segment, after a frame is published, once a frame used
    /// more than half of it: the growth then happens between frames, not inside the next
    /// frame that needs it. A loan larger than the segment makes the publisher allocate and
    /// map a new one (`AllocationStrategy::PowerOfTwo`): 230 µs of one frame's publish in
    /// `falling_bodies` (1,058 records, 1,024 held), counted in that frame's time. Here the
    /// larger sample is loaned, written (its pages touched) and dropped unsent.
    fn grow_results_ahead(&mut self, records: usize, scene_id: u32, log: &mut Logger) {
        // A frame that outgrew the segment has grown it already.
        self.results_room = self.results_room.max(records.next_power_of_two());
        if records <= self.results_room / 2 {
            return;
        }
        let room = self.results_room.saturating_mul(2);
        match self.results.loan_slice_uninit(room) {
            Ok(sample) => {
                drop(sample.write_from_fn(|_| ResultRecord::default()));
                self.results_room = room;
            }
            // No chunk free (subscribers hold them all), or no memory: the frame that needs
            // the room grows the segment itself, as before.
            Err(e) => {
                let cause = Cause {
                    what: "results segment not grown ahead",
                    code: 0,
                };
                log.once(Level::Debug, Subject::Scene(scene_id), cause, || {
                    format!("results segment not grown ahead of need: {e:?}")
                });
            }
        }
    }

    /// Its budgeted frames that were late, and why.
    pub fn lateness(&self) -> &Lateness {
        &self.lateness
    }

    /// Drops the waiting and the parked frame unanswered (its scene is gone).
    pub fn discard_waiting(&mut self) {
        self.waiting = None;
        self.parked = None;
    }

    /// Publishes the scene's last result frame, which tells whoever reads its results (its
    /// owner, a monitor holding its token) that the daemon let go of it: status
    /// `SceneReleased`, no records, `OWNER_GONE` when the owner's absence was why.
    ///
    /// # Errors
    /// The iceoryx2 failure, as text.
    pub fn publish_release(&self) -> Result<(), String> {
        let mut header = ResultFrameHeader {
            protocol_version: PROTOCOL_VERSION,
            status: ErrorCode::SceneReleased as u32,
            error_body: u32::MAX,
            instance: self.keys.instance,
            ..ResultFrameHeader::default()
        };
        if self.keys.signals.is_owner_gone() {
            header.flags |= wire::frame_flags::OWNER_GONE;
        }
        let mut sample = self
            .results
            .loan_slice_uninit(0)
            .map_err(|e| format!("results loan: {e:?}"))?
            .write_from_fn(|_| ResultRecord::default());
        *sample.user_header_mut() = header;
        self.send(sample)
    }

    /// Runs the pipeline for `query`: exact without a deadline (no budget, or one beyond
    /// what an [`Instant`] holds), within `slice_end` when given (`None` if that came
    /// first), else within the frame's deadline.
    fn step(
        &mut self,
        scene: &Scene,
        query: Query,
        key: FrameKey,
        slice_end: Option<Instant>,
    ) -> Option<StepReport> {
        let (workspace, output) = (&mut self.workspace, &mut self.output);
        match (key.deadline(), slice_end) {
            (Some(deadline), _) => Some(pipeline::step_within(
                scene,
                query,
                &mut Deadline(deadline),
                workspace,
                output,
            )),
            (None, Some(end)) => pipeline::step_sliced(scene, query, end, workspace, output),
            (None, None) => Some(pipeline::step(scene, query, workspace, output)),
        }
    }

    /// Writes and publishes the result frame and notifies.
    fn publish(
        &self,
        mut header: ResultFrameHeader,
        received: Instant,
        budget_ns: u64,
    ) -> Result<Published, String> {
        let publish_started = Instant::now();
        let FrameResults {
            pairs,
            contacts,
            tois,
        } = &self.output;
        let tois_from = pairs.len() + contacts.len();
        let mut sample = self
            .results
            .loan_slice_uninit(tois_from + tois.len())
            .map_err(|e| format!("results loan: {e:?}"))?
            .write_from_fn(|i| match pairs.get(i) {
                Some(pair) => pair_record(pair),
                None if i < tois_from => contact_record(pairs, &contacts[i - pairs.len()]),
                None => toi_record(&tois[i - tois_from]),
            });
        header.stage_ns[wire::stage::PUBLISH] = elapsed_ns(publish_started);
        header.elapsed_ns = elapsed_ns(received);
        let cpu_ns = thread_cpu_ns();
        header.budget_met = u32::from(budget_ns == 0 || header.elapsed_ns <= budget_ns);
        *sample.user_header_mut() = header;
        self.send(sample)?;
        Ok(Published {
            publish_ns: elapsed_ns(publish_started),
            elapsed_ns: header.elapsed_ns,
            cpu_ns,
        })
    }

    /// Sends a written result frame and notifies its readers.
    fn send(&self, sample: ResultSample<S>) -> Result<(), String> {
        sample.send().map_err(|e| format!("results send: {e:?}"))?;
        self.notifier
            .notify_with_custom_event_id(EventId::new(EVENT_RESULTS_READY))
            .map_err(|e| format!("results notify: {e:?}"))?;
        Ok(())
    }
}

/// What [`SceneFrames::publish`] measured.
struct Published {
    /// Writing, publishing and notifying, nanoseconds.
    publish_ns: u64,
    /// The header's `elapsed_ns`: receipt to the result stamped for sending.
    elapsed_ns: u64,
    /// The frame thread's CPU time ([`thread_cpu_ns`]) when `elapsed_ns` was taken.
    cpu_ns: u64,
}

/// Logs a scene's first late frame of each kind (the OS's stall, the daemon's work); later
/// ones are counted ([`Logger::once`]).
fn log_late(log: &mut Logger, scene_id: u32, seq: u64, late: LateFrame) {
    let (level, code, why) = if late.stalled_by_os() {
        (Level::Debug, 0, "the OS held the frame thread off the CPU")
    } else {
        (Level::Warn, 1, "late by the daemon's work")
    };
    let cause = Cause {
        what: "late frame",
        code,
    };
    log.once(level, Subject::Scene(scene_id), cause, || {
        format!(
            "frame {seq} late by {} µs ({why}: {} µs off the CPU)",
            late.late_ns / 1_000,
            late.off_cpu_ns / 1_000
        )
    });
}

fn elapsed_ns(since: Instant) -> u64 {
    u64::try_from(since.elapsed().as_nanos()).unwrap_or(u64::MAX)
}

/// Copies the pipeline's report into a successful frame's header.
fn fill_header(header: &mut ResultFrameHeader, report: &StepReport) {
    header.status = ErrorCode::Ok as u32;
    header.completeness = match report.completeness {
        Completeness::Exact => wire::Completeness::Exact as u32,
        Completeness::Truncated { level } => {
            header.deepest_level = level;
            wire::Completeness::Truncated as u32
        }
    };
    header.stage_ns[wire::stage::BROAD] = report.broad_ns;
    header.stage_ns[wire::stage::MID] = report.mid_ns;
    header.stage_ns[wire::stage::NARROW] = report.narrow_ns;
    // With TOI the swept candidates, a superset of the others.
    header.candidate_count = report.candidates.max(report.toi_candidates);
    header.pair_count = report.pairs;
    header.contact_count = report.contacts;
    header.toi_count = report.tois;
    header.dropped_candidates = report.dropped_candidates;
    if report.dropped_candidates > 0 {
        header.flags |= wire::frame_flags::PAIRS_CAPPED;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use iceoryx2::prelude::local;

    #[test]
    fn a_scene_whose_services_someone_else_set_up_first_is_refused_not_served() {
        let node = NodeBuilder::new().create::<local::Service>().unwrap();
        let root = format!("frame-loop-test-{}", std::process::id());
        let workers = Arc::new(WorkerPool::new(0));
        let keys = |n| SceneKeys {
            token: SceneToken([n, 7]),
            frame_key: 1,
            instance: 1,
            signals: SceneSignals::default(),
        };
        // Each of the four services, set up ahead with hostile settings (one event id, a
        // deadline, safe overflow off): the scene is refused, whichever it is.
        let _results_ready =
            proxima_ipc::results_ready_service_builder(&node, &root, keys(1).token)
                .unwrap()
                .event_id_max_value(1)
                .create()
                .unwrap();
        let _poses_ready = proxima_ipc::poses_ready_service_builder(&node, &root, keys(2).token)
            .unwrap()
            .deadline(std::time::Duration::from_millis(1))
            .create()
            .unwrap();
        let _results = proxima_ipc::results_service_builder(&node, &root, keys(3).token)
            .unwrap()
            .enable_safe_overflow(false)
            .create()
            .unwrap();
        let _poses = proxima_ipc::poses_service_builder(&node, &root, keys(4).token)
            .unwrap()
            .create()
            .unwrap();
        for (n, service) in [
            (1, "results-ready"),
            (2, "poses-ready"),
            (3, "results"),
            (4, "poses"),
        ] {
            let refused = SceneFrames::open(&node, &root, keys(n), &workers).err();
            let why = refused.unwrap_or_else(|| panic!("{service}: served"));
            assert!(
                why.contains(&format!("creating the {service} service"))
                    && why.contains("AlreadyExists"),
                "{service}: {why}"
            );
        }
        // A fresh token's services are created and served.
        assert!(SceneFrames::open(&node, &root, keys(5), &workers).is_ok());
    }
}
