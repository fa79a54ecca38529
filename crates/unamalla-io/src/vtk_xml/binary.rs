//! Binary (base64, uncompressed) data arrays: written above [`BINARY_THRESHOLD_POINTS`] points,
//! read with a `UInt64` or `UInt32` header.

use std::io::{self, Write};
use std::path::Path;

use unamalla_mesh::DVec3;

use crate::error::IoError;
use crate::xml::{self, Element};

/// Meshes with more points than this are written with binary data arrays
/// (`format="binary"`: base64 of a `UInt64` byte count, then base64 of the little-endian
/// values, encoded separately as VTK and meshio do), smaller ones in ASCII. Both read back bit
/// for bit (sizes measured in `docs/solvers-and-gis.md`).
pub const BINARY_THRESHOLD_POINTS: usize = 10_000;

/// Base64 text of a binary data array: the 8-byte little-endian byte count, then the bytes,
/// each encoded separately.
pub(super) fn binary_text(bytes: &[u8]) -> String {
    use base64::Engine as _;
    let e = &base64::engine::general_purpose::STANDARD;
    let mut s = e.encode((bytes.len() as u64).to_le_bytes());
    s.push_str(&e.encode(bytes));
    s
}

pub(super) fn f64_bytes(v: impl Iterator<Item = f64>) -> Vec<u8> {
    v.flat_map(f64::to_le_bytes).collect()
}

pub(super) fn binary_array(
    w: &mut dyn Write,
    ty: &str,
    name: &str,
    comps: usize,
    bytes: &[u8],
) -> io::Result<()> {
    let nc = if comps > 1 {
        format!(" NumberOfComponents=\"{comps}\"")
    } else {
        String::new()
    };
    writeln!(
        w,
        "        <DataArray type=\"{ty}\" Name=\"{}\"{nc} format=\"binary\">",
        xml::escape(name)
    )?;
    writeln!(w, "          {}", binary_text(bytes))?;
    writeln!(w, "        </DataArray>")
}

pub(super) fn points_array(
    w: &mut dyn Write,
    pts: impl Iterator<Item = DVec3>,
    binary: bool,
) -> io::Result<()> {
    writeln!(w, "      <Points>")?;
    if binary {
        let bytes = f64_bytes(pts.flat_map(|p| [p.x, p.y, p.z]));
        binary_array(w, "Float64", "Points", 3, &bytes)?;
        return writeln!(w, "      </Points>");
    }
    writeln!(
        w,
        "        <DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" format=\"ascii\">"
    )?;
    for p in pts {
        writeln!(w, "          {:?} {:?} {:?}", p.x, p.y, p.z)?;
    }
    writeln!(w, "        </DataArray>")?;
    writeln!(w, "      </Points>")
}

/// Whether a `<DataArray>` is binary (`format="binary"`, uncompressed); other formats than
/// `ascii` and `binary`, and compressed data, are unsupported.
pub(super) fn is_binary(e: &Element, path: &Path) -> Result<bool, IoError> {
    match e.attr("format") {
        None | Some("ascii") => Ok(false),
        Some("binary") => Ok(true),
        Some(f) => Err(IoError::Unsupported {
            path: path.to_path_buf(),
            line: e.line,
            what: format!("DataArray format {f:?} (ascii and binary are read)"),
        }),
    }
}

/// The values of a binary `<DataArray>` as `f64`: its base64 text decoded (a `UInt64` or
/// `UInt32` byte count encoded separately, then the data), the data read per its `type`.
pub(super) fn binary_values(e: &Element, path: &Path) -> Result<Vec<f64>, IoError> {
    use base64::Engine as _;
    let eng = &base64::engine::general_purpose::STANDARD;
    let name = e.attr("Name").unwrap_or("(unnamed)");
    let bad = |m: String| IoError::Malformed {
        path: path.to_path_buf(),
        line: e.text_line,
        message: format!("DataArray {name}: {m}"),
    };
    let text: String = e.text.split_whitespace().collect();
    // header: 8 bytes (12 base64 characters) or 4 bytes (8 characters), whichever states the
    // length of the rest
    let mut data = None;
    for (chars, size) in [(12usize, 8usize), (8, 4)] {
        if text.len() < chars {
            continue;
        }
        let (Ok(h), Ok(d)) = (eng.decode(&text[..chars]), eng.decode(&text[chars..])) else {
            continue;
        };
        if h.len() != size {
            continue;
        }
        let mut b = [0u8; 8];
        b[..size].copy_from_slice(&h);
        if u64::from_le_bytes(b) == d.len() as u64 {
            data = Some(d);
            break;
        }
    }
    let d =
        data.ok_or_else(|| bad("binary data is not base64 of a byte count and the data".into()))?;
    let ty = e.attr("type").unwrap_or("");
    let width = match ty {
        "Float64" | "Int64" | "UInt64" => 8,
        "Float32" | "Int32" | "UInt32" => 4,
        "Int16" | "UInt16" => 2,
        "Int8" | "UInt8" => 1,
        other => return Err(bad(format!("unsupported binary type {other:?}"))),
    };
    if d.len() % width != 0 {
        return Err(bad(format!(
            "{} bytes is not a whole number of {ty}",
            d.len()
        )));
    }
    Ok(d.chunks_exact(width)
        .map(|c| {
            let mut b = [0u8; 8];
            b[..width].copy_from_slice(c);
            match ty {
                "Float64" => f64::from_le_bytes(b),
                "Float32" => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                "Int64" => i64::from_le_bytes(b) as f64,
                "Int32" => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                "Int16" => i16::from_le_bytes([b[0], b[1]]) as f64,
                "Int8" => b[0] as i8 as f64,
                _ => u64::from_le_bytes(b) as f64,
            }
        })
        .collect())
}

