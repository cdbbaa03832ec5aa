//! iceoryx2's one world-writable file, made the daemon user's own (issue #31, attack 10).
//!
//! iceoryx2 0.10 creates its shared memory and files with mode 0600, except the *node
//! counter*: `<prefix><40 hex digits>_node.<version>.global_mgmt` in `/dev/shm` (16 bytes,
//! where every new node draws its id), which it leaves 0666. Another OS user who writes it
//! stops every new node under that prefix (`UnableToGenerateUniqueNodeId`): no client could
//! connect. So at start, once its node exists (and with it the counter), the daemon:
//! - makes the counter 0600 when its own user owns it (logged): from then on only that user's
//!   processes, the ones that could use the daemon anyway, can write it;
//! - refuses to start when another user owns it: that user created it first and may write
//!   it whenever it likes. The operator removes it or picks another `--iceoryx-prefix`.
//!
//! Linux only (where `/dev/shm` holds iceoryx2's shared memory); elsewhere nothing is done.

use super::error::DaemonStartError;
use std::path::PathBuf;

/// Where iceoryx2 keeps its shared memory on Linux.
pub const SHM_DIR: &str = "/dev/shm";

/// Whether `file` (a name in [`SHM_DIR`]) is the node counter of iceoryx2 prefix `prefix`:
/// the prefix, 40 hex digits, `_node.`, anything, `.global_mgmt`. (A longer prefix that
/// begins with `prefix`, such as `iox2_test_` for `iox2_`, is another prefix's counter.)
#[must_use]
pub fn is_node_counter(file: &str, prefix: &str) -> bool {
    let Some(rest) = file.strip_prefix(prefix) else {
        return false;
    };
    let Some((hash, tail)) = rest.split_at_checked(40) else {
        return false;
    };
    hash.bytes().all(|b| b.is_ascii_hexdigit())
        && tail.starts_with("_node.")
        && tail.ends_with(".global_mgmt")
}

/// What [`secure`] did with each node counter of the prefix.
#[derive(Debug, Default, PartialEq, Eq)]
pub struct Secured {
    /// Counters that were writable by others and are now 0600.
    pub restricted: Vec<PathBuf>,
}

/// Makes the node counters of iceoryx2 prefix `prefix` readable and writable by their owner
/// only; see the module docs.
///
/// # Errors
/// [`DaemonStartError::Occupied`] when another user owns one; [`DaemonStartError::Ipc`]
/// when `/dev/shm` or a counter cannot be read or changed.
#[cfg(target_os = "linux")]
pub fn secure(prefix: &str) -> Result<Secured, DaemonStartError> {
    use std::os::unix::fs::{MetadataExt, PermissionsExt};
    let io = |what: String| move |e: std::io::Error| DaemonStartError::Ipc(format!("{what}: {e}"));
    // The owner of this process's /proc entry is its effective user.
    let me = std::fs::metadata("/proc/self")
        .map_err(io("reading /proc/self".to_owned()))?
        .uid();
    let mut secured = Secured::default();
    let entries = std::fs::read_dir(SHM_DIR).map_err(io(format!("listing {SHM_DIR}")))?;
    for entry in entries {
        let entry = entry.map_err(io(format!("listing {SHM_DIR}")))?;
        let name = entry.file_name();
        if !name.to_str().is_some_and(|n| is_node_counter(n, prefix)) {
            continue;
        }
        let path = entry.path();
        let metadata =
            std::fs::symlink_metadata(&path).map_err(io(format!("reading {}", path.display())))?;
        if !metadata.is_file() || metadata.uid() != me {
            return Err(DaemonStartError::Occupied(format!(
                "iceoryx2's node counter {} belongs to user {}, who can stop new clients from \
                 connecting: remove it, or start with another --iceoryx-prefix",
                path.display(),
                metadata.uid()
            )));
        }
        if metadata.mode() & 0o077 != 0 {
            std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o600))
                .map_err(io(format!("restricting {}", path.display())))?;
            secured.restricted.push(path);
        }
    }
    Ok(secured)
}

/// Elsewhere than Linux: nothing to do (see the module docs).
///
/// # Errors
/// Never.
#[cfg(not(target_os = "linux"))]
pub fn secure(_prefix: &str) -> Result<Secured, DaemonStartError> {
    Ok(Secured::default())
}

#[cfg(test)]
mod tests {
    use super::*;

    const HASH: &str = "9204dd183d1c4d8e1ff592a30766ffa6765aa8b5";

    #[test]
    fn only_the_prefixs_own_counter_is_recognised() {
        let counter = |prefix: &str| format!("{prefix}{HASH}_node.0_10_0.global_mgmt");
        assert!(is_node_counter(&counter("iox2_"), "iox2_"));
        assert!(is_node_counter(&counter("iox2_pxt7_1_"), "iox2_pxt7_1_"));
        // Another prefix that merely begins with this one.
        assert!(!is_node_counter(&counter("iox2_pxt7_1_"), "iox2_"));
        assert!(!is_node_counter(&counter("iox2_"), "iox2_pxt"));
        // Other files of the prefix.
        let data = format!("iox2_{HASH}_3969.data");
        assert!(!is_node_counter(&data, "iox2_"));
        assert!(!is_node_counter("iox2_short_node.0.global_mgmt", "iox2_"));
        assert!(!is_node_counter(&format!("iox2_{}", &HASH[..39]), "iox2_"));
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn a_world_writable_counter_of_the_prefix_is_made_private_and_others_are_left_alone() {
        use std::os::unix::fs::PermissionsExt;
        let prefix = format!("pxguard{}_", std::process::id());
        let ours = PathBuf::from(SHM_DIR).join(format!("{prefix}{HASH}_node.0_10_0.global_mgmt"));
        let other = PathBuf::from(SHM_DIR).join(format!("{prefix}x_{HASH}_node.0.global_mgmt"));
        for path in [&ours, &other] {
            std::fs::write(path, [0u8; 16]).unwrap();
            std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o666)).unwrap();
        }
        let mode = |p: &PathBuf| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        let secured = secure(&prefix);
        let again = secure(&prefix);
        let modes = (mode(&ours), mode(&other));
        for path in [&ours, &other] {
            let _ = std::fs::remove_file(path);
        }
        assert_eq!(secured.unwrap().restricted, vec![ours.clone()]);
        assert_eq!(again.unwrap(), Secured::default(), "already private");
        assert_eq!(modes, (0o600, 0o666));
    }
}
