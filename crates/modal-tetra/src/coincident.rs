//! Coincident triangles: one face written more than once.
//!
//! Files repeat faces in three ways. A duplicated export writes a face twice
//! with the same winding. A double-sided export (two-sided materials, some
//! scan and CAD tools) writes every face once per side, with opposite
//! windings. Two bodies modelled touching (bricks in a stack) leave a pair of
//! opposite faces where they meet.
//!
//! The generalized winding number `w(x) = Σ_t Ω_t(x) / 4π` sums each
//! triangle's signed solid angle (Jacobson et al. 2013), so a same-winding
//! copy doubles a face's share and an opposite pair cancels exactly:
//! - a same-winding copy is dropped;
//! - where two bodies touch, both faces of the pair are dropped: `w` does not
//!   change and the union's surface is left manifold;
//! - a part whose every face is paired is double-sided: its `w` is 0
//!   everywhere, so it enclosed nothing. Where one side is a closed surface,
//!   one face of each pair is kept and the orientation repair turns it
//!   outward. Where one side is an open sheet (a double-sided flag, leaf or
//!   sign), one side alone would give `w` = ±½ around it and stuff an
//!   arbitrary slab, so both are dropped, as `w` did before, unless the
//!   caller gives sheets a thickness ([`Sheets::Keep`]).
//!
//! - a part partly paired (an export that writes only the faces of a
//!   two-sided material twice) where dropping both faces of every pair would
//!   open it, but dropping one of each leaves it manifold (closed, or open
//!   where it was open before: a hole), keeps one: kept as they were, the
//!   pairs made its edges non-manifold, and the orientation repair turned
//!   faces inside out (a box with half its faces written twice lost half its
//!   volume; a torus with a hole as well was meshed in 25 s as 1.3 M tets
//!   holding a quarter of it).
//!
//! Pairs that fit no case are kept as they are: `w` is the same either way.

use std::collections::HashMap;

use modal_mesh::DisjointSets;

use crate::stuff::edge_triangles;

/// What becomes of a double-sided part whose one side is an open sheet.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Sheets {
    /// Keep one side: the caller gives open sheets a thickness.
    Keep,
    /// Drop both sides: a sheet without thickness encloses nothing.
    Drop,
}

/// How many triangles `drop_coincident` removed, by cause.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Coincident {
    /// Same-winding copies of another triangle.
    pub repeated: usize,
    /// Back faces of double-sided parts (one of each opposite pair).
    pub double_sided: usize,
    /// Faces of double-sided open sheets, both sides dropped ([`Sheets::Drop`]).
    pub double_sided_sheet: usize,
    /// Both faces of opposite pairs where two parts touch.
    pub touching: usize,
}

/// Removes coincident triangles from `triangles` (welded, non-degenerate), as
/// the module doc says; the kept triangles stay in file order.
pub(crate) fn drop_coincident(triangles: &mut Vec<[usize; 3]>, sheets: Sheets) -> Coincident {
    let mut counts = Coincident::default();
    let mut keep = vec![true; triangles.len()];
    let pairs = opposite_pairs(triangles, &mut keep, &mut counts);
    if !pairs.is_empty() {
        settle_pairs(triangles, &pairs, sheets, &mut keep, &mut counts);
    }
    let mut flags = keep.into_iter();
    triangles.retain(|_| flags.next().unwrap_or(true));
    counts
}

/// The corners in ascending order, and whether the triangle runs through
/// them in that cyclic order (its winding relative to the sorted key).
fn key(t: [usize; 3]) -> ([usize; 3], bool) {
    let mut k = t;
    k.sort_unstable();
    let rotation = t.iter().position(|&v| v == k[0]).unwrap_or(0);
    (k, t[(rotation + 1) % 3] == k[1])
}

/// Drops same-winding copies (keeping the first) and returns the opposite
/// pairs left: (first of one winding, first of the other). Sorted, not
/// hashed: this runs on every input.
fn opposite_pairs(
    triangles: &[[usize; 3]],
    keep: &mut [bool],
    counts: &mut Coincident,
) -> Vec<(usize, usize)> {
    let mut keyed: Vec<([usize; 3], bool, usize)> = triangles
        .iter()
        .enumerate()
        .map(|(i, &t)| {
            let (corners, forward) = key(t);
            (corners, forward, i)
        })
        .collect();
    keyed.sort_unstable();
    let mut pairs = Vec::new();
    for same_corners in keyed.chunk_by(|x, y| x.0 == y.0) {
        let mut first = [None; 2];
        for &(_, forward, i) in same_corners {
            match first[usize::from(forward)] {
                Some(_) => {
                    keep[i] = false;
                    counts.repeated += 1;
                }
                None => first[usize::from(forward)] = Some(i),
            }
        }
        if let [Some(a), Some(b)] = first {
            pairs.push((a.min(b), a.max(b)));
        }
    }
    pairs.sort_unstable();
    pairs
}

