//! Where the real recordings are: `../shared/realdata/` beside the checkout (as CI has it),
//! or where `TRACKER_REALDATA` says. Never copied into the repository.

use std::path::{Path, PathBuf};

/// The real-data folder.
pub fn dir() -> PathBuf {
    std::env::var_os("TRACKER_REALDATA").map_or_else(
        || Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/realdata"),
        PathBuf::from,
    )
}

/// A file in it (`radar/NAME`, `ais/NAME`, …); a missing one fails the test.
#[allow(dead_code)] // not every test file reads single files
pub fn file(relative: &str) -> PathBuf {
    let p = dir().join(relative);
    assert!(
        p.is_file(),
        "{}: missing (set TRACKER_REALDATA)",
        p.display()
    );
    p
}
