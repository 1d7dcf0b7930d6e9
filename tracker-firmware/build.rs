//! Puts the root `memory.x` (the thesis's 1 MiB flash / 64 KiB RAM budget) on the link path.
//! `-Tlink.x` and `-Tdefmt.x` are in `.cargo/config.toml`: a build script's link args would
//! not reach the on-target test binaries.
use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let memory = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it"))
        .join("../memory.x");
    fs::copy(&memory, out.join("memory.x")).expect("memory.x at the workspace root");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed={}", memory.display());
}
