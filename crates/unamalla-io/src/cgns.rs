//! Structured multi-zone CGNS output (feature `cgns`, linking the system CGNS library — Debian
//! `libcgns-dev`; the default build does not have this module).
//!
//! [`write_cgns`] writes, through the CGNS mid-level library (CGNS SIDS, "Standard Interface
//! Data Structures", AIAA R-101A; mid-level library manual `cg_*` calls):
//!
//! * one `CGNSBase_t` `Base`, cell dimension 2, physical dimension 2;
//! * **one `Zone_t` per block** (`block-<b>`, `Structured`, size `[m, n, m−1, n−1]`) with
//!   `GridCoordinates/CoordinateX, CoordinateY` (i fastest, as the block's node order);
//! * **`GridConnectivity1to1_t` across every cut**: each maximal run of a block side shared
//!   with one neighbour block is an interface `c<b>-<b'>-<k>` with its point range, the donor's
//!   point range and the transform (below); both zones list it;
//! * **`BC_t` per named patch** on each block side: each maximal run of boundary edges of one
//!   patch is a BC named after the patch (`name`, `name.2`, … when a zone has several runs of
//!   it), `PointRange` of vertices, type `BCWall` (names containing `wall` or `coast`),
//!   `BCFarfield` (`sea`, `far`, `open`), `BCInflow` (`inlet`, `inflow`), `BCOutflow`
//!   (`outlet`, `outflow`), else `BCGeneral`, and a `FamilyName` = the patch, one `Family_t` per
//!   patch in the base.
//!
//! # Transform of a 1-to-1 interface (SIDS §8.2)
//!
//! `transform[k] = ±(k′ + 1)` says that the current zone's index `k` runs along the donor's
//! index `k′`, in the same (+) or the opposite (−) direction. Along the interface the direction
//! is read off the two ranges; across it, leaving the current zone through its side (index
//! increasing at a max side, decreasing at a min side) must enter the donor (index decreasing
//! from a max side, increasing from a min side): same direction ⇒ +.

use std::collections::HashMap;
use std::ffi::{c_char, c_int, CStr, CString};
use std::path::Path;

use unamalla_mesh::{BlockMesh2, HasNodes, StructuredGrid2};

use crate::error::IoError;
use crate::msh::EdgeGroup;
use crate::patches::edge_names;

#[cfg(cgns_64bit)]
type CgSize = i64;
#[cfg(not(cgns_64bit))]
type CgSize = c_int;

const CG_MODE_WRITE: c_int = 1;
const ONE: c_int = 1;
const STRUCTURED: c_int = 2;
const REAL_DOUBLE: c_int = 4;
const POINT_RANGE: c_int = 4;
const BC_FARFIELD: c_int = 7;
const BC_GENERAL: c_int = 8;
const BC_INFLOW: c_int = 9;
const BC_OUTFLOW: c_int = 13;
const BC_WALL: c_int = 20;

#[link(name = "cgns")]
extern "C" {
    fn cg_open(filename: *const c_char, mode: c_int, fn_: *mut c_int) -> c_int;
    fn cg_close(fn_: c_int) -> c_int;
    fn cg_base_write(
        fn_: c_int,
        name: *const c_char,
        cell_dim: c_int,
        phys_dim: c_int,
        b: *mut c_int,
    ) -> c_int;
    fn cg_zone_write(
        fn_: c_int,
        b: c_int,
        name: *const c_char,
        size: *const CgSize,
        ty: c_int,
        z: *mut c_int,
    ) -> c_int;
    fn cg_coord_write(
        fn_: c_int,
        b: c_int,
        z: c_int,
        ty: c_int,
        name: *const c_char,
        data: *const std::ffi::c_void,
        c: *mut c_int,
    ) -> c_int;
    fn cg_1to1_write(
        fn_: c_int,
        b: c_int,
        z: c_int,
        name: *const c_char,
        donor: *const c_char,
        range: *const CgSize,
        donor_range: *const CgSize,
        transform: *const c_int,
        i: *mut c_int,
    ) -> c_int;
    fn cg_boco_write(
        fn_: c_int,
        b: c_int,
        z: c_int,
        name: *const c_char,
        ty: c_int,
        ptset: c_int,
        npnts: CgSize,
        pnts: *const CgSize,
        bc: *mut c_int,
    ) -> c_int;
    fn cg_family_write(fn_: c_int, b: c_int, name: *const c_char, f: *mut c_int) -> c_int;
    fn cg_goto(fn_: c_int, b: c_int, ...) -> c_int;
    fn cg_famname_write(name: *const c_char) -> c_int;
    fn cg_get_error() -> *const c_char;
}

