//! Thin walls meshed in layers: prisms across the wall, three tets each.
//!
//! A shell (a bell, a bowl, a cup, a closed plate, a pipe) is a closed
//! surface whose area lies in pairs of skins a wall thickness `t` apart,
//! joined at rims. Stuffing needs cells finer than `t` everywhere (the
//! corpus bell, `t` = 1.5 mm on 20 cm: 2 M tets, refused); a layer of
//! 10-node tets across the wall, with edges along it of two wall
//! thicknesses, keeps the bending modes of the generated bowls within about
//! 1 % (`modal_mesh::MAX_CURVED_CELL_PER_WALL`).
//!
//! Steps ([`layered`]):
//! 1. **Pairs** and 2. **Skins** (module `pairing`): from each triangle a
//!    ray across the wall to an opposite-facing triangle; the paired
//!    triangles form skins, two sides per wall, one of them a single skin
//!    (the master). A skin that faces itself (a handle's tube) means the
//!    body is no shell, and stuffing is used. A surface that fails any
//!    of the steps is tried again on a smoothed copy, if that stays close
//!    to it (module `second_try`, by the caller).
//! 3. **Master skin** brought to the wall rule's edges (module
//!    `wall_rule`): a finely tessellated skin is coarsened first (module
//!    `coarsen`: edges shorter than [`INPUT_COLLAPSE_SHARE`] of the rule's
//!    longest are collapsed), then refined by longest-edge bisection
//!    (Rivara) until no edge exceeds the in-plane size (conforming), then
//!    the short edges bisection leaves of the input's slivers are collapsed
//!    ([`REFINED_COLLAPSE_SHARE`]). On a slender shell ([`slender_length`]),
//!    where the wall is straight along an edge and curved across it (a
//!    chime's axis), the edge may be longer ([`EdgeLimits`]); where that
//!    folds a prism or misses volume (a bell's crown), every edge is refined.
//! 4. **Columns** from each master vertex to the opposite side, divided into
//!    `layers` equal steps: rays along the normal averaged over a wall
//!    thickness, or, where those fold, the closest points ([`Columns`]).
//! 5. **Prisms** between a master triangle and its columns, split into three
//!    tets by the smallest-vertex rule (Dompierre et al. 1999, "How to
//!    subdivide pyramids, prisms and hexahedra into tetrahedra"): each quad
//!    face's diagonal starts at its lowest-numbered column's outer node, so
//!    two prisms sharing a face cut it alike and the mesh is conforming.
//! 6. **Checks**: every tet keeps at least [`MIN_VOLUME_RATIO`] of the volume
//!    its place in an ideal straight prism would have (no folds), and the
//!    mesh volume is within [`VOLUME_TOLERANCE`] of the enclosed volume (a
//!    thick part no pair of skins covers fails it).
//!
//! The rims are replaced by the prisms' side faces (a bell's lip band of
//! height `t/2` below its walls' ends is not meshed: it moves the rim by at
//! most `t/2`).

use std::collections::HashMap;

use rayon::prelude::*;

use crate::bvh::Bvh;
use crate::coarsen::{coarsen, Targets};
use crate::geom::{add, area_vector, cross, dot, norm, orient6, scale, sub, unit, V3};
use crate::pairing::Skins;
use crate::stuff::edge;
use crate::wall_rule::{bend, slender_length, EdgeLimits};

/// Each tet keeps at least this fraction of its ideal-prism volume.
pub const MIN_VOLUME_RATIO: f64 = 0.05;

/// Largest relative difference between the mesh volume and the enclosed one.
pub const VOLUME_TOLERANCE: f64 = 0.05;

/// Refinement passes of the master skin: a guard, never reached (a pass
/// bisects every too-long triangle's longest edge, so two passes halve the
/// longest edge, and the triangle budget stops the loop long before). It was
/// 12, which silently left a plate exported as two triangles a face with
/// edges of 1/64 of its diagonal, whatever the wall rule asked.
const MAX_PASSES: usize = 64;

/// A finely tessellated master skin is coarsened to the wall rule's size
/// first (module `coarsen`), its new triangles and edges within this many
/// wall thicknesses of the input: a crease, a bead or a tight curve keeps
/// its input triangles, and the curved 10-node boundary puts the mid-edge
/// nodes back on the input surface.
pub const MAX_SAG_PER_WALL: f64 = 0.05;

