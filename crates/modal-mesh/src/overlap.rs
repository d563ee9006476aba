//! Overlap check: after [`crate::check`] has turned every tet positive, the
//! two tets sharing an interior face must lie on opposite sides of it.
//!
//! Reorienting a negatively oriented tet is right when a whole mesh (or a
//! part of it) follows the other vertex-order convention, but wrong when a
//! single element is *inverted* inside an otherwise good mesh (a folded or
//! tangled mesh, e.g. from a bad smoothing step): flipping it would hide the
//! fold and the FEM would silently integrate the overlap twice. A fold shows
//! up locally: the corners opposite a shared face fall on the same side of
//! its plane. A face shared by three or more tets is an overlap too.

use std::collections::HashMap;

use crate::validate::volume6;
use crate::{MeshError, TetMesh};

/// The four faces of a tet as (corner indices of the face, opposite corner).
const FACES: [([usize; 3], usize); 4] = [([1, 2, 3], 0), ([0, 2, 3], 1), ([0, 1, 3], 2), ([0, 1, 2], 3)];

/// Errors naming two overlapping elements; `mesh` must be positively
/// oriented and free of degenerate tets.
pub(crate) fn check_overlaps(mesh: &TetMesh) -> Result<(), MeshError> {
    // face (sorted node ids) → (first element, its opposite corner, second element)
    let mut faces: HashMap<[usize; 3], (usize, usize, Option<usize>)> =
        HashMap::with_capacity(2 * mesh.cells.len());
    for element in 0..mesh.cells.len() {
        let corners = mesh.cells.corners(element);
        for (face, opposite) in FACES {
            let mut key = face.map(|k| corners[k]);
            key.sort_unstable();
            let apex = corners[opposite];
            match faces.get_mut(&key) {
                None => {
                    faces.insert(key, (element, apex, None));
                }
                Some((first, _, Some(second))) => {
                    return Err(MeshError::OverlappingTets { element, first: *first, second: *second });
                }
                Some((first, first_apex, second)) => {
                    if same_side(&mesh.nodes, key, apex, *first_apex) {
                        return Err(MeshError::FoldedTets { element, first: *first });
                    }
                    *second = Some(element);
                }
            }
        }
    }
    Ok(())
}

/// True when `a` and `b` lie on the same side of the plane through `face`.
fn same_side(nodes: &[[f64; 3]], face: [usize; 3], a: usize, b: usize) -> bool {
    let side = |apex: usize| volume6(nodes, [face[0], face[1], face[2], apex]);
    side(a) * side(b) > 0.0
}
