//! `include/voussoir.h` is generated from `src/capi` by the pinned cbindgen, with the version
//! macros taken from Cargo.toml. These tests regenerate it in memory and fail on any drift;
//! `VSR_BLESS=1 cargo test --test capi_header` rewrites it.

use std::ffi::CStr;
use std::path::Path;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

fn generate() -> String {
    let root = Path::new(ROOT);
    let mut config =
        cbindgen::Config::from_file(root.join("cbindgen.toml")).expect("cbindgen.toml");
    config.after_includes = Some(format!(
        "\n/* The version of the crate this header was generated from (Cargo.toml). */\n\
         #define VSR_VERSION_MAJOR {}\n\
         #define VSR_VERSION_MINOR {}\n\
         #define VSR_VERSION_PATCH {}\n\
         #define VSR_VERSION_STRING \"{}\"",
        env!("CARGO_PKG_VERSION_MAJOR"),
        env!("CARGO_PKG_VERSION_MINOR"),
        env!("CARGO_PKG_VERSION_PATCH"),
        env!("CARGO_PKG_VERSION"),
    ));
    let bindings = cbindgen::Builder::new()
        .with_config(config)
        .with_src(root.join("src/capi/mod.rs"))
        .generate()
        .expect("cbindgen failed on src/capi");
    let mut out = Vec::new();
    bindings.write(&mut out);
    String::from_utf8(out).expect("UTF-8 header")
}

fn header_path() -> std::path::PathBuf {
    Path::new(ROOT).join("include/voussoir.h")
}

#[test]
fn header_matches_the_sources() {
    let fresh = generate();
    let path = header_path();
    if std::env::var_os("VSR_BLESS").is_some_and(|v| v == "1") {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, &fresh).unwrap();
        return;
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    if committed != fresh {
        let line = committed
            .lines()
            .zip(fresh.lines())
            .position(|(a, b)| a != b)
            .unwrap_or_else(|| committed.lines().count().min(fresh.lines().count()));
        panic!(
            "include/voussoir.h is out of date (first difference at line {}:\n  committed: {:?}\n  generated: {:?}).\n\
             Rewrite it with: VSR_BLESS=1 cargo test --test capi_header",
            line + 1,
            committed.lines().nth(line).unwrap_or("<end>"),
            fresh.lines().nth(line).unwrap_or("<end>"),
        );
    }
}

fn macro_value(header: &str, name: &str) -> String {
    let prefix = format!("#define {name} ");
    header
        .lines()
        .find_map(|l| l.strip_prefix(&prefix))
        .unwrap_or_else(|| panic!("{name} missing from include/voussoir.h"))
        .trim()
        .to_string()
}

#[test]
fn version_macros_agree_with_cargo_and_the_library() {
    let header = std::fs::read_to_string(header_path()).expect("include/voussoir.h");
    let parts = [
        macro_value(&header, "VSR_VERSION_MAJOR"),
        macro_value(&header, "VSR_VERSION_MINOR"),
        macro_value(&header, "VSR_VERSION_PATCH"),
    ];
    let cargo = [
        env!("CARGO_PKG_VERSION_MAJOR"),
        env!("CARGO_PKG_VERSION_MINOR"),
        env!("CARGO_PKG_VERSION_PATCH"),
    ];
    assert_eq!(parts, cargo);
    let string = macro_value(&header, "VSR_VERSION_STRING");
    assert_eq!(string, format!("\"{}\"", env!("CARGO_PKG_VERSION")));

    let lib = unsafe { CStr::from_ptr(voussoir::capi::vsr_version()) };
    assert_eq!(lib.to_str().unwrap(), env!("CARGO_PKG_VERSION"));
    assert_eq!(lib.to_str().unwrap(), parts.join("."));

    let abi: u32 = macro_value(&header, "VSR_ABI_VERSION").parse().unwrap();
    assert_eq!(abi, voussoir::capi::vsr_abi_version());
    assert_eq!(abi, voussoir::capi::VSR_ABI_VERSION);
}

/// Every exported function has a doc comment in the header, and every status a name.
#[test]
fn every_function_is_documented() {
    let header = std::fs::read_to_string(header_path()).expect("include/voussoir.h");
    let lines: Vec<&str> = header.lines().collect();
    let mut functions = 0;
    for (i, l) in lines.iter().enumerate() {
        let is_decl = l.contains(" vsr_") && l.contains('(') && !l.trim_start().starts_with('*');
        if is_decl {
            functions += 1;
            let above = lines[..i]
                .iter()
                .rev()
                .take_while(|p| !p.trim().is_empty() && !p.ends_with(';'))
                .count();
            assert!(above > 0, "undocumented in the header: {l}");
            assert!(
                lines[i - 1].trim_end().ends_with("*/"),
                "no doc comment right above: {l}"
            );
        }
    }
    assert!(functions > 40, "found only {functions} functions");
}
