//! The frame half of the client: a [`SceneLink`] publishes a scene's pose frames, writing
//! the records straight into a loaned shared-memory sample, and receives its result frames
//! without copying them ([`ResultFrame`]).
//!
//! ```no_run
//! use proxima_ipc::client::ClientBuilder;
//! use proxima_ipc::wire::query;
//! use std::time::Duration;
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let client = ClientBuilder::new().connect::<iceoryx2::service::ipc::Service>()?;
//! let scene = client.create_scene()?;
//! let link = client.open_scene(scene)?;
//! let body = 7;
//! link.publish_poses_with(1, 1_000_000, query::CLOSE, 1, |_| {
//!     proxima_ipc::wire::PoseRecord {
//!         body,
//!         reserved: 0,
//!         position: [0.0, 0.0, 1.0],
//!         orientation: [0.0, 0.0, 0.0, 1.0],
//!     }
//! })?;
//! if let Some(frame) = link.receive_results_for(1, Duration::from_millis(10))? {
//!     for pair in frame.pairs() {
//!         println!("{} – {}: {} m", pair.body_a, pair.body_b, pair.distance);
//!     }
//! }
//! # Ok(())
//! # }
//! ```
//!
//! Waiting is hybrid (see `shared/notes/iceoryx2-0.10.md`): the subscriber is polled for
//! [`RESULTS_SPIN`](crate::transport::RESULTS_SPIN), then the wait blocks on the scene's
//! results-ready listener until the daemon notifies
//! [`EVENT_RESULTS_READY`](crate::EVENT_RESULTS_READY) or the deadline passes; the spin
//! catches the answers that come sooner than a wake-up (see [`transport`](crate::transport)).
//! Pose frames are announced on a separate poses-ready service, so the client's own
//! notifications never wake its wait.
//!
//! The daemon creates a scene's services and ports before it answers `CreateScene`, so a
//! link opened after that reply loses no frame. Only the scene's owner holds its
//! [`SceneAccess`] (the [`Client`](crate::client::Client) that created it keeps it).

use std::time::Duration;

use iceoryx2::node::Node;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::prelude::{AllocationStrategy, EventId};
use iceoryx2::service::Service;
use iceoryx2::service::port_factory::event::PortFactory as EventPortFactory;
use iceoryx2::service::port_factory::publish_subscribe::PortFactory as PubSubPortFactory;

use crate::error::{FrameReceiveError, FrameSendError, SceneOpenError};
use crate::transport::{event_open_error, open_error, pub_sub_open_error};
use crate::wire::{PoseFrameHeader, PoseRecord};
use crate::{EVENT_POSES_SENT, PROTOCOL_VERSION, SceneToken};

pub use crate::result_feed::{ResultFeed, ResultFrame};

/// What the owner of a scene holds, from the scene's `CreateScene` reply: everything a
/// [`SceneLink`] needs. `Debug` prints only the id.
#[derive(Clone, Copy, PartialEq, Eq)]
pub struct SceneAccess {
    /// The scene's id, for control requests and pose frame headers.
    pub scene: u32,
    /// The token that names its services; also the capability to read its results
    /// ([`ResultFeed::open`]), which the owner may share with a monitor.
    pub token: SceneToken,
    /// The secret every pose frame carries ([`PoseFrameHeader::frame_key`]).
    pub frame_key: u64,
    /// The daemon instance that created the scene; result frames of another are refused.
    pub instance: u64,
}

impl std::fmt::Debug for SceneAccess {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SceneAccess")
            .field("scene", &self.scene)
            .finish_non_exhaustive()
    }
}

/// Pose records the publisher's first shared-memory segment holds; a larger frame makes it
/// allocate a segment of the next power of two (a one-off cost, for the daemon too).
pub const POSES_INITIAL_MAX_SLICE_LEN: usize = 1024;

/// Pose frames a link's publisher has on loan at once: one frame is written at a time.
pub const POSES_MAX_LOANED_SAMPLES: usize = 1;

