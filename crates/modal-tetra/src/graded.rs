//! Graded background mesh: the BCC lattice refined by conforming
//! longest-edge bisection (Rivara's longest-edge propagation, 3D).
//!
//! A tet is refined by bisecting its longest edge e at its midpoint, in
//! every tet around e; a tet around e whose own longest edge is not e is
//! refined first (recursively), so the mesh stays conforming. Edges are
//! totally ordered by (squared length, lexicographic end coordinates), so
//! ties between equally long edges are broken the same way in every tet
//! and the recursion ends (the key grows along it).
//!
//! On the BCC lattice this is the Sommerville bisection: a BCC tet (two
//! black edges of length h, four red of √3 h/2) is cut across a black edge
//! into two half tets, whose longest edge is the other black edge; their
//! halves (quarter tets) have a unique longest red edge; cutting it gives
//! BCC tets of the lattice with cell h/2. So every background tet is a BCC,
//! half or quarter tet of some level — the three shapes of Labelle &
//! Shewchuk's graded (octree) isosurface stuffing — and their dihedral
//! angles stay in [45°, 135°] (checked in the tests below).
//!
//! Coordinates are exact integers: the lattice's doubled coordinates times
//! 2^[`MAX_LEVELS`] + 1, so midpoints down to the finest level are exact.

use std::collections::HashMap;

use crate::geom::V3;
use crate::lattice::Lattice;

/// Finest refinement: cells down to h / 2^MAX_LEVELS (3 bisections per level).
pub const MAX_LEVELS: u32 = 3;
const SCALE: i64 = 1 << (MAX_LEVELS + 1);

type E = (u32, u32);

fn key(a: u32, b: u32) -> E {
    (a.min(b), a.max(b))
}

/// Conforming longest-edge refinement of a set of lattice tets.
pub(crate) struct Refiner<'a> {
    lattice: &'a Lattice,
    /// Integer coordinates (units of h / (2 SCALE)).
    coords: Vec<[i64; 3]>,
    tets: Vec<[u32; 4]>,
    alive: Vec<bool>,
    edge_tets: HashMap<E, Vec<u32>>,
}

impl<'a> Refiner<'a> {
    /// Starts from `tets` (indices of `lattice` points).
    pub fn new(lattice: &'a Lattice, tets: Vec<[usize; 4]>) -> Self {
        let coords = (0..lattice.point_count()).map(|i| lattice.coord(i).map(|x| x * SCALE)).collect();
        let tets: Vec<[u32; 4]> = tets.into_iter().map(|t| t.map(|v| v as u32)).collect();
        let mut edge_tets: HashMap<E, Vec<u32>> = HashMap::with_capacity(tets.len() * 2);
        for (i, t) in tets.iter().enumerate() {
            for (a, b) in EDGES {
                edge_tets.entry(key(t[a], t[b])).or_default().push(i as u32);
            }
        }
        let alive = vec![true; tets.len()];
        Refiner { lattice, coords, tets, alive, edge_tets }
    }

    /// Number of live tets.
    pub fn live(&self) -> usize {
        self.alive.iter().filter(|&&a| a).count()
    }

    /// Position (m) of vertex `v`.
    pub fn position(&self, v: u32) -> V3 {
        let c = self.coords[v as usize];
        std::array::from_fn(|a| self.lattice.origin[a] + 0.5 * self.lattice.h * c[a] as f64 / SCALE as f64)
    }

    fn length2(&self, e: E) -> i64 {
        let (p, q) = (self.coords[e.0 as usize], self.coords[e.1 as usize]);
        (0..3).map(|a| (p[a] - q[a]).pow(2)).sum()
    }

    fn order(&self, e: E) -> (i64, [i64; 3], [i64; 3]) {
        let (p, q) = (self.coords[e.0 as usize], self.coords[e.1 as usize]);
        (self.length2(e), p.min(q), p.max(q))
    }

    /// The longest edge of tet `t` in the total edge order.
    fn longest(&self, t: u32) -> E {
        let v = self.tets[t as usize];
        EDGES.iter().map(|&(a, b)| key(v[a], v[b])).max_by_key(|&e| self.order(e)).unwrap_or((0, 0))
    }

    /// Longest edge length (m) of tet `t`.
    pub fn size(&self, t: u32) -> f64 {
        let e = self.longest(t);
        (self.length2(e) as f64).sqrt() * 0.5 * self.lattice.h / SCALE as f64
    }

