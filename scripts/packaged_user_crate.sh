#!/usr/bin/env bash
# A user's crate against the *packaged* crate family (docs/publishing.md, "A user's crate against
# the packages"): packages the workspace (`cargo package --workspace`, unless NO_PACKAGE=1 and
# target/package/ already holds the unpacked packages), writes a scratch crate outside the
# workspace that depends on `unamalla-core = "0.1.0"` with every crate of the family patched to
# its unpacked package, and runs it: the README's library example verbatim, then
# `Mesher::new().cells(5000)` on a bundled region, asserting 0 non-convex cells and 0 interior
# singularities.
#
# usage (from the repository root): scripts/packaged_user_crate.sh [REGION (default
# fixtures/regions/kiwi-bird.geojson)]
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
REGION=$(realpath "${1:-$ROOT/fixtures/regions/kiwi-bird.geojson}")
cd "$ROOT"
if [ "${NO_PACKAGE:-0}" != 1 ]; then
  cargo package --workspace --no-verify
fi
PKG="$ROOT/target/package"
VERSION=$(sed -n 's/^version = "\(.*\)"/\1/p' Cargo.toml | head -1)
SCRATCH=${SCRATCH:-$(mktemp -d /tmp/unamalla-user-XXXXXX)}
mkdir -p "$SCRATCH/src"
{
  echo '[package]'
  echo 'name = "unamalla-user"'
  echo 'version = "0.0.0"'
  echo 'edition = "2021"'
  echo 'publish = false'
  echo
  echo '[dependencies]'
  echo "unamalla-core = \"$VERSION\""
  echo
  echo '[patch.crates-io]'
  for c in mesh io contour compat-ilp decompose functionals optim bspline core; do
    echo "unamalla-$c = { path = \"$PKG/unamalla-$c-$VERSION\" }"
  done
  echo
  echo '[profile.release]'
  echo 'debug = false'
} > "$SCRATCH/Cargo.toml"
# the README's library example (the first ```rust block), then the main job on REGION
EXAMPLE=$(awk '/^```rust$/{f=1; next} /^```$/{if (f) exit} f' README.md)
cat > "$SCRATCH/src/main.rs" <<EOF
fn readme_example() {
$EXAMPLE
}

fn main() {
    readme_example();
    let path = std::env::args().nth(1).expect("a region file");
    let region = unamalla_core::io::input::load_region(
        std::path::Path::new(&path),
        &unamalla_core::io::input::LoadOptions::default(),
    )
    .expect("region")
    .region;
    let m = unamalla_core::pipeline::Mesher::new()
        .cells(5000)
        .mesh(&region)
        .expect("mesh");
    let r = &m.report;
    println!(
        "{path}: {} cells, {} blocks, {} non-convex, {} interior singularities, mu>=0.8 on {:.1} %",
        r.cells, r.blocks, r.non_convex_cells, r.interior_singularities, r.mu_ge_0_8_percent
    );
    assert_eq!(r.non_convex_cells, 0);
    assert_eq!(r.interior_singularities, 0);
}
EOF
cd "$SCRATCH"
echo "scratch crate: $SCRATCH"
cargo run --release --quiet -- "$REGION"
