//! Test harness: the real `proximad` binary with a unique service root and iceoryx2 prefix,
//! stopped with SIGTERM and its shared-memory files removed on drop. Included by the daemon
//! test files with `#[path]` (it needs `CARGO_BIN_EXE_proximad`, which only integration
//! tests have, so it is not part of `support`).
#![allow(dead_code)]

use iceoryx2::prelude::ipc;
use proxima_ipc::client::{BodySpec, Client, ClientBuilder, Motion};
use proxima_ipc::wire::PoseRecord;
use std::path::PathBuf;
use std::process::{Child, Command, ExitStatus};
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

/// A daemon process with a unique root and prefix, stopped and cleaned up on drop.
pub struct Daemon {
    child: Child,
    root: String,
    prefix: String,
    /// Extra command-line arguments, kept for [`restart`](Self::restart).
    args: Vec<String>,
    /// Whether `--max-scenes 3` precedes `args` (not for [`start_plain`](Self::start_plain)).
    default_max_scenes: bool,
}

impl Daemon {
    /// A daemon with `--max-scenes 3` and otherwise default settings.
    pub fn start() -> Self {
        Self::start_with(&[])
    }

    /// A daemon with `--max-scenes 3` and the extra arguments `args` (e.g. `--grace-ms`).
    pub fn start_with(args: &[&str]) -> Self {
        Self::spawn_unique(args, true)
    }

    /// A daemon with only a unique root and prefix and the arguments `args`: no
    /// `--max-scenes 3`, so `args` (or a `--config` file) may set the scene limit.
    pub fn start_plain(args: &[&str]) -> Self {
        Self::spawn_unique(args, false)
    }

    fn spawn_unique(args: &[&str], default_max_scenes: bool) -> Self {
        static NEXT: AtomicU32 = AtomicU32::new(0);
        let tag = format!(
            "{}_{}",
            std::process::id(),
            NEXT.fetch_add(1, Ordering::Relaxed)
        );
        let (root, prefix) = (format!("proxima-test-{tag}"), format!("iox2_pxt{tag}_"));
        let args: Vec<String> = args.iter().map(|&a| a.to_owned()).collect();
        let child = spawn(&root, &prefix, &args, default_max_scenes);
        Self {
            child,
            root,
            prefix,
            args,
            default_max_scenes,
        }
    }

    /// The daemon's service root (`--root`).
    pub fn root(&self) -> &str {
        &self.root
    }

    /// The daemon's iceoryx2 prefix (`--iceoryx-prefix`).
    pub fn prefix(&self) -> &str {
        &self.prefix
    }

    /// The daemon's process id.
    pub fn pid(&self) -> u32 {
        self.child.id()
    }

    /// A connected client with a 10 s reply timeout.
    pub fn client(&self) -> Client<ipc::Service> {
        self.client_with_timeout(Duration::from_secs(10))
    }

    /// A connected client with reply timeout `timeout`.
    pub fn client_with_timeout(&self, timeout: Duration) -> Client<ipc::Service> {
        self.client_builder()
            .reply_timeout(timeout)
            .connect::<ipc::Service>()
            .expect("the daemon answers Hello")
    }

    /// A client builder for this daemon's root and prefix.
    pub fn client_builder(&self) -> ClientBuilder {
        ClientBuilder::new()
            .root(&self.root)
            .iceoryx_prefix(&self.prefix)
    }

    /// Kills the daemon with SIGKILL (no chance to clean up) and reaps it.
    pub fn kill(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }

    /// Starts a new daemon process with the same root, prefix and arguments (after
    /// [`kill`](Self::kill) or [`terminate`](Self::terminate)).
    pub fn restart(&mut self) {
        assert!(
            matches!(self.child.try_wait(), Ok(Some(_))),
            "the old daemon has stopped"
        );
        self.child = spawn(
            &self.root,
            &self.prefix,
            &self.args,
            self.default_max_scenes,
        );
    }

    /// Sends SIGTERM and waits up to `timeout` for the daemon to exit; its exit status, or
    /// `None` if it was still running (it is then killed).
    pub fn terminate(&mut self, timeout: Duration) -> Option<ExitStatus> {
        if let Ok(Some(status)) = self.child.try_wait() {
            return Some(status);
        }
        signal(self.child.id(), "-TERM");
        let deadline = Instant::now() + timeout;
        while Instant::now() < deadline {
            if let Ok(Some(status)) = self.child.try_wait() {
                return Some(status);
            }
            std::thread::sleep(Duration::from_millis(5));
        }
        self.kill();
        None
    }

    /// Whether the daemon process has exited (it is reaped if so).
    pub fn has_exited(&mut self) -> bool {
        matches!(self.child.try_wait(), Ok(Some(_)))
    }
}

impl Drop for Daemon {
    fn drop(&mut self) {
        // SIGTERM: the daemon's service loop sees it and the process exits cleanly.
        if self.terminate(Duration::from_secs(2)).is_none() {
            self.kill();
        }
        remove_shared_memory(&self.prefix);
    }
}

/// Starts `proximad` with `root`, `prefix`, `--max-scenes 3` if `default_max_scenes`, and
/// `args`.
fn spawn(root: &str, prefix: &str, args: &[String], default_max_scenes: bool) -> Child {
    let max_scenes: &[&str] = if default_max_scenes {
        &["--max-scenes", "3"]
    } else {
        &[]
    };
    Command::new(env!("CARGO_BIN_EXE_proximad"))
        .args(["--root", root, "--iceoryx-prefix", prefix])
        .args(max_scenes)
        .args(args)
        .spawn()
        .expect("proximad starts")
}

/// Sends `signal` (e.g. `-TERM`) to process `pid`.
pub fn signal(pid: u32, signal: &str) {
    let _ = Command::new("kill")
        .args([signal, &pid.to_string()])
        .status();
}

/// Removes the `/dev/shm` files of iceoryx2 prefix `prefix` (the client crate's helper).
pub use proxima_ipc::tools::daemon_process::remove_shared_memory;

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

/// The pose record of `body` at `(x, 0, 0)`, unrotated.
pub fn pose_at(body: u32, x: f64) -> PoseRecord {
    PoseRecord {
        body,
        reserved: 0,
        position: [x, 0.0, 0.0],
        orientation: [0.0, 0.0, 0.0, 1.0],
    }
}

/// Registers `mesh` in `scene` over the protocol and waits for its build; its shape id.
pub fn register_trimesh(
    client: &Client<ipc::Service>,
    scene: u32,
    mesh: &proxima::geometry::TriMesh,
) -> Result<u32, proxima_ipc::error::ControlError> {
    let vertices: Vec<[f64; 3]> = mesh.vertices().iter().map(|v| v.to_array()).collect();
    client.register_mesh(scene, &vertices, mesh.triangles())
}

/// A configuration file at a unique temporary path, removed on drop.
pub struct ConfigFile {
    path: PathBuf,
}

impl ConfigFile {
    pub fn new(text: &str) -> Self {
        static NEXT: AtomicU32 = AtomicU32::new(0);
        let path = std::env::temp_dir().join(format!(
            "proxima-test-config-{}-{}.toml",
            std::process::id(),
            NEXT.fetch_add(1, Ordering::Relaxed)
        ));
        std::fs::write(&path, text).expect("the temporary configuration file is written");
        Self { path }
    }

    pub fn path(&self) -> &str {
        self.path.to_str().expect("a UTF-8 temporary path")
    }
}

impl Drop for ConfigFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}
