//! Real-time scheduling of the frame thread, on request (`--realtime-priority N`).
//!
//! # Why
//! On a machine shared with the simulation clients and everything else, the kernel's fair
//! scheduler can take the CPU from the frame thread in the middle of a frame for as long as
//! another thread's time slice: a frame late by hundreds of microseconds that the daemon
//! did nothing to cause. Measured (`examples/deadline_bench --scene falling`, 2 ms budget,
//! 960 frames, 2-core VM), late frames the OS held off the CPU: 0–10 a run at normal
//! priority (7, 8, 9, 10, 0, 8 in six runs), none in any of three runs with this option
//! (nor in two with the whole daemon under `chrt -f 10`). The frames late by the daemon's
//! own work (its tail estimates; 1–17 a run either way) are not this module's to fix.
//!
//! It is not a default, as it can lose too. On the README demo (1 ms budget, 304 bodies at
//! 200 Hz, its client on the same two cores) it measured worse: three runs of
//! `proximad demo --realtime-priority 10` met 997, 993 and 996 of 1,000 frames, against
//! 999–1,000 without it. Every stage was slower: ingest 16–27 µs against 9, the broad phase
//! 66–91 µs against 29.
//!
//! # What
//! Only the frame thread is raised, to `SCHED_FIFO` at the priority asked: it blocks on its
//! listeners between frames (after a spin of [`DaemonConfig::spin`](super::config::DaemonConfig::spin)),
//! so it holds a CPU only while frames are due. The threads it does not own stay under
//! the fair scheduler: the control thread, the builder, the lane that answers frames
//! without a deadline (started before the raise, so it does not inherit it) and the
//! worker pool. The kernel's real-time throttling (`sched_rt_runtime_us`, 95 % by default)
//! still leaves other threads a share should the frame thread ever run away.
//!
//! # Failure
//! Raising needs `CAP_SYS_NICE` (or an `RLIMIT_RTPRIO` that allows the priority): without
//! it the daemon says so once and serves at normal priority. Off Linux it is not
//! available.

use std::fmt;

/// Why the frame thread could not be raised.
#[derive(Debug)]
pub struct NotRaised(String);

impl fmt::Display for NotRaised {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

/// Lowest and highest `SCHED_FIFO` priorities Linux accepts.
pub const PRIORITIES: std::ops::RangeInclusive<u8> = 1..=99;

/// `priority` when it is one of [`PRIORITIES`], else why not: the one check of the flags
/// ([`parse_priority`]) and the configuration file.
///
/// # Errors
/// The reason, for a priority outside [`PRIORITIES`].
pub fn checked_priority(priority: u8) -> Result<u8, String> {
    if PRIORITIES.contains(&priority) {
        Ok(priority)
    } else {
        Err(format!(
            "{priority} is not a SCHED_FIFO priority ({}..={})",
            PRIORITIES.start(),
            PRIORITIES.end()
        ))
    }
}

/// Parses a `--realtime-priority` value (the value parser of the daemon's and the demo's
/// flag): a number in [`PRIORITIES`].
///
/// # Errors
/// The reason, when `text` is not such a number.
pub fn parse_priority(text: &str) -> Result<u8, String> {
    let priority = text
        .parse::<u8>()
        .map_err(|e| format!("{text:?} is not a SCHED_FIFO priority: {e}"))?;
    checked_priority(priority)
}

/// Moves the calling thread to `SCHED_FIFO` at `priority` (in [`PRIORITIES`]).
///
/// # Errors
/// [`NotRaised`] with the reason: a priority out of range, the operating system's refusal
/// (most often: no `CAP_SYS_NICE`), or a platform without it.
pub fn raise_current_thread(priority: u8) -> Result<(), NotRaised> {
    checked_priority(priority).map_err(NotRaised)?;
    #[cfg(target_os = "linux")]
    {
        let param = libc::sched_param {
            sched_priority: i32::from(priority),
        };
        // SAFETY: `sched_setscheduler` with pid 0 changes only the calling thread's policy
        // (Linux schedules threads); it reads `param`, a live local, and writes nothing.
        let status = unsafe { libc::sched_setscheduler(0, libc::SCHED_FIFO, &raw const param) };
        if status == 0 {
            Ok(())
        } else {
            let e = std::io::Error::last_os_error();
            Err(NotRaised(format!(
                "SCHED_FIFO priority {priority} refused: {e} (needs CAP_SYS_NICE or RLIMIT_RTPRIO)"
            )))
        }
    }
    #[cfg(not(target_os = "linux"))]
    {
        Err(NotRaised(
            "real-time scheduling is available on Linux only".to_owned(),
        ))
    }
}

/// Moves the calling thread back to the fair scheduler (`SCHED_OTHER`), as the frame thread
/// does when it stops serving, so the caller of `Daemon::run` gets its thread back as it
/// was. A failure is ignored: a thread may always lower its own policy.
pub fn lower_current_thread() {
    #[cfg(target_os = "linux")]
    {
        let param = libc::sched_param { sched_priority: 0 };
        // SAFETY: as in `raise_current_thread`: the calling thread's policy only.
        let _ = unsafe { libc::sched_setscheduler(0, libc::SCHED_OTHER, &raw const param) };
    }
}

/// The calling thread's scheduling policy is `SCHED_FIFO` (Linux; `false` elsewhere).
#[must_use]
pub fn current_thread_is_realtime() -> bool {
    #[cfg(target_os = "linux")]
    {
        // SAFETY: `sched_getscheduler(0)` reads the calling thread's policy; no memory.
        unsafe { libc::sched_getscheduler(0) == libc::SCHED_FIFO }
    }
    #[cfg(not(target_os = "linux"))]
    {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_flag_takes_the_priorities_linux_accepts_and_nothing_else() {
        assert_eq!(parse_priority("1"), Ok(1));
        assert_eq!(parse_priority("99"), Ok(99));
        for text in ["0", "100", "-1", "ten", ""] {
            let e = parse_priority(text).expect_err(text);
            assert!(e.contains("not a SCHED_FIFO priority"), "{e}");
        }
    }

    #[test]
    fn a_priority_out_of_range_is_refused_before_asking() {
        for p in [0, 100, 255] {
            let e = raise_current_thread(p).expect_err("out of range");
            assert!(
                e.to_string().contains("not a SCHED_FIFO priority (1..=99)"),
                "{e}"
            );
        }
    }

    /// On a thread of its own (the policy is per thread): raised when the system allows
    /// it, else a refusal that names the capability; either way the test's other threads
    /// keep their policy.
    #[test]
    fn a_raise_changes_the_calling_thread_only_or_says_why_not() {
        let raised = std::thread::spawn(|| {
            let outcome = raise_current_thread(1);
            let realtime = current_thread_is_realtime();
            lower_current_thread();
            assert!(!current_thread_is_realtime(), "lowered back");
            (outcome.map_err(|e| e.to_string()), realtime)
        })
        .join()
        .expect("the thread runs");
        match raised {
            (Ok(()), realtime) => assert!(realtime, "raised but not SCHED_FIFO"),
            (Err(reason), realtime) => {
                assert!(!realtime);
                assert!(
                    reason.contains("CAP_SYS_NICE") || reason.contains("Linux only"),
                    "{reason}"
                );
            }
        }
        assert!(
            !current_thread_is_realtime(),
            "the test thread is untouched"
        );
    }
}
