//! Exit codes, argument checks, region parts and the guarantee check shared by the
//! subcommands (the guarantee holds or the run fails; see `docs/reliability.md`).
//!
//! Exit codes (also in `--help` and docs/reliability.md):
//!
//! | code | meaning |
//! |---|---|
//! | 0 | success: the output is written and passed the independent check |
//! | 1 | input error: a file cannot be read or its content is invalid or unmeshable |
//! | 2 | usage error: a bad option or option value (clap's own errors are 2 too), a size above the memory limit |
//! | 3 | the guarantee is not met (non-convex cells, cells outside the region, area or holes off): nothing written, or — with `--allow-non-convex` — the output written with a warning; with `mesh --strict`, also a quality target missed ([`strict_targets`]): the output written with a warning |
//! | 4 | anything else: writing the output failed (disk full, read-only directory), an internal error |

use std::fmt;
use std::path::Path;

use anyhow::{bail, Result};
use unamalla_core::io::{self, PartSelector};
use unamalla_core::mesh::Region;
use unamalla_core::output::OutputError;
use unamalla_core::pipeline::MeshReport;
use unamalla_core::preflight::PreflightError;
use unamalla_core::verify::{GuaranteeNotMet, Verification};
use unamalla_core::CoreError;

/// Exit code: input error.
pub const EXIT_INPUT: u8 = 1;
/// Exit code: usage error.
pub const EXIT_USAGE: u8 = 2;
/// Exit code: the guarantee is not met.
pub const EXIT_NOT_MET: u8 = 3;
/// Exit code: other failures (writing, internal).
pub const EXIT_OTHER: u8 = 4;

/// A bad option value found after parsing (exit 2).
#[derive(Debug)]
pub struct Usage(pub String);

impl fmt::Display for Usage {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}
impl std::error::Error for Usage {}

/// `bail!` with exit code 2.
macro_rules! usage {
    ($($t:tt)*) => {
        return Err(anyhow::Error::new($crate::reliability::Usage(format!($($t)*))))
    };
}
pub(crate) use usage;

/// Context marking the write phase (exit 4 when it fails).
#[derive(Debug)]
pub struct WriteFailed(pub String);

impl fmt::Display for WriteFailed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

/// The output was written although the guarantee is not met (`--allow-non-convex`): exit 3
/// after the warning.
#[derive(Debug)]
pub struct WrittenNotMet(pub String);

impl fmt::Display for WrittenNotMet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}
impl std::error::Error for WrittenNotMet {}

/// The exit code of an error (module documentation).
pub fn exit_code(e: &anyhow::Error) -> u8 {
    if e.downcast_ref::<WriteFailed>().is_some() {
        return EXIT_OTHER;
    }
    for cause in e.chain() {
        if cause.is::<Usage>() {
            return EXIT_USAGE;
        }
        if cause.is::<GuaranteeNotMet>() || cause.is::<WrittenNotMet>() {
            return EXIT_NOT_MET;
        }
        if cause.is::<OutputError>() {
            return EXIT_OTHER;
        }
        if let Some(p) = cause.downcast_ref::<PreflightError>() {
            return match p {
                PreflightError::TooLarge { .. } | PreflightError::BadLimit(_) => EXIT_USAGE,
                _ => EXIT_INPUT,
            };
        }
        if let Some(c) = cause.downcast_ref::<CoreError>() {
            match c {
                CoreError::Guarantee(_) => return EXIT_NOT_MET,
                CoreError::Preflight(
                    PreflightError::TooLarge { .. } | PreflightError::BadLimit(_),
                ) => return EXIT_USAGE,
                _ => {}
            }
        }
    }
    EXIT_INPUT
}

/// Replaces the staging names of [`unamalla_core::output`] (`.out.unamalla-tmp-…`) in a
/// message by the target's name, so errors name the path the user gave.
pub fn clean_paths(msg: &str) -> String {
    const INFIX: &str = ".unamalla-tmp-";
    let mut out = String::with_capacity(msg.len());
    let mut rest = msg;
    while let Some(k) = rest.find(INFIX) {
        // the segment starts after the last '/' or whitespace before k, with a '.'
        let before = &rest[..k];
        let start = before
            .rfind(|c: char| c == '/' || c.is_whitespace() || c == '\'' || c == '"')
            .map_or(0, |i| i + 1);
        let seg_end = rest[k..]
            .find(|c: char| c == '/' || c.is_whitespace() || c == ':' || c == '\'' || c == '"')
            .map_or(rest.len(), |i| k + i);
        if rest[start..].starts_with('.') && start < k {
            out.push_str(&rest[..start]);
            out.push_str(&rest[start + 1..k]);
        } else {
            out.push_str(&rest[..seg_end]);
        }
        rest = &rest[seg_end..];
    }
    out.push_str(rest);
    out
}