/// One client's link to one scene: its pose publisher, result subscriber and the event
/// notifier and listener that let either side sleep instead of spin.
///
/// Not shareable between threads with `ipc::Service` (iceoryx2's ports are single-threaded
/// there). A result subscriber lends at most two frames at once: drop a [`ResultFrame`]
/// before receiving the third.
pub struct SceneLink<S: Service> {
    access: SceneAccess,
    // Fields drop in order: the ports before their services.
    poses: Publisher<S, [PoseRecord], PoseFrameHeader>,
    /// Notifies the poses-ready service (the daemon listens).
    notifier: Notifier<S>,
    /// The receiving half: result subscriber and results-ready listener.
    feed: ResultFeed<S>,
    _poses_service: PubSubPortFactory<S, [PoseRecord], PoseFrameHeader>,
    _poses_ready_service: EventPortFactory<S>,
}

impl<S: Service> std::fmt::Debug for SceneLink<S> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SceneLink")
            .field("scene", &self.access.scene)
            .finish_non_exhaustive()
    }
}

impl<S: Service> SceneLink<S> {
    /// Opens the pose, result and event services of the scene `access` names (the daemon
    /// created them with the scene) under `root` on `node`, and creates this client's ports
    /// on them. The ports keep what they need alive; `node` may be dropped first.
    ///
    /// # Errors
    /// [`SceneOpenError::InvalidRoot`] when `root` makes no valid service name,
    /// [`SceneOpenError::NoSuchScene`] when no daemon serves the scene,
    /// [`SceneOpenError::Transport`] when iceoryx2 fails (too many ports).
    pub fn open(node: &Node<S>, root: &str, access: &SceneAccess) -> Result<Self, SceneOpenError> {
        let invalid = |_| SceneOpenError::InvalidRoot(root.to_owned());
        let poses_service = crate::poses_service_builder(node, root, access.token)
            .map_err(invalid)?
            .open()
            .map_err(|e| pub_sub_open_error("opening the pose service", e))?;
        let poses_ready_service = crate::poses_ready_service_builder(node, root, access.token)
            .map_err(invalid)?
            .open()
            .map_err(|e| event_open_error("opening the poses-ready event service", e))?;
        let poses = poses_service
            .publisher_builder()
            .initial_max_slice_len(POSES_INITIAL_MAX_SLICE_LEN)
            .allocation_strategy(AllocationStrategy::PowerOfTwo)
            .max_loaned_samples(POSES_MAX_LOANED_SAMPLES)
            .create()
            .map_err(|e| open_error("creating the pose publisher", e))?;
        let notifier = poses_ready_service
            .notifier_builder()
            .create()
            .map_err(|e| open_error("creating the event notifier", e))?;
        let mut feed = ResultFeed::open(node, root, access.token)?;
        feed.expect_instance(access.instance);
        Ok(Self {
            access: *access,
            poses,
            notifier,
            feed,
            _poses_service: poses_service,
            _poses_ready_service: poses_ready_service,
        })
    }

    /// The scene id this link publishes to.
    #[must_use]
    pub fn scene(&self) -> u32 {
        self.access.scene
    }

    /// Publishes pose frame `frame_seq` (budget `budget_ns` nanoseconds, 0 = none; `query_flags`
    /// a set of [`query`](crate::wire::query) bits) carrying `poses`, copied once, straight
    /// into the loaned sample; then notifies the daemon.
    ///
    /// # Errors
    /// [`FrameSendError::TooLarge`] beyond `u32::MAX` poses; [`FrameSendError::Transport`]
    /// when iceoryx2 fails to loan, send or notify.
    pub fn publish_poses(
        &self,
        frame_seq: u64,
        budget_ns: u64,
        query_flags: u32,
        poses: &[PoseRecord],
    ) -> Result<(), FrameSendError> {
        let header = self.header(frame_seq, budget_ns, query_flags, poses.len())?;
        let mut sample = self.loan(poses.len())?;
        *sample.user_header_mut() = header;
        let sample = sample.write_from_slice(poses);
        sample
            .send()
            .map_err(|e| FrameSendError::Transport(format!("sending the pose frame: {e}")))?;
        self.notify_sent()
    }

