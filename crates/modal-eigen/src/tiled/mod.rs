//! Block triangular solves `L Lᵀ X = B` (or `L D Lᵀ X = B`) with a supernodal factor
//! repacked into row tiles.
//!
//! Why not faer's own supernodal solve: it runs every supernode's update as a general matrix
//! product, packing L on every call; with the Krylov blocks of 8 right-hand sides it reached
//! ≈ 10 GFLOP/s (30k DOF: 55–60 ms per solve of the 145 MB factor), a fraction of what
//! streaming the factor allows (≈ 29 GB/s on one core here). So after each numeric
//! factorization the factor is repacked once into tiles, and the sweeps read it strictly in
//! order:
//!
//! - a supernode with columns `c₀ … c₀+s` and pattern rows `R` (below the diagonal block) is
//!   stored as *diagonal tiles* (rows `8t … 8t+8` of the diagonal block, columns `0 … 8t+8`)
//!   followed by *pattern tiles* (8 pattern rows, all `s` columns); inside a tile, column by
//!   column, the 8 row values are contiguous (rows past the end are zero);
//! - the right-hand sides are row-major, [`LANES`] values per row: a row is one cache line
//!   (and one AVX-512 register), so gathering and scattering the rows of `R` costs a line each;
//! - forward sweep (`L y = b`), per supernode: diagonal tiles left-looking
//!   (`y_T = L_TT⁻¹ (b_T − L_T,<T y_<T)`), then pattern tiles `b_R −= L_R y`;
//! - backward sweep (`Lᵀ x = y`), supernodes in reverse: `y −= L_Rᵀ x_R`, then diagonal tiles
//!   from the last, right-looking (solve the tile's 8 unknowns, subtract them from the earlier
//!   ones).
//!
//! Each 8 × 8 tile step is 64 fused multiply–adds on 8 factor values: the kernel is compiled
//! for AVX-512 and for AVX2 + FMA and chosen at run time, with a portable fallback. The
//! arithmetic differs from faer's (summation order), not its accuracy (tests compare both).
//! The tiles are written into faer's own allocation ([`TiledFactor::pack`]), and the sweeps
//! are split over two cores along the elimination tree (`split`).

mod split;

use crate::simd::{self, MulAdd};
use faer::dyn_stack::{MemStack, StackReq};
use faer::reborrow::ReborrowMut;
use faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky;
use faer::sparse::linalg::cholesky::{SymbolicCholesky, SymbolicCholeskyRaw};
use faer::MatMut;
pub(crate) use split::split as split_tree;
use split::Split;
use std::ops::Range;

/// Right-hand sides per sweep (one row = 8 × f64 = one cache line).
pub const LANES: usize = 8;
/// Factor rows per tile.
const TILE: usize = 8;

type Row = [f64; LANES];

/// Where one supernode lives in the packed arrays.
struct Node {
    /// First column (permuted numbering).
    start: usize,
    /// Number of columns.
    ncols: usize,
    /// Offset of its first diagonal tile in the tiles.
    diag: usize,
    /// Offset of its first pattern tile in the tiles.
    pattern: usize,
    /// Offset of its padded pattern rows in `rows`.
    rows: usize,
    /// Number of pattern tiles.
    pattern_tiles: usize,
}

impl Node {
    fn diag_tiles(&self) -> usize {
        self.ncols.div_ceil(TILE)
    }

    /// Offset of diagonal tile `t` (tiles before it are full: `Σ_{u<t} 8·8(u+1)` values).
    fn diag_tile(&self, t: usize) -> usize {
        self.diag + TILE * TILE * t * (t + 1) / 2
    }

    /// Columns stored in diagonal tile `t`.
    fn diag_width(&self, t: usize) -> usize {
        (TILE * (t + 1)).min(self.ncols)
    }

    fn pattern_tile(&self, t: usize) -> usize {
        self.pattern + t * TILE * self.ncols
    }

    /// Factor values stored (the work of one sweep through this supernode).
    fn values(&self) -> usize {
        self.pattern - self.diag + self.pattern_tiles * TILE * self.ncols
    }
}

/// A supernodal `LLᵀ` or `LDLᵀ` factor in tiles, with its fill-reducing permutation.
pub struct TiledFactor {
    n: usize,
    /// `perm[new] = old`.
    perm: Option<Vec<usize>>,
    nodes: Vec<Node>,
    /// Holds the tiles from `base` on (see [`Self::pack`]).
    values: Vec<f64>,
    base: usize,
    /// Pattern rows per node, padded to whole tiles with the zero row `n`.
    rows: Vec<usize>,
    /// Multiplier of each unknown in both sweeps: `1/L_jj` (LLᵀ) or 1 (unit LDLᵀ).
    pivot_scale: Vec<f64>,
    /// `1/D_j` between the sweeps (LDLᵀ only).
    d_inv: Option<Vec<f64>>,
    /// The two-core cut of the sweeps (`None`: one sequential pass).
    split: Option<Split>,
}

