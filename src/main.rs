//! `proximad`, the Proxima collision daemon: parse the command line, build the daemon, serve
//! until SIGINT/SIGTERM. `proximad demo` runs the daemon with a built-in simulation client
//! instead ([`demo`], part of this binary only).

mod demo;

use clap::{Parser, Subcommand};
use iceoryx2::prelude::ipc;
use proxima::daemon::{Daemon, DaemonConfig};
use std::error::Error;
use std::time::Duration;

/// How often the service loop wakes when idle.
const CYCLE_TIME: Duration = Duration::from_micros(200);

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
        ..DaemonConfig::default()
    };
    let mut daemon = Daemon::<ipc::Service>::new(config)?;
    eprintln!(
        "proximad {} (protocol {}) serving",
        env!("CARGO_PKG_VERSION"),
        proxima_ipc::PROTOCOL_VERSION
    );
    daemon.run(CYCLE_TIME)?;
    eprintln!("proximad: stopped");
    Ok(())
}
