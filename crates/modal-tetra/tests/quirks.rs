//! Exporter quirks combined at random, on random closed shapes.
//!
//! The readers and the repair each handle one quirk at a time in the other
//! tests. Files in the wild carry several at once: a CAD export may be
//! unwelded, double-sided and full of T-junctions. Every quirk here leaves the
//! generalized winding number `w(x) = Σ_t Ω_t(x) / 4π` as it was (or, for the
//! double-sided copy, leaves one side of every pair that repair keeps), so the
//! solid is the clean shape's: the mesh must hold the same volume and pass the
//! same checks. The second property adds quirks that do change the solid (a
//! hole, half of the faces written twice, copies of a corner rounded apart):
//! those may be refused,
//! never panic, and what they give must pass the checks.

mod common;

use common::{assert_good, rel, translate, union};
use modal_tetra::{shapes, tetrahedralize, TetOptions, TriSurface};
use proptest::prelude::*;

/// SplitMix64: picks the triangles each quirk touches from one seed, so a
/// failing case is reproduced by its seed alone.
struct Picks(u64);

impl Picks {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }

    /// `count` distinct indices below `n` (all of them when `count ≥ n`).
    fn some(&mut self, count: usize, n: usize) -> Vec<usize> {
        let mut all: Vec<usize> = (0..n).collect();
        for i in (1..n).rev() {
            all.swap(i, self.below(i + 1));
        }
        all.truncate(count.min(n));
        all.sort_unstable();
        all
    }
}

/// The shapes: a box (sharp edges, found and snapped), a sphere (smooth), a
/// torus (a hole through it), and two separate boxes (two parts).
fn shape(kind: u8, size: [f64; 3]) -> TriSurface {
    match kind % 4 {
        0 => shapes::cuboid(size[0], size[1], size[2]),
        1 => shapes::icosphere(0.5 * size[0], 3),
        2 => shapes::torus(0.5 * size[0], 0.25 * size[0].min(size[1]), 24, 12),
        _ => {
            let a = shapes::cuboid(size[0], size[1], size[2]);
            let mut b = shapes::cuboid(size[2], size[1], size[0]);
            translate(&mut b, [1.5 * size[0], 0.0, 0.0]);
            union(&a, &b)
        }
    }
}

/// The quirks that keep the solid, each on or off.
#[derive(Clone, Copy, Debug)]
struct Keeping {
    t_junctions: bool,
    degenerate: bool,
    flipped: bool,
    repeated: bool,
    double_sided: bool,
    unwelded: bool,
    shuffled: bool,
}

fn keeping() -> impl Strategy<Value = Keeping> {
    any::<[bool; 7]>().prop_map(|b| Keeping {
        t_junctions: b[0],
        degenerate: b[1],
        flipped: b[2],
        repeated: b[3],
        double_sided: b[4],
        unwelded: b[5],
        shuffled: b[6],
    })
}

/// Splits `count` triangles at the middle of one edge each, on a new vertex,
/// leaving the neighbour across that edge whole: a T-junction. With
/// `both_sides` the neighbour is split there too: the same surface without
/// T-junctions, which is what their repair should give.
fn add_t_junctions(s: &mut TriSurface, picks: &mut Picks, count: usize, both_sides: bool) {
    let mut splits = Vec::new();
    for t in picks.some(count, s.triangles.len()) {
        let [a, b, c] = s.triangles[t];
        let (p, q) = (s.vertices[a], s.vertices[b]);
        let m = s.vertices.len();
        s.vertices.push(std::array::from_fn(|k| 0.5 * (p[k] + q[k])));
        s.triangles[t] = [a, m, c];
        s.triangles.push([m, b, c]);
        splits.push((a, b, m));
    }
    if !both_sides {
        return;
    }
    for (a, b, m) in splits {
        // The neighbour runs through the edge the other way: b then a.
        for t in 0..s.triangles.len() {
            let tri = s.triangles[t];
            if let Some(k) = (0..3).find(|&k| tri[k] == b && tri[(k + 1) % 3] == a) {
                let c = tri[(k + 2) % 3];
                s.triangles[t] = [b, m, c];
                s.triangles.push([m, a, c]);
                break;
            }
        }
    }
}

