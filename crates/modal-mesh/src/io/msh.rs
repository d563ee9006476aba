//! Gmsh `.msh` reader: format 4.1 (ASCII and binary) and 2.2 (ASCII and
//! binary). Only 4-node (type 4) and 10-node (type 11) tets are kept;
//! every other element type is skipped. Node tags may be sparse.
//!
//! Gmsh's 10-node tet stores its edge nodes on edges
//! (0,1), (1,2), (2,0), (3,0), (3,2), (3,1); we use the VTK order of
//! [`crate::TET10_EDGES`], so Gmsh nodes 8 and 9 are swapped on reading
//! (and back on writing).
//!
//! A file with both 4-node and 10-node tets is rejected
//! ([`MeshError::MixedOrders`]): promoting the linear ones silently would
//! hide a meshing mistake. A file with no tets gives [`MeshError::NoTets`].
//!
//! Physical groups of dimension 3 become [`PhysicalGroup`]s, named from
//! `$PhysicalNames` (or by their tag when unnamed). Format reference:
//! Gmsh reference manual, section "MSH file format" (versions 4.1 and 2.2).

use std::collections::{BTreeMap, HashMap};

use super::cursor::Cursor;
use crate::{Cells, MeshError, PhysicalGroup, TetMesh};

/// Gmsh 10-node position `k` holds our node `GMSH_TET10[k]` (a self-inverse
/// permutation: positions 8 and 9 swap).
pub(crate) const GMSH_TET10: [usize; 10] = [0, 1, 2, 3, 4, 5, 6, 7, 9, 8];

/// Number of nodes of Gmsh element type `t` (types listed in the manual).
fn nodes_per_element(t: i32) -> Option<usize> {
    Some(match t {
        15 => 1,
        1 => 2,
        2 | 8 => 3,
        3 | 4 | 26 => 4,
        7 | 27 => 5,
        6 | 9 | 28 => 6,
        16 => 8,
        5 => 8,
        10 | 20 => 9,
        11 | 21 => 10,
        22 => 12,
        19 => 13,
        14 => 14,
        18 | 23 | 24 => 15,
        13 => 18,
        17 | 29 => 20,
        25 => 21,
        12 => 27,
        30 => 35,
        31 => 56,
        92 => 64,
        93 => 125,
        _ => return None,
    })
}

/// Tets as read, before group assembly.
#[derive(Default)]
struct Tets {
    tet4: Vec<[usize; 4]>,
    tet10: Vec<[usize; 10]>,
    /// Per tet (in reading order): elementary entity tag (4.1) or physical tag (2.2).
    owner: Vec<i32>,
}

/// Reader state shared by both format versions.
struct Msh<'a> {
    cur: Cursor<'a>,
    version: Version,
    binary: bool,
    /// Bytes of a binary `size_t` (4.1 only).
    size_t: usize,
    scale: f64,
    nodes: Vec<[f64; 3]>,
    tag_index: HashMap<u64, usize>,
    tets: Tets,
    names: BTreeMap<i32, String>,
    /// Volume entity tag → its physical tags (4.1 only).
    volume_physicals: HashMap<i32, Vec<i32>>,
}

#[derive(Clone, Copy, PartialEq)]
enum Version {
    V2,
    V41,
}

/// Reads a Gmsh mesh from the bytes of a `.msh` file, multiplying
/// coordinates by `scale`.
pub fn read_msh(data: &[u8], scale: f64) -> Result<TetMesh, MeshError> {
    let mut cur = Cursor::new(data);
    match cur.token() {
        Some(b"$MeshFormat") => {}
        _ => {
            return Err(MeshError::Syntax {
                at: crate::Location::Line(1),
                message: "not a Gmsh file: expected `$MeshFormat`".into(),
            })
        }
    }
    let mut msh = Msh {
        cur,
        version: Version::V41,
        binary: false,
        size_t: 8,
        scale,
        nodes: Vec::new(),
        tag_index: HashMap::new(),
        tets: Tets::default(),
        names: BTreeMap::new(),
        volume_physicals: HashMap::new(),
    };
    msh.read_format()?;
    msh.read_sections()?;
    msh.finish()
}