/// Which kind of factor faer's values hold.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum FactorKind {
    /// Cholesky `L Lᵀ`, L's diagonal positive.
    Llt,
    /// `L D Lᵀ`, unit L, D stored on L's diagonal.
    Ldlt,
}

impl TiledFactor {
    /// Length of the allocation holding the tiles of this symbolic factor (see
    /// [`Self::pack`]); `None` if it is simplicial.
    pub fn packed_len(symbolic: &SymbolicCholesky<usize>) -> Option<usize> {
        let SymbolicCholeskyRaw::Supernodal(sn) = symbolic.raw() else { return None };
        let (nodes, total, _) = layout(sn);
        Some(tiles_base(sn, &nodes, total) + total)
    }

    /// Repacks faer's numeric factor in the same allocation: the tiles fill it from the end,
    /// last supernode first, each supernode's faer block copied aside before its tiles are
    /// written, so no tile lands on a block not yet read. `Err` gives the values back if the
    /// factor is simplicial (small problems, where faer's own solve is used).
    pub fn pack(
        symbolic: &SymbolicCholesky<usize>,
        mut values: Vec<f64>,
        kind: FactorKind,
    ) -> Result<Self, Vec<f64>> {
        let SymbolicCholeskyRaw::Supernodal(sn) = symbolic.raw() else { return Err(values) };
        assert_eq!(values.len(), sn.len_val(), "tiled pack: values do not match the symbolic factor");
        let n = sn.nrows();
        let (nodes, total, total_rows) = layout(sn);
        let faer_ptr = sn.col_ptr_for_val();
        let tiles_end = |s: usize| nodes.get(s + 1).map_or(total, |next| next.diag);
        let base = tiles_base(sn, &nodes, total);
        // `base + total ≥ faer's length` (the last term of `tiles_base`); more only when
        // padding outweighs the triangles.
        values.resize(base + total, 0.0);
        let mut out = Self {
            n,
            perm: symbolic.perm().map(|p| p.arrays().0.to_vec()),
            nodes: Vec::new(),
            values: Vec::new(),
            base,
            rows: vec![n; total_rows],
            pivot_scale: vec![1.0; n],
            d_inv: (kind == FactorKind::Ldlt).then(|| vec![1.0; n]),
            split: None,
        };
        let mut aside = Vec::new();
        // Last supernode first: its tiles go above the faer values still to be read.
        for (s, node) in nodes.iter().enumerate().rev() {
            aside.clear();
            aside.extend_from_slice(&values[faer_ptr[s]..faer_ptr[s + 1]]);
            let pattern = sn.supernode(s).pattern();
            let l = faer::MatRef::from_column_major_slice(&aside, node.ncols + pattern.len(), node.ncols);
            let pivots = match kind {
                FactorKind::Llt => &mut out.pivot_scale,
                FactorKind::Ldlt => out.d_inv.as_mut().expect("ldlt"),
            };
            for j in 0..node.ncols {
                pivots[node.start + j] = 1.0 / l[(j, j)];
            }
            out.rows[node.rows..][..pattern.len()].copy_from_slice(pattern);
            let tiles = &mut values[base + node.diag..base + tiles_end(s)];
            tiles.fill(0.0);
            write_tiles(node, l, tiles);
        }
        out.values = values;
        out.nodes = nodes;
        out.split = out.cut(sn, split::MIN_SPLIT_VALUES);
        Ok(out)
    }

    /// Gives the allocation back (for the next factorization).
    pub fn into_values(self) -> Vec<f64> {
        self.values
    }

    /// The tiles (all supernodes, in order).
    fn tiles(&self) -> &[f64] {
        &self.values[self.base..]
    }

    /// The two-core cut of this factor's elimination tree (see [`split`]).
    fn cut(&self, sn: &SymbolicSupernodalCholesky<usize>, min_values: usize) -> Option<Split> {
        let mut node_of_column = vec![0usize; self.n];
        for (s, node) in self.nodes.iter().enumerate() {
            node_of_column[node.start..node.start + node.ncols].fill(s);
        }
        // The parent of a supernode holds the first row of its pattern.
        let parent: Vec<Option<usize>> = (0..self.nodes.len())
            .map(|s| sn.supernode(s).pattern().iter().min().map(|&r| node_of_column[r]))
            .collect();
        let work: Vec<usize> = self.nodes.iter().map(Node::values).collect();
        let starts: Vec<usize> = self.nodes.iter().map(|n| n.start).collect();
        let ncols: Vec<usize> = self.nodes.iter().map(|n| n.ncols).collect();
        split::split(&starts, &ncols, &parent, &work, min_values)
    }