/// Zero-area triangles: a repeated corner, and a corner on the opposite edge.
fn add_degenerate(s: &mut TriSurface, picks: &mut Picks) {
    let [a, b, _] = s.triangles[picks.below(s.triangles.len())];
    let (p, q) = (s.vertices[a], s.vertices[b]);
    let m = s.vertices.len();
    s.vertices.push(std::array::from_fn(|k| 0.25 * p[k] + 0.75 * q[k]));
    s.triangles.extend([[a, a, b], [a, m, b]]);
}

fn flip(s: &mut TriSurface, picks: &mut Picks, count: usize) {
    for t in picks.some(count, s.triangles.len()) {
        s.triangles[t].swap(1, 2);
    }
}

fn repeat(s: &mut TriSurface, picks: &mut Picks, count: usize) {
    for t in picks.some(count, s.triangles.len()) {
        s.triangles.push(s.triangles[t]);
    }
}

/// Every face once more, facing the other way (a double-sided export).
fn double_side(s: &mut TriSurface) {
    let back: Vec<[usize; 3]> = s.triangles.iter().map(|&[a, b, c]| [a, c, b]).collect();
    s.triangles.extend(back);
}

/// Every triangle on its own three vertices (an unwelded soup).
fn unweld(s: &mut TriSurface) {
    let vertices = std::mem::take(&mut s.vertices);
    for t in &mut s.triangles {
        *t = t.map(|v| {
            s.vertices.push(vertices[v]);
            s.vertices.len() - 1
        });
    }
}

/// Triangles in another order, each starting at another corner.
fn shuffle(s: &mut TriSurface, picks: &mut Picks) {
    let n = s.triangles.len();
    for i in (1..n).rev() {
        s.triangles.swap(i, picks.below(i + 1));
    }
    for t in &mut s.triangles {
        t.rotate_left(picks.below(3));
    }
}

/// One part named for the whole file: the quirks moved triangles across the
/// shape's own parts.
fn one_part(mut s: TriSurface) -> TriSurface {
    s.parts = vec![("quirky".into(), 0..s.triangles.len())];
    s
}

fn apply_keeping(clean: &TriSurface, q: Keeping, seed: u64) -> TriSurface {
    let mut picks = Picks(seed);
    let mut s = clean.clone();
    if q.t_junctions {
        let count = 1 + picks.below(4);
        add_t_junctions(&mut s, &mut picks, count, false);
    }
    if q.degenerate {
        add_degenerate(&mut s, &mut picks);
    }
    if q.flipped {
        let count = 1 + picks.below(s.triangles.len() / 2);
        flip(&mut s, &mut picks, count);
    }
    if q.repeated {
        let count = 1 + picks.below(s.triangles.len());
        repeat(&mut s, &mut picks, count);
    }
    if q.double_sided {
        double_side(&mut s);
    }
    if q.unwelded {
        unweld(&mut s);
    }
    if q.shuffled {
        shuffle(&mut s, &mut picks);
    }
    one_part(s)
}

/// The surface the quirky one stands for: the clean shape with the same
/// edges split as the T-junctions split them, on both sides. (Splitting a
/// box's sharp edge moves its mesh's volume by up to 2·10⁻⁴: the mesher
/// follows the triangles, so the reference must have the same ones.)
fn meant(clean: &TriSurface, q: Keeping, seed: u64) -> TriSurface {
    let mut s = clean.clone();
    if q.t_junctions {
        let mut picks = Picks(seed);
        let count = 1 + picks.below(4);
        add_t_junctions(&mut s, &mut picks, count, true);
    }
    s
}

fn sizes() -> impl Strategy<Value = [f64; 3]> {
    [0.03..0.2f64, 0.02..0.12f64, 0.015..0.08f64]
}

/// 24 cases from a fixed seed, so that a CI run is reproducible; explore
/// with `PROPTEST_CASES=500 PROPTEST_RNG_SEED=<any u64> cargo test -p
/// modal-tetra --test quirks`.
fn config() -> ProptestConfig {
    let mut config = ProptestConfig { failure_persistence: None, ..ProptestConfig::default() };
    if std::env::var_os("PROPTEST_CASES").is_none() {
        config.cases = 24;
    }
    if std::env::var_os("PROPTEST_RNG_SEED").is_none() {
        config.rng_seed = proptest::test_runner::RngSeed::Fixed(20_261_128);
    }
    config
}