/// `--part`: `all` or a 0-based index.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PartArg {
    /// Every part.
    All,
    /// One part.
    Index(usize),
}

/// Parses `--part`.
pub fn parse_part(s: &str) -> Result<PartArg, String> {
    if s.eq_ignore_ascii_case("all") {
        return Ok(PartArg::All);
    }
    s.trim()
        .parse::<usize>()
        .map(PartArg::Index)
        .map_err(|_| format!("expected 'all' or a part index 0, 1, …; got '{s}'"))
}

/// A whole number ≥ 1 (for counts: `--cells`, `--density`, …). Negative numbers reach this
/// parser (the options set `allow_negative_numbers`), so `--cells -5` is named.
pub fn positive_count(s: &str) -> Result<usize, String> {
    match s.trim().parse::<i128>() {
        Ok(v) if v >= 1 && v <= usize::MAX as i128 => Ok(v as usize),
        Ok(v) => Err(format!("must be a whole number ≥ 1, got {v}")),
        Err(_) => Err(format!("must be a whole number ≥ 1, got '{s}'")),
    }
}

/// A finite number (`--cell-size -1` reaches the command's own range check).
pub fn finite_number(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(format!("must be a finite number, got '{s}'")),
    }
}

/// The region parts of a GeoJSON file as `(part index, region)` (repeated points removed,
/// with a note). With several parts and no `part`: every part when `all_by_default`, else an
/// error naming `--part`. A part index beyond the parts is an input error naming it.
pub fn read_region_parts(
    path: &Path,
    part: Option<PartArg>,
    all_by_default: bool,
) -> Result<Vec<(usize, Region)>> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| anyhow::anyhow!("{}: cannot read the region file: {e}", path.display()))?;
    let parts = match io::geojson::parse_polygon_parts(&text) {
        Ok(p) => p,
        Err(_) => {
            // the reader names the file in its error
            io::read_region_geojson_cleaned(path, PartSelector::Largest)?;
            bail!("{}: no polygon parts", path.display())
        }
    };
    let count = parts.len();
    let chosen: Vec<usize> = match part {
        Some(PartArg::Index(k)) if k >= count => bail!(
            "{}: --part {k}, but the file has {count} polygon part(s) (0 … {})",
            path.display(),
            count.saturating_sub(1)
        ),
        Some(PartArg::Index(k)) => vec![k],
        Some(PartArg::All) => (0..count).collect(),
        None if count <= 1 || all_by_default => (0..count).collect(),
        None => {
            let areas: Vec<String> = parts
                .iter()
                .enumerate()
                .map(|(k, p)| format!("part {k}: area {:.4e}", p.outer_area()))
                .collect();
            bail!(
                "{}: a MultiPolygon with {count} parts ({}); this command meshes one part: choose it with --part N",
                path.display(),
                areas.join(", ")
            )
        }
    };
    let mut out = Vec::with_capacity(chosen.len());
    for k in chosen {
        let (r, removed) = io::read_region_geojson_cleaned(path, PartSelector::Index(k))?;
        if removed > 0 {
            eprintln!("note: removed {removed} repeated point(s) from the region (part {k})");
        }
        out.push((k, r));
    }
    Ok(out)
}

/// One region part (see [`read_region_parts`]).
pub fn read_one_region(path: &Path, part: Option<usize>) -> Result<Region> {
    let mut parts = read_region_parts(path, part.map(PartArg::Index), false)?;
    match parts.pop() {
        Some((_, r)) => Ok(r),
        None => bail!("{}: no polygon", path.display()),
    }
}

/// What a failed check means for the run: `Ok(None)` passed; `Err` the guarantee error
/// (nothing is written); with `allow`, `Ok(Some(message))`: write, warn, exit 3.
pub fn guarantee(v: &Verification, allow: bool, what: &str) -> Result<Option<String>> {
    if v.passed() {
        return Ok(None);
    }
    if allow {
        Ok(Some(format!(
            "{what}: the guarantee is NOT met: {v} (written anyway because of --allow-non-convex)"
        )))
    } else {
        Err(
            anyhow::Error::new(GuaranteeNotMet(Box::new(v.clone()))).context(format!(
            "{what}: nothing written (pass --allow-non-convex to write it anyway, with exit code 3)"
        )),
        )
    }
}

