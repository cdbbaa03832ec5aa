//! `proximad`, the Proxima collision daemon.
//!
//! The service loop (control service, per-scene pose subscriber, result publisher) is built
//! by issue #4; until it lands this binary reports its version and the protocol it will
//! speak, so that the workspace's binary target exists from the start.

use std::error::Error;

fn main() -> Result<(), Box<dyn Error>> {
    // TODO(#4): parse the CLI, build Daemon from the config and run its frame loop.
    println!(
        "proximad {} (protocol {}): the service loop arrives with issue #4",
        env!("CARGO_PKG_VERSION"),
        proxima_ipc::PROTOCOL_VERSION
    );
    Ok(())
}