    /// Workspace of [`Self::solve_in_place`].
    pub fn scratch(n: usize) -> StackReq {
        StackReq::new_aligned::<Row>(n + 1, 64).and(StackReq::new_aligned::<Row>(n + 1, 64))
    }

    /// Solves `A X = B` in place for every column of `rhs` (n × p, any p), [`LANES`] columns
    /// per sweep pair.
    pub fn solve_in_place(&self, mut rhs: MatMut<'_, f64>, stack: &mut MemStack) {
        let n = self.n;
        assert_eq!(rhs.nrows(), n, "tiled solve: wrong number of rows");
        // Row n stays zero: padded pattern rows point at it.
        let (mut x, stack) = stack.make_aligned_with::<Row>(n + 1, 64, |_| [0.0; LANES]);
        let (mut private, _) = stack.make_aligned_with::<Row>(n + 1, 64, |_| [0.0; LANES]);
        let p = rhs.ncols();
        for c0 in (0..p).step_by(LANES) {
            let width = LANES.min(p - c0);
            {
                let mut cols = rhs.rb_mut().subcols_mut(c0, width);
                for c in 0..width {
                    let col = cols.rb_mut().col_mut(c);
                    for (new, row) in x[..n].iter_mut().enumerate() {
                        row[c] = col[self.old_index(new)];
                    }
                }
                for row in x[..n].iter_mut() {
                    row[width..].fill(0.0);
                }
            }
            self.solve_rows(&mut x, &mut private);
            for c in 0..width {
                let mut col = rhs.rb_mut().col_mut(c0 + c);
                for (new, row) in x[..n].iter().enumerate() {
                    col[self.old_index(new)] = row[c];
                }
            }
        }
    }

    #[inline]
    fn old_index(&self, new: usize) -> usize {
        self.perm.as_ref().map_or(new, |p| p[new])
    }

    /// Both sweeps on permuted row-major right-hand sides `x` (`n + 1` rows, the last zero);
    /// `private` (same size, row n zero) is bin 1's copy when the sweeps are split.
    fn solve_rows(&self, x: &mut [Row], private: &mut [Row]) {
        debug_assert_eq!(x.len(), self.n + 1);
        let Some(split) = &self.split else {
            let all = 0..self.nodes.len();
            self.run(std::slice::from_ref(&all), x, Sweep::Forward);
            self.scale_by_d(x);
            self.run(std::slice::from_ref(&all), x, Sweep::Backward);
            return;
        };
        copy_rows(&split.bin1_rows, x, private);
        for r in &split.top_rows {
            private[r.clone()].fill([0.0; LANES]);
        }
        rayon::join(
            || self.run(&split.bins[0], x, Sweep::Forward),
            || self.run(&split.bins[1], private, Sweep::Forward),
        );
        copy_rows(&split.bin1_rows, private, x);
        for r in &split.top_rows {
            for (xr, pr) in x[r.clone()].iter_mut().zip(&private[r.clone()]) {
                for (a, b) in xr.iter_mut().zip(pr) {
                    *a += b;
                }
            }
        }
        self.run(&split.top, x, Sweep::Forward);
        self.scale_by_d(x);
        self.run(&split.top, x, Sweep::Backward);
        copy_rows(&split.bin1_rows, x, private);
        copy_rows(&split.top_rows, x, private);
        rayon::join(
            || self.run(&split.bins[0], x, Sweep::Backward),
            || self.run(&split.bins[1], private, Sweep::Backward),
        );
        copy_rows(&split.bin1_rows, private, x);
    }

    /// One sweep over the supernodes of `ranges` (forward: in order; backward: reversed).
    fn run(&self, ranges: &[Range<usize>], x: &mut [Row], sweep: Sweep) {
        simd::dispatch(Sweeps { factor: self, ranges, x, sweep });
    }

    /// `x ← D⁻¹ x` between the sweeps of an LDLᵀ factor.
    fn scale_by_d(&self, x: &mut [Row]) {
        if let Some(d_inv) = &self.d_inv {
            for (row, d) in x.iter_mut().zip(d_inv) {
                for v in row.iter_mut() {
                    *v *= d;
                }
            }
        }
    }

