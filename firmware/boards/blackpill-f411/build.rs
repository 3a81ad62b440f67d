//! Puts `memory.x` where the linker finds it (cortex-m-rt's `link.x` includes it) and links with
//! `link.x`. The link argument lives here, not in `.cargo/config.toml` `rustflags`, because a
//! `RUSTFLAGS` in the environment (a user or CI may set one) would replace the config's flags.

use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    fs::copy("memory.x", out.join("memory.x")).expect("copy memory.x to OUT_DIR");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=build.rs");
}
