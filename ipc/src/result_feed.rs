//! The receiving half of a scene's frame path: a [`ResultFeed`] subscribes to a scene's
//! result frames and waits for them (hybrid: a spin, then a blocking wait on the scene's
//! results-ready listener); each arrives as a [`ResultFrame`], read in place in shared memory.
//!
//! A [`SceneLink`](crate::scene_link::SceneLink) holds one to receive the answers to its
//! own pose frames; a monitor opens one alone to watch a scene it does not drive (a scene's
//! result service admits [`RESULTS_MAX_SUBSCRIBERS`](crate::RESULTS_MAX_SUBSCRIBERS)).

use std::time::{Duration, Instant};

use iceoryx2::config::Config;
use iceoryx2::node::{Node, NodeState, NodeView as _};
use iceoryx2::port::listener::Listener;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::{CallbackProgression, PortFactory as _};
use iceoryx2::sample::Sample;
use iceoryx2::service::Service;
use iceoryx2::service::port_factory::event::PortFactory as EventPortFactory;
use iceoryx2::service::port_factory::publish_subscribe::PortFactory as PubSubPortFactory;

use crate::SceneToken;
use crate::error::{FrameReceiveError, SceneOpenError};
use crate::transport::{RESULTS_SPIN, event_open_error, open_error, pub_sub_open_error};
use crate::wire::{ErrorCode, ResultFrameHeader, ResultRecord, frame_flags};

/// A subscription to one scene's result frames.
///
/// A subscriber lends at most two frames at once: drop a [`ResultFrame`] before receiving
/// the third. Not shareable between threads with `ipc::Service`.
pub struct ResultFeed<S: Service> {
    // Fields drop in order: the ports before their services.
    results: Subscriber<S, [ResultRecord], ResultFrameHeader>,
    /// Listens on the results-ready service (the daemon notifies).
    listener: Listener<S>,
    /// How long a receive polls before it blocks.
    spin: Duration,
    /// The daemon instance whose frames this feed accepts (0: any).
    instance: u64,
    /// The iceoryx2 configuration of the node that opened the feed (to list nodes).
    config: Config,
    results_service: PubSubPortFactory<S, [ResultRecord], ResultFrameHeader>,
    _results_ready_service: EventPortFactory<S>,
}

impl<S: Service> std::fmt::Debug for ResultFeed<S> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ResultFeed").finish_non_exhaustive()
    }
}

impl<S: Service> ResultFeed<S> {
    /// Opens the result and results-ready services of the scene with token `token` (the
    /// capability its owner shares, [`SceneAccess::token`](crate::scene_link::SceneAccess))
    /// under `root` on `node`, and subscribes. The daemon creates a scene's services with
    /// the scene; this only opens them. Frames published before this call are not seen (the
    /// service keeps no history).
    ///
    /// # Errors
    /// [`SceneOpenError::InvalidRoot`] when `root` makes no valid service name,
    /// [`SceneOpenError::NoSuchScene`] when no daemon serves a scene with this token,
    /// [`SceneOpenError::Transport`] when iceoryx2 fails (too many subscribers).
    pub fn open(node: &Node<S>, root: &str, token: SceneToken) -> Result<Self, SceneOpenError> {
        let invalid = |_| SceneOpenError::InvalidRoot(root.to_owned());
        let results_service = crate::results_service_builder(node, root, token)
            .map_err(invalid)?
            .open()
            .map_err(|e| pub_sub_open_error("opening the result service", e))?;
        let results_ready_service = crate::results_ready_service_builder(node, root, token)
            .map_err(invalid)?
            .open()
            .map_err(|e| event_open_error("opening the results-ready event service", e))?;
        let results = results_service
            .subscriber_builder()
            .create()
            .map_err(|e| open_error("creating the result subscriber", e))?;
        let listener = results_ready_service
            .listener_builder()
            .create()
            .map_err(|e| open_error("creating the event listener", e))?;
        Ok(Self {
            results,
            listener,
            spin: RESULTS_SPIN,
            instance: 0,
            config: node.config().clone(),
            results_service,
            _results_ready_service: results_ready_service,
        })
    }