    /// `y_S = L_SS⁻¹ b_S`, then `b_R −= L_RS y_S`.
    #[inline(always)]
    fn forward_node<F: MulAdd>(&self, node: &Node, x: &mut [Row]) {
        let (head, tail) = x.split_at_mut(node.start + node.ncols);
        let own = &mut head[node.start..];
        let scale = &self.pivot_scale[node.start..][..node.ncols];
        for t in 0..node.diag_tiles() {
            let width = node.diag_width(t);
            let tile = &self.tiles()[node.diag_tile(t)..][..TILE * width];
            let solved = TILE * t;
            let mut sum = [[0.0; LANES]; TILE];
            tile_times_rows::<F>(&tile[..TILE * solved], &own[..solved], &mut sum);
            let rows = width - solved;
            let mut acc = [[0.0; LANES]; TILE];
            for r in 0..rows {
                for c in 0..LANES {
                    acc[r][c] = own[solved + r][c] - sum[r][c];
                }
            }
            // The tile's own lower triangle, column by column.
            for jj in 0..rows {
                let col = &tile[TILE * (solved + jj)..][..TILE];
                let s = scale[solved + jj];
                let xj = acc[jj].map(|v| v * s);
                acc[jj] = xj;
                for r in jj + 1..rows {
                    for c in 0..LANES {
                        acc[r][c] = F::mul_add(-col[r], xj[c], acc[r][c]);
                    }
                }
            }
            own[solved..width].copy_from_slice(&acc[..rows]);
        }
        let rows = &self.rows[node.rows..][..TILE * node.pattern_tiles];
        let shift = node.start + node.ncols;
        for (t, tile_rows) in rows.chunks_exact(TILE).enumerate() {
            let tile = &self.tiles()[node.pattern_tile(t)..][..TILE * node.ncols];
            let mut sum = [[0.0; LANES]; TILE];
            tile_times_rows::<F>(tile, own, &mut sum);
            for (r, &row) in tile_rows.iter().enumerate() {
                let target = &mut tail[row - shift];
                for c in 0..LANES {
                    target[c] -= sum[r][c];
                }
            }
        }
    }

    /// `y_S −= L_RSᵀ x_R`, then `x_S = L_SS⁻ᵀ y_S`.
    #[inline(always)]
    fn backward_node<F: MulAdd>(&self, node: &Node, x: &mut [Row]) {
        let (head, tail) = x.split_at_mut(node.start + node.ncols);
        let own = &mut head[node.start..];
        let scale = &self.pivot_scale[node.start..][..node.ncols];
        let rows = &self.rows[node.rows..][..TILE * node.pattern_tiles];
        let shift = node.start + node.ncols;
        for (t, tile_rows) in rows.chunks_exact(TILE).enumerate() {
            let tile = &self.tiles()[node.pattern_tile(t)..][..TILE * node.ncols];
            let mut g = [[0.0; LANES]; TILE];
            for (r, &row) in tile_rows.iter().enumerate() {
                g[r] = tail[row - shift];
            }
            rows_minus_tile_t::<F>(tile, &g, own);
        }
        for t in (0..node.diag_tiles()).rev() {
            let width = node.diag_width(t);
            let tile = &self.tiles()[node.diag_tile(t)..][..TILE * width];
            let solved = TILE * t;
            let rows = width - solved;
            let mut acc = [[0.0; LANES]; TILE];
            acc[..rows].copy_from_slice(&own[solved..width]);
            for jj in (0..rows).rev() {
                let col = &tile[TILE * (solved + jj)..][..TILE];
                let mut v = acc[jj];
                for r in jj + 1..rows {
                    for c in 0..LANES {
                        v[c] = F::mul_add(-col[r], acc[r][c], v[c]);
                    }
                }
                let s = scale[solved + jj];
                acc[jj] = v.map(|e| e * s);
            }
            own[solved..width].copy_from_slice(&acc[..rows]);
            rows_minus_tile_t::<F>(&tile[..TILE * solved], &acc, &mut own[..solved]);
        }
    }
}

/// Direction of a sweep.
#[derive(Copy, Clone, PartialEq, Eq)]
enum Sweep {
    /// `L y = b`.
    Forward,
    /// `Lᵀ x = y`.
    Backward,
}

/// One sweep over some supernodes, as a [`simd::Kernel`].
struct Sweeps<'a> {
    factor: &'a TiledFactor,
    ranges: &'a [Range<usize>],
    x: &'a mut [Row],
    sweep: Sweep,
}

impl simd::Kernel for Sweeps<'_> {
    type Output = ();
    #[inline(always)]
    fn run<F: MulAdd>(self) {
        let nodes = &self.factor.nodes;
        match self.sweep {
            Sweep::Forward => {
                for node in self.ranges.iter().flat_map(|r| &nodes[r.clone()]) {
                    self.factor.forward_node::<F>(node, self.x);
                }
            }
            Sweep::Backward => {
                for node in self.ranges.iter().rev().flat_map(|r| nodes[r.clone()].iter().rev()) {
                    self.factor.backward_node::<F>(node, self.x);
                }
            }
        }
    }
}

/// `to[r] = from[r]` for the rows of `ranges`.
fn copy_rows(ranges: &[Range<usize>], from: &[Row], to: &mut [Row]) {
    for r in ranges {
        to[r.clone()].copy_from_slice(&from[r.clone()]);
    }
}

