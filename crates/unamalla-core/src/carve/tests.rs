use super::*;
use unamalla_mesh::HasQuadCells;

/// The unit grid on `[0, k]²` as one block (nodes at the integer points).
fn unit_grid(k: usize) -> BlockMesh2 {
    let g = StructuredGrid2::from_fn(k + 1, k + 1, |i, j| DVec2::new(i as f64, j as f64)).unwrap();
    BlockMesh2::merge(vec![g], 1e-9).unwrap()
}

fn square(c: DVec2, half: f64) -> Polygon {
    // vertex 0 at the lower left corner, counter-clockwise
    Polygon::new(vec![
        c + DVec2::new(-half, -half),
        c + DVec2::new(half, -half),
        c + DVec2::new(half, half),
        c + DVec2::new(-half, half),
    ])
    .unwrap()
}

/// Interior nodes (not on an edge used by one cell) and the cells around each node.
fn valences(mesh: &BlockMesh2) -> Vec<(bool, usize)> {
    let g = mesh.global();
    let mut around = vec![0usize; g.nodes().len()];
    let mut edges = std::collections::HashMap::new();
    for c in g.cells() {
        for k in 0..4 {
            around[c[k]] += 1;
            let (a, b) = (c[k], c[(k + 1) % 4]);
            *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    let mut boundary = vec![false; around.len()];
    for ((a, b), n) in edges {
        if n == 1 {
            boundary[a] = true;
            boundary[b] = true;
        }
    }
    boundary.iter().map(|&b| !b).zip(around).collect()
}

#[test]
fn a_two_by_two_island_becomes_a_hole_on_its_contour() {
    // the island [2.1, 3.9]² holds the centroids of the cells (2..=3, 2..=3); the ring of their
    // eight boundary nodes, square [2, 4]², goes by arc length onto the island's square: corners
    // to corners, midpoints to midpoints (the offset 0 is sampled and is the least-squares one)
    let mesh = unit_grid(6);
    let island = square(DVec2::splat(3.0), 0.9);
    let c = carve_islands(&mesh, &[(7, &island)]).unwrap();
    assert_eq!(c.carved_ids(), vec![7]);
    let CarveOutcome::Carved { cells, ring } = &c.outcomes[0].1 else {
        panic!("{:?}", c.outcomes)
    };
    assert_eq!(*cells, 4);
    let expected = [
        (2.1, 2.1),
        (3.0, 2.1),
        (3.9, 2.1),
        (3.9, 3.0),
        (3.9, 3.9),
        (3.0, 3.9),
        (2.1, 3.9),
        (2.1, 3.0),
    ];
    assert_eq!(ring.len(), 8);
    for (p, e) in ring.iter().zip(expected) {
        assert!(p.distance(DVec2::new(e.0, e.1)) < 1e-12, "{ring:?}");
    }
    // 36 − 4 cells, 49 − 1 nodes (the centre node goes), eight blocks around the hole
    assert_eq!(c.mesh.global().num_quads(), 32);
    assert_eq!(c.mesh.global().nodes().len(), 48);
    assert_eq!(c.mesh.blocks().len(), 8);
    assert_eq!(c.origin, vec![0; 8]);
    // every interior node keeps four cells; the hole's nodes are boundary nodes (and fixed)
    let v = valences(&c.mesh);
    assert!(v.iter().all(|&(interior, n)| !interior || n == 4), "{v:?}");
    let g = c.mesh.global();
    for p in ring {
        let k = g
            .nodes()
            .iter()
            .position(|q| q.distance(*p) < 1e-12)
            .unwrap();
        assert!(!v[k].0 && g.fixed()[k]);
    }
    // the mesh's area is the square's minus the hole's (the island's square, 1.8²)
    let area: f64 = (0..g.num_quads())
        .map(|q| unamalla_mesh::region::signed_area(&g.quad_points(q)))
        .sum();
    assert!((area - (36.0 - 1.8 * 1.8)).abs() < 1e-9, "{area}");
}

#[test]
fn an_island_smaller_than_a_cell_takes_the_cell_of_its_centroid_if_it_is_a_quarter_of_it() {
    let mesh = unit_grid(6);
    // area 0.64 ≥ 0.25 · 1, centroid (4.95, 2.95) in cell (4, 2); spanning [4.55, 5.35] ×
    // [2.55, 3.35], it holds no cell centroid (no half-integer coordinate)
    let big = square(DVec2::new(4.95, 2.95), 0.4);
    // area 0.16 < 0.25, spanning [1.75, 2.15] × [3.75, 4.15]: no centroid either
    let small = square(DVec2::new(1.95, 3.95), 0.2);
    let c = carve_islands(&mesh, &[(0, &big), (1, &small)]).unwrap();
    assert!(matches!(
        c.outcomes[0].1,
        CarveOutcome::Carved { cells: 1, .. }
    ));
    assert_eq!(
        c.outcomes[1].1,
        CarveOutcome::Skipped(CarveSkip::BelowMinArea)
    );
    // one cell less, no node less (the four corners become the hole's ring)
    assert_eq!(c.mesh.global().num_quads(), 35);
    assert_eq!(c.mesh.global().nodes().len(), 49);
    let v = valences(&c.mesh);
    assert!(v.iter().all(|&(interior, n)| !interior || n == 4));
}

#[test]
fn islands_touching_the_boundary_or_each_other_or_lying_across_are_left_out() {
    let mesh = unit_grid(6);
    // cell (0, 3) has a region-boundary node
    let shore = square(DVec2::new(0.5, 3.5), 0.45);
    // cells (3, 3) and (4, 3) share two nodes
    let a = square(DVec2::new(3.5, 3.5), 0.45);
    let b = square(DVec2::new(4.5, 3.5), 0.45);
    // a thin diagonal needle from (1.5, 1.5) to (4.5, 4.5): holds the centroids of the diagonal
    // cells (1, 1) .. (4, 4), whose bounding rectangle is 16 cells for an area of 0.02√2 · 3.04√2
    // ≈ 0.12, below a quarter of the cell containing its centroid
    let needle = Polygon::new(vec![
        DVec2::new(1.48, 1.5),
        DVec2::new(1.5, 1.48),
        DVec2::new(4.52, 4.5),
        DVec2::new(4.5, 4.52),
    ])
    .unwrap();
    let c = carve_islands(&mesh, &[(0, &shore), (1, &a), (2, &b), (3, &needle)]).unwrap();
    let got: Vec<_> = c.outcomes.iter().map(|(_, o)| o.clone()).collect();
    assert_eq!(got[0], CarveOutcome::Skipped(CarveSkip::TouchesBoundary));
    assert!(matches!(got[1], CarveOutcome::Carved { cells: 1, .. }));
    assert_eq!(got[2], CarveOutcome::Skipped(CarveSkip::TouchesCarved));
    assert_eq!(got[3], CarveOutcome::Skipped(CarveSkip::NotCompact));
    assert_eq!(c.carved_ids(), vec![1]);
    assert_eq!(c.mesh.global().num_quads(), 35);
}

#[test]
fn an_island_outside_the_mesh_is_reported() {
    let mesh = unit_grid(3);
    let far = square(DVec2::new(10.0, 10.0), 0.45);
    let c = carve_islands(&mesh, &[(4, &far)]).unwrap();
    assert_eq!(
        c.outcomes,
        vec![(4, CarveOutcome::Skipped(CarveSkip::OutsideMesh))]
    );
    assert_eq!(c.mesh.global().num_quads(), 9);
}

#[test]
fn islands_in_one_block_split_it_again_and_stay_conformal() {
    // two 1-cell islands apart in one 8 × 8 block: the second lies in one of the first's pieces
    let mesh = unit_grid(8);
    let a = square(DVec2::new(2.5, 2.5), 0.45);
    let b = square(DVec2::new(5.5, 5.5), 0.45);
    let c = carve_islands(&mesh, &[(0, &a), (1, &b)]).unwrap();
    assert_eq!(c.carved_ids(), vec![0, 1]);
    assert_eq!(c.mesh.global().num_quads(), 62);
    let v = valences(&c.mesh);
    assert!(v.iter().all(|&(interior, n)| !interior || n == 4));
    // boundary nodes: 32 on the square, four on each hole
    assert_eq!(v.iter().filter(|(interior, _)| !interior).count(), 32 + 8);
}
