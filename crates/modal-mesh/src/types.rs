//! Core mesh types shared by every crate downstream.

/// Corner pairs of the six edges of a tet, in the order the mid-edge nodes
/// 4..10 of a 10-node tet are stored (VTK `VTK_QUADRATIC_TETRA` order).
pub const TET10_EDGES: [[usize; 2]; 6] = [[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]];

/// Element connectivity: linear 4-node or quadratic 10-node tetrahedra.
#[derive(Clone, Debug, PartialEq)]
pub enum Cells {
    /// 4-node tets: corner indices into [`TetMesh::nodes`].
    Tet4(Vec<[usize; 4]>),
    /// 10-node tets: 4 corners then 6 mid-edge nodes in [`TET10_EDGES`] order.
    Tet10(Vec<[usize; 10]>),
}

impl Cells {
    /// Number of tets.
    pub fn len(&self) -> usize {
        match self {
            Cells::Tet4(t) => t.len(),
            Cells::Tet10(t) => t.len(),
        }
    }

    /// True when there are no tets.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Element order: 1 for 4-node, 2 for 10-node tets.
    pub fn order(&self) -> u8 {
        match self {
            Cells::Tet4(_) => 1,
            Cells::Tet10(_) => 2,
        }
    }

    /// The four corner nodes of tet `i`.
    pub fn corners(&self, i: usize) -> [usize; 4] {
        match self {
            Cells::Tet4(t) => t[i],
            Cells::Tet10(t) => [t[i][0], t[i][1], t[i][2], t[i][3]],
        }
    }

    /// All node indices of tet `i` (4 or 10 of them).
    pub fn nodes_of(&self, i: usize) -> &[usize] {
        match self {
            Cells::Tet4(t) => &t[i],
            Cells::Tet10(t) => &t[i],
        }
    }
}

/// A named set of tets (a Gmsh physical group of dimension 3).
#[derive(Clone, Debug, PartialEq)]
pub struct PhysicalGroup {
    /// Group name (Gmsh `$PhysicalNames`), or the tag as text when unnamed.
    pub name: String,
    /// Gmsh physical tag.
    pub tag: i32,
    /// Indices into the mesh's cells.
    pub cells: Vec<usize>,
}

/// A tetrahedral mesh in SI units (metres).
#[derive(Clone, Debug, PartialEq)]
pub struct TetMesh {
    /// Node coordinates (m). DOF `3 i + c` of the FEM belongs to node `i`.
    pub nodes: Vec<[f64; 3]>,
    /// Tets.
    pub cells: Cells,
    /// Physical groups of tets, kept by name.
    pub groups: Vec<PhysicalGroup>,
}

impl TetMesh {
    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Element order, 1 or 2.
    pub fn order(&self) -> u8 {
        self.cells.order()
    }
}

/// The boundary of a tet mesh: faces that belong to exactly one tet,
/// oriented with outward normals (counter-clockwise seen from outside).
///
/// Surface nodes are numbered locally `0..node_ids.len()`; `node_ids[k]` is
/// the mesh node behind local node `k`. For 10-node meshes the surface also
/// holds the mid-edge nodes of boundary faces so shapes can be interpolated
/// quadratically over a triangle.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Surface {
    /// Mesh node index of each surface node.
    pub node_ids: Vec<usize>,
    /// Surface node positions (m) (`nodes[node_ids[k]]`).
    pub positions: Vec<[f64; 3]>,
    /// Corner triangles, local surface-node indices, outward orientation.
    pub triangles: Vec<[usize; 3]>,
    /// For 10-node meshes: the mid-edge node (local index) of edges
    /// (0,1), (1,2), (2,0) of each triangle. `None` for 4-node meshes.
    pub triangle_edge_nodes: Option<Vec<[usize; 3]>>,
}