/// Writes a supernode's tiles (zeroed; `tiles` starts at its first diagonal tile) from its
/// faer block `l` ((ncols + pattern) × ncols, column-major).
fn write_tiles(node: &Node, l: faer::MatRef<'_, f64>, tiles: &mut [f64]) {
    let ns = node.ncols;
    for t in 0..node.diag_tiles() {
        let tile = &mut tiles[node.diag_tile(t) - node.diag..][..TILE * node.diag_width(t)];
        for j in 0..node.diag_width(t) {
            // Strictly lower part only: the pivots live in `pivot_scale`/`d_inv`.
            for r in 0..TILE.min(ns - TILE * t) {
                let i = TILE * t + r;
                if j < i {
                    tile[j * TILE + r] = l[(i, j)];
                }
            }
        }
    }
    let pattern_len = l.nrows() - ns;
    for t in 0..node.pattern_tiles {
        let tile = &mut tiles[node.pattern_tile(t) - node.diag..][..TILE * ns];
        let rows = TILE.min(pattern_len - TILE * t);
        for j in 0..ns {
            let col = l.col(j).try_as_col_major().expect("column-major block").as_slice();
            tile[j * TILE..][..rows].copy_from_slice(&col[ns + TILE * t..][..rows]);
        }
    }
}

/// Where the tiles start in faer's allocation, packed from the last supernode down: the
/// tiles of supernode s and after must stay above the faer blocks before s,
/// `base + tiles_start(s) ≥ faer_start(s)` for every s (and at the end, `base + total` must
/// cover faer's length: tiles are usually smaller, since a diagonal block is stored as a
/// triangle, but small supernodes pad to whole tiles).
fn tiles_base(sn: &SymbolicSupernodalCholesky<usize>, nodes: &[Node], total: usize) -> usize {
    let faer_ptr = sn.col_ptr_for_val();
    let starts = nodes.iter().map(|n| n.diag).chain([total]);
    starts.enumerate().map(|(s, t)| faer_ptr[s].saturating_sub(t)).max().unwrap_or(0)
}

/// Tile offsets: (nodes, values length, padded rows length).
fn layout(sn: &SymbolicSupernodalCholesky<usize>) -> (Vec<Node>, usize, usize) {
    let begin = sn.supernode_begin();
    let end = sn.supernode_end();
    let mut nodes = Vec::with_capacity(sn.n_supernodes());
    let (mut values, mut rows) = (0usize, 0usize);
    for s in 0..sn.n_supernodes() {
        let ncols = end[s] - begin[s];
        // Not the spacing of `col_ptr_for_row_idx`: faer's row index array can hold slack.
        let pattern_len = sn.supernode(s).pattern().len();
        let pattern_tiles = pattern_len.div_ceil(TILE);
        let mut node = Node { start: begin[s], ncols, diag: values, pattern: 0, rows, pattern_tiles };
        let diag_len = (0..node.diag_tiles()).map(|t| TILE * node.diag_width(t)).sum::<usize>();
        node.pattern = values + diag_len;
        values = node.pattern + pattern_tiles * TILE * ncols;
        rows += pattern_tiles * TILE;
        nodes.push(node);
    }
    (nodes, values, rows)
}

/// `sum[r] += Σ_j tile[j, r] · xs[j]` for a tile of `xs.len()` columns.
#[inline(always)]
fn tile_times_rows<F: MulAdd>(tile: &[f64], xs: &[Row], sum: &mut [Row; TILE]) {
    debug_assert_eq!(tile.len(), TILE * xs.len());
    if F::AVX512 {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: `F::AVX512` is only set by the AVX-512 entry point.
        unsafe {
            return avx512::tile_times_rows(tile, xs, sum);
        }
    }
    for (col, xj) in tile.chunks_exact(TILE).zip(xs) {
        for r in 0..TILE {
            for c in 0..LANES {
                sum[r][c] = F::mul_add(col[r], xj[c], sum[r][c]);
            }
        }
    }
}

/// `ys[j] −= Σ_r tile[j, r] · g[r]` for a tile of `ys.len()` columns.
#[inline(always)]
fn rows_minus_tile_t<F: MulAdd>(tile: &[f64], g: &[Row; TILE], ys: &mut [Row]) {
    debug_assert_eq!(tile.len(), TILE * ys.len());
    if F::AVX512 {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: as in `tile_times_rows`.
        unsafe {
            return avx512::rows_minus_tile_t(tile, g, ys);
        }
    }
    for (col, yj) in tile.chunks_exact(TILE).zip(ys.iter_mut()) {
        let mut v = *yj;
        for r in 0..TILE {
            for c in 0..LANES {
                v[c] = F::mul_add(-col[r], g[r][c], v[c]);
            }
        }
        *yj = v;
    }
}

/// The two tile kernels with explicit AVX-512 registers: one factor value is broadcast
/// against a whole row of 8 right-hand sides. Written out because the compiler kept the
/// gathered rows of the backward kernel on the stack.
#[cfg(target_arch = "x86_64")]
mod avx512 {
    use super::{Row, TILE};
    use std::arch::x86_64::*;