impl<'a> Msh<'a> {
    fn read_format(&mut self) -> Result<(), MeshError> {
        let version = self.cur.expect_token("the format version")?;
        self.version = match version {
            "4.1" => Version::V41,
            v if v.starts_with("2.") => Version::V2,
            v => return Err(self.cur.error(format!("unsupported MSH version {v}; save it as 4.1 or 2.2"))),
        };
        let file_type: u8 = self.cur.parse("the file type (0 ASCII, 1 binary)")?;
        let data_size: usize = self.cur.parse("the data size")?;
        self.binary = match file_type {
            0 => false,
            1 => true,
            t => return Err(self.cur.error(format!("unknown file type {t}, expected 0 or 1"))),
        };
        if self.binary {
            if data_size != 4 && data_size != 8 {
                return Err(self.cur.error(format!("unsupported data size {data_size}, expected 4 or 8")));
            }
            self.size_t = data_size;
            self.cur.skip_line_end()?;
            let one = self.cur.bytes(4, "endianness marker")?;
            self.cur.big_endian = match one {
                [1, 0, 0, 0] => false,
                [0, 0, 0, 1] => true,
                _ => return Err(self.cur.error("bad binary endianness marker (expected the integer 1)")),
            };
        }
        self.expect_end("MeshFormat")
    }

    fn expect_end(&mut self, section: &str) -> Result<(), MeshError> {
        let want = format!("$End{section}");
        let was_binary = std::mem::replace(&mut self.cur.binary, false);
        let token = self.cur.token();
        self.cur.binary = was_binary;
        match token {
            Some(t) if t == want.as_bytes() => Ok(()),
            Some(_) => Err(self.cur.error(format!("expected `{want}` (wrong count or truncated section?)"))),
            None => Err(self.cur.error(format!("file ends before `{want}`"))),
        }
    }

    fn read_sections(&mut self) -> Result<(), MeshError> {
        while let Some(token) = self.cur.token() {
            let Some(name) = token.strip_prefix(b"$") else {
                return Err(self.cur.error("expected a section header starting with `$`"));
            };
            let name = String::from_utf8_lossy(name).into_owned();
            match name.as_str() {
                "PhysicalNames" => self.read_physical_names()?,
                "Entities" if self.version == Version::V41 => self.read_entities()?,
                "Nodes" => self.read_nodes()?,
                "Elements" => self.read_elements()?,
                _ => {
                    if !self.cur.skip_past(format!("$End{name}").as_bytes()) {
                        return Err(self.cur.error(format!("file ends before `$End{name}`")));
                    }
                    continue;
                }
            }
            self.expect_end(&name)?;
        }
        Ok(())
    }

    // ----- numbers in the current encoding -----

    /// A count or tag: `size_t` in 4.1 binary, `int` in 2.2 binary.
    fn size(&mut self, what: &str) -> Result<u64, MeshError> {
        match (self.binary, self.version) {
            (false, _) => self.cur.parse(what),
            (true, Version::V41) => self.cur.bin_unsigned(self.size_t, what),
            (true, Version::V2) => {
                let v = self.cur.bin_i32(what)?;
                u64::try_from(v).map_err(|_| self.cur.error(format!("negative {what} {v}")))
            }
        }
    }

    fn int(&mut self, what: &str) -> Result<i32, MeshError> {
        if self.binary {
            self.cur.bin_i32(what)
        } else {
            self.cur.parse(what)
        }
    }

    fn float(&mut self, what: &str) -> Result<f64, MeshError> {
        if self.binary {
            self.cur.bin_f64(what)
        } else {
            self.cur.parse(what)
        }
    }

    /// Smallest number of bytes one item of `fields` numbers can take.
    fn min_bytes(&self, fields: usize) -> usize {
        if self.binary {
            4 * fields
        } else {
            2 * fields
        }
    }

    /// Text counts that precede binary data in 2.2 files.
    fn header_count(&mut self, what: &str) -> Result<u64, MeshError> {
        let n = self.cur.parse(what)?;
        if self.binary {
            self.cur.skip_line_end()?;
        }
        Ok(n)
    }

    fn begin_binary(&mut self) -> Result<(), MeshError> {
        if self.binary {
            self.cur.skip_line_end()?;
            self.cur.binary = true;
        }
        Ok(())
    }

    // ----- sections -----

    fn read_physical_names(&mut self) -> Result<(), MeshError> {
        let count: u64 = self.cur.parse("the number of physical names")?;
        let count = self.cur.check_count(count, 6, "physical name")?;
        for _ in 0..count {
            let dim: i32 = self.cur.parse("a physical name dimension")?;
            let tag: i32 = self.cur.parse("a physical tag")?;
            let name = self.cur.quoted("physical name")?;
            if dim == 3 {
                self.names.insert(tag, name);
            }
        }
        Ok(())
    }