/// An input skin's edges shorter than this share of the longest the wall
/// rule keeps anywhere (along a chime's axis, else the curved size) are
/// collapsed where the rule keeps the result (Botsch & Kobbelt's 4/5 of a
/// target whose longest edge is 4/3 of it).
pub const INPUT_COLLAPSE_SHARE: f64 = 0.6;

/// After the refinement, edges shorter than this share of the curved size
/// are collapsed: bisection leaves edges of ½–1 of its limit, and what is
/// shorter comes from the input (a CAD sliver's short side, cut across).
pub const REFINED_COLLAPSE_SHARE: f64 = 0.35;

/// A layered mesh of a thin-walled solid.
#[derive(Clone, Debug)]
pub(crate) struct Layered {
    /// Node positions [m].
    pub nodes: Vec<V3>,
    /// Positively oriented 4-node tets.
    pub tets: Vec<[usize; 4]>,
    /// Tet layers across the wall.
    pub layers: usize,
    /// Area-weighted median wall thickness of the paired triangles [m].
    pub wall_m: f64,
    /// Longest master-skin edge after refinement [m].
    pub longest_edge_m: f64,
    /// Shortest edge of the tets [m].
    pub shortest_edge_m: f64,
}

/// Why a surface was not meshed in layers (stuffing is used instead).
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum NotLayered {
    /// Too little of the area lies in paired skins.
    Unpaired { paired_fraction: f64 },
    /// The skins do not pair two by two.
    Skins,
    /// The column at this point found no opposite skin.
    Column { at: V3 },
    /// A tet at this point folded (its volume changed sign or nearly vanished).
    Fold { at: V3 },
    /// The layers miss part of the volume (a thick part).
    Volume { ratio: f64 },
    /// More tets than allowed at in-plane size `in_plane_m`.
    TooMany { estimated: usize, in_plane_m: f64 },
}

/// The size of the layered mesh: the in-plane edge and the tet limit.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LayerSizing {
    /// Longest edge along the wall [m], everywhere; `None`: [`wall_cells`]
    /// wall thicknesses, [`straight_wall_cells`] along straight directions
    /// of a wall curved across them.
    pub in_plane_m: Option<f64>,
    /// Edges along a curved wall in wall thicknesses when `in_plane_m` is `None`.
    pub wall_cells: f64,
    /// Edges along a wall straight along them and curved across (a pipe's
    /// axis) in wall thicknesses when `in_plane_m` is `None`.
    pub straight_wall_cells: f64,
    /// The factor every default size is scaled by (`TetOptions::size_factor`).
    pub size_factor: f64,
    /// Upper bound of the in-plane edge when it follows the wall [m].
    pub max_in_plane_m: f64,
    /// Refuse (as [`NotLayered::TooMany`]) beyond this many tets.
    pub max_tets: usize,
    /// The modes the bank keeps, which size flat walls (`TetOptions::resolved_modes`).
    pub resolved_modes: usize,
}