proptest! {
    #![proptest_config(config())]

    /// Quirks that keep the solid are repaired to the clean surface: closed,
    /// manifold, the same parts and the same enclosed volume (to rounding).
    /// Its mesh is the clean shape's mesh (its edges split where the
    /// T-junctions split them): the same tets, nodes within 10⁻¹² of the
    /// diagonal. Before the repaired surface was put in canonical order, the
    /// mesh followed the file's order: a shuffled torus moved its volume by
    /// 6·10⁻⁷, and two boxes with T-junctions, double-sided, repeated and
    /// shuffled by 2·10⁻⁴, with a false gap warning (seed 4242, 300 cases).
    #[test]
    fn quirks_that_keep_the_solid_are_repaired_to_the_clean_surface(
        kind in 0u8..4,
        size in sizes(),
        quirks in keeping(),
        seed in any::<u64>(),
    ) {
        let clean = one_part(meant(&shape(kind, size), quirks, seed));
        let quirky = apply_keeping(&shape(kind, size), quirks, seed);
        let (want, got) = (modal_tetra::diagnose(&clean), modal_tetra::diagnose(&quirky));
        prop_assert_eq!((got.open_boundary_edges, got.non_manifold_edges), (0, 0), "{:?}, seed {}: {:?}", quirks, seed, got);
        prop_assert_eq!(got.components, want.components, "{:?}, seed {}", quirks, seed);
        prop_assert!(
            rel(got.enclosed_volume_m3, want.enclosed_volume_m3).abs() < 1e-12,
            "{quirks:?}, seed {seed}: encloses {} against {}", got.enclosed_volume_m3, want.enclosed_volume_m3
        );
        let options = TetOptions::default();
        let (want, expected) = tetrahedralize(&clean, &options).expect("the clean shape meshes");
        let (mesh, report) = tetrahedralize(&quirky, &options)
            .unwrap_or_else(|e| panic!("{quirks:?} (seed {seed}) refused: {e}"));
        assert_good(&mesh, &report);
        // The same nodes and tets but for rounding: a triangle split at two
        // T-junctions is fanned from a centre, not as `meant` splits it, and the
        // winding number sums the other triangles' angles.
        let moved = mesh.nodes.iter().zip(&want.nodes).flat_map(|(p, q)| (0..3).map(move |c| (p[c] - q[c]).abs()));
        let moved = moved.fold(0.0, f64::max);
        prop_assert!(
            mesh.nodes.len() == want.nodes.len() && mesh.cells == want.cells && moved <= 1e-12 * clean.diagonal(),
            "{quirks:?}, seed {seed}: {} nodes against {} clean, moved by {moved:e} m, volume {} against {}; warnings {:?}",
            mesh.nodes.len(), want.nodes.len(), report.volume_m3, expected.volume_m3, report.warnings
        );
    }

    /// Quirks that change the solid: a hole, half of the faces written
    /// twice facing both ways, vertices moved apart by less than the weld
    /// tolerance, and a speck of dust
    /// beside the shape. Refused or meshed, never a panic; a mesh passes the
    /// checks and holds the shape to within the hole's share.
    #[test]
    fn quirks_that_change_the_solid_never_panic(
        kind in 0u8..4,
        size in sizes(),
        quirks in keeping(),
        damage in any::<[bool; 4]>(),
        seed in any::<u64>(),
    ) {
        let clean = shape(kind, size);
        let mut s = apply_keeping(&clean, quirks, seed);
        let mut picks = Picks(seed ^ 0x5eed);
        if damage[0] {
            s.triangles.remove(picks.below(s.triangles.len()));
        }
        if damage[1] {
            let half: Vec<[usize; 3]> = picks
                .some(s.triangles.len() / 2, s.triangles.len())
                .into_iter()
                .map(|t| { let [a, b, c] = s.triangles[t]; [a, c, b] })
                .collect();
            s.triangles.extend(half);
        }
        if damage[2] {
            // Within half the weld tolerance (10⁻¹⁰ of the diagonal): copies of a corner
            // rounded apart, as per-face exports write them.
            let hair = 3e-11 * s.diagonal();
            for v in picks.some(s.vertices.len() / 3, s.vertices.len()) {
                let k = picks.below(3);
                s.vertices[v][k] += hair;
            }
        }
        if damage[3] {
            let mut speck = shapes::cuboid(1e-4, 1e-4, 1e-4);
            translate(&mut speck, [-0.01, -0.01, -0.01]);
            s = union(&s, &speck);
        }
        let s = one_part(s);
        match tetrahedralize(&s, &TetOptions::default()) {
            Ok((mesh, report)) => {
                assert_good(&mesh, &report);
                let (_, expected) = tetrahedralize(&clean, &TetOptions::default()).expect("clean");
                prop_assert!(
                    rel(report.volume_m3, expected.volume_m3).abs() < 0.05,
                    "{quirks:?} {damage:?}, seed {seed}: volume {} against {} clean",
                    report.volume_m3, expected.volume_m3
                );
            }
            // Refused: one line saying why, as the CLI prints it.
            Err(e) => prop_assert!(!e.to_string().contains('\n'), "{e}"),
        }
    }
}

