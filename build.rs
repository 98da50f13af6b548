//! Generates the C header from src/capi with cbindgen into `$OUT_DIR/curvetet.h`.
//!
//! The header is made C89-clean after cbindgen (`gcc -std=c89 -pedantic -Werror` accepts
//! it; tests/c_header.rs compiles it so): no comma after an enum's last value, no `//`
//! comments.
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
    let number = version_number(&major, &minor, &patch);
    config.after_includes = Some(format!(
        "\n/** Version of the header; curvetet_version() gives the library's. */\n\
         #define CURVETET_VERSION_MAJOR {major}\n\
         #define CURVETET_VERSION_MINOR {minor}\n\
         #define CURVETET_VERSION_PATCH {patch}\n\
         #define CURVETET_VERSION \"{version}\"\n\
         /** MAJOR * 10000 + MINOR * 100 + PATCH (0.1.0: 100); curvetet_version_number(). */\n\
         #define CURVETET_VERSION_NUMBER {number}\n\
         /** The shared library's ABI version (its SONAME is libcurvetet.so.<this>). */\n\
         #define CURVETET_ABI_VERSION \"{abi}\""
    ));
    match cbindgen::Builder::new()
        .with_config(config)
        .with_src(dir.join("src/capi/mod.rs"))
        .generate()
    {
        Ok(bindings) => {
            let mut text = Vec::new();
            bindings.write(&mut text);
            let text = String::from_utf8(text).expect("cbindgen writes UTF-8");
            let text = c89_clean(&text);
            // Rewrite only when it changed, so dependents do not rebuild for nothing.
            if std::fs::read_to_string(&out).ok().as_deref() != Some(text.as_str()) {
                std::fs::write(&out, text)
                    .unwrap_or_else(|e| panic!("cannot write {}: {e}", out.display()));
            }
        }
        Err(e) => panic!("cbindgen failed on src/capi: {e}"),
    }
}

/// MAJOR * 10000 + MINOR * 100 + PATCH; minor and patch must stay below 100 for the
/// number to order versions.
fn version_number(major: &str, minor: &str, patch: &str) -> u32 {
    let n = |s: &str| -> u32 { s.parse().expect("cargo's version parts are numbers") };
    let (major, minor, patch) = (n(major), n(minor), n(patch));
    assert!(
        minor < 100 && patch < 100,
        "CURVETET_VERSION_NUMBER needs minor, patch < 100"
    );
    major * 10000 + minor * 100 + patch
}

/// cbindgen's output made acceptable to `-std=c89 -pedantic`: the comma after an enum's
/// last value dropped (C89 forbids it), `// text` comments written as `/* text */`.
fn c89_clean(header: &str) -> String {
    let lines: Vec<&str> = header.lines().collect();
    let mut out = String::with_capacity(header.len());
    for (i, line) in lines.iter().enumerate() {
        let mut line = line.to_string();
        // The last enumerator: a line ending in ',' followed by the closing brace.
        let next = lines[i + 1..].iter().find(|l| !l.trim().is_empty());
        if line.ends_with(',') && next.is_some_and(|l| l.trim_start().starts_with('}')) {
            line.pop();
        }
        if let Some(k) = line.find("//") {
            if !line[..k].contains('"') && !line[..k].contains("/*") {
                let text = line[k + 2..].trim().to_string();
                line = format!("{}/* {text} */", &line[..k]);
            }
        }
        out.push_str(&line);
        out.push('\n');
    }
    out
}