/// Meshes the closed, outward-oriented surface (`vertices`, `triangles`,
/// with `bvh` over the same triangles) in layers, if it is a shell (module
/// doc); on a `noisy` (smoothed) surface the skins' small holes are closed
/// (module `pairing`).
pub(crate) fn layered(
    vertices: &[V3],
    triangles: &[[usize; 3]],
    bvh: &Bvh,
    diagonal: f64,
    (enclosed_volume, bodies): (f64, usize),
    sizing: LayerSizing,
    noisy: bool,
) -> Result<Layered, NotLayered> {
    let skins = Skins::pair(vertices, triangles, bvh, diagonal, bodies, noisy)?;
    let (master, opposite) = (&skins.master, &skins.opposite);
    let wall_m = skins.median_wall();
    let master_points: Vec<V3> = master.iter().flat_map(|&t| triangles[t].map(|v| vertices[v])).collect();
    let master_area = skins.master_area();
    let limits = EdgeLimits::new(&sizing, wall_m, master_area, slender_length(&master_points));
    let layers = ((wall_m / limits.curved_m).round() as usize).max(1);
    // Refined triangles ≥ area / (√3/4 · h_longest²); three tets per prism and layer.
    let longest = limits.longest();
    let estimated = (3.0 * layers as f64 * master_area / (0.433 * longest * longest)) as usize;
    if estimated > sizing.max_tets {
        return Err(NotLayered::TooMany { estimated, in_plane_m: longest });
    }
    let opposite = Bvh::new(opposite.iter().map(|&t| triangles[t].map(|v| vertices[v])).collect());
    let layering =
        Layering { opposite: &opposite, reach: 3.0 * skins.max_wall(), wall_m, layers, enclosed_volume };
    let skin = Skin::from_triangles(vertices, triangles, master).coarsened(
        &limits,
        wall_m,
        INPUT_COLLAPSE_SHARE * limits.longest(),
    );
    let max_triangles = sizing.max_tets / (3 * layers) + 1;
    // Longer edges along straight walls first; where their prisms fold or
    // miss volume (a bell's crown), every edge at the curved size.
    let (skin, mesh) = layering.mesh(skin.clone(), &limits, max_triangles).or_else(|long| {
        if limits.is_isotropic() {
            return Err(long);
        }
        layering.mesh(skin, &limits.isotropic(), max_triangles)
    })?;
    let longest_edge_m = skin.longest_edge();
    let shortest_edge_m = shortest_edge(&mesh.nodes, &mesh.tets);
    Ok(Layered { nodes: mesh.nodes, tets: mesh.tets, layers, wall_m, longest_edge_m, shortest_edge_m })
}

/// Steps 3–6 of the module doc for one master skin.
struct Layering<'a> {
    /// The opposite side's triangles.
    opposite: &'a Bvh,
    /// How far a column may reach [m].
    reach: f64,
    wall_m: f64,
    layers: usize,
    enclosed_volume: f64,
}

impl Layering<'_> {
    /// The master skin refined to `limits` and its checked layered tets.
    fn mesh(
        &self,
        mut skin: Skin,
        limits: &EdgeLimits,
        max_triangles: usize,
    ) -> Result<(Skin, Prisms), NotLayered> {
        let layers = self.layers;
        skin.refine(limits, self.wall_m, max_triangles).map_err(|count| NotLayered::TooMany {
            estimated: 3 * layers * count,
            in_plane_m: limits.curved_m,
        })?;
        let skin = skin.coarsened(limits, self.wall_m, REFINED_COLLAPSE_SHARE * limits.curved_m);
        // Normals first (they keep faceted curved walls one-to-one), closest
        // points where those fold (creases); neither: not meshed in layers.
        let columns = |rule| {
            skin.column_ends(self.opposite, (self.reach, self.wall_m), rule)
                .and_then(|ends| skin.prisms(&ends, layers))
        };
        let mesh = columns(Columns::Normals).or_else(|_| columns(Columns::Closest))?;
        let volume: f64 = mesh
            .tets
            .iter()
            .map(|t| orient6(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], mesh.nodes[t[3]]) / 6.0)
            .sum();
        let ratio = volume / self.enclosed_volume;
        if !((1.0 - VOLUME_TOLERANCE)..=(1.0 + VOLUME_TOLERANCE)).contains(&ratio) {
            return Err(NotLayered::Volume { ratio });
        }
        Ok((skin, mesh))
    }
}

/// The master skin as its own triangle mesh: vertex positions, triangles
/// (outward, counter-clockwise).
#[derive(Clone)]
struct Skin {
    vertices: Vec<V3>,
    triangles: Vec<[usize; 3]>,
}

/// The layered tets and their nodes.
struct Prisms {
    nodes: Vec<V3>,
    tets: Vec<[usize; 4]>,
}

impl Skin {
    fn from_triangles(vertices: &[V3], triangles: &[[usize; 3]], master: &[usize]) -> Skin {
        let mut index: HashMap<usize, usize> = HashMap::new();
        let mut out = Skin { vertices: Vec::new(), triangles: Vec::with_capacity(master.len()) };
        for &t in master {
            let tri = triangles[t].map(|v| {
                *index.entry(v).or_insert_with(|| {
                    out.vertices.push(vertices[v]);
                    out.vertices.len() - 1
                })
            });
            out.triangles.push(tri);
        }
        out
    }