    /// Accepts only frames of daemon instance `instance` (from the `CreateScene` reply,
    /// [`SceneAccess::instance`](crate::scene_link::SceneAccess)); a frame of another is
    /// [`FrameReceiveError::DaemonLost`]. 0 accepts any.
    pub fn expect_instance(&mut self, instance: u64) {
        self.instance = instance;
    }

    /// The next result frame if one has arrived, without waiting.
    ///
    /// # Errors
    /// [`FrameReceiveError::DaemonLost`] for a frame of another daemon instance (see
    /// [`expect_instance`](Self::expect_instance));
    /// [`FrameReceiveError::SceneReleased`] for the scene's last frame, once the daemon let
    /// go of it;
    /// [`FrameReceiveError::Transport`] when iceoryx2 fails (e.g. two frames are still held).
    pub fn try_receive(&self) -> Result<Option<ResultFrame<S>>, FrameReceiveError> {
        let frame = self
            .results
            .receive()
            .map(|sample| sample.map(|sample| ResultFrame { sample }))
            .map_err(|e| FrameReceiveError::Transport(format!("receiving a result frame: {e}")))?;
        match frame {
            Some(frame) if self.instance != 0 && frame.header().instance != self.instance => {
                Err(FrameReceiveError::DaemonLost)
            }
            Some(frame) if frame.header().status == ErrorCode::SceneReleased as u32 => {
                let owner_gone = frame.header().flags & frame_flags::OWNER_GONE != 0;
                Err(FrameReceiveError::SceneReleased { owner_gone })
            }
            frame => Ok(frame),
        }
    }

    /// Whether the daemon's result publisher still serves the scene: listed, and its node's
    /// process alive (a daemon killed without a chance to clean up stays listed).
    fn daemon_is_alive(&self) -> bool {
        let mut publishers = Vec::new();
        self.results_service
            .dynamic_config()
            .list_publishers(|publisher| {
                publishers.push(publisher.node_id);
                CallbackProgression::Continue
            });
        let mut alive = false;
        let listed = Node::<S>::list(&self.config, |state| {
            if let NodeState::Alive(view) = &state
                && publishers.contains(view.id())
            {
                alive = true;
                return CallbackProgression::Stop;
            }
            CallbackProgression::Continue
        });
        // Nodes that cannot be listed are no proof the daemon is gone.
        alive || listed.is_err()
    }

    /// Sets how long a receive polls before it blocks ([`RESULTS_SPIN`] by default). A
    /// longer spin saves the 60–120 µs of waking a halted vCPU when answers take longer than
    /// [`RESULTS_SPIN`], at the price of a busy core while waiting: worth it only when this
    /// process has a core of its own (never spin on a core the daemon needs).
    pub fn set_spin(&mut self, spin: Duration) {
        self.spin = spin;
    }

    /// The next result frame, waiting up to `timeout` (hybrid: a spin (see
    /// [`set_spin`](Self::set_spin)), then a
    /// blocking wait on the event listener); `Ok(None)` when none arrived in time.
    ///
    /// # Errors
    /// [`FrameReceiveError::Transport`] when iceoryx2 fails.
    pub fn receive(&self, timeout: Duration) -> Result<Option<ResultFrame<S>>, FrameReceiveError> {
        self.receive_until(Instant::now() + timeout, |_| true)
    }

