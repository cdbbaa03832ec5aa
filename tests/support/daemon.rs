//! Test harness: the real `proximad` binary with a unique service root and iceoryx2 prefix,
//! stopped with SIGTERM and its shared-memory files removed on drop. Included by the daemon
//! test files with `#[path]` (it needs `CARGO_BIN_EXE_proximad`, which only integration
//! tests have, so it is not part of `support`).
#![allow(dead_code)]

use iceoryx2::prelude::ipc;
use proxima_ipc::client::{BodySpec, Client, ClientBuilder, Motion};
use std::process::{Child, Command};
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::Duration;

/// A daemon process with a unique root and prefix, stopped and cleaned up on drop.
pub struct Daemon {
    child: Child,
    root: String,
    prefix: String,
}

impl Daemon {
    pub fn start() -> Self {
        static NEXT: AtomicU32 = AtomicU32::new(0);
        let tag = format!(
            "{}_{}",
            std::process::id(),
            NEXT.fetch_add(1, Ordering::Relaxed)
        );
        let (root, prefix) = (format!("proxima-test-{tag}"), format!("iox2_pxt{tag}_"));
        let child = Command::new(env!("CARGO_BIN_EXE_proximad"))
            .args([
                "--root",
                &root,
                "--iceoryx-prefix",
                &prefix,
                "--max-scenes",
                "3",
            ])
            .spawn()
            .expect("proximad starts");
        Self {
            child,
            root,
            prefix,
        }
    }

    pub fn client(&self) -> Client<ipc::Service> {
        ClientBuilder::new()
            .root(&self.root)
            .iceoryx_prefix(&self.prefix)
            .reply_timeout(Duration::from_secs(10))
            .connect::<ipc::Service>()
            .expect("the daemon answers Hello")
    }
}

impl Drop for Daemon {
    fn drop(&mut self) {
        // SIGTERM: the daemon's node.wait() sees it and the process exits cleanly.
        let _ = Command::new("kill")
            .args(["-TERM", &self.child.id().to_string()])
            .status();
        let stopped = (0..200).any(|_| {
            std::thread::sleep(Duration::from_millis(10));
            matches!(self.child.try_wait(), Ok(Some(_)))
        });
        if !stopped {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
        if let Ok(entries) = std::fs::read_dir("/dev/shm") {
            for entry in entries.flatten() {
                if entry
                    .file_name()
                    .to_string_lossy()
                    .starts_with(&self.prefix)
                {
                    let _ = std::fs::remove_file(entry.path());
                }
            }
        }
    }
}

/// A dynamic body of `shape` at `(x, 0, 0)`, unrotated, pairing with everything, with the
/// scene's default margin.
pub fn body(shape: u32, x: f64) -> BodySpec {
    BodySpec {
        shape,
        position: [x, 0.0, 0.0],
        orientation: [0.0, 0.0, 0.0, 1.0],
        motion: Motion::Dynamic,
        group: u32::MAX,
        mask: u32::MAX,
        margin: None,
    }
}
