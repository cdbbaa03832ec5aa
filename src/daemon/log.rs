//! The daemon's log: leveled lines on stderr, and "once per subject and cause" for things
//! a client can repeat at frame rate.
//!
//! A line reads `proximad: <level>: <message>`. [`Logger::once`] logs the first occurrence
//! of a (subject, cause) pair — a subject is a scene or a control client, a cause what went
//! wrong — and then only counts; the count is logged every [`SUMMARY_EVERY`] repeats and
//! when the subject is [released](Logger::release) (its scene dropped, its client gone), so a
//! misbehaving client cannot flood the log nor hide how often it misbehaved.

use std::collections::HashMap;
use std::fmt;
use std::io::Write as _;
use std::str::FromStr;

/// Repeats of one (subject, cause) pair between two count lines.
pub const SUMMARY_EVERY: u64 = 10_000;

/// How much the daemon says; each level includes the ones above it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Level {
    /// The daemon cannot do its job (it stops, or a scene is lost).
    Error,
    /// A client did something wrong, or a client went away.
    Warn,
    /// Start, stop, scenes created and released.
    Info,
    /// Every control request.
    Debug,
}

impl Level {
    /// The level's name as the CLI spells it.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Error => "error",
            Self::Warn => "warn",
            Self::Info => "info",
            Self::Debug => "debug",
        }
    }
}

impl fmt::Display for Level {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Level {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        [Self::Error, Self::Warn, Self::Info, Self::Debug]
            .into_iter()
            .find(|level| level.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| format!("unknown log level {s:?} (error, warn, info or debug)"))
    }
}

/// What a repeated message is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Subject {
    /// A scene, by id.
    Scene(u32),
    /// A control client, by its iceoryx2 port id value.
    Client(u128),
    /// The daemon as a whole (its own services).
    Daemon,
}

impl fmt::Display for Subject {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Scene(id) => write!(f, "scene {id}"),
            Self::Client(id) => write!(f, "client {id:x}"),
            Self::Daemon => f.write_str("daemon"),
        }
    }
}

/// What went wrong, for [`Logger::once`]: a fixed description and a code (e.g. the wire
/// error code) that tells causes with the same description apart.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Cause {
    /// What happened, e.g. `"refused control request"`.
    pub what: &'static str,
    /// Which variant of it, e.g. the wire `ErrorCode` value.
    pub code: u32,
}

/// Where lines go.
#[derive(Debug)]
enum Sink {
    Stderr,
    /// Kept in memory (tests).
    Lines(Vec<String>),
}

/// The daemon's logger (one per daemon; not shared between threads).
#[derive(Debug)]
pub struct Logger {
    level: Level,
    /// Occurrences of each (subject, cause) pair after the logged first one, and its level.
    repeats: HashMap<(Subject, Cause), (Level, u64)>,
    sink: Sink,
}

impl Logger {
    /// Logs at `level` and above to stderr.
    #[must_use]
    pub fn new(level: Level) -> Self {
        Self {
            level,
            repeats: HashMap::new(),
            sink: Sink::Stderr,
        }
    }

    /// Logs at `level` and above into memory; read with [`lines`](Self::lines).
    #[must_use]
    pub fn in_memory(level: Level) -> Self {
        Self {
            sink: Sink::Lines(Vec::new()),
            ..Self::new(level)
        }
    }

    /// The lines logged so far by an [`in_memory`](Self::in_memory) logger (empty for
    /// stderr).
    #[must_use]
    pub fn lines(&self) -> &[String] {
        match &self.sink {
            Sink::Stderr => &[],
            Sink::Lines(lines) => lines,
        }
    }

    /// Whether messages of `level` are written.
    #[must_use]
    pub fn enabled(&self, level: Level) -> bool {
        level <= self.level
    }

    /// Writes `message` at `level` if that level is enabled.
    pub fn log(&mut self, level: Level, message: fmt::Arguments<'_>) {
        if !self.enabled(level) {
            return;
        }
        match &mut self.sink {
            Sink::Stderr => {
                // Nowhere to report a failing stderr: the daemon keeps serving.
                let _ = writeln!(std::io::stderr().lock(), "proximad: {level}: {message}");
            }
            Sink::Lines(lines) => lines.push(format!("proximad: {level}: {message}")),
        }
    }

    /// [`log`](Self::log) at [`Level::Error`].
    pub fn error(&mut self, message: fmt::Arguments<'_>) {
        self.log(Level::Error, message);
    }

    /// [`log`](Self::log) at [`Level::Warn`].
    pub fn warn(&mut self, message: fmt::Arguments<'_>) {
        self.log(Level::Warn, message);
    }

    /// [`log`](Self::log) at [`Level::Info`].
    pub fn info(&mut self, message: fmt::Arguments<'_>) {
        self.log(Level::Info, message);
    }

    /// [`log`](Self::log) at [`Level::Debug`].
    pub fn debug(&mut self, message: fmt::Arguments<'_>) {
        self.log(Level::Debug, message);
    }