/// The 10 × 6 × 4 cm box whose top face has a corner (8) half-way along its
/// front edge 4-5, which the front face keeps whole.
fn box_with_t_junction() -> TriSurface {
    let mut s = shapes::cuboid(0.1, 0.06, 0.04);
    s.vertices.push([0.05, 0.0, 0.04]);
    s.triangles.retain(|t| *t != [4, 5, 6] && *t != [5, 7, 6]);
    s.triangles.extend([[4, 8, 6], [8, 7, 6], [8, 5, 7]]);
    one_part(s)
}

/// Written double-sided, a box with a T-junction was refused as an open
/// sheet: the T-junction's edge, used by a face and its copy, looked closed,
/// so it was not stitched, and the side left open was taken for a sheet.
#[test]
fn a_double_sided_box_with_a_t_junction_meshes_like_the_one_sided_box() {
    let one_side = box_with_t_junction();
    let mut both = one_side.clone();
    double_side(&mut both);
    let both = one_part(both);
    let report = modal_tetra::diagnose(&both);
    assert_eq!(
        (report.t_junctions, report.open_boundary_edges, report.non_manifold_edges),
        (1, 0, 0),
        "{report:?}"
    );
    let (a, _) = tetrahedralize(&one_side, &TetOptions::default()).unwrap();
    let (b, r) = tetrahedralize(&both, &TetOptions::default()).expect("not refused");
    assert_good(&b, &r);
    // The same nodes, but for the rounding of the winding number's sum.
    assert_eq!((a.nodes.len(), a.cells.len()), (b.nodes.len(), b.cells.len()));
    let moved = a.nodes.iter().zip(&b.nodes).flat_map(|(p, q)| (0..3).map(move |c| (p[c] - q[c]).abs()));
    assert!(moved.fold(0.0, f64::max) < 1e-12);
}

/// A box with every other triangle written again, reversed (an export that
/// writes only the faces of a two-sided material twice): the pairs were kept,
/// and the orientation repair turned faces inside out: half the volume.
#[test]
fn a_box_with_half_its_faces_written_twice_meshes_as_the_box() {
    let clean = shapes::cuboid(0.1, 0.06, 0.04);
    let mut s = clean.clone();
    let backs: Vec<[usize; 3]> = s.triangles.iter().step_by(2).map(|&[a, b, c]| [a, c, b]).collect();
    s.triangles.extend(backs);
    let s = one_part(s);
    let report = modal_tetra::diagnose(&s);
    assert_eq!((report.double_sided_faces, report.open_boundary_edges, report.non_manifold_edges), (6, 0, 0));
    let (a, _) = tetrahedralize(&clean, &TetOptions::default()).unwrap();
    let (b, _) = tetrahedralize(&s, &TetOptions::default()).unwrap();
    assert_eq!(a.nodes, b.nodes);
}