    /// Factor values fetched ahead of use.
    const PREFETCH: usize = 1024;

    /// See `super::tile_times_rows`: 8 independent accumulators, one per tile row.
    #[inline]
    #[target_feature(enable = "avx512f")]
    pub unsafe fn tile_times_rows(tile: &[f64], xs: &[Row], sum: &mut [Row; TILE]) {
        let mut acc = [_mm512_setzero_pd(); TILE];
        for (col, xj) in tile.chunks_exact(TILE).zip(xs) {
            _mm_prefetch::<_MM_HINT_T0>(col.as_ptr().wrapping_add(PREFETCH).cast());
            let x = _mm512_loadu_pd(xj.as_ptr());
            for r in 0..TILE {
                acc[r] = _mm512_fmadd_pd(_mm512_set1_pd(col[r]), x, acc[r]);
            }
        }
        for r in 0..TILE {
            let old = _mm512_loadu_pd(sum[r].as_ptr());
            _mm512_storeu_pd(sum[r].as_mut_ptr(), _mm512_add_pd(old, acc[r]));
        }
    }

    /// See `super::rows_minus_tile_t`: the 8 gathered rows stay in registers; two partial
    /// sums per column halve the dependency chain.
    #[inline]
    #[target_feature(enable = "avx512f")]
    pub unsafe fn rows_minus_tile_t(tile: &[f64], g: &[Row; TILE], ys: &mut [Row]) {
        let mut gv = [_mm512_setzero_pd(); TILE];
        for r in 0..TILE {
            gv[r] = _mm512_loadu_pd(g[r].as_ptr());
        }
        for (col, yj) in tile.chunks_exact(TILE).zip(ys.iter_mut()) {
            _mm_prefetch::<_MM_HINT_T0>(col.as_ptr().wrapping_add(PREFETCH).cast());
            let mut even = _mm512_mul_pd(_mm512_set1_pd(col[0]), gv[0]);
            let mut odd = _mm512_mul_pd(_mm512_set1_pd(col[1]), gv[1]);
            for r in (2..TILE).step_by(2) {
                even = _mm512_fmadd_pd(_mm512_set1_pd(col[r]), gv[r], even);
                odd = _mm512_fmadd_pd(_mm512_set1_pd(col[r + 1]), gv[r + 1], odd);
            }
            let y = _mm512_loadu_pd(yj.as_ptr());
            _mm512_storeu_pd(yj.as_mut_ptr(), _mm512_sub_pd(y, _mm512_add_pd(even, odd)));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::factor::ShiftedFactor;
    use crate::test_support::{steel_box, time_ms};
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::sparse::linalg::cholesky::{
        factorize_symbolic_cholesky, CholeskySymbolicParams, LdltRef, LltRef, SymmetricOrdering,
    };
    use faer::sparse::SparseColMat;
    use faer::{Mat, Par, Side};

    /// K − σM of a TET10 steel box with `cells` per side (upper triangle is what faer reads).
    fn shifted_box(cells: usize, sigma_rel: f64) -> (SparseColMat<usize, f64>, f64) {
        let a = steel_box([cells; 3]);
        // σ relative to the spectrum scale max Kᵢᵢ/Mᵢᵢ.
        let scale = (0..a.k.ncols())
            .map(|j| a.k.get(j, j).copied().unwrap_or(0.0) / a.m.get(j, j).copied().unwrap())
            .fold(0.0, f64::max);
        let sigma = sigma_rel * scale;
        let shifted = &a.k - &(&a.m * faer::Scale(sigma));
        (shifted, sigma)
    }

    fn symbolic(a: &SparseColMat<usize, f64>) -> SymbolicCholesky<usize> {
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: faer::sparse::linalg::SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        };
        factorize_symbolic_cholesky(a.symbolic(), Side::Upper, SymmetricOrdering::Amd, params).unwrap()
    }

    /// faer's numeric factor of `a` (must succeed).
    fn numeric(sym: &SymbolicCholesky<usize>, a: &SparseColMat<usize, f64>, kind: FactorKind) -> Vec<f64> {
        crate::test_support::faer_numeric(sym, a.as_ref(), kind)
    }

    /// A⁻¹ b with faer's own solve.
    fn faer_solve(sym: &SymbolicCholesky<usize>, values: &[f64], kind: FactorKind, b: &Mat<f64>) -> Mat<f64> {
        let mut x = b.clone();
        let mut buf = MemBuffer::new(sym.solve_in_place_scratch::<f64>(b.ncols(), Par::Seq));
        let stack = MemStack::new(&mut buf);
        match kind {
            FactorKind::Llt => {
                LltRef::new(sym, values).solve_in_place_with_conj(faer::Conj::No, x.as_mut(), Par::Seq, stack)
            }
            FactorKind::Ldlt => LdltRef::new(sym, values).solve_in_place_with_conj(
                faer::Conj::No,
                x.as_mut(),
                Par::Seq,
                stack,
            ),
        }
        x
    }

    /// A⁻¹ b with the tiled solve.
    fn tiled_solve(tiled: &TiledFactor, b: &Mat<f64>) -> Mat<f64> {
        let mut x = b.clone();
        tiled.solve_in_place(x.as_mut(), MemStack::new(&mut MemBuffer::new(TiledFactor::scratch(b.nrows()))));
        x
    }

    fn random_rhs(n: usize, p: usize) -> Mat<f64> {
        let mut rng = crate::block::Rng::new(7);
        let mut b = Mat::zeros(n, p);
        rng.fill(b.as_mut());
        b
    }

    /// max |a − b| / max |b|, infinite if anything is not finite (faer's norms skip NaN).
    fn max_rel_diff(a: &Mat<f64>, b: &Mat<f64>) -> f64 {
        let (mut diff, mut scale) = (0.0f64, 0.0f64);
        for j in 0..a.ncols() {
            for i in 0..a.nrows() {
                if !(a[(i, j)].is_finite() && b[(i, j)].is_finite()) {
                    return f64::INFINITY;
                }
                diff = diff.max((a[(i, j)] - b[(i, j)]).abs());
                scale = scale.max(b[(i, j)].abs());
            }
        }
        diff / scale
    }

    /// The tiled solve equals faer's for LLᵀ, for block widths below, at and above LANES.
    #[test]
    fn tiled_llt_solve_matches_faer() {
        let (a, _) = shifted_box(3, -1e-6);
        let sym = symbolic(&a);
        let values = numeric(&sym, &a, FactorKind::Llt);
        let tiled = TiledFactor::pack(&sym, values.clone(), FactorKind::Llt).expect("supernodal");
        for p in [1, 3, 8, 11] {
            let b = random_rhs(a.nrows(), p);
            let reference = faer_solve(&sym, &values, FactorKind::Llt, &b);
            let x = tiled_solve(&tiled, &b);
            let d = max_rel_diff(&x, &reference);
            assert!(d < 1e-10, "p = {p}: tiled vs faer differ by {d:e}");
            // And it really solves A x = b.
            let ax = &a * &x;
            let r = max_rel_diff(&ax, &b);
            assert!(r < 1e-6, "p = {p}: relative residual {r:e}");
        }
    }

    /// Two paths, one answer: the portable sweeps, every SIMD entry point this CPU has, and
    /// the two-core split of the sweeps agree to rounding; the split gives the same bits on
    /// one thread as on two.
    #[test]
    fn kernel_variants_and_split_agree() {
        let (a, _) = shifted_box(3, -1e-6);
        let sym = symbolic(&a);
        let values = numeric(&sym, &a, FactorKind::Llt);
        let mut tiled = TiledFactor::pack(&sym, values.clone(), FactorKind::Llt).unwrap();
        let SymbolicCholeskyRaw::Supernodal(sn) = sym.raw() else { unreachable!() };
        let n = a.nrows();
        let mut rng = crate::block::Rng::new(3);
        let mut start = Mat::zeros(n + 1, LANES);
        rng.fill(start.as_mut().subrows_mut(0, n));
        let rows =
            |m: &Mat<f64>| -> Vec<Row> { (0..=n).map(|i| std::array::from_fn(|c| m[(i, c)])).collect() };
        // Sequential sweeps through one kernel variant.
        let all = 0..tiled.nodes.len();
        let all = std::slice::from_ref(&all);
        let sequential = |exec: &dyn Fn(Sweeps) -> Option<()>, x: &mut [Row]| -> Option<()> {
            exec(Sweeps { factor: &tiled, ranges: all, x, sweep: Sweep::Forward })?;
            exec(Sweeps { factor: &tiled, ranges: all, x, sweep: Sweep::Backward })
        };
        let mut portable = rows(&start);
        sequential(
            &|k| {
                simd::run_portable(k);
                Some(())
            },
            &mut portable,
        );
        assert!(portable.iter().flatten().all(|v| v.is_finite()));
        let scale = portable.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        // NaN compares false: a non-finite result fails the `< tol` checks below.
        let differs = |x: &[Row]| {
            let d = x.iter().flatten().zip(portable.iter().flatten()).map(|(a, b)| (a - b).abs());
            d.fold(0.0, |m: f64, e| if e.is_nan() { f64::NAN } else { m.max(e) }) / scale
        };
        let mut avx2 = rows(&start);
        if sequential(&|k| simd::dispatch_avx2(k), &mut avx2).is_some() {
            assert!(differs(&avx2) < 1e-11, "avx2: {:e}", differs(&avx2));
        }
        assert!(tiled.split.is_none(), "a 1k-DOF factor is not split by default");
        let mut private = vec![[0.0; LANES]; n + 1];
        let mut dispatched = rows(&start);
        tiled.solve_rows(&mut dispatched, &mut private);
        assert!(differs(&dispatched) < 1e-11, "dispatched: {:e}", differs(&dispatched));
        // Force the split and run it on two threads and on one.
        tiled.split = tiled.cut(sn, 0);
        let split = tiled.split.as_ref().expect("the tree of a box can be cut");
        assert!(split.bins.iter().all(|b| !b.is_empty()) && !split.top.is_empty());
        let solve_on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let mut x = rows(&start);
            let mut private = vec![[0.0; LANES]; n + 1];
            pool.install(|| tiled.solve_rows(&mut x, &mut private));
            x
        };
        let two = solve_on(2);
        assert!(differs(&two) < 1e-11, "split: {:e}", differs(&two));
        assert!(two == solve_on(1), "the split must not depend on the thread count");
    }