    /// Publishes pose frame `frame_seq` of `count` poses, record `i` being `fill(i)`, written
    /// straight into shared memory (no intermediate buffer); `fill` is called once per index,
    /// in order. Then notifies the daemon. See [`publish_poses`](Self::publish_poses).
    ///
    /// # Errors
    /// As [`publish_poses`](Self::publish_poses).
    pub fn publish_poses_with(
        &self,
        frame_seq: u64,
        budget_ns: u64,
        query_flags: u32,
        count: usize,
        fill: impl FnMut(usize) -> PoseRecord,
    ) -> Result<(), FrameSendError> {
        let header = self.header(frame_seq, budget_ns, query_flags, count)?;
        let mut sample = self.loan(count)?;
        *sample.user_header_mut() = header;
        let sample = sample.write_from_fn(fill);
        sample
            .send()
            .map_err(|e| FrameSendError::Transport(format!("sending the pose frame: {e}")))?;
        self.notify_sent()
    }

    /// Sets how long receiving polls before it blocks: see [`ResultFeed::set_spin`].
    pub fn set_result_spin(&mut self, spin: Duration) {
        self.feed.set_spin(spin);
    }

    /// The next result frame if one has arrived, without waiting.
    ///
    /// # Errors
    /// [`FrameReceiveError::Transport`] when iceoryx2 fails (e.g. two frames are still held).
    pub fn try_receive_results(&self) -> Result<Option<ResultFrame<S>>, FrameReceiveError> {
        self.feed.try_receive()
    }

    /// The next result frame, waiting up to `timeout` (see [`ResultFeed::receive`]);
    /// `Ok(None)` when none arrived in time.
    ///
    /// # Errors
    /// [`FrameReceiveError::Transport`] when iceoryx2 fails.
    pub fn receive_results(
        &self,
        timeout: Duration,
    ) -> Result<Option<ResultFrame<S>>, FrameReceiveError> {
        self.feed.receive(timeout)
    }

    /// The result frame answering pose frame `frame_seq`, waiting up to `timeout` (see
    /// [`ResultFeed::receive_for`]); `Ok(None)` when it did not arrive in time.
    ///
    /// # Errors
    /// [`FrameReceiveError::Transport`] when iceoryx2 fails.
    pub fn receive_results_for(
        &self,
        frame_seq: u64,
        timeout: Duration,
    ) -> Result<Option<ResultFrame<S>>, FrameReceiveError> {
        self.feed.receive_for(frame_seq, timeout)
    }

    /// The header of a frame of `count` poses.
    fn header(
        &self,
        frame_seq: u64,
        budget_ns: u64,
        query_flags: u32,
        count: usize,
    ) -> Result<PoseFrameHeader, FrameSendError> {
        Ok(PoseFrameHeader {
            protocol_version: PROTOCOL_VERSION,
            scene: self.access.scene,
            frame_seq,
            budget_ns,
            query_flags,
            count: u32::try_from(count).map_err(|_| FrameSendError::TooLarge(count))?,
            frame_key: self.access.frame_key,
        })
    }

    /// Loans an uninitialised sample of `count` pose records.
    fn loan(
        &self,
        count: usize,
    ) -> Result<
        iceoryx2::sample_mut_uninit::SampleMutUninit<
            S,
            [std::mem::MaybeUninit<PoseRecord>],
            PoseFrameHeader,
        >,
        FrameSendError,
    > {
        self.poses
            .loan_slice_uninit(count)
            .map_err(|e| FrameSendError::Transport(format!("loaning {count} pose records: {e}")))
    }

    /// Tells the daemon a pose frame is waiting.
    fn notify_sent(&self) -> Result<(), FrameSendError> {
        self.notifier
            .notify_with_custom_event_id(EventId::new(EVENT_POSES_SENT))
            .map(drop)
            .map_err(|e| FrameSendError::Transport(format!("notifying the daemon: {e}")))
    }
}

#[cfg(test)]
#[path = "scene_link_tests.rs"]
mod tests;
