//! # proxima-ipc
//!
//! Proxima's wire protocol over iceoryx2 shared memory: the `#[repr(C)]` records, the service
//! names and the protocol version a client checks on connect. Depends only on iceoryx2 and
//! std; records use plain arrays (`[f64; 3]`), never glam, so clients in any language that
//! iceoryx2 binds can speak it.

/// The protocol version. A client and a daemon whose versions differ refuse to talk; bump it
/// on any change to a wire record's layout or meaning.
pub const PROTOCOL_VERSION: u32 = 1;

/// The default root prefix of every service name (`<root>/control`, `<root>/<scene>/poses`…).
pub const DEFAULT_ROOT: &str = "proxima";

/// The name of the control service under `root`.
#[must_use]
pub fn control_service_name(root: &str) -> String {
    format!("{root}/control")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_service_lives_under_the_root() {
        assert_eq!(control_service_name("proxima"), "proxima/control");
        assert_eq!(control_service_name("test-7"), "test-7/control");
    }
}
