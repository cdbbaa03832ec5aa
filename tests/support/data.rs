//! Where the real meshes and poses live: the data folder of `../shared/data`'s layout
//! (`meshes/*.obj`, `poses/*.txt`), which a clone of the repository does not have.
//!
//! The folder is `PROXIMA_DATA` when it is set, else `../shared/data` beside the package
//! when that exists. A suite that needs it and finds none skips with one visible line on
//! stderr (written past libtest's output capture, so `cargo test` shows it). A
//! `PROXIMA_DATA` that names a folder without `meshes/` is a mistake, not a skip: CI sets it
//! so that these suites always run there.
//!
//! Also compiled into benches and examples (`#[path = "../tests/support/data.rs"]`), so
//! every target finds the data by the same rule.

use std::io::Write;
use std::path::{Path, PathBuf};

/// The environment variable naming the data folder.
pub const DATA_VAR: &str = "PROXIMA_DATA";

/// The data folder, or `None` when `PROXIMA_DATA` is unset and `../shared/data` is absent.
///
/// # Panics
/// When `PROXIMA_DATA` is set but the folder it names has no `meshes/`.
pub fn data_dir() -> Option<PathBuf> {
    match std::env::var_os(DATA_VAR) {
        Some(dir) => {
            let dir = PathBuf::from(dir);
            assert!(
                dir.join("meshes").is_dir(),
                "{DATA_VAR}={} has no meshes/ folder",
                dir.display()
            );
            Some(dir)
        }
        None => {
            let beside = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data");
            beside.join("meshes").is_dir().then_some(beside)
        }
    }
}

/// The data folder for the suite `who`, or `None` after printing one visible line saying
/// that `who` did not run and why.
pub fn data_dir_or_skip(who: &str) -> Option<PathBuf> {
    let dir = data_dir();
    if dir.is_none() {
        // `eprintln!` would be captured with a passing test's output; the stderr handle is not.
        let _ = writeln!(
            std::io::stderr(),
            "SKIPPED {who}: no data folder (set {DATA_VAR} to a folder with meshes/ and poses/, \
             or place ../shared/data beside the checkout)"
        );
    }
    dir
}

/// The path of `meshes/<file>` for the suite `who`, or `None` after the skip line.
pub fn mesh_path_or_skip(who: &str, file: &str) -> Option<PathBuf> {
    data_dir_or_skip(who).map(|dir| dir.join("meshes").join(file))
}
