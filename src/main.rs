//! `proximad`, the Proxima collision daemon: parse the command line, build the daemon, serve
//! until SIGINT/SIGTERM. `proximad demo` runs the daemon with a built-in simulation client
//! instead ([`demo`], part of this binary only).

mod demo;

use clap::{Parser, Subcommand};
use iceoryx2::prelude::{LogLevel, set_log_level_from_env_or};
use proxima::daemon::config_file::ConfigFile;
use proxima::daemon::log::Level;
use proxima::daemon::{Daemon, DaemonConfig};
use std::error::Error;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

/// Large scenes' tables on transparent huge pages ([`proxima::huge_pages`]).
#[global_allocator]
static ALLOC: proxima::huge_pages::HugePageAlloc = proxima::huge_pages::HugePageAlloc;

/// Proxima's collision co-processor: serves scenes over iceoryx2 shared memory.
///
/// Settings come from the defaults, then `--config FILE` (TOML), then the flags given.
#[derive(Debug, Parser)]
#[command(version, about)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// TOML configuration file (see the `proxima::daemon::config_file` docs for its keys).
    #[arg(long, value_name = "FILE")]
    config: Option<PathBuf>,
    /// Root prefix of every service name [default: proxima].
    #[arg(long)]
    root: Option<String>,
    /// iceoryx2 file-name prefix, to keep daemons (and test runs) apart.
    #[arg(long)]
    iceoryx_prefix: Option<String>,
    /// Most scenes alive at once [default: 64].
    #[arg(long)]
    max_scenes: Option<u32>,
    /// Milliseconds a scene outlives the client that created it [default: 2000].
    #[arg(long)]
    grace_ms: Option<u64>,
    /// Microseconds the frame and control threads keep polling after their last work
    /// before they block [default: 50].
    #[arg(long)]
    spin_us: Option<u64>,
    /// The least important messages written to stderr: error, warn, info or debug
    /// [default: info].
    #[arg(long)]
    log_level: Option<Level>,
    /// Worker threads answering mesh pairs beside the frame thread [default: cores − 1].
    #[arg(long)]
    workers: Option<usize>,
    /// Run the frame thread under SCHED_FIFO at this priority (1–99), so no other thread
    /// takes its CPU mid-frame; needs CAP_SYS_NICE, else a warning and normal priority
    /// [default: off].
    #[arg(long, value_parser = proxima::daemon::realtime::parse_priority)]
    realtime_priority: Option<u8>,
    /// Write this run's instance id (hex, one line) to FILE, readable by the owner only,
    /// once the daemon serves: clients that read it connect only to this daemon.
    #[arg(long, value_name = "FILE")]
    instance_file: Option<PathBuf>,
}

/// What to run instead of serving.
#[derive(Debug, Subcommand)]
enum Command {
    /// Start the daemon and a demo simulation client in a second process: bouncing spheres
    /// and tumbling tori, per-frame pairs, contacts, latency and deadline hits, a summary.
    Demo(demo::DemoArgs),
}

impl Cli {
    /// The defaults, overridden by the configuration file, overridden by the flags given.
    fn config(&self) -> Result<DaemonConfig, Box<dyn Error>> {
        let mut config = DaemonConfig::default();
        if let Some(path) = &self.config {
            config = ConfigFile::load(path)?.apply(&config)?;
        }
        if let Some(root) = &self.root {
            config.root.clone_from(root);
        }
        if let Some(prefix) = &self.iceoryx_prefix {
            config.iceoryx_prefix = Some(prefix.clone());
        }
        if let Some(max_scenes) = self.max_scenes {
            config.max_scenes = max_scenes;
        }
        if let Some(ms) = self.grace_ms {
            config.dead_client_grace = Duration::from_millis(ms);
        }
        if let Some(us) = self.spin_us {
            config.spin = Duration::from_micros(us);
        }
        if let Some(level) = self.log_level {
            config.log_level = level;
        }
        if let Some(workers) = self.workers {
            config.workers = workers;
        }
        if let Some(priority) = self.realtime_priority {
            config.realtime_priority = Some(priority);
        }
        Ok(config)
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // iceoryx2's own warnings (e.g. "no config file loaded": we configure it in code) stay
    // quiet unless IOX2_LOG_LEVEL asks for them.
    set_log_level_from_env_or(LogLevel::Error);
    let outcome = match &cli.command {
        Some(Command::Demo(args)) => demo::run(args),
        None => serve(&cli),
    };
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("proximad: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Builds the daemon from the command line and serves until a termination signal.
fn serve(cli: &Cli) -> Result<(), Box<dyn Error>> {
    let mut daemon = Daemon::new(cli.config()?)?;
    if let Some(path) = &cli.instance_file {
        write_instance_file(path, daemon.instance())
            .map_err(|e| format!("writing the instance file {}: {e}", path.display()))?;
    }
    daemon.run()?;
    Ok(())
}

/// Writes `instance` as hex to `path`, created (or truncated) with mode 0600 on Unix.
fn write_instance_file(path: &std::path::Path, instance: u64) -> std::io::Result<()> {
    let mut options = std::fs::OpenOptions::new();
    options.write(true).create(true).truncate(true);
    #[cfg(unix)]
    std::os::unix::fs::OpenOptionsExt::mode(&mut options, 0o600);
    let mut file = options.open(path)?;
    std::io::Write::write_all(&mut file, format!("{instance:#018x}\n").as_bytes())
}