    /// The skin with its edges shorter than the wall rule asks collapsed
    /// (module `coarsen`) into edges the refinement keeps (`limits`, with
    /// the normals and curvatures of this fine skin), sagging at most
    /// [`MAX_SAG_PER_WALL`] of the wall `wall_m` off the input.
    fn coarsened(self, limits: &EdgeLimits, wall_m: f64, short_m: f64) -> Skin {
        let field = NormalField::new(&self, wall_m);
        let normals: Vec<V3> = self.vertices.par_iter().map(|&v| field.at(v)).collect();
        let kappa = self.largest_normal_curvature(&normals);
        let at = |v: usize| (self.vertices[v], normals[v]);
        let fits = |a: usize, b: usize| {
            let middle = || field.at(scale(add(self.vertices[a], self.vertices[b]), 0.5));
            !limits.too_long(at(a), at(b), kappa[a].max(kappa[b]), middle)
        };
        let targets = Targets { short_m, sag_m: MAX_SAG_PER_WALL * wall_m };
        let (vertices, triangles) = coarsen(&self.vertices, &self.triangles, &field.near, targets, &fits);
        Skin { vertices, triangles }
    }

    fn longest_edge(&self) -> f64 {
        self.triangles
            .iter()
            .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
            .map(|(a, b)| norm(sub(self.vertices[a], self.vertices[b])))
            .fold(0.0, f64::max)
    }

    /// Longest-edge bisection (Rivara 1984) until no edge is too long for
    /// `limits` (normals of the unrefined skin averaged over a wall
    /// thickness `wall`, at vertices and midpoints alike, so a coarse
    /// plate's rim does not tilt its faces' midpoints; averaged over the
    /// curved size instead, the corpus bell's crown, which meets its wall
    /// through a 0.08 mm wedge, took edges of 7 mm and its flap mode rose
    /// by 13 %): each pass marks the longest edge
    /// of every triangle with a too long edge, closes the marks (a triangle with a marked edge has its longest
    /// edge marked too, so the mesh stays conforming) and bisects each marked
    /// triangle by its longest edge, then its halves by their marked edges.
    /// Unlike splitting every long edge, a CAD sliver (a 0.2 m × 4 mm strip of
    /// a pipe) is cut across its length only: its pieces become well shaped
    /// and about 16× fewer. `Err(count)` beyond `max_triangles` triangles.
    fn refine(&mut self, limits: &EdgeLimits, wall: f64, max_triangles: usize) -> Result<(), usize> {
        let field = NormalField::new(self, wall);
        let mut normals: Vec<V3> = self.vertices.par_iter().map(|&v| field.at(v)).collect();
        for _ in 0..MAX_PASSES {
            let longest: Vec<(usize, usize)> =
                self.triangles.iter().map(|&t| self.longest_edge_of(t)).collect();
            let kappa = self.largest_normal_curvature(&normals);
            let at = |v: usize| (self.vertices[v], normals[v]);
            let too_long = |a: usize, b: usize| {
                let middle = || field.at(scale(add(self.vertices[a], self.vertices[b]), 0.5));
                limits.too_long(at(a), at(b), kappa[a].max(kappa[b]), middle)
            };
            let mut marked: std::collections::HashSet<(usize, usize)> = self
                .triangles
                .iter()
                .zip(&longest)
                .filter(|(t, _)| (0..3).any(|k| too_long(t[k], t[(k + 1) % 3])))
                .map(|(_, &l)| l)
                .collect();
            if marked.is_empty() {
                return Ok(());
            }
            loop {
                let before = marked.len();
                for (t, &l) in self.triangles.iter().zip(&longest) {
                    if !marked.contains(&l) && (0..3).any(|k| marked.contains(&edge(t[k], t[(k + 1) % 3]))) {
                        marked.insert(l);
                    }
                }
                if marked.len() == before {
                    break;
                }
            }
            // Midpoints numbered in edge order: the hash set's order differs
            // from run to run, and so did the output mesh's node numbering.
            let mut marked: Vec<(usize, usize)> = marked.into_iter().collect();
            marked.sort_unstable();
            let mut mid: HashMap<(usize, usize), usize> = HashMap::new();
            for &(a, b) in &marked {
                self.vertices.push(scale(add(self.vertices[a], self.vertices[b]), 0.5));
                mid.insert((a, b), self.vertices.len() - 1);
            }
            let added: Vec<V3> = self.vertices[normals.len()..].par_iter().map(|&v| field.at(v)).collect();
            normals.extend(added);
            let split = |a: usize, b: usize| mid.get(&edge(a, b)).copied();
            let mut next = Vec::with_capacity(2 * self.triangles.len());
            for (&t, &l) in self.triangles.iter().zip(&longest) {
                bisect(t, l, &split, &mut next);
            }
            self.triangles = next;
            if self.triangles.len() > max_triangles {
                return Err(self.triangles.len());
            }
        }
        Err(self.triangles.len())
    }

