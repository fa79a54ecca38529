//! The crate map of `docs/architecture.md` matches the workspace: every workspace crate is in
//! the table (and nothing else), and each row's "depends on" column lists exactly the crate's
//! normal dependencies on other workspace crates, as `cargo metadata` reports them. The layer
//! column is checked too: a crate's layer is above every layer it depends on.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::process::Command;

/// The workspace crates and their normal (not dev, not build) dependencies on workspace crates.
fn metadata() -> BTreeMap<String, BTreeSet<String>> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .args([
            "metadata",
            "--no-deps",
            "--format-version",
            "1",
            "--offline",
        ])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("cargo metadata runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let m: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    let mut map = BTreeMap::new();
    for p in m["packages"].as_array().expect("packages") {
        let name = p["name"].as_str().expect("name").to_string();
        if name == "unamalla-workspace" {
            continue; // the root package of workspace tests and benches, not a crate of the map
        }
        let deps = p["dependencies"]
            .as_array()
            .expect("dependencies")
            .iter()
            .filter(|d| d["kind"].is_null() && d["path"].is_string())
            .map(|d| d["name"].as_str().expect("name").to_string())
            .collect();
        map.insert(name, deps);
    }
    map
}

/// The rows of the table between the `crate-map` markers: crate → (layer, dependencies).
fn documented() -> BTreeMap<String, (u32, BTreeSet<String>)> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/architecture.md");
    let text = std::fs::read_to_string(&path).expect("docs/architecture.md");
    let start = text.find("<!-- crate-map:start -->").expect("start marker");
    let end = text.find("<!-- crate-map:end -->").expect("end marker");
    let names = |cell: &str| -> BTreeSet<String> {
        cell.split(',')
            .map(|s| s.trim().trim_matches('`').to_string())
            .filter(|s| !s.is_empty() && s != "–")
            .collect()
    };
    let mut rows = BTreeMap::new();
    for line in text[start..end].lines() {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        // | crate | layer | what | depends on |  → ["", crate, layer, what, deps, ""]
        if cells.len() != 6 || !cells[1].starts_with("`unamalla-") {
            continue;
        }
        let name = cells[1].trim_matches('`').to_string();
        let layer = cells[2].parse().expect("layer number");
        assert!(
            rows.insert(name.clone(), (layer, names(cells[4])))
                .is_none(),
            "{name} listed twice"
        );
    }
    rows
}

#[test]
fn the_crate_map_matches_cargo_metadata() {
    let actual = metadata();
    let doc = documented();
    let in_doc: BTreeSet<&String> = doc.keys().collect();
    let in_ws: BTreeSet<&String> = actual.keys().collect();
    assert_eq!(
        in_doc, in_ws,
        "crates in docs/architecture.md vs the workspace"
    );
    for (name, deps) in &actual {
        let (layer, listed) = &doc[name];
        assert_eq!(listed, deps, "dependencies of {name} (docs vs Cargo.toml)");
        for d in deps {
            assert!(
                doc[d].0 < *layer,
                "{name} (layer {layer}) depends on {d} (layer {})",
                doc[d].0
            );
        }
    }
}
