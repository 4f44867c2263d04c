//! Build script: links the HDF5 high-level library (dimension scales, `H5DS*`) next to the
//! HDF5 library that the `hdf5` crate links (with the `hdf5` feature), and records the git commit for provenance
//! (marked `-dirty` when tracked files differ from it).

use std::process::Command;

fn main() {
    // Without the `hdf5` feature (the Python extension) no HDF5 library is linked.
    if std::env::var_os("CARGO_FEATURE_HDF5").is_some() {
        link_hdf5_hl();
    }
    record_commit();
}

fn link_hdf5_hl() {
    // The hdf5 crate finds HDF5 with pkg-config (Debian: .../hdf5/serial); the high-level
    // library `hdf5_hl` sits in the same directory.
    let mut found = false;
    if let Ok(out) = Command::new("pkg-config")
        .args(["--libs-only-L", "hdf5"])
        .output()
    {
        for dir in String::from_utf8_lossy(&out.stdout).split_whitespace() {
            if let Some(dir) = dir.strip_prefix("-L") {
                println!("cargo:rustc-link-search=native={dir}");
                found = true;
            }
        }
    }
    if !found {
        for dir in [
            "/usr/lib/x86_64-linux-gnu/hdf5/serial",
            "/usr/lib/aarch64-linux-gnu/hdf5/serial",
        ] {
            if std::path::Path::new(dir).exists() {
                println!("cargo:rustc-link-search=native={dir}");
            }
        }
    }
    println!("cargo:rustc-link-lib=dylib=hdf5_hl");
}

fn record_commit() {
    let commit = Command::new("git")
        .args(["rev-parse", "HEAD"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_default();
    // Sources that differ from the commit (tracked files modified) mark it `-dirty`.
    let dirty = Command::new("git")
        .args(["status", "--porcelain", "--untracked-files=no"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .is_some_and(|o| !o.stdout.is_empty());
    let commit = if commit.is_empty() {
        "unknown".to_string()
    } else if dirty {
        format!("{commit}-dirty")
    } else {
        commit
    };
    println!("cargo:rustc-env=RUBBER_ATLAS_GIT_COMMIT={commit}");
    println!("cargo:rerun-if-changed=.git/HEAD");
    println!("cargo:rerun-if-changed=.git/index");
    println!("cargo:rerun-if-changed=.git/refs/heads");
    println!("cargo:rerun-if-changed=build.rs");
    // Any edit of the sources may make the build dirty (or clean again).
    for path in ["src", "Cargo.toml", "Cargo.lock", "benches", "tests"] {
        println!("cargo:rerun-if-changed={path}");
    }
}