    /// Per vertex, the largest normal curvature `|Δn·Δx|/L²` of its edges
    /// (`normals` per vertex) [1/m].
    fn largest_normal_curvature(&self, normals: &[V3]) -> Vec<f64> {
        let mut kappa = vec![0.0f64; self.vertices.len()];
        for t in &self.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let d = sub(self.vertices[b], self.vertices[a]);
                let length2 = dot(d, d);
                if length2 > 0.0 {
                    let curvature = bend(d, sub(normals[b], normals[a])) / length2;
                    kappa[a] = kappa[a].max(curvature);
                    kappa[b] = kappa[b].max(curvature);
                }
            }
        }
        kappa
    }

    /// The longest edge of `t` as a sorted key (ties: the smaller key).
    fn longest_edge_of(&self, t: [usize; 3]) -> (usize, usize) {
        (0..3)
            .map(|k| edge(t[k], t[(k + 1) % 3]))
            .map(|e| (norm(sub(self.vertices[e.0], self.vertices[e.1])), e))
            .min_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)))
            .map_or((t[0], t[1]), |(_, e)| e)
    }

    /// Step 4: where each vertex's column ends on the opposite skins, within
    /// `reach`, by one of two [`Columns`] rules; [`NotLayered::Column`] where none is found.
    fn column_ends(
        &self,
        opposite: &Bvh,
        (reach, wall): (f64, f64),
        rule: Columns,
    ) -> Result<Vec<V3>, NotLayered> {
        let normals = match rule {
            Columns::Normals => self.vertex_normals(wall),
            Columns::Closest => Vec::new(),
        };
        let ends: Vec<Option<V3>> = (0..self.vertices.len())
            .into_par_iter()
            .map(|i| {
                let v = self.vertices[i];
                match rule {
                    Columns::Normals => ray_end(opposite, v, normals[i], reach),
                    Columns::Closest => opposite.closest(v).filter(|&e| norm(sub(e, v)) <= reach),
                }
            })
            .collect();
        // The first vertex without an end, in order (the same on every run).
        ends.into_iter().zip(&self.vertices).map(|(e, &v)| e.ok_or(NotLayered::Column { at: v })).collect()
    }

    /// Unit normal at each vertex: the area-weighted normal of the skin's
    /// triangles whose bounding boxes meet the cube of half-side `radius` (a
    /// wall thickness) about it. Over
    /// the vertex's own triangles alone, a refined sliver beside a facet edge
    /// of a faceted cylinder takes its facet's normal while the edge's vertex
    /// takes the mean of two facets, and across a 2 mm wall their columns
    /// cross 0.07 mm from the edge; averaged over a wall thickness, the normal
    /// turns by at most about the crease angle per wall thickness.
    fn vertex_normals(&self, radius: f64) -> Vec<V3> {
        let field = NormalField::new(self, radius);
        self.vertices.par_iter().map(|&v| field.at(v)).collect()
    }

    /// Step 5: the prisms of every triangle and layer, split into tets, checked for folds.
    fn prisms(&self, ends: &[V3], layers: usize) -> Result<Prisms, NotLayered> {
        let per = layers + 1;
        let mut nodes = Vec::with_capacity(self.vertices.len() * per);
        for (&v, &e) in self.vertices.iter().zip(ends) {
            for k in 0..per {
                nodes.push(add(v, scale(sub(e, v), k as f64 / layers as f64)));
            }
        }
        // Every triangle's result, then the first error in triangle order: the
        // place a warning names is the same on every run and thread count.
        let tets: Vec<Result<Vec<[usize; 4]>, NotLayered>> = self
            .triangles
            .par_iter()
            .map(|&t| {
                let mut out = Vec::with_capacity(3 * layers);
                let column = self.ideal_column(t, ends, layers);
                for k in 0..layers {
                    for tet in split_prism(t, k, per) {
                        out.push(self.oriented(tet, (column, self.vertices[t[0]]), &nodes, per)?);
                    }
                }
                Ok(out)
            })
            .collect();
        let tets: Vec<Vec<[usize; 4]>> = tets.into_iter().collect::<Result<_, _>>()?;
        Ok(Prisms { nodes, tets: tets.into_iter().flatten().collect() })
    }

    /// The step of one layer along the ideal column of triangle `t`: its own
    /// normal, inwards, as long as the mean of its three columns / `layers`.
    fn ideal_column(&self, t: [usize; 3], ends: &[V3], layers: usize) -> V3 {
        let length = t.iter().map(|&c| norm(sub(ends[c], self.vertices[c]))).sum::<f64>() / 3.0;
        let normal = unit(area_vector(self.vertices[t[0]], self.vertices[t[1]], self.vertices[t[2]]));
        scale(normal, -length / layers as f64)
    }

    /// `tet` (of a prism whose ideal layer step is `step`, first corner
    /// `corner`) positively oriented, if it keeps the sign and at least
    /// [`MIN_VOLUME_RATIO`] of its volume in the ideal prism (every column along `step`).
    fn oriented(
        &self,
        tet: [usize; 4],
        (step, corner): (V3, V3),
        nodes: &[V3],
        per: usize,
    ) -> Result<[usize; 4], NotLayered> {
        let ideal: [V3; 4] = tet.map(|n| add(self.vertices[n / per], scale(step, (n % per) as f64)));
        let expected = orient6(ideal[0], ideal[1], ideal[2], ideal[3]);
        let actual = orient6(nodes[tet[0]], nodes[tet[1]], nodes[tet[2]], nodes[tet[3]]);
        if expected == 0.0 || actual * expected.signum() < MIN_VOLUME_RATIO * expected.abs() {
            return Err(NotLayered::Fold { at: corner });
        }
        Ok(if expected > 0.0 { tet } else { [tet[0], tet[1], tet[3], tet[2]] })
    }
}

