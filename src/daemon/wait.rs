//! How the daemon's threads block: one WaitSet wait on a set of event listeners, bounded by
//! a timeout, with the notifications that woke it consumed.
//!
//! The attachments (guards borrowing the listeners) exist only for the duration of one
//! wait, so the listeners stay owned by whoever owns them (a scene's listener by its scene)
//! and one that is gone between two waits simply is not attached at the next. Zero events is
//! not a timeout (a leftover wake-up can end a wait with none): callers always poll again.

use super::Ipc;
use super::error::DaemonRunError;
use iceoryx2::port::listener::Listener;
use iceoryx2::prelude::*;
use iceoryx2::waitset::WaitSetRunResult;
use std::time::Duration;

/// Whether a thread goes on after a blocking wait.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Wake {
    /// Serve again.
    Serve,
    /// A termination signal arrived.
    Stop,
}

/// Blocks until one of `listeners()` is notified, `timeout` passes or a termination signal
/// arrives (as the WaitSet's signal handling reports it); consumes the notifications that
/// woke it. `listeners` is called for each pass over them and must list the same listeners
/// each time.
///
/// # Allocation
/// One small list of attachments per wait, never on a polled path.
///
/// # Errors
/// [`DaemonRunError`] when iceoryx2 fails to attach, wait or read a listener.
pub fn wait_for_events<'a, I>(
    waitset: &WaitSet<Ipc>,
    listeners: impl Fn() -> I,
    timeout: Duration,
) -> Result<Wake, DaemonRunError>
where
    I: Iterator<Item = &'a Listener<Ipc>>,
{
    if timeout.is_zero() {
        return Ok(Wake::Serve);
    }
    let guards = listeners()
        .map(|listener| waitset.attach_notification(listener))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| DaemonRunError::Ipc(format!("wait set attach: {e:?}")))?;
    let mut drain_error = None;
    let result = waitset
        .wait_and_process_once_with_timeout(
            |id| {
                for (listener, guard) in listeners().zip(&guards) {
                    if id.has_event_from(guard)
                        && let Err(e) = listener.try_wait(|_| {})
                    {
                        drain_error = Some(e);
                    }
                }
                CallbackProgression::Continue
            },
            timeout,
        )
        .map_err(|e| DaemonRunError::Ipc(format!("wait set wait: {e:?}")))?;
    if let Some(e) = drain_error {
        return Err(DaemonRunError::Ipc(format!("event listener: {e:?}")));
    }
    Ok(match result {
        WaitSetRunResult::TerminationRequest => Wake::Stop,
        _ => Wake::Serve,
    })
}