/// One side of a block: which index is fixed (0 = i, 1 = j) and whether at its max.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Side {
    normal: usize,
    max: bool,
}

const SIDES: [Side; 4] = [
    Side {
        normal: 1,
        max: false,
    }, // j = 1
    Side {
        normal: 0,
        max: true,
    }, // i = m
    Side {
        normal: 1,
        max: true,
    }, // j = n
    Side {
        normal: 0,
        max: false,
    }, // i = 1
];

/// The (i, j) (0-based) of position `t` along side `s` of a block, `t` running with the
/// varying index.
fn side_ij(g: &StructuredGrid2, s: Side, t: usize) -> [usize; 2] {
    let fixed = |len: usize| if s.max { len - 1 } else { 0 };
    if s.normal == 0 {
        [fixed(g.m()), t]
    } else {
        [t, fixed(g.n())]
    }
}

fn side_len(g: &StructuredGrid2, s: Side) -> usize {
    if s.normal == 0 {
        g.n()
    } else {
        g.m()
    }
}

/// An interface or BC run found on a block side.
#[derive(Debug, Clone, PartialEq)]
pub struct Interface {
    /// Current block and donor block.
    pub blocks: (usize, usize),
    /// Current range `[i0, j0, i1, j1]` and donor range, 1-based vertex indices.
    pub range: [usize; 4],
    /// Donor range.
    pub donor_range: [usize; 4],
    /// SIDS transform.
    pub transform: [i32; 2],
}

/// A BC run on a block side: block, patch index, vertex range (1-based).
#[derive(Debug, Clone, PartialEq)]
pub struct BcRun {
    /// Block.
    pub block: usize,
    /// Index into the groups.
    pub group: usize,
    /// `[i0, j0, i1, j1]`, 1-based.
    pub range: [usize; 4],
}