    /// Corner positions (m) of tet `t`.
    pub fn corners(&self, t: u32) -> [V3; 4] {
        self.tets[t as usize].map(|v| self.position(v))
    }

    /// Centroid (m) of tet `t`.
    pub fn centroid(&self, t: u32) -> V3 {
        let p = self.tets[t as usize].map(|v| self.position(v));
        std::array::from_fn(|a| 0.25 * (p[0][a] + p[1][a] + p[2][a] + p[3][a]))
    }

    /// Whether bisecting tet `t` keeps coordinates exact (above the finest level).
    pub fn can_split(&self, t: u32) -> bool {
        self.exact_mid(self.longest(t))
    }

    /// Refines until `needs(refiner, t)` is false for every live tet, or the
    /// finest level, or more than `limit` live tets (then `Err(live)`).
    pub fn refine(&mut self, needs: impl Fn(&Self, u32) -> bool, limit: usize) -> Result<(), usize> {
        let mut queue: Vec<u32> = (0..self.tets.len() as u32).filter(|&t| needs(self, t)).collect();
        let mut live = self.live();
        while let Some(t) = queue.pop() {
            if !self.alive[t as usize] || !self.can_split(t) || !needs(self, t) {
                continue;
            }
            let before = self.tets.len();
            let added = self.refine_edge(self.longest(t));
            if added == 0 {
                continue;
            }
            live += added;
            if live > limit {
                return Err(live);
            }
            queue.extend((before as u32..self.tets.len() as u32).filter(|&c| self.alive[c as usize]));
            if self.alive[t as usize] {
                queue.push(t);
            }
        }
        Ok(())
    }

    /// Bisects edge `e0` with conformity closure; returns the live-tet increase
    /// (0 when a neighbour at the finest level blocks it).
    fn refine_edge(&mut self, e0: E) -> usize {
        let mut added = 0;
        let mut stack = vec![e0];
        while let Some(&e) = stack.last() {
            let Some(around) = self.edge_tets.get(&e) else {
                stack.pop();
                continue;
            };
            if !self.exact_mid(e) {
                break;
            }
            match around.iter().map(|&t| self.longest(t)).find(|&l| l != e) {
                Some(l) => stack.push(l),
                None => {
                    added += self.split(e);
                    stack.pop();
                }
            }
        }
        added
    }

    fn exact_mid(&self, e: E) -> bool {
        let (p, q) = (self.coords[e.0 as usize], self.coords[e.1 as usize]);
        (0..3).all(|a| (p[a] + q[a]) % 2 == 0)
    }

    /// Splits every tet around `e` at its midpoint; returns the live-tet increase.
    fn split(&mut self, e: E) -> usize {
        let around = self.edge_tets.remove(&e).unwrap_or_default();
        // An edge is split once (its children never contain it): a new vertex.
        let (p, q) = (self.coords[e.0 as usize], self.coords[e.1 as usize]);
        self.coords.push(std::array::from_fn(|a| (p[a] + q[a]) / 2));
        let m = (self.coords.len() - 1) as u32;
        for &t in &around {
            let v = self.tets[t as usize];
            self.alive[t as usize] = false;
            for (a, b) in EDGES {
                let k = key(v[a], v[b]);
                if k != e {
                    if let Some(list) = self.edge_tets.get_mut(&k) {
                        list.retain(|&x| x != t);
                    }
                }
            }
            for replaced in [e.0, e.1] {
                let child = v.map(|x| if x == replaced { m } else { x });
                let id = self.tets.len() as u32;
                self.tets.push(child);
                self.alive.push(true);
                for (a, b) in EDGES {
                    self.edge_tets.entry(key(child[a], child[b])).or_default().push(id);
                }
            }
        }
        around.len()
    }

    /// The live tets and every vertex position (lattice points first, in
    /// lattice order, then the added midpoints), and the black (axis-aligned) test.
    pub fn finish(self) -> (Vec<V3>, Vec<[usize; 4]>, Vec<[i64; 3]>) {
        let positions = (0..self.coords.len() as u32).map(|v| self.position(v)).collect();
        let tets = self
            .tets
            .iter()
            .zip(&self.alive)
            .filter(|(_, &a)| a)
            .map(|(t, _)| t.map(|v| v as usize))
            .collect();
        (positions, tets, self.coords)
    }
}

/// The six edges of a tet as local vertex pairs.
const EDGES: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];