/// `p` turned 0.5 rad about z, then 0.3 rad about x, and written with six
/// significant digits, as many exporters write.
fn turned_six_digits(p: [f64; 3]) -> [f64; 3] {
    let (a, b) = (0.5f64, 0.3f64);
    let q = [a.cos() * p[0] - a.sin() * p[1], a.sin() * p[0] + a.cos() * p[1], p[2]];
    let r = [q[0], b.cos() * q[1] - b.sin() * q[2], b.sin() * q[1] + b.cos() * q[2]];
    r.map(|c| format!("{c:.5e}").parse().expect("a number"))
}

/// An exporter closes a split edge with a sliver: the top face is split a
/// third of the way along edge 4-5, the front face keeps 4-5 whole, and the
/// triangle (4, 5, m) fills the gap. Its area is zero but for the six-digit
/// rounding, which kept it (10⁻⁸ m off the edge against a weld tolerance of
/// 10⁻¹¹ m), and made edge 4-5 non-manifold. It is dropped and the edge
/// stitched. (The same box in `tools/export_quirks.py`'s
/// `box_rotated_filler_6digits.obj` was meshed 7.8·10⁻⁴ of the volume short
/// of the plain box; now 3·10⁻⁵, what splitting the top face alone moves.)
#[test]
fn a_sliver_filling_a_split_edge_is_dropped_and_the_edge_stitched() {
    let mut plain = shapes::cuboid(0.1, 0.06, 0.04);
    let mut s = plain.clone();
    let (p4, p5) = (s.vertices[4], s.vertices[5]);
    s.vertices.push(std::array::from_fn(|k| p4[k] + (p5[k] - p4[k]) / 3.0));
    s.triangles.retain(|t| *t != [4, 5, 6]);
    s.triangles.extend([[4, 8, 6], [8, 5, 6], [4, 5, 8]]);
    for surface in [&mut plain, &mut s] {
        surface.vertices.iter_mut().for_each(|p| *p = turned_six_digits(*p));
    }
    let s = one_part(s);
    let report = modal_tetra::diagnose(&s);
    assert_eq!(
        (
            report.degenerate_triangles,
            report.t_junctions,
            report.open_boundary_edges,
            report.non_manifold_edges
        ),
        (1, 1, 0, 0),
        "{report:?}"
    );
    let (_, want) = tetrahedralize(&plain, &TetOptions::default()).unwrap();
    let (mesh, got) = tetrahedralize(&s, &TetOptions::default()).unwrap();
    assert_good(&mesh, &got);
    assert!(rel(got.volume_m3, want.volume_m3).abs() < 1e-4, "{} against {}", got.volume_m3, want.volume_m3);
}

/// An unwelded soup whose copies of a corner are 0.4 of the weld tolerance
/// apart (per-face transforms): the weld rounded coordinates to a grid of
/// that spacing, so copies straddling a cell boundary stayed apart, however
/// close, and the surface read as open.
#[test]
fn copies_of_a_corner_closer_than_the_weld_tolerance_are_welded() {
    let clean = shapes::cuboid(0.1, 0.06, 0.04);
    let tol = 1e-10 * clean.diagonal();
    let mut soup = TriSurface::default();
    for (i, t) in clean.triangles.iter().enumerate() {
        let shift = if i % 2 == 0 { 0.2 * tol } else { -0.2 * tol };
        for &v in t {
            soup.vertices.push(clean.vertices[v].map(|c| c + shift));
        }
        let n = soup.vertices.len();
        soup.triangles.push([n - 3, n - 2, n - 1]);
    }
    let soup = one_part(soup);
    let report = modal_tetra::diagnose(&soup);
    assert_eq!(report.duplicate_vertices, soup.vertices.len() - clean.vertices.len(), "{report:?}");
    assert_eq!((report.open_boundary_edges, report.non_manifold_edges, report.components), (0, 0, 1));
}