/// Appends the pieces of triangle `t` (longest edge `longest`) after
/// longest-edge bisection by the marked edges `split` (orientation kept): no
/// marked edge, `t` itself; else halves at the longest edge's midpoint `m`,
/// each half cut again from `m` to the midpoint of its other marked edge.
fn bisect(
    t: [usize; 3],
    longest: (usize, usize),
    split: &impl Fn(usize, usize) -> Option<usize>,
    out: &mut Vec<[usize; 3]>,
) {
    let Some(m) = split(longest.0, longest.1) else {
        out.push(t);
        return;
    };
    // Rotate so the longest edge is (a, b).
    let k = (0..3).find(|&k| edge(t[k], t[(k + 1) % 3]) == longest).unwrap_or(0);
    let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
    match split(c, a) {
        Some(ca) => out.extend([[a, m, ca], [m, c, ca]]),
        None => out.push([a, m, c]),
    }
    match split(b, c) {
        Some(bc) => out.extend([[m, b, bc], [m, bc, c]]),
        None => out.push([m, b, c]),
    }
}

/// The skin's normal averaged over a cube about any point ([`Skin::vertex_normals`]).
struct NormalField {
    near: Bvh,
    areas: Vec<V3>,
    radius: f64,
}

impl NormalField {
    fn new(skin: &Skin, radius: f64) -> NormalField {
        let corners = |t: &[usize; 3]| t.map(|v| skin.vertices[v]);
        NormalField {
            areas: skin.triangles.iter().map(&corners).map(|[a, b, c]| area_vector(a, b, c)).collect(),
            near: Bvh::new(skin.triangles.iter().map(corners).collect()),
            radius,
        }
    }