/// True for an axis-aligned ("black") edge between integer coordinates.
pub(crate) fn is_black(p: [i64; 3], q: [i64; 3]) -> bool {
    (0..3).filter(|&a| p[a] != q[a]).count() == 1
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{dihedral_angles_deg, orient6};

    fn lattice_tets(l: &Lattice) -> Vec<[usize; 4]> {
        let mut tets = Vec::new();
        l.for_each_tet(|t| tets.push(t));
        tets
    }

    #[test]
    fn refining_near_a_point_stays_conforming_with_bcc_half_and_quarter_shapes() {
        let l = Lattice { origin: [0.0; 3], h: 1.0, n: [4, 4, 4] };
        let tets = lattice_tets(&l);
        let volume0: f64 = tets
            .iter()
            .map(|t| {
                let p = t.map(|i| l.position(l.coord(i)));
                orient6(p[0], p[1], p[2], p[3]).abs() / 6.0
            })
            .sum();
        let mut r = Refiner::new(&l, tets);
        let focus = [1.3, 2.1, 1.7];
        // Size wanted: 0.15 at the focus, growing by 0.5 per unit distance.
        let needs = |r: &Refiner, t: u32| {
            let c = r.centroid(t);
            let d = crate::geom::norm(crate::geom::sub(c, focus));
            r.size(t) > 0.15 + 0.5 * d
        };
        r.refine(needs, 1_000_000).unwrap();
        let (pos, tets, _) = r.finish();
        assert!(tets.len() > 2000, "{}", tets.len());
        // Volume is kept, every tet has a good shape, and every face is
        // shared by at most two tets with interior faces matched (conforming):
        // the boundary faces' area equals the lattice's.
        let mut volume = 0.0;
        let (mut lo, mut hi) = (180.0f64, 0.0f64);
        for t in &tets {
            let p = t.map(|i| pos[i]);
            volume += orient6(p[0], p[1], p[2], p[3]).abs() / 6.0;
            for a in dihedral_angles_deg(p) {
                lo = lo.min(a);
                hi = hi.max(a);
            }
        }
        assert!((volume - volume0).abs() < 1e-9 * volume0, "{volume} vs {volume0}");
        assert!(lo > 45.0 - 1e-9 && hi < 135.0 + 1e-9, "dihedral angles {lo}..{hi}");
        let mut faces: HashMap<[usize; 3], usize> = HashMap::new();
        for t in &tets {
            for skip in 0..4 {
                let mut f: Vec<usize> = (0..4).filter(|&k| k != skip).map(|k| t[k]).collect();
                f.sort_unstable();
                *faces.entry([f[0], f[1], f[2]]).or_default() += 1;
            }
        }
        assert!(faces.values().all(|&c| c <= 2));
        let boundary_area: f64 = faces
            .iter()
            .filter(|(_, &c)| c == 1)
            .map(|(f, _)| {
                let [a, b, c] = f.map(|i| pos[i]);
                0.5 * crate::geom::norm(crate::geom::cross(crate::geom::sub(b, a), crate::geom::sub(c, a)))
            })
            .sum();
        // A hanging vertex would leave unmatched faces inside: more boundary area.
        let mut lattice_faces: HashMap<[usize; 3], usize> = HashMap::new();
        for t in lattice_tets(&l) {
            for skip in 0..4 {
                let mut f: Vec<usize> = (0..4).filter(|&k| k != skip).map(|k| t[k]).collect();
                f.sort_unstable();
                *lattice_faces.entry([f[0], f[1], f[2]]).or_default() += 1;
            }
        }
        let lattice_area: f64 = lattice_faces
            .iter()
            .filter(|(_, &c)| c == 1)
            .map(|(f, _)| {
                let [a, b, c] = f.map(|i| l.position(l.coord(i)));
                0.5 * crate::geom::norm(crate::geom::cross(crate::geom::sub(b, a), crate::geom::sub(c, a)))
            })
            .sum();
        assert!(
            (boundary_area - lattice_area).abs() < 1e-9 * lattice_area,
            "{boundary_area} vs {lattice_area}"
        );
        // The finest tets near the focus are at most 0.15 (+ one bisection level).
        let smallest = tets
            .iter()
            .map(|t| {
                let p = t.map(|i| pos[i]);
                EDGES
                    .iter()
                    .map(|&(a, b)| crate::geom::norm(crate::geom::sub(p[a], p[b])))
                    .fold(0.0, f64::max)
            })
            .fold(f64::INFINITY, f64::min);
        assert!((0.0625 - 1e-12..=0.15).contains(&smallest), "{smallest}");
    }
}
