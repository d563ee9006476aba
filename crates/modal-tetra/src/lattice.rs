//! The body-centred-cubic (BCC) lattice of isosurface stuffing.
//!
//! Points are addressed by "doubled" integer coordinates c: the primary grid
//! (cube corners) has all-even c, the dual grid (cube centres) all-odd c;
//! position = origin + (h/2) c with h the cube edge (the *cell size*).
//! Black edges join neighbours of one grid (length h, c differs by ±2 in
//! one axis), red edges join a corner to the 8 nearest centres (length
//! √3 h/2, c differs by ±1 in every axis). Each BCC tet has two opposite
//! black edges and four red ones; there are 12 tets per cube (volume h³/12
//! each), enumerated here through the primary squares they straddle.

use crate::geom::V3;

/// Lattice point coordinates, doubled (see the module doc).
pub type Coord = [i64; 3];

/// A finite BCC lattice covering a box.
#[derive(Clone, Debug)]
pub struct Lattice {
    /// Position of doubled coordinate (0, 0, 0) (m).
    pub origin: V3,
    /// Cube edge h (m).
    pub h: f64,
    /// Number of cubes per axis.
    pub n: [usize; 3],
}

impl Lattice {
    /// Lattice of cube size `h` covering [lo, hi] with `pad` cubes of margin.
    pub fn covering(lo: V3, hi: V3, h: f64, pad: usize) -> Self {
        let n = std::array::from_fn(|c| ((hi[c] - lo[c]) / h).ceil() as usize + 2 * pad);
        let origin = std::array::from_fn(|c| {
            let span = n[c] as f64 * h;
            0.5 * (lo[c] + hi[c]) - 0.5 * span
        });
        Lattice { origin, h, n }
    }

    fn primary_count(&self) -> usize {
        (self.n[0] + 1) * (self.n[1] + 1) * (self.n[2] + 1)
    }

    /// Number of lattice points (corners and centres).
    pub fn point_count(&self) -> usize {
        self.primary_count() + self.n[0] * self.n[1] * self.n[2]
    }

    /// Index of the point at doubled coordinate `c`, if it exists.
    pub fn index(&self, c: Coord) -> Option<usize> {
        let parity = c[0].rem_euclid(2);
        if c.iter().any(|&x| x.rem_euclid(2) != parity) || c.iter().any(|&x| x < 0) {
            return None;
        }
        if parity == 0 {
            let i = c.map(|x| (x / 2) as usize);
            if (0..3).any(|a| i[a] > self.n[a]) {
                return None;
            }
            Some(i[0] + (self.n[0] + 1) * (i[1] + (self.n[1] + 1) * i[2]))
        } else {
            let i = c.map(|x| ((x - 1) / 2) as usize);
            if (0..3).any(|a| i[a] >= self.n[a]) {
                return None;
            }
            Some(self.primary_count() + i[0] + self.n[0] * (i[1] + self.n[1] * i[2]))
        }
    }

    /// Doubled coordinate of point `index` (inverse of [`Lattice::index`]).
    pub fn coord(&self, index: usize) -> Coord {
        let p = self.primary_count();
        if index < p {
            let (nx, ny) = (self.n[0] + 1, self.n[1] + 1);
            let i = [index % nx, (index / nx) % ny, index / (nx * ny)];
            i.map(|x| 2 * x as i64)
        } else {
            let r = index - p;
            let (nx, ny) = (self.n[0], self.n[1]);
            let i = [r % nx, (r / nx) % ny, r / (nx * ny)];
            i.map(|x| 2 * x as i64 + 1)
        }
    }

    /// Position (m) of doubled coordinate `c`.
    pub fn position(&self, c: Coord) -> V3 {
        std::array::from_fn(|a| self.origin[a] + 0.5 * self.h * c[a] as f64)
    }

    /// Calls `f` with the four point indices of every BCC tet.
    pub fn for_each_tet(&self, mut f: impl FnMut([usize; 4])) {
        for a in 0..3 {
            let (b, c) = ((a + 1) % 3, (a + 2) % 3);
            for p in 1..self.n[a] as i64 {
                for ib in 0..self.n[b] as i64 {
                    for ic in 0..self.n[c] as i64 {
                        let at = |da: i64, db: i64, dc: i64| {
                            let mut x = [0i64; 3];
                            x[a] = 2 * p + da;
                            x[b] = 2 * ib + db;
                            x[c] = 2 * ic + dc;
                            x
                        };
                        let (Some(lo), Some(hi)) = (self.index(at(-1, 1, 1)), self.index(at(1, 1, 1))) else {
                            continue;
                        };
                        let sq = [at(0, 0, 0), at(0, 2, 0), at(0, 2, 2), at(0, 0, 2)].map(|x| self.index(x));
                        for e in 0..4 {
                            if let (Some(u), Some(v)) = (sq[e], sq[(e + 1) % 4]) {
                                f([lo, hi, u, v]);
                            }
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::orient6;

    #[test]
    fn index_and_coord_round_trip() {
        let l = Lattice { origin: [0.0; 3], h: 1.0, n: [3, 4, 5] };
        for i in 0..l.point_count() {
            assert_eq!(l.index(l.coord(i)), Some(i));
        }
        assert_eq!(l.index([1, 0, 0]), None);
    }

    #[test]
    fn tets_fill_interior_cubes_with_volume_h3_over_12() {
        let l = Lattice { origin: [0.0; 3], h: 2.0, n: [4, 4, 4] };
        let mut count = 0;
        let mut volume = 0.0;
        l.for_each_tet(|t| {
            let p = t.map(|i| l.position(l.coord(i)));
            let v = orient6(p[0], p[1], p[2], p[3]).abs() / 6.0;
            assert!((v - 8.0 / 12.0).abs() < 1e-12);
            count += 1;
            volume += v;
        });
        // 4 tets per interior primary square: 3 axes × 3 planes × 16 squares.
        assert_eq!(count, 4 * 3 * 3 * 16);
        assert!(volume > 0.0);
    }
}