    /// The unit area-weighted normal of the triangles whose bounding boxes
    /// meet the cube of half-side `radius` about `p`.
    fn at(&self, p: V3) -> V3 {
        let (lo, hi) = (sub(p, [self.radius; 3]), add(p, [self.radius; 3]));
        unit(self.near.in_box(lo, hi).into_iter().fold([0.0; 3], |acc, t| add(acc, self.areas[t])))
    }
}

/// How a master vertex finds the end of its column (step 4 of the module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Columns {
    /// A ray along −n (the area-weighted normal over a wall thickness) to the opposite
    /// skin: one-to-one on faceted curved walls, but at a crease (a bell's
    /// lip) the normal tilts by half its angle and neighbouring columns can
    /// cross inside a narrow strip.
    Normals,
    /// The closest point of the opposite skin: no crossing at creases, but
    /// many-to-one near the edges of a faceted opposite skin (a pipe's
    /// inner facets are narrower than the outer ones): degenerate prisms.
    Closest,
}

/// Where the ray from `v` along `−n` first meets `skin` within `reach`. A
/// ray through the seam between two triangles can miss both by rounding, so
/// starts 10⁻⁴ of the reach to either side are tried too.
fn ray_end(skin: &Bvh, v: V3, n: V3, reach: f64) -> Option<V3> {
    let helper = if n[0].abs() < 0.9 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
    let t1 = unit(cross(n, helper));
    let t2 = cross(n, t1);
    let side = 1e-4 * reach;
    [[0.0; 3], scale(t1, side), scale(t1, -side), scale(t2, side), scale(t2, -side)].iter().find_map(|&o| {
        let from = add(v, o);
        let to = sub(from, scale(n, reach));
        skin.first_crossing(from, to).map(|(s, _)| add(from, scale(sub(to, from), s)))
    })
}

/// The three tets of the prism on triangle `t` between layers `k` (outer)
/// and `k + 1`, by the smallest-vertex rule (module doc, step 5); node of
/// column `c`, layer `l` is `c · per + l`.
fn split_prism(t: [usize; 3], k: usize, per: usize) -> [[usize; 4]; 3] {
    let low = (0..3).min_by_key(|&i| t[i]).unwrap_or(0);
    let (a, b, c) = (t[low], t[(low + 1) % 3], t[(low + 2) % 3]);
    let top = |v: usize| v * per + k;
    let bottom = |v: usize| v * per + k + 1;
    let first = [top(a), bottom(a), bottom(b), bottom(c)];
    if b < c {
        [first, [top(a), top(b), top(c), bottom(c)], [top(a), top(b), bottom(c), bottom(b)]]
    } else {
        [first, [top(a), top(b), top(c), bottom(b)], [top(a), top(c), bottom(c), bottom(b)]]
    }
}

fn shortest_edge(nodes: &[V3], tets: &[[usize; 4]]) -> f64 {
    tets.par_iter()
        .map(|t| {
            let mut best = f64::INFINITY;
            for i in 0..4 {
                for j in i + 1..4 {
                    best = best.min(norm(sub(nodes[t[i]], nodes[t[j]])));
                }
            }
            best
        })
        .reduce(|| f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neighbouring_prisms_cut_their_shared_face_alike() {
        // Two prisms on triangles (0, 1, 2) and (2, 1, 3) share face 1-2.
        let per = 2;
        let diagonal = |tets: [[usize; 4]; 3]| {
            let on_face = |n: usize| n / per == 1 || n / per == 2;
            let mut edges = Vec::new();
            for t in tets {
                for i in 0..4 {
                    for j in i + 1..4 {
                        let (a, b) = (t[i], t[j]);
                        if on_face(a) && on_face(b) && a / per != b / per && a % per != b % per {
                            edges.push((a.min(b), a.max(b)));
                        }
                    }
                }
            }
            edges.sort_unstable();
            edges.dedup();
            edges
        };
        let left = diagonal(split_prism([0, 1, 2], 0, per));
        let right = diagonal(split_prism([2, 1, 3], 0, per));
        assert_eq!(left.len(), 1, "one diagonal on the shared face: {left:?}");
        assert_eq!(left, right);
    }
}
