//! `proximad`, the Proxima collision daemon: parse the command line, build the daemon, serve
//! until SIGINT/SIGTERM. `proximad demo` runs the daemon with a built-in simulation client
//! instead ([`demo`], part of this binary only).

mod demo;

use clap::{Parser, Subcommand};
use iceoryx2::prelude::ipc;
use proxima::daemon::log::Level;
use proxima::daemon::{Daemon, DaemonConfig};
use std::error::Error;
use std::time::Duration;

/// Proxima's collision co-processor: serves scenes over iceoryx2 shared memory.
#[derive(Debug, Parser)]
#[command(version, about)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Root prefix of every service name.
    #[arg(long, default_value = proxima_ipc::DEFAULT_ROOT)]
    root: String,
    /// iceoryx2 file-name prefix, to keep daemons (and test runs) apart.
    #[arg(long)]
    iceoryx_prefix: Option<String>,
    /// Most scenes alive at once.
    #[arg(long, default_value_t = DaemonConfig::default().max_scenes)]
    max_scenes: u32,
    /// Milliseconds a scene outlives the client that created it before it is dropped.
    #[arg(long, default_value_t = DaemonConfig::default().dead_client_grace.as_millis() as u64)]
    grace_ms: u64,
    /// Microseconds the service loop keeps polling after its last work before it blocks.
    #[arg(long, default_value_t = DaemonConfig::default().spin.as_micros() as u64)]
    spin_us: u64,
    /// The least important messages written to stderr: error, warn, info or debug.
    #[arg(long, default_value_t = DaemonConfig::default().log_level)]
    log_level: Level,
}

/// What to run instead of serving.
#[derive(Debug, Subcommand)]
enum Command {
    /// Start the daemon and a demo simulation client in a second process: bouncing spheres
    /// and tumbling tori, per-frame pairs, contacts, latency and deadline hits, a summary.
    Demo(demo::DemoArgs),
}

fn main() -> Result<(), Box<dyn Error>> {
    let cli = Cli::parse();
    if let Some(Command::Demo(args)) = &cli.command {
        return demo::run(args);
    }
    let config = DaemonConfig {
        root: cli.root,
        iceoryx_prefix: cli.iceoryx_prefix,
        max_scenes: cli.max_scenes,
        dead_client_grace: Duration::from_millis(cli.grace_ms),
        spin: Duration::from_micros(cli.spin_us),
        log_level: cli.log_level,
        ..DaemonConfig::default()
    };
    let mut daemon = Daemon::<ipc::Service>::new(config)?;
    eprintln!(
        "proximad {} (protocol {}) serving",
        env!("CARGO_PKG_VERSION"),
        proxima_ipc::PROTOCOL_VERSION
    );
    daemon.run()?;
    eprintln!("proximad: stopped");
    Ok(())
}
