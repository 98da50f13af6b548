//! Generates the C header from src/capi with cbindgen into `$OUT_DIR/curvetet.h`.
//!
//! The checked-in `include/curvetet.h` is never written by a normal build: the test
//! `tests/c_header.rs` compares it with the generated one and fails when they differ
//! (so a stale header cannot pass CI); `scripts/update-header` copies the generated one
//! over it.

use std::env;
use std::path::PathBuf;

fn main() {
    let dir = PathBuf::from(env::var("CARGO_MANIFEST_DIR").expect("cargo sets it"));
    let out = PathBuf::from(env::var("OUT_DIR").expect("cargo sets it")).join("curvetet.h");
    println!("cargo:rerun-if-changed=src/capi");
    println!("cargo:rerun-if-changed=cbindgen.toml");
    println!("cargo:rerun-if-changed=build.rs");

    // The shared library's SONAME: the ABI version (major, or 0.minor before 1.0), so
    // programs linked against it find a compatible library at run time.
    let major = env::var("CARGO_PKG_VERSION_MAJOR").expect("cargo sets it");
    let minor = env::var("CARGO_PKG_VERSION_MINOR").expect("cargo sets it");
    let abi = if major == "0" {
        format!("0.{minor}")
    } else {
        major.clone()
    };
    if env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("linux") {
        println!("cargo:rustc-cdylib-link-arg=-Wl,-soname,libcurvetet.so.{abi}");
    }

    let mut config = cbindgen::Config::from_file(dir.join("cbindgen.toml"))
        .expect("cbindgen.toml is readable and valid");
    let version = env::var("CARGO_PKG_VERSION").expect("cargo sets it");
    let patch = env::var("CARGO_PKG_VERSION_PATCH").expect("cargo sets it");
    config.after_includes = Some(format!(
        "\n/** Version of the header; curvetet_version() gives the library's. */\n\
         #define CURVETET_VERSION_MAJOR {major}\n\
         #define CURVETET_VERSION_MINOR {minor}\n\
         #define CURVETET_VERSION_PATCH {patch}\n\
         #define CURVETET_VERSION \"{version}\"\n\
         /** The shared library's ABI version (its SONAME is libcurvetet.so.<this>). */\n\
         #define CURVETET_ABI_VERSION \"{abi}\""
    ));
    match cbindgen::Builder::new()
        .with_config(config)
        .with_src(dir.join("src/capi/mod.rs"))
        .generate()
    {
        Ok(bindings) => {
            bindings.write_to_file(&out);
        }
        Err(e) => panic!("cbindgen failed on src/capi: {e}"),
    }
}
