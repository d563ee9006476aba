//! Face-connected parts of a tet mesh, and hinges between them.
//!
//! Two tets belong to one part when a chain of tets, each sharing a whole
//! face (three corners) with the next, links them. Tets that share only an
//! edge or a vertex are *hinged*: in the continuum such a contact carries no
//! load (its area is zero), and in the FEM it is a zero-stiffness mechanism
//! (a rotation about the edge or vertex) that is not a rigid-body mode of
//! either side. Left in, such mechanisms give clusters of near-zero
//! eigenvalues that the eigensolver can neither deflate nor skip cheaply.
//!
//! [`face_parts`] finds the parts and the hinges; [`split_hinges`] gives each
//! part its own copy of every node it shares with another part, so that the
//! parts become separate bodies (six rigid-body modes each) and the node
//! graph agrees with the face graph everywhere downstream (FEM assembly,
//! rigid-mode deflation, mass properties).

use std::collections::HashMap;

use crate::{Cells, DisjointSets, TetMesh};

/// Parts of a mesh found through shared faces.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FaceParts {
    /// Number of face-connected parts.
    pub count: usize,
    /// Part of every tet, `0..count`, numbered in order of each part's first tet.
    pub part_of_tet: Vec<usize>,
    /// Tets in each part.
    pub tets: Vec<usize>,
    /// Contacts between parts through shared nodes only, one per pair of parts.
    pub hinges: Vec<Hinge>,
}

/// Two face-connected parts that share nodes but no face.
#[derive(Clone, Debug, PartialEq)]
pub struct Hinge {
    /// The two parts, smaller index first.
    pub parts: [usize; 2],
    /// Shared corner nodes (1: a vertex, 2 or more: an edge or several points).
    pub shared_corners: usize,
    /// Mean position of the shared corner nodes (m).
    pub at: [f64; 3],
}

impl Hinge {
    /// "vertex" or "edge" (several shared corners).
    pub fn kind(&self) -> &'static str {
        if self.shared_corners == 1 {
            "vertex"
        } else {
            "edge"
        }
    }
}

/// Face-connected parts and the hinges between them. Node indices must be
/// in range (as after [`crate::check`]); corner faces decide, so 4- and
/// 10-node meshes are treated alike.
pub fn face_parts(mesh: &TetMesh) -> FaceParts {
    let tets = mesh.cells.len();
    let mut faces: Vec<([usize; 3], usize)> = Vec::with_capacity(4 * tets);
    for e in 0..tets {
        let c = mesh.cells.corners(e);
        for skip in 0..4 {
            let mut f = [c[(skip + 1) % 4], c[(skip + 2) % 4], c[(skip + 3) % 4]];
            f.sort_unstable();
            faces.push((f, e));
        }
    }
    faces.sort_unstable();
    let mut sets = DisjointSets::new(tets);
    for pair in faces.windows(2) {
        if pair[0].0 == pair[1].0 {
            sets.join(pair[0].1, pair[1].1);
        }
    }
    let mut id_of_root = vec![usize::MAX; tets];
    let mut sizes = Vec::new();
    let part_of_tet: Vec<usize> = (0..tets)
        .map(|e| {
            let r = sets.root(e);
            if id_of_root[r] == usize::MAX {
                id_of_root[r] = sizes.len();
                sizes.push(0);
            }
            sizes[id_of_root[r]] += 1;
            id_of_root[r]
        })
        .collect();
    // Parts at every corner node; a node with two or more is a hinge node.
    let mut at_node: Vec<Vec<usize>> = vec![Vec::new(); mesh.nodes.len()];
    for (e, &p) in part_of_tet.iter().enumerate() {
        for n in mesh.cells.corners(e) {
            let list = &mut at_node[n];
            if !list.contains(&p) {
                list.push(p);
            }
        }
    }
    let mut contacts: HashMap<[usize; 2], (usize, [f64; 3])> = HashMap::new();
    for (n, list) in at_node.iter().enumerate().filter(|(_, l)| l.len() > 1) {
        for i in 0..list.len() {
            for j in i + 1..list.len() {
                let key = [list[i].min(list[j]), list[i].max(list[j])];
                let entry = contacts.entry(key).or_insert((0, [0.0; 3]));
                entry.0 += 1;
                (0..3).for_each(|c| entry.1[c] += mesh.nodes[n][c]);
            }
        }
    }
    let mut hinges: Vec<Hinge> = contacts
        .into_iter()
        .map(|(parts, (k, sum))| Hinge { parts, shared_corners: k, at: sum.map(|s| s / k as f64) })
        .collect();
    hinges.sort_by_key(|h| h.parts);
    FaceParts { count: sizes.len(), part_of_tet, tets: sizes, hinges }
}

