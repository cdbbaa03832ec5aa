//! Why a scene's frames were late: the frame thread's own work, or the operating system
//! holding the thread off the CPU.
//!
//! Each frame's wall time (receipt to publish) is set against the frame thread's CPU time
//! over the same span. A frame late by less than the time the thread spent off the CPU would
//! have been on time had the thread kept its core: the OS stalled it (DESIGN §5: a late frame
//! should be an OS stall, never work the daemon chose to do). A frame late by more was late
//! by the daemon's own work (this frame's, or another scene's frame answered first). The
//! counts are logged when the scene closes.

/// The calling thread's CPU time, nanoseconds (Linux; elsewhere 0, so every late frame
/// counts as late by work).
#[must_use]
pub fn thread_cpu_ns() -> u64 {
    #[cfg(target_os = "linux")]
    {
        let mut now = libc::timespec {
            tv_sec: 0,
            tv_nsec: 0,
        };
        // SAFETY: `clock_gettime` writes one `timespec` to the valid, exclusively borrowed
        // `now` and reads nothing else; CLOCK_THREAD_CPUTIME_ID is the calling thread's own
        // clock. On failure `now` stays zero.
        let failed = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &raw mut now) };
        if failed == 0 {
            let secs = u64::try_from(now.tv_sec).unwrap_or(0);
            let nanos = u64::try_from(now.tv_nsec).unwrap_or(0);
            return secs.saturating_mul(1_000_000_000).saturating_add(nanos);
        }
    }
    0
}

/// One late frame: by how much, and how long its thread was off the CPU meanwhile.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LateFrame {
    /// Wall time past the budget, nanoseconds.
    pub late_ns: u64,
    /// Wall time the frame thread was not running during the frame, nanoseconds.
    pub off_cpu_ns: u64,
}

impl LateFrame {
    /// Whether the OS, not the daemon's work, made the frame late: the thread was off the
    /// CPU for longer than the frame was late.
    #[must_use]
    pub fn stalled_by_os(&self) -> bool {
        self.off_cpu_ns >= self.late_ns
    }
}

/// A scene's budgeted frames, late frames, and late frames the OS stalled.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Lateness {
    /// Frames with a budget.
    pub budgeted: u64,
    /// Of those, published after their budget.
    pub late: u64,
    /// Of the late ones, those whose thread was off the CPU longer than they were late.
    pub stalled: u64,
    /// The latest any frame was, nanoseconds.
    pub worst_late_ns: u64,
}

impl Lateness {
    /// Counts a frame with budget `budget_ns` (0: none, not counted) that took `wall_ns`
    /// from receipt to publish, `cpu_ns` of them on the CPU; returns it when it was late.
    pub fn note(&mut self, budget_ns: u64, wall_ns: u64, cpu_ns: u64) -> Option<LateFrame> {
        if budget_ns == 0 {
            return None;
        }
        self.budgeted += 1;
        if wall_ns <= budget_ns {
            return None;
        }
        let frame = LateFrame {
            late_ns: wall_ns - budget_ns,
            off_cpu_ns: wall_ns.saturating_sub(cpu_ns),
        };
        self.late += 1;
        self.stalled += u64::from(frame.stalled_by_os());
        self.worst_late_ns = self.worst_late_ns.max(frame.late_ns);
        Some(frame)
    }

    /// One line for the log: how many frames were late and why; `None` when none were.
    #[must_use]
    pub fn summary(&self) -> Option<String> {
        (self.late > 0).then(|| {
            format!(
                "{} of {} budgeted frames late (worst by {} µs): {} while the OS held the \
                 frame thread off the CPU longer than the frame was late, {} by the daemon's work",
                self.late,
                self.budgeted,
                self.worst_late_ns / 1_000,
                self.stalled,
                self.late - self.stalled,
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_late_frame_is_stalled_when_its_thread_was_off_the_cpu_longer_than_it_was_late() {
        let mut lateness = Lateness::default();
        assert_eq!(lateness.note(0, 9_000, 100), None, "no budget: not counted");
        assert_eq!(lateness.note(1_000, 900, 900), None, "on time");
        let stalled = lateness.note(1_000, 1_500, 900).expect("late");
        assert_eq!(
            stalled,
            LateFrame {
                late_ns: 500,
                off_cpu_ns: 600
            }
        );
        assert!(stalled.stalled_by_os());
        let by_work = lateness.note(1_000, 1_500, 1_450).expect("late");
        assert!(!by_work.stalled_by_os());
        assert_eq!(
            lateness,
            Lateness {
                budgeted: 3,
                late: 2,
                stalled: 1,
                worst_late_ns: 500
            }
        );
        let line = lateness.summary().expect("a summary");
        assert!(line.starts_with("2 of 3 budgeted frames late"), "{line}");
        assert_eq!(Lateness::default().summary(), None);
    }

    #[test]
    fn the_thread_cpu_clock_moves_with_work_and_not_with_sleep() {
        if !cfg!(target_os = "linux") {
            return;
        }
        let start = thread_cpu_ns();
        assert!(start > 0);
        std::thread::sleep(std::time::Duration::from_millis(30));
        let slept = thread_cpu_ns() - start;
        let busy_from = thread_cpu_ns();
        let wall = std::time::Instant::now();
        while wall.elapsed() < std::time::Duration::from_millis(30) {
            std::hint::spin_loop();
        }
        let busy = thread_cpu_ns() - busy_from;
        assert!(slept < 10_000_000, "asleep 30 ms, {slept} ns on the CPU");
        assert!(
            busy > slept,
            "spinning 30 ms: {busy} ns on the CPU, asleep {slept}"
        );
    }
}
