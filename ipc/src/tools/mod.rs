//! Helpers for tools and tests that drive a daemon: **not part of the protocol**. A client
//! needs none of this to speak to `proximad`; the protocol is [`wire`](crate::wire), the
//! service names and settings at the crate root, [`client`](crate::client),
//! [`scene_link`](crate::scene_link) and [`error`](crate::error).
//!
//! - [`daemon_process`]: a daemon (or helper) started as a child process under a service
//!   root and iceoryx2 prefix of its own, stopped and cleaned up on drop;
//! - [`latency`]: round-trip recording and the percentile summary every tool prints;
//! - [`latency_scene`]: the scene every round-trip measurement uses.

pub mod daemon_process;
pub mod latency;
pub mod latency_scene;