/// The 1-to-1 interfaces (both directions) and BC runs of a block mesh (what [`write_cgns`]
/// writes), computed without the CGNS library.
pub fn structure(mesh: &BlockMesh2, groups: &[EdgeGroup]) -> (Vec<Interface>, Vec<BcRun>) {
    let names = edge_names(groups);
    // global edge -> [(block, side, t)] for the block-side edges (t = the lower position)
    let mut owners: HashMap<(usize, usize), Vec<(usize, usize, usize)>> = HashMap::new();
    // global node -> [(block, side, t)]
    let mut at: HashMap<usize, Vec<(usize, usize, usize)>> = HashMap::new();
    for (b, g) in mesh.blocks().iter().enumerate() {
        let map = mesh.block_node_map(b);
        for (si, &s) in SIDES.iter().enumerate() {
            let len = side_len(g, s);
            for t in 0..len {
                let [i, j] = side_ij(g, s, t);
                at.entry(map[g.index(i, j)]).or_default().push((b, si, t));
                if t + 1 < len {
                    let [i1, j1] = side_ij(g, s, t + 1);
                    let (u, v) = (map[g.index(i, j)], map[g.index(i1, j1)]);
                    owners
                        .entry((u.min(v), u.max(v)))
                        .or_default()
                        .push((b, si, t));
                }
            }
        }
    }
    let mut ifaces = Vec::new();
    let mut bcs = Vec::new();
    for (b, g) in mesh.blocks().iter().enumerate() {
        let map = mesh.block_node_map(b);
        for (si, &s) in SIDES.iter().enumerate() {
            let len = side_len(g, s);
            // classify each edge t: Some(Ok((donor block, donor side))) or Some(Err(group))
            let class: Vec<Option<Result<(usize, usize), usize>>> = (0..len - 1)
                .map(|t| {
                    let [i, j] = side_ij(g, s, t);
                    let [i1, j1] = side_ij(g, s, t + 1);
                    let (u, v) = (map[g.index(i, j)], map[g.index(i1, j1)]);
                    let key = (u.min(v), u.max(v));
                    let other = owners
                        .get(&key)
                        .and_then(|l| l.iter().find(|&&(ob, os, _)| (ob, os) != (b, si)));
                    match other {
                        Some(&(ob, os, _)) => Some(Ok((ob, os))),
                        None => names.get(&key).map(|&k| Err(k)),
                    }
                })
                .collect();
            let mut t0 = 0;
            while t0 < len - 1 {
                let mut t1 = t0 + 1;
                while t1 < len - 1 && class[t1] == class[t0] {
                    t1 += 1;
                }
                // the run covers nodes t0..=t1
                let a = side_ij(g, s, t0);
                let z = side_ij(g, s, t1);
                let range = [a[0] + 1, a[1] + 1, z[0] + 1, z[1] + 1];
                match class[t0] {
                    Some(Ok((ob, os))) => {
                        let og = &mesh.blocks()[ob];
                        let pos = |node: usize| {
                            at.get(&node)
                                .and_then(|l| l.iter().find(|&&(bb, ss, _)| bb == ob && ss == os))
                                .map(|&(_, _, t)| t)
                        };
                        let (ga, gz) = (map[g.index(a[0], a[1])], map[g.index(z[0], z[1])]);
                        if let (Some(pa), Some(pz)) = (pos(ga), pos(gz)) {
                            let osd = SIDES[os];
                            let da = side_ij(og, osd, pa);
                            let dz = side_ij(og, osd, pz);
                            let along = 1 - s.normal;
                            let oalong = 1 - osd.normal;
                            let dir = |p: usize, q: usize| if q >= p { 1i32 } else { -1 };
                            let mut tr = [0i32; 2];
                            tr[along] = dir(t0, t1) * dir(pa, pz) * (oalong as i32 + 1);
                            let out = if s.max { 1 } else { -1 };
                            let inn = if osd.max { -1 } else { 1 };
                            tr[s.normal] = out * inn * (osd.normal as i32 + 1);
                            ifaces.push(Interface {
                                blocks: (b, ob),
                                range,
                                donor_range: [da[0] + 1, da[1] + 1, dz[0] + 1, dz[1] + 1],
                                transform: tr,
                            });
                        }
                    }
                    Some(Err(k)) => bcs.push(BcRun {
                        block: b,
                        group: k,
                        range,
                    }),
                    None => {}
                }
                t0 = t1;
            }
        }
    }
    (ifaces, bcs)
}

fn bc_type(name: &str) -> c_int {
    let n = name.to_ascii_lowercase();
    if n.contains("wall") || n.contains("coast") {
        BC_WALL
    } else if n.contains("sea") || n.contains("far") || n.contains("open") {
        BC_FARFIELD
    } else if n.contains("inlet") || n.contains("inflow") {
        BC_INFLOW
    } else if n.contains("outlet") || n.contains("outflow") {
        BC_OUTFLOW
    } else {
        BC_GENERAL
    }
}

fn cstr(s: &str) -> Result<CString, IoError> {
    CString::new(s).map_err(|_| IoError::InvalidPatch {
        name: s.to_string(),
        reason: "contains a NUL byte".into(),
    })
}

struct File(c_int);

impl Drop for File {
    fn drop(&mut self) {
        // SAFETY: self.0 is a file number cg_open returned and that was not closed yet
        unsafe {
            cg_close(self.0);
        }
    }
}