/// Gives every face-connected part its own copy of each node it shares
/// with another part (corner and mid-edge nodes alike): the part with the
/// lowest index keeps the original, the others get new nodes appended at
/// the same position. Returns the number of nodes added.
pub fn split_hinges(mesh: &mut TetMesh, parts: &FaceParts) -> usize {
    let n = mesh.nodes.len();
    // The lowest part at each node keeps it.
    let mut owner = vec![usize::MAX; n];
    for e in 0..mesh.cells.len() {
        let p = parts.part_of_tet[e];
        for &k in mesh.cells.nodes_of(e) {
            owner[k] = owner[k].min(p);
        }
    }
    // (node, part) → index of that part's copy.
    let mut copies: HashMap<(usize, usize), usize> = HashMap::new();
    let nodes = &mut mesh.nodes;
    let mut remap = |node: &mut usize, part: usize| {
        if owner[*node] != part {
            let old = *node;
            *node = *copies.entry((old, part)).or_insert_with(|| {
                nodes.push(nodes[old]);
                nodes.len() - 1
            });
        }
    };
    match &mut mesh.cells {
        Cells::Tet4(t) => {
            for (e, tet) in t.iter_mut().enumerate() {
                tet.iter_mut().for_each(|k| remap(k, parts.part_of_tet[e]));
            }
        }
        Cells::Tet10(t) => {
            for (e, tet) in t.iter_mut().enumerate() {
                tet.iter_mut().for_each(|k| remap(k, parts.part_of_tet[e]));
            }
        }
    }
    mesh.nodes.len() - n
}

/// One line describing the hinges of `parts` for a warning or an error,
/// naming where each contact is (at most `max` of them, then a count).
pub fn describe_hinges(parts: &FaceParts, max: usize) -> String {
    let mut items: Vec<String> = parts
        .hinges
        .iter()
        .take(max)
        .map(|h| {
            let [a, b] = h.parts;
            format!(
                "part {} ({} tets) and part {} ({} tets) touch at {} ({:.4}, {:.4}, {:.4}) m",
                a + 1,
                parts.tets[a],
                b + 1,
                parts.tets[b],
                if h.kind() == "vertex" { "a vertex" } else { "an edge near" },
                h.at[0],
                h.at[1],
                h.at[2]
            )
        })
        .collect();
    if parts.hinges.len() > max {
        items.push(format!("and {} more contacts", parts.hinges.len() - max));
    }
    items.join("; ")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two_tets(shared: usize) -> TetMesh {
        // Tet A on nodes 0..4; tet B shares its first `shared` corners with A.
        let mut nodes = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let b: Vec<usize> = (0..4)
            .map(|k| {
                if k < shared {
                    k
                } else {
                    nodes.push([-1.0 - k as f64, -1.0 + 0.3 * k as f64, -1.0 - 0.1 * k as f64]);
                    nodes.len() - 1
                }
            })
            .collect();
        TetMesh {
            nodes,
            cells: Cells::Tet4(vec![[0, 1, 2, 3], [b[0], b[1], b[2], b[3]]]),
            groups: Vec::new(),
        }
    }

    #[test]
    fn parts_are_found_through_faces_only() {
        for (shared, parts, hinges) in [(0, 2, 0), (1, 2, 1), (2, 2, 1), (3, 1, 0)] {
            let fp = face_parts(&two_tets(shared));
            assert_eq!((fp.count, fp.hinges.len()), (parts, hinges), "{shared} shared corners");
            if hinges == 1 {
                assert_eq!(fp.hinges[0].shared_corners, shared);
                assert_eq!(fp.hinges[0].kind(), if shared == 1 { "vertex" } else { "edge" });
            }
        }
        let fp = face_parts(&two_tets(2));
        assert_eq!(fp.hinges[0].at, [0.5, 0.0, 0.0]);
        let text = describe_hinges(&fp, 3);
        assert!(
            text.contains(
                "part 1 (1 tets) and part 2 (1 tets) touch at an edge near (0.5000, 0.0000, 0.0000)"
            ),
            "{text}"
        );
    }

    #[test]
    fn splitting_makes_node_parts_equal_face_parts() {
        let mut mesh = two_tets(2);
        let fp = face_parts(&mesh);
        let added = split_hinges(&mut mesh, &fp);
        assert_eq!(added, 2);
        assert_eq!(mesh.nodes.len(), 4 + 2 + 2);
        let (count, _) = crate::connected_parts(&mesh);
        assert_eq!(count, 2);
        let Cells::Tet4(t) = &mesh.cells else { unreachable!() };
        assert_eq!(t[0], [0, 1, 2, 3]);
        assert!(t[1][..2].iter().all(|&k| k >= 6));
        // The copies sit where the originals were.
        assert_eq!(mesh.nodes[t[1][0]], mesh.nodes[0]);
        assert_eq!(mesh.nodes[t[1][1]], mesh.nodes[1]);
        // Nothing to split in a face-connected mesh.
        let mut one = two_tets(3);
        let fp = face_parts(&one);
        assert_eq!(split_hinges(&mut one, &fp), 0);
    }
}