#[cfg(test)]
mod binary_tests {
    use super::*;
    use unamalla_mesh::{DVec2, HasNodes, QuadMesh, StructuredGrid2};

    use crate::vtk::VtkMesh;
    use crate::vtk_xml::{parse_vtk_xml, read_vtk_xml, write_vts2, write_vtu_quads};

    #[test]
    fn a_large_grid_is_written_binary_and_reads_back_bit_for_bit() {
        // 120 × 100 nodes = 12 000 > threshold; irrational coordinates test every bit
        let g = StructuredGrid2::from_fn(120, 100, |i, j| {
            DVec2::new(
                (i as f64).sqrt() + 0.1 * j as f64,
                (j as f64) / 3.0 + 1e-7 * i as f64,
            )
        })
        .unwrap();
        let dir = std::env::temp_dir().join(format!("unamalla-vtkbin-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let cells: Vec<f64> = (0..g.num_cells()).map(|c| (c as f64).ln_1p()).collect();
        let data: &[(&str, &[f64])] = &[("q", &cells)];
        write_vts2(dir.join("g.vts"), &g, data).unwrap();
        let q = QuadMesh::from_grid(&g);
        write_vtu_quads(dir.join("g.vtu"), &q, data).unwrap();
        let vts = std::fs::read_to_string(dir.join("g.vts")).unwrap();
        assert!(vts.contains("format=\"binary\"") && !vts.contains("format=\"ascii\""));
        let back = read_vtk_xml(dir.join("g.vts")).unwrap();
        assert_eq!(back.mesh, VtkMesh::Structured2(g.clone()));
        assert_eq!(back.cell_array("q"), Some(&cells[..]));
        let back = read_vtk_xml(dir.join("g.vtu")).unwrap();
        assert_eq!(back.mesh, VtkMesh::Quads(q));
        // binary is smaller than ASCII of the same data: 8 bytes per value × 4/3 base64 vs
        // up to 20 decimal characters
        let small = StructuredGrid2::from_fn(120, 83, |i, j| g.node(i, j)).unwrap();
        assert!(small.num_nodes() <= BINARY_THRESHOLD_POINTS);
        let scells: Vec<f64> = (0..small.num_cells()).map(|c| (c as f64).ln_1p()).collect();
        write_vts2(dir.join("s.vts"), &small, &[("q", &scells)]).unwrap();
        let ascii_per_node =
            std::fs::metadata(dir.join("s.vts")).unwrap().len() as f64 / small.num_nodes() as f64;
        let bin_per_node = vts.len() as f64 / g.num_nodes() as f64;
        assert!(
            bin_per_node < 0.75 * ascii_per_node,
            "{bin_per_node} vs {ascii_per_node}"
        );
        std::fs::remove_dir_all(dir).ok();
    }

    #[test]
    fn a_uint32_header_is_read_and_a_wrong_count_is_an_error() {
        use base64::Engine as _;
        let e = &base64::engine::general_purpose::STANDARD;
        let pts: Vec<u8> = [
            0.0f64, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0,
        ]
        .iter()
        .flat_map(|x| x.to_le_bytes())
        .collect();
        let enc =
            |b: &[u8], header: u32| format!("{}{}", e.encode(header.to_le_bytes()), e.encode(b));
        let doc = |header: u32| {
            format!(
                r#"<?xml version="1.0"?><VTKFile type="StructuredGrid" version="1.0" byte_order="LittleEndian">
<StructuredGrid WholeExtent="0 1 0 1 0 0"><Piece Extent="0 1 0 1 0 0"><Points>
<DataArray type="Float64" NumberOfComponents="3" format="binary">{}</DataArray>
</Points></Piece></StructuredGrid></VTKFile>"#,
                enc(&pts, header)
            )
        };
        let f = parse_vtk_xml(&doc(96)).unwrap();
        assert_eq!(f.mesh.num_nodes(), 4);
        let err = parse_vtk_xml(&doc(95)).unwrap_err().to_string();
        assert!(err.contains("not base64 of a byte count"), "{err}");
    }
}