    fn read_entities(&mut self) -> Result<(), MeshError> {
        self.begin_binary()?;
        let mut counts = [0usize; 4];
        for (dim, c) in counts.iter_mut().enumerate() {
            let n = self.size(&format!("the number of dimension-{dim} entities"))?;
            *c = self.cur.check_count(n, self.min_bytes(5), "entity")?;
        }
        for (dim, &count) in counts.iter().enumerate() {
            for _ in 0..count {
                let tag = self.int("an entity tag")?;
                let n_coords = if dim == 0 { 3 } else { 6 };
                for _ in 0..n_coords {
                    self.float("an entity bounding-box coordinate")?;
                }
                let n_phys = self.size("the number of physical tags")?;
                let n_phys = self.cur.check_count(n_phys, self.min_bytes(1), "physical tag")?;
                let mut physicals = Vec::with_capacity(n_phys);
                for _ in 0..n_phys {
                    physicals.push(self.int("a physical tag")?);
                }
                if dim > 0 {
                    let n_bound = self.size("the number of bounding entities")?;
                    let n_bound = self.cur.check_count(n_bound, self.min_bytes(1), "bounding entity")?;
                    for _ in 0..n_bound {
                        self.int("a bounding entity tag")?;
                    }
                }
                if dim == 3 {
                    self.volume_physicals.insert(tag, physicals);
                }
            }
        }
        self.cur.binary = false;
        Ok(())
    }

    fn push_node(&mut self, tag: u64, xyz: [f64; 3]) -> Result<(), MeshError> {
        if !xyz.iter().all(|c| c.is_finite()) {
            return Err(self.cur.error(format!("node tag {tag} has a non-finite coordinate {xyz:?}")));
        }
        let index = self.nodes.len();
        if self.tag_index.insert(tag, index).is_some() {
            return Err(self.cur.error(format!("node tag {tag} appears twice")));
        }
        self.nodes.push(xyz.map(|c| c * self.scale));
        Ok(())
    }

    fn read_xyz(&mut self) -> Result<[f64; 3], MeshError> {
        Ok([self.float("an x coordinate")?, self.float("a y coordinate")?, self.float("a z coordinate")?])
    }

    fn read_nodes(&mut self) -> Result<(), MeshError> {
        if !self.nodes.is_empty() {
            return Err(self.cur.error("a second $Nodes section is not supported"));
        }
        match self.version {
            Version::V41 => self.read_nodes_41(),
            Version::V2 => self.read_nodes_2(),
        }?;
        self.cur.binary = false;
        Ok(())
    }

    fn read_nodes_2(&mut self) -> Result<(), MeshError> {
        let count = self.header_count("the number of nodes")?;
        self.cur.binary = self.binary;
        let count = self.cur.check_count(count, self.min_bytes(4), "node")?;
        self.nodes.reserve(count);
        self.tag_index.reserve(count);
        for _ in 0..count {
            let tag = self.size("a node tag")?;
            let xyz = self.read_xyz()?;
            self.push_node(tag, xyz)?;
        }
        Ok(())
    }

    fn read_nodes_41(&mut self) -> Result<(), MeshError> {
        self.begin_binary()?;
        let blocks = self.size("the number of node blocks")?;
        let total = self.size("the number of nodes")?;
        self.size("the minimum node tag")?;
        self.size("the maximum node tag")?;
        let blocks = self.cur.check_count(blocks, self.min_bytes(4), "node block")?;
        let total = self.cur.check_count(total, self.min_bytes(4), "node")?;
        self.nodes.reserve(total);
        self.tag_index.reserve(total);
        for _ in 0..blocks {
            let dim = self.int("a node block entity dimension")?;
            self.int("a node block entity tag")?;
            let parametric = self.int("the parametric flag")?;
            let n = self.size("the number of nodes in a block")?;
            let n = self.cur.check_count(n, self.min_bytes(4), "node")?;
            let mut tags = Vec::with_capacity(n);
            for _ in 0..n {
                tags.push(self.size("a node tag")?);
            }
            let extra = if parametric != 0 { dim.clamp(0, 3) as usize } else { 0 };
            for tag in tags {
                let xyz = self.read_xyz()?;
                for _ in 0..extra {
                    self.float("a parametric coordinate")?;
                }
                self.push_node(tag, xyz)?;
            }
        }
        Ok(())
    }

    fn read_elements(&mut self) -> Result<(), MeshError> {
        if self.nodes.is_empty() {
            return Err(self.cur.error("$Elements before (or without) $Nodes"));
        }
        match self.version {
            Version::V41 => self.read_elements_41(),
            Version::V2 => self.read_elements_2(),
        }?;
        self.cur.binary = false;
        Ok(())
    }

