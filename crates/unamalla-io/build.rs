//! With feature `cgns`: tells whether the system CGNS library was built with 64-bit sizes
//! (`cgsize_t` = `long`), read from `cgnstypes.h` (`CG_BUILD_64BIT 1` and not `CG_BUILD_LEGACY 1`).
fn main() {
    println!("cargo::rustc-check-cfg=cfg(cgns_64bit)");
    println!("cargo::rerun-if-env-changed=CGNS_INCLUDE_DIR");
    if std::env::var_os("CARGO_FEATURE_CGNS").is_none() {
        return;
    }
    let dir = std::env::var("CGNS_INCLUDE_DIR").unwrap_or_else(|_| "/usr/include".into());
    let header = std::path::Path::new(&dir).join("cgnstypes.h");
    println!("cargo::rerun-if-changed={}", header.display());
    let text = std::fs::read_to_string(&header).unwrap_or_default();
    let has = |def: &str| {
        text.lines()
            .any(|l| l.split_whitespace().collect::<Vec<_>>() == ["#define", def, "1"])
    };
    if has("CG_BUILD_64BIT") && !has("CG_BUILD_LEGACY") {
        println!("cargo::rustc-cfg=cgns_64bit");
    }
}
