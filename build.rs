//! Computes POLHODE_BUILD_ID: a hash of the sources, the data they embed (data/) and
//! Cargo.lock, recorded in Monte Carlo manifests so that `polhode merge` can refuse shards
//! written by different code (the package version alone does not change between commits or
//! dependency updates).

use std::path::{Path, PathBuf};

fn files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            files(&p, out);
        } else {
            out.push(p);
        }
    }
}

fn main() {
    let root = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap_or_else(|_| ".".into()));
    let mut paths = Vec::new();
    files(&root.join("src"), &mut paths);
    // Model data that the sources embed (include_str!), e.g. the IGRF-14 coefficients.
    files(&root.join("data"), &mut paths);
    paths.push(root.join("Cargo.lock"));
    paths.push(root.join("Cargo.toml"));
    paths.sort();
    // FNV-1a, 64 bits, over each file's relative path and contents.
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut feed = |bytes: &[u8]| {
        for b in bytes {
            h ^= u64::from(*b);
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    };
    for p in &paths {
        let rel = p.strip_prefix(&root).unwrap_or(p);
        feed(rel.to_string_lossy().as_bytes());
        feed(&[0]);
        if let Ok(bytes) = std::fs::read(p) {
            feed(&bytes);
        }
        feed(&[0]);
    }
    println!("cargo:rustc-env=POLHODE_BUILD_ID={h:016x}");
    println!("cargo:rerun-if-changed=src");
    println!("cargo:rerun-if-changed=data");
    println!("cargo:rerun-if-changed=Cargo.lock");
    println!("cargo:rerun-if-changed=Cargo.toml");
}