/// Decides, per edge-connected part, whether its opposite pairs are the two
/// sides of one face (keep one) or where two bodies touch (drop both).
fn settle_pairs(
    triangles: &[[usize; 3]],
    pairs: &[(usize, usize)],
    sheets: Sheets,
    keep: &mut [bool],
    counts: &mut Coincident,
) {
    let part = parts(triangles, keep);
    let mut paired = vec![false; triangles.len()];
    pairs.iter().for_each(|&(a, b)| (paired[a], paired[b]) = (true, true));
    let mut by_part: HashMap<usize, Vec<(usize, usize)>> = HashMap::new();
    for &(a, b) in pairs {
        by_part.entry(part[a]).or_default().push((a, b));
    }
    let mut members: HashMap<usize, Vec<usize>> = by_part.keys().map(|&p| (p, Vec::new())).collect();
    for t in (0..triangles.len()).filter(|&t| keep[t]) {
        if let Some(m) = members.get_mut(&part[t]) {
            m.push(t);
        }
    }
    let mut part_ids: Vec<usize> = by_part.keys().copied().collect();
    part_ids.sort_unstable();
    for p in part_ids {
        let (members, part_pairs) = (&members[&p], &by_part[&p]);
        if members.iter().all(|&t| paired[t]) {
            let fronts: Vec<usize> = part_pairs.iter().map(|&(front, _)| front).collect();
            if sheets == Sheets::Drop && has_open_edge(triangles, &fronts) {
                part_pairs.iter().for_each(|&(a, b)| (keep[a], keep[b]) = (false, false));
                counts.double_sided_sheet += part_pairs.len();
            } else {
                part_pairs.iter().for_each(|&(_, back)| keep[back] = false);
                counts.double_sided += part_pairs.len();
            }
        } else if !opens(triangles, members, part_pairs) {
            part_pairs.iter().for_each(|&(a, b)| (keep[a], keep[b]) = (false, false));
            counts.touching += 2 * part_pairs.len();
        } else if manifold_without_backs(triangles, members, part_pairs) {
            part_pairs.iter().for_each(|&(_, back)| keep[back] = false);
            counts.double_sided += part_pairs.len();
        }
    }
}

/// Edge-connected parts of the kept triangles, across every shared edge
/// (non-manifold ones too): a part id per triangle.
fn parts(triangles: &[[usize; 3]], keep: &[bool]) -> Vec<usize> {
    let kept: Vec<usize> = (0..triangles.len()).filter(|&t| keep[t]).collect();
    let mut sets = DisjointSets::new(triangles.len());
    for on_edge in edge_triangles(&pick(triangles, &kept)).values() {
        on_edge.iter().for_each(|&i| sets.join(kept[on_edge[0]], kept[i]));
    }
    (0..triangles.len()).map(|t| sets.root(t)).collect()
}

/// The triangles `ids` of `triangles`, in that order.
fn pick(triangles: &[[usize; 3]], ids: &[usize]) -> Vec<[usize; 3]> {
    ids.iter().map(|&t| triangles[t]).collect()
}

/// True when some edge of `ids`' triangles belongs to one of them only.
fn has_open_edge(triangles: &[[usize; 3]], ids: &[usize]) -> bool {
    edge_triangles(&pick(triangles, ids)).values().any(|on_edge| on_edge.len() == 1)
}

/// True when dropping both triangles of every pair leaves an edge of the
/// part with one triangle that had more: the pairs were not a seam.
fn opens(triangles: &[[usize; 3]], members: &[usize], pairs: &[(usize, usize)]) -> bool {
    let mut dropped = vec![false; triangles.len()];
    pairs.iter().for_each(|&(a, b)| (dropped[a], dropped[b]) = (true, true));
    edge_triangles(&pick(triangles, members)).values().any(|on_edge| {
        let left = on_edge.iter().filter(|&&i| !dropped[members[i]]).count();
        left == 1 && on_edge.len() > 1
    })
}