    fn read_elements_41(&mut self) -> Result<(), MeshError> {
        self.begin_binary()?;
        let blocks = self.size("the number of element blocks")?;
        self.size("the number of elements")?;
        self.size("the minimum element tag")?;
        self.size("the maximum element tag")?;
        let blocks = self.cur.check_count(blocks, self.min_bytes(4), "element block")?;
        for _ in 0..blocks {
            self.int("an element block entity dimension")?;
            let entity = self.int("an element block entity tag")?;
            let kind = self.int("an element type")?;
            let n = self.size("the number of elements in a block")?;
            let per = nodes_per_element(kind)
                .ok_or_else(|| self.cur.error(format!("unknown element type {kind}")))?;
            let n = self.cur.check_count(n, self.min_bytes(1 + per), "element")?;
            for _ in 0..n {
                let tag = self.size("an element tag")?;
                self.read_element(kind, per, tag, entity)?;
            }
        }
        Ok(())
    }

    fn read_elements_2(&mut self) -> Result<(), MeshError> {
        let total = self.header_count("the number of elements")?;
        self.cur.binary = self.binary;
        let total = self.cur.check_count(total, self.min_bytes(4), "element")?;
        let mut read = 0;
        while read < total {
            if self.binary {
                // Binary 2.2: blocks of (type, count, tag count) headers.
                let kind = self.int("an element type")?;
                let n = self.size("the number of elements in a block")?;
                let n_tags = self.size("the number of element tags")? as usize;
                let per = nodes_per_element(kind)
                    .ok_or_else(|| self.cur.error(format!("unknown element type {kind}")))?;
                let n = self.cur.check_count(n, self.min_bytes(1 + n_tags.min(1 << 20) + per), "element")?;
                if read + n > total {
                    return Err(self.cur.error("element blocks hold more elements than the header says"));
                }
                for _ in 0..n {
                    let tag = self.size("an element tag")?;
                    let physical = self.element_tags(n_tags)?;
                    self.read_element(kind, per, tag, physical)?;
                }
                read += n;
            } else {
                let tag = self.size("an element tag")?;
                let kind = self.int("an element type")?;
                let per = nodes_per_element(kind)
                    .ok_or_else(|| self.cur.error(format!("unknown element type {kind}")))?;
                let n_tags = self.size("the number of element tags")?;
                let n_tags = self.cur.check_count(n_tags, 2, "element tag")?;
                let physical = self.element_tags(n_tags)?;
                self.read_element(kind, per, tag, physical)?;
                read += 1;
            }
        }
        Ok(())
    }

    /// Reads 2.2 element tags and returns the first (physical) one, or 0.
    fn element_tags(&mut self, n_tags: usize) -> Result<i32, MeshError> {
        let mut physical = 0;
        for i in 0..n_tags {
            let t = self.int("an element tag")?;
            if i == 0 {
                physical = t;
            }
        }
        Ok(physical)
    }

    fn node_index(&mut self, element_tag: u64) -> Result<usize, MeshError> {
        let tag = self.size("an element node tag")?;
        self.tag_index.get(&tag).copied().ok_or_else(|| {
            self.cur
                .error(format!("element tag {element_tag} references node tag {tag}, which is not in $Nodes"))
        })
    }

    fn read_element(&mut self, kind: i32, per: usize, tag: u64, owner: i32) -> Result<(), MeshError> {
        match kind {
            4 => {
                let mut t = [0; 4];
                for slot in &mut t {
                    *slot = self.node_index(tag)?;
                }
                self.tets.tet4.push(t);
            }
            11 => {
                let mut t = [0; 10];
                for k in 0..10 {
                    t[GMSH_TET10[k]] = self.node_index(tag)?;
                }
                self.tets.tet10.push(t);
            }
            _ => {
                for _ in 0..per {
                    self.size("an element node tag")?;
                }
                return Ok(());
            }
        }
        self.tets.owner.push(owner);
        Ok(())
    }

    fn finish(self) -> Result<TetMesh, MeshError> {
        let Tets { tet4, tet10, owner } = self.tets;
        let cells = match (tet4.is_empty(), tet10.is_empty()) {
            (true, true) => return Err(MeshError::NoTets),
            (false, false) => return Err(MeshError::MixedOrders),
            (false, true) => Cells::Tet4(tet4),
            (true, false) => Cells::Tet10(tet10),
        };
        let mut members: BTreeMap<i32, Vec<usize>> = BTreeMap::new();
        for (cell, &o) in owner.iter().enumerate() {
            match self.version {
                Version::V2 if o != 0 => members.entry(o).or_default().push(cell),
                Version::V41 => {
                    for &p in self.volume_physicals.get(&o).into_iter().flatten() {
                        members.entry(p).or_default().push(cell);
                    }
                }
                _ => {}
            }
        }
        let groups = members
            .into_iter()
            .map(|(tag, cells)| PhysicalGroup {
                name: self.names.get(&tag).cloned().unwrap_or_else(|| tag.to_string()),
                tag,
                cells,
            })
            .collect();
        Ok(TetMesh { nodes: self.nodes, cells, groups })
    }
}