/// Writes the block mesh as structured multi-zone CGNS (see the module docs) to `path`: into
/// a temporary file in the same directory, renamed over `path` when complete.
pub fn write_cgns(
    path: impl AsRef<Path>,
    mesh: &BlockMesh2,
    groups: &[EdgeGroup],
) -> Result<(), IoError> {
    let path = path.as_ref();
    for g in groups {
        crate::patches::check_patch_name(&g.name)?;
    }
    let (ifaces, bcs) = structure(mesh, groups);
    let tmp = path.with_extension(format!("cgns.tmp{}", std::process::id()));
    let fail = |what: &str| {
        // SAFETY: cg_get_error returns a pointer to a static NUL-terminated message
        let msg = unsafe { CStr::from_ptr(cg_get_error()) }
            .to_string_lossy()
            .into_owned();
        IoError::Io {
            path: path.to_path_buf(),
            source: std::io::Error::other(format!("CGNS {what}: {msg}")),
        }
    };
    let name = cstr(&tmp.to_string_lossy())?;
    let result = (|| {
        let mut f = 0;
        // SAFETY: valid NUL-terminated strings and out-pointers for every call below; array
        // arguments have the lengths the CGNS manual gives (size: 6 for a 2D structured zone,
        // ranges: 4, transform: 2, BC point range: 2 points × 2 indices)
        unsafe {
            if cg_open(name.as_ptr(), CG_MODE_WRITE, &mut f) != 0 {
                return Err(fail("open"));
            }
            let file = File(f);
            let mut base = 0;
            let bname = cstr("Base")?;
            if cg_base_write(file.0, bname.as_ptr(), 2, 2, &mut base) != 0 {
                return Err(fail("base"));
            }
            for g in groups {
                let mut fam = 0;
                let n = cstr(&g.name)?;
                if cg_family_write(file.0, base, n.as_ptr(), &mut fam) != 0 {
                    return Err(fail("family"));
                }
            }
            let zname = |b: usize| cstr(&format!("block-{b}"));
            let mut zones = Vec::new();
            for (b, g) in mesh.blocks().iter().enumerate() {
                let size: [CgSize; 6] = [
                    g.m() as CgSize,
                    g.n() as CgSize,
                    (g.m() - 1) as CgSize,
                    (g.n() - 1) as CgSize,
                    0,
                    0,
                ];
                let mut z = 0;
                let zn = zname(b)?;
                if cg_zone_write(file.0, base, zn.as_ptr(), size.as_ptr(), STRUCTURED, &mut z) != 0
                {
                    return Err(fail("zone"));
                }
                let xs: Vec<f64> = g.nodes().iter().map(|p| p.x).collect();
                let ys: Vec<f64> = g.nodes().iter().map(|p| p.y).collect();
                for (cn, data) in [("CoordinateX", &xs), ("CoordinateY", &ys)] {
                    let mut c = 0;
                    let cn = cstr(cn)?;
                    if cg_coord_write(
                        file.0,
                        base,
                        z,
                        REAL_DOUBLE,
                        cn.as_ptr(),
                        data.as_ptr().cast(),
                        &mut c,
                    ) != 0
                    {
                        return Err(fail("coordinates"));
                    }
                }
                zones.push(z);
            }
            for (k, it) in ifaces.iter().enumerate() {
                let (b, ob) = it.blocks;
                let cn = cstr(&format!("c{b}-{ob}-{k}"))?;
                let dn = zname(ob)?;
                let r = it.range.map(|v| v as CgSize);
                let d = it.donor_range.map(|v| v as CgSize);
                let tr = it.transform.map(|v| v as c_int);
                let mut i = 0;
                if cg_1to1_write(
                    file.0,
                    base,
                    zones[b],
                    cn.as_ptr(),
                    dn.as_ptr(),
                    r.as_ptr(),
                    d.as_ptr(),
                    tr.as_ptr(),
                    &mut i,
                ) != 0
                {
                    return Err(fail("1to1 connectivity"));
                }
            }
            let mut used: HashMap<(usize, usize), usize> = HashMap::new();
            for bc in &bcs {
                let g = &groups[bc.group];
                let k = used.entry((bc.block, bc.group)).or_insert(0);
                *k += 1;
                let bn = if *k == 1 {
                    g.name.clone()
                } else {
                    format!("{}.{}", g.name, k)
                };
                let bn = cstr(&bn)?;
                let pts = bc.range.map(|v| v as CgSize);
                let mut id = 0;
                if cg_boco_write(
                    file.0,
                    base,
                    zones[bc.block],
                    bn.as_ptr(),
                    bc_type(&g.name),
                    POINT_RANGE,
                    2,
                    pts.as_ptr(),
                    &mut id,
                ) != 0
                {
                    return Err(fail("BC"));
                }
                let zt = cstr("Zone_t")?;
                let zbc = cstr("ZoneBC_t")?;
                let bct = cstr("BC_t")?;
                let end = cstr("end")?;
                if cg_goto(
                    file.0,
                    base,
                    zt.as_ptr(),
                    zones[bc.block],
                    zbc.as_ptr(),
                    ONE,
                    bct.as_ptr(),
                    id,
                    end.as_ptr(),
                ) != 0
                {
                    return Err(fail("goto BC"));
                }
                let fam = cstr(&g.name)?;
                if cg_famname_write(fam.as_ptr()) != 0 {
                    return Err(fail("family name"));
                }
            }
            let fnum = file.0;
            std::mem::forget(file);
            if cg_close(fnum) != 0 {
                return Err(fail("close"));
            }
        }
        Ok(())
    })();
    match result {
        Ok(()) => std::fs::rename(&tmp, path).map_err(|source| IoError::Io {
            path: path.to_path_buf(),
            source,
        }),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(e)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use unamalla_mesh::DVec2;

    #[test]
    fn two_blocks_side_by_side_have_one_interface_each_way_with_identity_transform() {
        // block 0 on [0,2]×[0,1], block 1 on [2,4]×[0,1], 3×2 nodes each: the shared side is
        // i = 3 of block 0 and i = 1 of block 1, both j = 1..2; transform (1, 2)
        let blk = |x0: f64| {
            StructuredGrid2::from_fn(3, 2, |i, j| DVec2::new(x0 + i as f64, j as f64)).unwrap()
        };
        let mesh = BlockMesh2::merge(vec![blk(0.0), blk(2.0)], 1e-9).unwrap();
        let groups = crate::msh::boundary_edge_groups(mesh.global());
        let (ifaces, bcs) = structure(&mesh, &groups);
        assert_eq!(ifaces.len(), 2);
        assert_eq!(ifaces[0].blocks, (0, 1));
        assert_eq!(ifaces[0].range, [3, 1, 3, 2]);
        assert_eq!(ifaces[0].donor_range, [1, 1, 1, 2]);
        assert_eq!(ifaces[0].transform, [1, 2]);
        // 3 BC sides per block
        assert_eq!(bcs.len(), 6);
        let dir = std::env::temp_dir().join(format!("unamalla-cgns-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        write_cgns(dir.join("two.cgns"), &mesh, &groups).unwrap();
        assert!(std::fs::metadata(dir.join("two.cgns")).unwrap().len() > 0);
    }

    #[test]
    fn a_rotated_neighbour_gets_a_permuted_transform() {
        // block 1's j runs along block 0's right side, its i = 1 side... build block 1 with
        // node (i, j) at (2 + j, 1 − i)·: its side j = 1 (bottom, i increasing downwards) is
        // block 0's i = 3 side traversed top to bottom
        let b0 = StructuredGrid2::from_fn(3, 2, |i, j| DVec2::new(i as f64, j as f64)).unwrap();
        let b1 = StructuredGrid2::from_fn(2, 3, |i, j| DVec2::new(2.0 + j as f64, 1.0 - i as f64))
            .unwrap();
        let mesh = BlockMesh2::merge(vec![b0, b1], 1e-9).unwrap();
        let groups = crate::msh::boundary_edge_groups(mesh.global());
        let (ifaces, _) = structure(&mesh, &groups);
        let it = ifaces.iter().find(|i| i.blocks == (0, 1)).unwrap();
        // current i (normal, leaving at max) enters the donor through j = 1 increasing: +2;
        // current j increasing (up) is donor i decreasing: −1
        assert_eq!(it.transform, [2, -1]);
        assert_eq!(it.range, [3, 1, 3, 2]);
        assert_eq!(it.donor_range, [2, 1, 1, 1]);
    }
}