/// Every starting triangle and every starting corner of a surface: the
/// orders a file may write it in, one file each.
fn every_start(s: &TriSurface) -> impl Iterator<Item = TriSurface> + '_ {
    (0..s.triangles.len()).flat_map(move |first| {
        (0..3).map(move |corner| {
            let mut t = s.clone();
            t.triangles.rotate_left(first);
            t.triangles.iter_mut().for_each(|tri| tri.rotate_left(corner));
            t
        })
    })
}

/// A box without its top encloses the box, capped flat as the winding number
/// caps it, whichever triangle comes first. The volume was summed about the
/// first corner of the first triangle: from a bottom corner the missing top
/// counted as a cone, and the box read two thirds of itself, and its cells
/// were sized for that.
#[test]
fn an_open_box_encloses_the_box_whatever_its_order() {
    let mut open = shapes::cuboid(0.1, 0.06, 0.04);
    open.triangles.retain(|t| *t != [4, 5, 6] && *t != [5, 7, 6]);
    let open = one_part(open);
    for s in every_start(&open) {
        let report = modal_tetra::diagnose(&s);
        assert_eq!(report.open_boundary_edges, 4);
        assert!(
            rel(report.enclosed_volume_m3, 0.1 * 0.06 * 0.04).abs() < 1e-12,
            "{}",
            report.enclosed_volume_m3
        );
    }
}

/// The corpus bracket's gusset, a box crossing the side of the L, is not a
/// part inside the L, whichever triangle or corner a file starts with:
/// nesting sampled the first corner of every triangle, and when the two
/// corners of the gusset outside the L were never first, it warned of a
/// closed part inside another.
#[test]
fn a_part_crossing_another_is_not_nested_in_any_order() {
    let bracket = one_part(modal_tetra::corpus::asset("bracket").expect("in the corpus"));
    let surfaces: Vec<TriSurface> = every_start(&bracket).collect();
    let (first, _) = tetrahedralize(&surfaces[0], &TetOptions::default()).expect("meshes");
    for s in &surfaces {
        let report = modal_tetra::diagnose(s);
        assert_eq!((report.components, report.cavities), (2, 0));
        assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    }
    // And the mesh is one, bit for bit, whatever the order.
    for s in surfaces.iter().step_by(17) {
        let (mesh, _) = tetrahedralize(s, &TetOptions::default()).expect("meshes");
        assert!(mesh.nodes == first.nodes && mesh.cells == first.cells);
    }
}

/// An unwelded box whose copies of a corner are up to 10⁻⁷ of the diagonal
/// apart (cracked beyond the weld tolerance, as per-face transforms in single
/// precision leave them), alone and with every other face written again,
/// reversed. Each triangle was a part of its own, flat: summed about their
/// rims their volumes were rounding of either sign, which turned triangles at
/// random and sized the cells by 2V/A ≈ 10⁻¹⁸ m (refused); before that, no
/// part had a volume to size the cells, and the faces written twice were not
/// found across the cracks (half the box lost). Now the cracks are welded.
#[test]
fn a_soup_cracked_beyond_the_weld_tolerance_meshes_as_the_box() {
    let clean = shapes::cuboid(0.1, 0.06, 0.04);
    let crack = 1e-7 * clean.diagonal();
    for half_twice in [false, true] {
        let mut picks = Picks(7);
        let mut soup = clean.clone();
        if half_twice {
            let backs: Vec<[usize; 3]> =
                soup.triangles.iter().step_by(2).map(|&[a, b, c]| [a, c, b]).collect();
            soup.triangles.extend(backs);
        }
        unweld(&mut soup);
        for p in &mut soup.vertices {
            for c in p.iter_mut() {
                *c += crack * ((picks.below(2001) as f64) / 1000.0 - 1.0);
            }
        }
        let soup = one_part(soup);
        let report = modal_tetra::diagnose(&soup);
        assert_eq!((report.open_boundary_edges, report.non_manifold_edges, report.components), (0, 0, 1));
        assert!(report.warnings[0].starts_with("the surface is cracked"), "{:?}", report.warnings);
        let (mesh, report) = tetrahedralize(&soup, &TetOptions::default()).expect("meshed");
        assert_good(&mesh, &report);
        assert!(rel(report.volume_m3, 0.1 * 0.06 * 0.04).abs() < 1e-6, "{}", report.volume_m3);
    }
}