/// After writing: the loud warning and the exit-3 error, when the guarantee was not met.
pub fn finish(not_met: Option<String>) -> Result<()> {
    match not_met {
        None => Ok(()),
        Some(msg) => {
            eprintln!("WARNING: {msg}");
            Err(anyhow::Error::new(WrittenNotMet(msg)))
        }
    }
}

/// `mesh --strict`: the share of cells with μ ≥ 0.8 (percent) a mesh must reach — the
/// pipeline's default quality target.
pub const STRICT_GOOD_PERCENT: f64 = unamalla_core::pipeline::QUALITY_TARGET_PERCENT;

/// The quality targets `mesh --strict` checks that `report` misses (empty: all met): μ ≥ 0.8
/// on at least [`STRICT_GOOD_PERCENT`] % of the cells, and, when a cell count was requested,
/// the count within ±[`unamalla_core::curves::BUDGET_REPORT_TOLERANCE`] of it.
pub fn strict_targets(report: &MeshReport, requested_cells: Option<usize>) -> Vec<String> {
    let mut missed = Vec::new();
    if report.mu_ge_0_8_percent < STRICT_GOOD_PERCENT {
        missed.push(format!(
            "μ ≥ 0.8 on {:.1} % of the cells, below {STRICT_GOOD_PERCENT} %",
            report.mu_ge_0_8_percent
        ));
    }
    if let Some(n) = requested_cells.filter(|&n| n > 0) {
        let tol = unamalla_core::curves::BUDGET_REPORT_TOLERANCE;
        let ratio = report.cells as f64 / n as f64;
        if (ratio - 1.0).abs() > tol {
            missed.push(format!(
                "{} cells, {:+.1} % off the requested {n} (tolerance ±{:.0} %)",
                report.cells,
                100.0 * (ratio - 1.0),
                100.0 * tol
            ));
        }
    }
    missed
}

/// Memory limit for the CLI's size checks.
pub fn limit() -> Result<u64> {
    Ok(unamalla_core::preflight::memory_limit()?)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The targets by hand on the report of a real (small) mesh whose two fields are set: 89.9 %
    /// misses the 90 % share, 90.0 % meets it; 1,151 cells are +15.1 % off 1,000, 1,150 are
    /// within; without a requested count only the share counts.
    #[test]
    fn strict_targets_by_hand() {
        let square = Region::new(
            vec![
                unamalla_core::mesh::DVec2::new(0.0, 0.0),
                unamalla_core::mesh::DVec2::new(1.0, 0.0),
                unamalla_core::mesh::DVec2::new(1.0, 1.0),
                unamalla_core::mesh::DVec2::new(0.0, 1.0),
            ],
            vec![],
        )
        .unwrap();
        let mut r = unamalla_core::pipeline::Mesher::new()
            .cells(100)
            .mesh(&square)
            .unwrap()
            .report;
        r.mu_ge_0_8_percent = 89.9;
        r.cells = 1151;
        let m = strict_targets(&r, Some(1000));
        assert_eq!(m.len(), 2, "{m:?}");
        assert!(m[0].contains("89.9 %") && m[1].contains("+15.1 %"), "{m:?}");
        r.mu_ge_0_8_percent = 90.0;
        r.cells = 1150;
        assert!(strict_targets(&r, Some(1000)).is_empty());
        r.cells = 10;
        assert!(strict_targets(&r, None).is_empty());
    }

    #[test]
    fn staging_names_are_replaced_by_the_target() {
        assert_eq!(
            clean_paths("/tmp/x/.out.unamalla-tmp-12-3-0000abcd/mesh.vtu: No space left"),
            "/tmp/x/out/mesh.vtu: No space left"
        );
        assert_eq!(
            clean_paths("writing .a.geojson.unamalla-tmp-1-2-3.geojson: denied"),
            "writing a.geojson: denied"
        );
        assert_eq!(clean_paths("plain message"), "plain message");
    }

    #[test]
    fn counts_and_parts_parse() {
        assert_eq!(positive_count("3"), Ok(3));
        assert!(positive_count("0").unwrap_err().contains("≥ 1, got 0"));
        assert!(positive_count("-5").unwrap_err().contains("got -5"));
        assert!(positive_count("x").is_err());
        assert_eq!(parse_part("all"), Ok(PartArg::All));
        assert_eq!(parse_part("2"), Ok(PartArg::Index(2)));
        assert!(parse_part("-1").is_err());
        assert!(finite_number("nan").is_err());
        assert_eq!(finite_number("-1"), Ok(-1.0));
    }
}