/// True when the part without the second face of each pair has no edge on
/// more than two triangles: manifold.
fn manifold_without_backs(triangles: &[[usize; 3]], members: &[usize], pairs: &[(usize, usize)]) -> bool {
    let mut back = vec![false; triangles.len()];
    pairs.iter().for_each(|&(_, b)| back[b] = true);
    let kept: Vec<usize> = members.iter().copied().filter(|&t| !back[t]).collect();
    edge_triangles(&pick(triangles, &kept)).values().all(|on_edge| on_edge.len() <= 2)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit box's 12 triangles on corners 0..8 (outward).
    fn box_triangles(offset: usize) -> Vec<[usize; 3]> {
        [
            [0, 1, 3],
            [0, 3, 2],
            [4, 6, 7],
            [4, 7, 5],
            [0, 4, 5],
            [0, 5, 1],
            [2, 3, 7],
            [2, 7, 6],
            [0, 2, 6],
            [0, 6, 4],
            [1, 5, 7],
            [1, 7, 3],
        ]
        .map(|t| t.map(|v| v + offset))
        .to_vec()
    }

    fn reversed(t: &[[usize; 3]]) -> Vec<[usize; 3]> {
        t.iter().map(|&[a, b, c]| [a, c, b]).collect()
    }

    #[test]
    fn the_winding_of_a_triangle_is_read_against_its_sorted_corners() {
        assert_eq!(key([4, 9, 2]), ([2, 4, 9], true));
        assert_eq!(key([9, 2, 4]), ([2, 4, 9], true));
        assert_eq!(key([2, 9, 4]), ([2, 4, 9], false));
    }

    #[test]
    fn a_repeated_box_is_kept_once() {
        let mut t = box_triangles(0);
        t.extend(box_triangles(0));
        let counts = drop_coincident(&mut t, Sheets::Drop);
        assert_eq!(counts, Coincident { repeated: 12, ..Default::default() });
        assert_eq!(t, box_triangles(0));
    }

    #[test]
    fn a_double_sided_box_keeps_its_first_side() {
        let mut t = reversed(&box_triangles(0));
        t.extend(box_triangles(0));
        let counts = drop_coincident(&mut t, Sheets::Drop);
        assert_eq!(counts, Coincident { double_sided: 12, ..Default::default() });
        assert_eq!(t, reversed(&box_triangles(0)));
    }

    #[test]
    fn a_double_sided_sheet_is_dropped_unless_sheets_are_kept() {
        let square = vec![[0, 1, 2], [0, 2, 3]];
        let double: Vec<[usize; 3]> = square.iter().copied().chain(reversed(&square)).collect();
        let mut t = double.clone();
        assert_eq!(
            drop_coincident(&mut t, Sheets::Drop),
            Coincident { double_sided_sheet: 2, ..Default::default() }
        );
        assert!(t.is_empty());
        let mut t = double;
        assert_eq!(
            drop_coincident(&mut t, Sheets::Keep),
            Coincident { double_sided: 2, ..Default::default() }
        );
        assert_eq!(t, square);
    }

    #[test]
    fn two_boxes_touching_over_a_face_lose_that_face_on_both() {
        // Box B's corners 0..4 are box A's corners 4..8 (it sits on A's face x = 1).
        let a = box_triangles(0);
        let b = box_triangles(4);
        let mut t: Vec<[usize; 3]> = a.iter().chain(&b).copied().collect();
        let counts = drop_coincident(&mut t, Sheets::Drop);
        assert_eq!(counts, Coincident { touching: 4, ..Default::default() });
        assert_eq!(t.len(), 20);
        let mut uses: HashMap<(usize, usize), usize> = HashMap::new();
        for tri in &t {
            for k in 0..3 {
                let (p, q) = (tri[k], tri[(k + 1) % 3]);
                *uses.entry((p.min(q), p.max(q))).or_default() += 1;
            }
        }
        assert!(uses.values().all(|&n| n == 2), "the union is closed and manifold: {uses:?}");
    }

    #[test]
    fn a_box_with_some_faces_written_twice_keeps_one_of_each() {
        // A double-sided box whose back faces lost one triangle: the part is
        // not all paired, and dropping the 11 pairs would leave one face
        // alone; dropping their backs leaves the box.
        let mut t = box_triangles(0);
        t.extend(reversed(&box_triangles(0))[1..].iter().copied());
        assert_eq!(
            drop_coincident(&mut t, Sheets::Drop),
            Coincident { double_sided: 11, ..Default::default() }
        );
        assert_eq!(t, box_triangles(0));
    }

    #[test]
    fn an_open_box_with_a_face_written_twice_keeps_one_side_of_it() {
        // An open box (its bottom's two triangles missing) with one side
        // triangle written twice: dropping the pair would open the box
        // further; dropping its back leaves the box as open as it was.
        let mut t = box_triangles(0)[2..].to_vec();
        t.push(reversed(&box_triangles(0))[4]);
        assert_eq!(
            drop_coincident(&mut t, Sheets::Drop),
            Coincident { double_sided: 1, ..Default::default() }
        );
        assert_eq!(t, box_triangles(0)[2..].to_vec());
    }

    #[test]
    fn pairs_on_an_edge_of_three_faces_are_kept() {
        // A box with a fin (a sheet on its edge 0-4, written on both sides)
        // and one box face written twice: without the backs, edge 0-4 still
        // has three faces, so no side can be told from the other.
        let mut t = box_triangles(0);
        t.extend([[0, 4, 8], [0, 8, 4]]);
        t.push(reversed(&box_triangles(0))[6]);
        let before = t.clone();
        assert_eq!(drop_coincident(&mut t, Sheets::Drop), Coincident::default());
        assert_eq!(t, before);
    }
}