    /// Logs `message()` at `level` the first time `cause` happens to `subject`; later
    /// occurrences are only counted (and the count logged every [`SUMMARY_EVERY`]).
    /// `message` is not called when nothing is written.
    pub fn once(
        &mut self,
        level: Level,
        subject: Subject,
        cause: Cause,
        message: impl FnOnce() -> String,
    ) {
        match self.repeats.get_mut(&(subject, cause)) {
            None => {
                self.repeats.insert((subject, cause), (level, 0));
                if self.enabled(level) {
                    let text = message();
                    self.log(level, format_args!("{subject}: {text}"));
                }
            }
            Some((_, count)) => {
                *count += 1;
                let count = *count;
                if count % SUMMARY_EVERY == 0 {
                    self.log(
                        level,
                        format_args!(
                            "{subject}: {} (code {}) repeated {count} more times",
                            cause.what, cause.code
                        ),
                    );
                }
            }
        }
    }

    /// Forgets every cause of `subject`, logging how often each repeated since its last
    /// count line. Call when the scene is dropped or the client is gone.
    pub fn release(&mut self, subject: Subject) {
        self.release_if(|s| s == subject);
    }

    /// [`release`](Self::release)s every subject for which `gone` is true.
    pub fn release_if(&mut self, mut gone: impl FnMut(Subject) -> bool) {
        let mut released: Vec<(Subject, Cause, Level, u64)> = Vec::new();
        self.repeats
            .retain(|&(subject, cause), &mut (level, count)| {
                let release = gone(subject);
                if release {
                    released.push((subject, cause, level, count));
                }
                !release
            });
        released
            .sort_by_key(|&(subject, cause, _, _)| (subject_key(subject), cause.what, cause.code));
        for (subject, cause, level, count) in released {
            let unreported = count % SUMMARY_EVERY;
            if unreported > 0 {
                self.log(
                    level,
                    format_args!(
                        "{subject}: {} (code {}) repeated {unreported} more times",
                        cause.what, cause.code
                    ),
                );
            }
        }
    }
}

/// A sort key for subjects (scenes first, by id; then clients).
fn subject_key(subject: Subject) -> (u8, u128) {
    match subject {
        Subject::Scene(id) => (0, u128::from(id)),
        Subject::Client(id) => (1, id),
        Subject::Daemon => (2, 0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const REFUSED: Cause = Cause {
        what: "refused control request",
        code: 4,
    };

    #[test]
    fn levels_parse_from_their_names_and_filter_what_is_below_them() {
        assert_eq!("warn".parse::<Level>(), Ok(Level::Warn));
        assert_eq!("DEBUG".parse::<Level>(), Ok(Level::Debug));
        assert!("loud".parse::<Level>().is_err());
        let mut log = Logger::in_memory(Level::Warn);
        log.error(format_args!("e"));
        log.warn(format_args!("w"));
        log.info(format_args!("i"));
        log.debug(format_args!("d"));
        assert_eq!(log.lines(), ["proximad: error: e", "proximad: warn: w"]);
        assert!(log.enabled(Level::Error) && !log.enabled(Level::Info));
    }

    #[test]
    fn a_repeated_cause_is_logged_once_then_counted_until_release() {
        let mut log = Logger::in_memory(Level::Info);
        for _ in 0..5 {
            log.once(Level::Warn, Subject::Client(0xab), REFUSED, || {
                "unknown shape 3".into()
            });
        }
        // Another subject or another code is another key.
        log.once(Level::Warn, Subject::Scene(2), REFUSED, || "x".into());
        let other = Cause { code: 6, ..REFUSED };
        log.once(Level::Warn, Subject::Client(0xab), other, || "y".into());
        assert_eq!(
            log.lines(),
            [
                "proximad: warn: client ab: unknown shape 3",
                "proximad: warn: scene 2: x",
                "proximad: warn: client ab: y",
            ]
        );
        log.release(Subject::Client(0xab));
        assert_eq!(
            &log.lines()[3..],
            ["proximad: warn: client ab: refused control request (code 4) repeated 4 more times"]
        );
        // Released: the next occurrence is logged in full again.
        log.once(Level::Warn, Subject::Client(0xab), REFUSED, || {
            "again".into()
        });
        assert_eq!(
            log.lines().last().unwrap(),
            "proximad: warn: client ab: again"
        );
        // Nothing repeated for scene 2: releasing it logs nothing.
        log.release(Subject::Scene(2));
        assert_eq!(log.lines().len(), 5);
    }

    #[test]
    fn the_count_is_logged_every_summary_interval_and_the_rest_on_release() {
        let mut log = Logger::in_memory(Level::Info);
        let mut built = 0;
        for _ in 0..=SUMMARY_EVERY + 3 {
            log.once(Level::Warn, Subject::Scene(1), REFUSED, || {
                built += 1;
                "bad frame".into()
            });
        }
        assert_eq!(built, 1, "the message is built only when written");
        assert_eq!(log.lines().len(), 2);
        assert_eq!(
            log.lines()[1],
            format!(
                "proximad: warn: scene 1: refused control request (code 4) repeated \
                 {SUMMARY_EVERY} more times"
            )
        );
        log.release(Subject::Scene(1));
        assert!(log.lines()[2].ends_with("repeated 3 more times"));
    }

    #[test]
    fn a_suppressed_level_is_still_counted_but_never_built() {
        let mut log = Logger::in_memory(Level::Error);
        log.once(Level::Warn, Subject::Scene(0), REFUSED, || {
            panic!("not built when the level is off")
        });
        log.once(Level::Warn, Subject::Scene(0), REFUSED, || unreachable!());
        log.release(Subject::Scene(0));
        assert!(log.lines().is_empty());
    }
}