    /// The result frame answering pose frame `frame_seq`, waiting up to `timeout`; every
    /// other frame received meanwhile (older answers, or newer ones if `frame_seq`'s was
    /// overwritten) is dropped. `Ok(None)` when it did not arrive in time.
    ///
    /// # Errors
    /// [`FrameReceiveError::Transport`] when iceoryx2 fails.
    pub fn receive_for(
        &self,
        frame_seq: u64,
        timeout: Duration,
    ) -> Result<Option<ResultFrame<S>>, FrameReceiveError> {
        self.receive_until(Instant::now() + timeout, |header| {
            header.frame_seq == frame_seq
        })
    }

    /// The first received frame whose header `accept`s, waiting until `deadline`.
    ///
    /// A notification that arrives between a poll and the blocking wait stays pending in the
    /// listener, so the wait returns at once and the loop polls again: no wake-up is lost.
    /// The listener may also wake with nothing new (a stale or foreign event, or zero
    /// activations), so the deadline is always judged by the clock.
    fn receive_until(
        &self,
        deadline: Instant,
        mut accept: impl FnMut(&ResultFrameHeader) -> bool,
    ) -> Result<Option<ResultFrame<S>>, FrameReceiveError> {
        let spin_end = Instant::now() + self.spin;
        loop {
            while let Some(frame) = self.try_receive()? {
                if accept(frame.header()) {
                    return Ok(Some(frame));
                }
            }
            let now = Instant::now();
            if now >= deadline {
                return if self.daemon_is_alive() {
                    Ok(None)
                } else {
                    Err(FrameReceiveError::DaemonLost)
                };
            }
            if now < spin_end {
                std::hint::spin_loop();
                continue;
            }
            self.listener
                .timed_wait(|_| {}, deadline - now)
                .map_err(|e| {
                    FrameReceiveError::Transport(format!(
                        "waiting on the scene's event listener: {e}"
                    ))
                })?;
        }
    }
}

/// A received result frame, read in place in shared memory. Dropping it hands the memory
/// back to the daemon's publisher.
pub struct ResultFrame<S: Service> {
    sample: Sample<S, [ResultRecord], ResultFrameHeader>,
}

impl<S: Service> std::fmt::Debug for ResultFrame<S> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ResultFrame")
            .field("header", self.header())
            .field("records", &self.records().len())
            .finish()
    }
}

impl<S: Service> ResultFrame<S> {
    /// The frame's header: status, `frame_seq`, counts, timings.
    #[must_use]
    pub fn header(&self) -> &ResultFrameHeader {
        self.sample.user_header()
    }

    /// Every record of the payload: the pairs, then the contacts, then the times of impact.
    #[must_use]
    pub fn records(&self) -> &[ResultRecord] {
        self.sample.payload()
    }

    /// The pair records: the first `pair_count`, fewer if the payload is shorter.
    #[must_use]
    pub fn pairs(&self) -> &[ResultRecord] {
        let header = self.header();
        split(self.records(), header.pair_count, header.contact_count).0
    }

    /// The contact records: the `contact_count` after the pairs, fewer if the payload is
    /// shorter.
    #[must_use]
    pub fn contacts(&self) -> &[ResultRecord] {
        let header = self.header();
        split(self.records(), header.pair_count, header.contact_count).1
    }

    /// The time-of-impact records ([`query::TOI`](crate::wire::query::TOI)): the
    /// `toi_count` after the contacts, fewer if the payload is shorter.
    #[must_use]
    pub fn tois(&self) -> &[ResultRecord] {
        let header = self.header();
        toi_records(
            self.records(),
            header.pair_count,
            header.contact_count,
            header.toi_count,
        )
    }

    /// The contact records of `pair` (one of [`pairs`](Self::pairs)): the `count` contacts
    /// from `index` on, counted from the first contact record; clamped to
    /// [`contacts`](Self::contacts), so a lying record cannot cause a panic.
    #[must_use]
    pub fn contacts_of(&self, pair: &ResultRecord) -> &[ResultRecord] {
        contacts_of(self.contacts(), pair)
    }
}