    /// The same for an indefinite LDLᵀ (σ inside the spectrum), whole and split over two
    /// cores (D⁻¹ is applied between the sweeps, after bin 1's rows are merged back).
    #[test]
    fn tiled_ldlt_solve_matches_faer() {
        let (a, _) = shifted_box(3, 1e-3);
        let sym = symbolic(&a);
        let values = numeric(&sym, &a, FactorKind::Ldlt);
        let mut tiled = TiledFactor::pack(&sym, values.clone(), FactorKind::Ldlt).expect("supernodal");
        let b = random_rhs(a.nrows(), 8);
        let reference = faer_solve(&sym, &values, FactorKind::Ldlt, &b);
        let d = max_rel_diff(&tiled_solve(&tiled, &b), &reference);
        assert!(d < 1e-8, "tiled vs faer differ by {d:e}");
        let SymbolicCholeskyRaw::Supernodal(sn) = sym.raw() else { unreachable!() };
        tiled.split = tiled.cut(sn, 0);
        assert!(tiled.split.is_some());
        let d = max_rel_diff(&tiled_solve(&tiled, &b), &reference);
        assert!(d < 1e-8, "split tiled vs faer differ by {d:e}");
    }

    /// Timing of one 8-column solve on the 30k-DOF benchmark box (14 mm cells): tiled,
    /// faer's, and a plain read of the tiled values (the memory floor of one sweep):
    /// `cargo test --release -p modal-eigen --lib tiled_solve_speed -- --ignored --nocapture`.
    #[test]
    #[ignore]
    fn tiled_solve_speed() {
        let asm = steel_box([14, 11, 7]);
        let a = &asm.k + &(&asm.m * faer::Scale(1e-3));
        let sym =
            ShiftedFactor::analyze(asm.k.as_ref(), asm.m.as_ref(), None, true, Par::Seq).unwrap().symbolic;
        let values = numeric(&sym, &a, FactorKind::Llt);
        let tiled = TiledFactor::pack(&sym, values.clone(), FactorKind::Llt).unwrap();
        if let Some(sp) = &tiled.split {
            let work = |rs: &[Range<usize>]| -> usize {
                rs.iter().flat_map(|r| &tiled.nodes[r.clone()]).map(Node::values).sum()
            };
            eprintln!(
                "two-core split: bins of {} and {} values, top {} values",
                work(&sp.bins[0]),
                work(&sp.bins[1]),
                work(&sp.top)
            );
        }
        let reps: usize = std::env::var("TILED_REPS").ok().and_then(|s| s.parse().ok()).unwrap_or(20);
        let time = |f: &mut dyn FnMut()| time_ms(reps, f);
        let mut b = random_rhs(a.nrows(), LANES);
        let mut tbuf = MemBuffer::new(TiledFactor::scratch(a.nrows()));
        let tiled_ms = time(&mut || tiled.solve_in_place(b.as_mut(), MemStack::new(&mut tbuf)));
        let mut sbuf = MemBuffer::new(sym.solve_in_place_scratch::<f64>(LANES, Par::Seq));
        let faer_ms = time(&mut || {
            LltRef::new(&sym, &values).solve_in_place_with_conj(
                faer::Conj::No,
                b.as_mut(),
                Par::Seq,
                MemStack::new(&mut sbuf),
            )
        });
        let mut total = 0.0;
        let read_ms = time(&mut || {
            let mut acc = [0.0f64; 32];
            for chunk in tiled.tiles().chunks_exact(32) {
                for (a, v) in acc.iter_mut().zip(chunk) {
                    *a += v;
                }
            }
            total += acc.iter().sum::<f64>();
        });
        eprintln!(
            "n = {}, tiled factor {:.0} MB: tiled solve {tiled_ms:.2} ms, faer {faer_ms:.2} ms, two plain reads {:.2} ms ({total:.1})",
            a.nrows(),
            tiled.tiles().len() as f64 * 8e-6,
            2.0 * read_ms
        );
    }
}
