//! A daemon (or any helper process speaking the protocol) started as a child process under
//! a service root and iceoryx2 prefix of its own, stopped and cleaned up on drop.
//!
//! Tools and tests that bring their own `proximad` (the demo, `ipc_latency`, the daemon
//! tests) use it so that they never meet another daemon's services, and leave no
//! shared-memory files behind: iceoryx2 removes a crashed process's files only when a later
//! process with the same prefix starts, and even a clean exit leaves one small segment.

use std::ffi::OsStr;
use std::path::PathBuf;
use std::process::{Child, Command};
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::Duration;

/// How long [`ChildProcess::stop`] waits for a clean exit after SIGTERM before SIGKILL.
pub const STOP_GRACE: Duration = Duration::from_secs(2);

/// A service root and iceoryx2 prefix no other process of this machine uses:
/// `<name>-<pid>-<n>` and `iox2_<short>_<pid>_<n>_` (`n` counts within this process).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Isolation {
    /// Root prefix of every service name.
    pub root: String,
    /// iceoryx2 file-name prefix.
    pub prefix: String,
}

impl Isolation {
    /// A fresh root and prefix tagged with `short` (a few lowercase letters, to tell the
    /// shared-memory files of different tools apart).
    #[must_use]
    pub fn unique(short: &str) -> Self {
        static NEXT: AtomicU32 = AtomicU32::new(0);
        let tag = format!(
            "{}_{}",
            std::process::id(),
            NEXT.fetch_add(1, Ordering::Relaxed)
        );
        Self {
            root: format!("proxima-{short}-{tag}"),
            prefix: format!("iox2_{short}{tag}_"),
        }
    }
}

/// A child process, stopped on drop (SIGTERM, then SIGKILL after [`STOP_GRACE`]) and the
/// shared-memory files of its iceoryx2 prefix removed.
#[derive(Debug)]
pub struct ChildProcess {
    child: Option<Child>,
    prefix: String,
}

impl ChildProcess {
    /// Starts `program` with `args`; on drop, removes `/dev/shm` files starting with
    /// `prefix` (pass the prefix the child uses).
    ///
    /// # Errors
    /// The program could not be started.
    pub fn spawn<I, A>(program: impl AsRef<OsStr>, args: I, prefix: &str) -> std::io::Result<Self>
    where
        I: IntoIterator<Item = A>,
        A: AsRef<OsStr>,
    {
        let child = Command::new(program).args(args).spawn()?;
        Ok(Self {
            child: Some(child),
            prefix: prefix.to_owned(),
        })
    }

    /// Starts the daemon `program` under `isolation`'s root and prefix, logging warnings
    /// and errors only (tools that print their own results).
    ///
    /// # Errors
    /// The program could not be started.
    pub fn spawn_quiet_daemon(
        program: impl AsRef<OsStr>,
        isolation: &Isolation,
    ) -> std::io::Result<Self> {
        Self::spawn_quiet_daemon_at_priority(program, isolation, None)
    }

    /// [`spawn_quiet_daemon`](Self::spawn_quiet_daemon), with the daemon's frame thread
    /// under `SCHED_FIFO` at `realtime_priority` when one is given
    /// (`--realtime-priority`).
    ///
    /// # Errors
    /// The program could not be started.
    pub fn spawn_quiet_daemon_at_priority(
        program: impl AsRef<OsStr>,
        isolation: &Isolation,
        realtime_priority: Option<u8>,
    ) -> std::io::Result<Self> {
        let Isolation { root, prefix } = isolation;
        let mut args = vec![
            "--root".to_owned(),
            root.clone(),
            "--iceoryx-prefix".to_owned(),
            prefix.clone(),
            "--log-level".to_owned(),
            "warn".to_owned(),
        ];
        if let Some(priority) = realtime_priority {
            args.extend(["--realtime-priority".to_owned(), priority.to_string()]);
        }
        Self::spawn(program, args, prefix)
    }

    /// The child's process id.
    #[must_use]
    pub fn id(&self) -> Option<u32> {
        self.child.as_ref().map(Child::id)
    }

    /// Whether the child has exited (reaping it if so).
    pub fn has_exited(&mut self) -> bool {
        self.child
            .as_mut()
            .is_none_or(|c| matches!(c.try_wait(), Ok(Some(_))))
    }

    /// Sends SIGTERM and waits up to [`STOP_GRACE`] for the exit, then SIGKILL. Returns
    /// whether the child exited by itself with status 0.
    pub fn stop(&mut self) -> bool {
        let Some(mut child) = self.child.take() else {
            return false;
        };
        if let Ok(Some(status)) = child.try_wait() {
            return status.success();
        }
        let _ = Command::new("kill")
            .args(["-TERM", &child.id().to_string()])
            .status();
        let polls = STOP_GRACE.as_millis() / 10;
        for _ in 0..polls {
            if let Ok(Some(status)) = child.try_wait() {
                return status.success();
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        let _ = child.kill();
        let _ = child.wait();
        false
    }

    /// Kills the child at once (SIGKILL), as a crash would.
    pub fn kill(&mut self) {
        if let Some(mut child) = self.child.take() {
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}

impl Drop for ChildProcess {
    fn drop(&mut self) {
        self.stop();
        remove_shared_memory(&self.prefix);
    }
}

/// Removes every `/dev/shm` file whose name starts with `prefix` (an iceoryx2 prefix).
pub fn remove_shared_memory(prefix: &str) {
    if prefix.is_empty() {
        return;
    }
    if let Ok(entries) = std::fs::read_dir("/dev/shm") {
        for entry in entries.flatten() {
            if entry.file_name().to_string_lossy().starts_with(prefix) {
                let _ = std::fs::remove_file(entry.path());
            }
        }
    }
}

/// `proximad` in the directory above the running example's (`target/<profile>/`), for
/// tools that start a private daemon.
///
/// # Errors
/// The path cannot be found, or no daemon was built there (run `cargo build --release`
/// first, or name the daemon explicitly).
pub fn sibling_daemon() -> Result<PathBuf, String> {
    let exe = std::env::current_exe().map_err(|e| format!("current executable: {e}"))?;
    let path = exe
        .parent()
        .and_then(|examples| examples.parent())
        .map(|profile| profile.join("proximad"))
        .ok_or("cannot locate proximad next to this example")?;
    if !path.exists() {
        return Err(format!(
            "{} does not exist: run `cargo build --release` first, or pass --daemon",
            path.display()
        ));
    }
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn isolations_are_unique_and_valid_names() {
        let (a, b) = (Isolation::unique("t"), Isolation::unique("t"));
        assert_ne!(a, b);
        assert!(a.prefix.starts_with("iox2_t") && a.prefix.ends_with('_'));
        assert!(a.root.starts_with("proxima-t-"));
    }

    #[test]
    fn a_stopped_child_is_reaped_and_its_files_removed() {
        let prefix = format!("iox2_cptest{}_", std::process::id());
        let file = format!("/dev/shm/{prefix}marker");
        std::fs::write(&file, b"x").unwrap();
        let mut child = ChildProcess::spawn("sleep", ["30"], &prefix).unwrap();
        assert!(!child.has_exited());
        // `sleep` dies of SIGTERM: not a clean exit.
        assert!(!child.stop());
        assert!(child.has_exited());
        drop(child);
        assert!(!std::path::Path::new(&file).exists());
    }
}