/// `pair.count` records of `contacts` from `pair.index` on, clamped to the slice.
fn contacts_of<'r>(contacts: &'r [ResultRecord], pair: &ResultRecord) -> &'r [ResultRecord] {
    let start = usize::try_from(pair.index).map_or(contacts.len(), |i| i.min(contacts.len()));
    let rest = &contacts[start..];
    let count = usize::try_from(pair.count).map_or(rest.len(), |c| c.min(rest.len()));
    &rest[..count]
}

/// Splits `records` into `pair_count` pairs and the `contact_count` contacts after them,
/// each clamped to what the slice holds, so a header that lies cannot cause a panic.
fn split(
    records: &[ResultRecord],
    pair_count: u32,
    contact_count: u32,
) -> (&[ResultRecord], &[ResultRecord]) {
    let (pairs, rest) = records.split_at(clamp(pair_count, records.len()));
    (pairs, &rest[..clamp(contact_count, rest.len())])
}

/// The `toi_count` records after the pairs and contacts of [`split`], clamped like it.
fn toi_records(
    records: &[ResultRecord],
    pair_count: u32,
    contact_count: u32,
    toi_count: u32,
) -> &[ResultRecord] {
    let (pairs, contacts) = split(records, pair_count, contact_count);
    let rest = &records[pairs.len() + contacts.len()..];
    &rest[..clamp(toi_count, rest.len())]
}

/// `count`, at most `len`.
fn clamp(count: u32, len: usize) -> usize {
    usize::try_from(count).map_or(len, |c| c.min(len))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `n` default records, record `i` with `index` `i`.
    fn indexed(n: u32) -> Vec<ResultRecord> {
        (0..n)
            .map(|i| ResultRecord {
                index: i,
                ..ResultRecord::default()
            })
            .collect()
    }

    #[test]
    fn toi_records_follow_the_contacts_and_never_exceed_the_slice() {
        let records = indexed(6);
        let counts = [0u32, 1, 2, 5, 6, 7, u32::MAX];
        for len in 0..=records.len() {
            for &p in &counts {
                for &c in &counts {
                    for &t in &counts {
                        let tois = toi_records(&records[..len], p, c, t);
                        let start = (p as usize).min(len);
                        let start = start + (c as usize).min(len - start);
                        let end = start + (t as usize).min(len - start);
                        assert_eq!(tois, &records[start..end], "{len} {p} {c} {t}");
                    }
                }
            }
        }
    }

    #[test]
    fn split_never_exceeds_the_slice_for_any_counts() {
        let records = indexed(6);
        let counts = [0u32, 1, 2, 5, 6, 7, 100, u32::MAX - 1, u32::MAX];
        for len in 0..=records.len() {
            for &p in &counts {
                for &c in &counts {
                    let (pairs, contacts) = split(&records[..len], p, c);
                    let expected_pairs = (p as usize).min(len);
                    assert_eq!(pairs, &records[..expected_pairs]);
                    let expected_contacts = (c as usize).min(len - expected_pairs);
                    assert_eq!(
                        contacts,
                        &records[expected_pairs..expected_pairs + expected_contacts]
                    );
                }
            }
        }
    }

    #[test]
    fn a_pairs_contacts_are_its_index_and_count_clamped_to_the_contact_records() {
        let contacts = indexed(5);
        let pair = |index, count| ResultRecord {
            index,
            count,
            ..ResultRecord::default()
        };
        assert_eq!(contacts_of(&contacts, &pair(1, 3)), &contacts[1..4]);
        assert_eq!(contacts_of(&contacts, &pair(0, 0)), &[]);
        assert_eq!(contacts_of(&contacts, &pair(3, 9)), &contacts[3..]);
        assert_eq!(contacts_of(&contacts, &pair(5, 1)), &[]);
        assert_eq!(contacts_of(&contacts, &pair(u32::MAX, u32::MAX)), &[]);
        assert_eq!(contacts_of(&[], &pair(0, 4)), &[]);
    }
}
