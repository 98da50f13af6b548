//! The checked-in C header `include/curvetet.h` must be exactly what cbindgen generates
//! from src/capi now (build.rs writes that to `$OUT_DIR/curvetet.h`). A normal build
//! never rewrites the checked-in file, so a stale header fails here — in CI too.
//! Run `scripts/update-header` after changing the C ABI.

use std::path::Path;

#[test]
fn checked_in_header_is_current() {
    let generated_path = Path::new(env!("OUT_DIR")).join("curvetet.h");
    let checked_in_path = Path::new(env!("CARGO_MANIFEST_DIR")).join("include/curvetet.h");
    let generated = std::fs::read_to_string(&generated_path)
        .unwrap_or_else(|e| panic!("{}: {e} (build.rs writes it)", generated_path.display()));
    let checked_in = std::fs::read_to_string(&checked_in_path).unwrap_or_default();
    if generated != checked_in {
        let first = generated
            .lines()
            .zip(checked_in.lines())
            .position(|(a, b)| a != b)
            .unwrap_or(generated.lines().count().min(checked_in.lines().count()));
        panic!(
            "include/curvetet.h is stale: it differs from what cbindgen generates from src/capi \
             (first difference at line {}).\n  generated: {:?}\n  checked in: {:?}\n\
             Run scripts/update-header and commit include/curvetet.h.",
            first + 1,
            generated.lines().nth(first).unwrap_or("<end of file>"),
            checked_in.lines().nth(first).unwrap_or("<end of file>"),
        );
    }
}

#[test]
fn header_declares_the_contract() {
    let h =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("include/curvetet.h"))
            .expect("include/curvetet.h");
    for needle in [
        "#ifndef CURVETET_H",
        "extern \"C\" {",
        "#define CURVETET_VERSION_MAJOR",
        "#define CURVETET_VERSION \"",
        "typedef struct curvetet_surface curvetet_surface;",
        "typedef struct curvetet_mesh curvetet_mesh;",
        "typedef int (*curvetet_progress_fn)(void *user_data, double fraction, const char *stage);",
        "const char *curvetet_version(void);",
        "uint32_t curvetet_version_number(void);",
        "#define CURVETET_VERSION_NUMBER ",
        "CURVETET_PIN_THREADS",
        "const char *curvetet_last_error_message(void);",
        "void curvetet_options_default(struct curvetet_options *out);",
        "enum curvetet_status curvetet_surface_read(const char *path, struct curvetet_surface **out);",
        "void curvetet_surface_free(struct curvetet_surface *s);",
        "size_t curvetet_mesh_num_nodes(const struct curvetet_mesh *m);",
        "const double *curvetet_mesh_nodes(const struct curvetet_mesh *m);",
        "size_t curvetet_mesh_num_tets(const struct curvetet_mesh *m);",
        "size_t curvetet_mesh_num_boundary_faces(const struct curvetet_mesh *m);",
        "enum curvetet_status curvetet_mesh_write(const struct curvetet_mesh *m, const char *path);",
        "void curvetet_mesh_free(struct curvetet_mesh *m);",
        "curvetet_node_order order,",
        "CURVETET_ERR_PANIC = 8\n} curvetet_status;",
        "CURVETET_ORDER_VTK = 1\n} curvetet_node_order;",
    ] {
        assert!(h.contains(needle), "include/curvetet.h lacks {needle:?}");
    }
    // Every exported function is documented: a doc comment closes right before it.
    let mut prev = "";
    for line in h.lines() {
        if line.starts_with("curvetet_status ")
            || line.starts_with("enum curvetet_status ")
            || line.starts_with("const ")
            || line.starts_with("void ")
            || line.starts_with("size_t ")
            || line.starts_with("double ")
            || line.starts_with("uint32_t ")
        {
            assert_eq!(prev.trim(), "*/", "undocumented: {line}");
        }
        prev = line;
    }
}

/// The header is plain C89 (no comma after an enum's last value, no `//` comments, no
/// declarations a pedantic C89 compiler warns about) and clean C++ too: compiled with
/// the system's `cc` and `c++` as warnings-are-errors.
#[test]
fn header_compiles_as_pedantic_c89_and_cxx() {
    let dir = std::env::temp_dir().join(format!("curvetet_c89_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let include = Path::new(env!("CARGO_MANIFEST_DIR")).join("include");
    let src = "#include <curvetet.h>\n\
               int main(void) {\n\
               \x20   curvetet_options o;\n\
               \x20   curvetet_options_default(&o);\n\
               \x20   return curvetet_version_number() == CURVETET_VERSION_NUMBER ? 0 : (int)o.threads;\n\
               }\n";
    for (compiler, file, flags) in [
        (
            "cc",
            "t.c",
            &["-std=c89", "-pedantic", "-Wall", "-Wextra", "-Werror"][..],
        ),
        (
            "c++",
            "t.cpp",
            &["-std=c++11", "-pedantic", "-Wall", "-Wextra", "-Werror"][..],
        ),
    ] {
        let path = dir.join(file);
        std::fs::write(&path, src).unwrap();
        let out = std::process::Command::new(compiler)
            .args(flags)
            .arg("-fsyntax-only")
            .arg("-I")
            .arg(&include)
            .arg(&path)
            .output()
            .unwrap_or_else(|e| panic!("cannot run {compiler}: {e}"));
        assert!(
            out.status.success(),
            "{compiler} {} rejects include/curvetet.h:\n{}",
            flags.join(" "),
            String::from_utf8_lossy(&out.stderr)
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}
