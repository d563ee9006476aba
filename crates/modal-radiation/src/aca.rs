//! Adaptive cross approximation of the blocks of [`crate::hmatrix`] (its
//! module doc gives the method): the entries a block has fetched
//! ([`Entries`], each evaluated once), the side-by-side matrix
//! `[A | s_1 R_1 | …]` ACA runs on, partial-pivoting ACA itself, and the
//! block it yields, low rank (recompressed, [`crate::lowrank`]) or dense.

use faer::c64;

use crate::assembly::Assembly;
use crate::hmatrix::{Data, ACA_TOLERANCE};

/// The entries of one block `rows × cols` fetched so far, as whole rows
/// and whole columns of `A` and of each source's right-hand-side parts
/// ([`Assembly::row`]): ACA asks for each entry once (a column crossing a
/// fetched row reads it, and so on), and a block ACA gives up on is
/// completed dense from them: it gave up after `m/2` rows and as many
/// columns, so only a quarter of its entries are left to evaluate.
struct Entries<'a, 'b> {
    asm: &'a Assembly<'b>,
    rows: &'a [usize],
    cols: &'a [usize],
    /// Right-hand sides, at least one (the layout of [`Assembly::row`]).
    nrhs: usize,
    /// Where each block row (column) is among the fetched ones.
    row_at: Vec<Option<usize>>,
    col_at: Vec<Option<usize>>,
    /// Fetched rows: `A` (`n_σ`) and the parts (`n_σ × nrhs`, row-major).
    fetched_rows: Vec<(Vec<c64>, Vec<c64>)>,
    /// Fetched columns: `A` (`m`) and the parts (`m × nrhs`, row-major).
    fetched_cols: Vec<(Vec<c64>, Vec<c64>)>,
}

impl<'a, 'b> Entries<'a, 'b> {
    fn new(asm: &'a Assembly<'b>, rows: &'a [usize], cols: &'a [usize]) -> Self {
        Entries {
            asm,
            rows,
            cols,
            nrhs: asm.fields().len().max(1),
            row_at: vec![None; rows.len()],
            col_at: vec![None; cols.len()],
            fetched_rows: Vec::new(),
            fetched_cols: Vec::new(),
        }
    }

    /// Row `i` of the block, `A` and parts: evaluated where no fetched
    /// column crosses it.
    fn row(&mut self, i: usize) -> &(Vec<c64>, Vec<c64>) {
        if self.row_at[i].is_none() {
            let (width, nrhs) = (self.cols.len(), self.nrhs);
            let zero = c64::new(0.0, 0.0);
            let todo: Vec<usize> = (0..width).filter(|&c| self.col_at[c].is_none()).collect();
            let sources: Vec<usize> = todo.iter().map(|&c| self.cols[c]).collect();
            let (mut a, mut parts) = (vec![zero; todo.len()], vec![zero; todo.len() * nrhs]);
            self.asm.row(self.rows[i], &sources, &mut a, &mut parts);
            let (mut ra, mut rp) = (vec![zero; width], vec![zero; width * nrhs]);
            for (t, &c) in todo.iter().enumerate() {
                ra[c] = a[t];
                rp[c * nrhs..(c + 1) * nrhs].copy_from_slice(&parts[t * nrhs..(t + 1) * nrhs]);
            }
            for (c, at) in self.col_at.iter().enumerate() {
                if let Some(k) = at {
                    let (ca, cp) = &self.fetched_cols[*k];
                    ra[c] = ca[i];
                    rp[c * nrhs..(c + 1) * nrhs].copy_from_slice(&cp[i * nrhs..(i + 1) * nrhs]);
                }
            }
            self.row_at[i] = Some(self.fetched_rows.len());
            self.fetched_rows.push((ra, rp));
        }
        self.row_at[i].map(|k| &self.fetched_rows[k]).unwrap_or_else(|| unreachable!())
    }

    /// Column `c` of the block, `A` and parts: evaluated where no fetched
    /// row crosses it.
    fn col(&mut self, c: usize) -> &(Vec<c64>, Vec<c64>) {
        if self.col_at[c].is_none() {
            let (m, nrhs) = (self.rows.len(), self.nrhs);
            let zero = c64::new(0.0, 0.0);
            let (mut ca, mut cp) = (vec![zero; m], vec![zero; m * nrhs]);
            for (i, at) in self.row_at.iter().enumerate() {
                let (a, p) = (&mut ca[i..=i], &mut cp[i * nrhs..(i + 1) * nrhs]);
                match at {
                    Some(k) => {
                        let (ra, rp) = &self.fetched_rows[*k];
                        a[0] = ra[c];
                        p.copy_from_slice(&rp[c * nrhs..(c + 1) * nrhs]);
                    }
                    None => self.asm.row(self.rows[i], &self.cols[c..=c], a, p),
                }
            }
            self.col_at[c] = Some(self.fetched_cols.len());
            self.fetched_cols.push((ca, cp));
        }
        self.col_at[c].map(|k| &self.fetched_cols[k]).unwrap_or_else(|| unreachable!())
    }

    /// The whole block, dense, and its right-hand side part (row-major
    /// `m × nrhs`, each row's parts summed in column order).
    fn dense(mut self) -> (Data, Vec<c64>) {
        let (m, width, nrhs) = (self.rows.len(), self.cols.len(), self.nrhs);
        let zero = c64::new(0.0, 0.0);
        let mut d = vec![zero; m * width];
        let mut rhs = vec![zero; m * nrhs];
        for ((i, row), b) in d.chunks_mut(width.max(1)).enumerate().zip(rhs.chunks_mut(nrhs)) {
            let (a, parts) = self.row(i);
            row.copy_from_slice(a);
            for part in parts.chunks(nrhs) {
                for (bf, p) in b.iter_mut().zip(part) {
                    *bf += p;
                }
            }
        }
        (Data::Dense(d), rhs)
    }
}

/// `M ≈ Σ_k u_k v_kᵀ` for [`aca`]: a matrix given by its rows and columns.
trait Crosses {
    /// Rows of `M`.
    fn rows(&self) -> usize;
    /// Columns of `M`.
    fn cols(&self) -> usize;
    /// Row `i` into `out`.
    fn row(&mut self, i: usize, out: &mut [c64]);
    /// Column `j` into `out`.
    fn col(&mut self, j: usize, out: &mut [c64]);
}

/// The side-by-side block `[A | s_1 R_1 | …]` (module doc) of some entries.
struct SideBySide<'e, 'a, 'b> {
    entries: &'e mut Entries<'a, 'b>,
    /// `s_f`.
    scale: Vec<f64>,
    /// Right-hand sides (`scale.len()`, possibly 0).
    fields: usize,
}

impl Crosses for SideBySide<'_, '_, '_> {
    fn rows(&self) -> usize {
        self.entries.rows.len()
    }

    fn cols(&self) -> usize {
        self.entries.cols.len() * (1 + self.fields)
    }

    fn row(&mut self, i: usize, out: &mut [c64]) {
        let (width, nrhs) = (self.entries.cols.len(), self.entries.nrhs);
        let (a, parts) = self.entries.row(i);
        out[..width].copy_from_slice(a);
        for (f, s) in self.scale.iter().enumerate() {
            for (c, x) in out[(1 + f) * width..(2 + f) * width].iter_mut().enumerate() {
                *x = parts[c * nrhs + f] * s;
            }
        }
    }

    fn col(&mut self, j: usize, out: &mut [c64]) {
        let (width, nrhs) = (self.entries.cols.len(), self.entries.nrhs);
        let (part, c) = (j / width, j % width);
        let (a, parts) = self.entries.col(c);
        if part == 0 {
            out.copy_from_slice(a);
        } else {
            let s = self.scale[part - 1];
            for (o, p) in out.iter_mut().zip(parts.chunks(nrhs)) {
                *o = p[part - 1] * s;
            }
        }
    }
}

/// The block `rows × cols` (module doc) and its right-hand side part
/// (row-major `m × nrhs`): low rank when `admissible` and ACA finds it
/// within half the smaller side, dense otherwise.
pub(crate) fn block(
    asm: &Assembly<'_>,
    rows: &[usize],
    cols: &[usize],
    admissible: bool,
) -> (Data, Vec<c64>) {
    let mut entries = Entries::new(asm, rows, cols);
    if admissible {
        if let Some(low) = low_rank(&mut entries) {
            return low;
        }
    }
    entries.dense()
}

/// The low-rank block of some entries (module doc) and its right-hand
/// side part, or `None` when ACA needs more than half the smaller side.
fn low_rank(entries: &mut Entries<'_, '_>) -> Option<(Data, Vec<c64>)> {
    let (m, width, nrhs) = (entries.rows.len(), entries.cols.len(), entries.asm.fields().len());
    let zero = c64::new(0.0, 0.0);
    let (a_norm, part_norms) = block_norms(entries, nrhs);
    let scale: Vec<f64> =
        part_norms.iter().map(|&s| if s > 0.0 && a_norm > 0.0 { a_norm / s } else { 1.0 }).collect();
    let mut side = SideBySide { entries, scale, fields: nrhs };
    let (u, v) = aca(&mut side, m.min(width) / 2)?;
    let w: Vec<Vec<c64>> = v.iter().map(|vk| vk[..width].to_vec()).collect();
    let mut rhs = vec![zero; m * nrhs];
    for (f, s) in side.scale.iter().enumerate() {
        for (uk, vk) in u.iter().zip(&v) {
            let t = vk[(1 + f) * width..(2 + f) * width].iter().sum::<c64>() / s;
            for (i, ui) in uk.iter().enumerate() {
                rhs[i * nrhs + f] += ui * t;
            }
        }
    }
    let (u, w) = crate::lowrank::recompress(&u, &w, ACA_TOLERANCE).unwrap_or((u, w));
    Some((Data::LowRank { u, w }, rhs))
}

/// `‖A‖` and each part's norm over the block's first row and first column:
/// the side-by-side scale `s_f = ‖A‖ / ‖R_f‖` makes ACA's relative tolerance
/// hold for `A` and each part alike. Row 0 alone can miss `A`: without the
/// hypersingular term (the CBIE, `α = 0`) a row whose panel is coplanar with
/// the block's columns has a double layer at rounding level, and the parts
/// scaled down to it lost their bits (right-hand sides 3.7·10⁸ off on a
/// flat-faced bar; test `a_conventional_system_on_a_flat_faced_bar_…`). The
/// column costs one more column of kernel evaluations where ACA would not
/// pivot there: no measurable time (a 15.7 kHz bowl group, three pairs).
/// Burton–Miller levels moved ≤ 0.1 dB (the tolerance's budget).
fn block_norms(entries: &mut Entries<'_, '_>, nrhs: usize) -> (f64, Vec<f64>) {
    let stride = entries.nrhs;
    let mut a2 = 0.0;
    let mut parts2 = vec![0.0; nrhs];
    let mut add = |(a, parts): &(Vec<c64>, Vec<c64>)| {
        a2 += a.iter().map(|z| z.norm_sqr()).sum::<f64>();
        for p in parts.chunks(stride) {
            for (sum, z) in parts2.iter_mut().zip(p) {
                *sum += z.norm_sqr();
            }
        }
    };
    add(entries.row(0));
    add(entries.col(0));
    (a2.sqrt(), parts2.into_iter().map(f64::sqrt).collect())
}

/// Partial-pivoting ACA (module doc) of an `m × n` matrix given by its rows
/// and columns: `(U, V)` with `M ≈ Σ_k u_k v_kᵀ` to [`ACA_TOLERANCE`], or
/// `None` when the rank would pass `max_rank`.
#[allow(clippy::type_complexity)]
fn aca(mat: &mut dyn Crosses, max_rank: usize) -> Option<(Vec<Vec<c64>>, Vec<Vec<c64>>)> {
    let (m, n) = (mat.rows(), mat.cols());
    let zero = c64::new(0.0, 0.0);
    let (mut us, mut vs): (Vec<Vec<c64>>, Vec<Vec<c64>>) = (Vec::new(), Vec::new());
    let mut used = vec![false; m];
    let mut norm2 = 0.0f64;
    let mut i = 0;
    loop {
        used[i] = true;
        let mut r = vec![zero; n];
        mat.row(i, &mut r);
        for (uk, vk) in us.iter().zip(&vs) {
            let a = uk[i];
            for (x, v) in r.iter_mut().zip(vk) {
                *x -= a * v;
            }
        }
        // Pivots by |x|² (no `hypot`): the same order as by |x|.
        let (j, pivot) = r.iter().enumerate().fold((0, 0.0f64), |best, (j, x)| {
            let a = x.norm_sqr();
            if a > best.1 {
                (j, a)
            } else {
                best
            }
        });
        if pivot == 0.0 {
            // Row `i` is already represented: try the next unused row.
            match used.iter().position(|&u| !u) {
                Some(next) => {
                    i = next;
                    continue;
                }
                None => break,
            }
        }
        if us.len() >= max_rank {
            return None;
        }
        let inv = 1.0 / r[j];
        let v: Vec<c64> = r.iter().map(|x| x * inv).collect();
        let mut u = vec![zero; m];
        mat.col(j, &mut u);
        for (uk, vk) in us.iter().zip(&vs) {
            let a = vk[j];
            for (x, w) in u.iter_mut().zip(uk) {
                *x -= a * w;
            }
        }
        let (uu, vv) = (sq(&u), sq(&v));
        let cross: f64 = us.iter().zip(&vs).map(|(uk, vk)| (cdot(uk, &u) * cdot(vk, &v)).re).sum();
        norm2 += uu * vv + 2.0 * cross;
        let next = (0..m)
            .filter(|&p| !used[p])
            .max_by(|&a, &b| u[a].norm_sqr().total_cmp(&u[b].norm_sqr()).then(b.cmp(&a)));
        us.push(u);
        vs.push(v);
        if (uu * vv).sqrt() <= ACA_TOLERANCE * norm2.max(0.0).sqrt() {
            break;
        }
        match next {
            Some(p) => i = p,
            None => break,
        }
    }
    Some((us, vs))
}

fn sq(a: &[c64]) -> f64 {
    a.iter().map(|z| z.norm_sqr()).sum()
}

/// `a^H b`.
fn cdot(a: &[c64], b: &[c64]) -> c64 {
    a.iter().zip(b).fold(c64::new(0.0, 0.0), |s, (x, y)| s + x.conj() * y)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An `m × n` matrix given entry by entry.
    pub(super) struct Entrywise<F: Fn(usize, usize) -> c64>(pub usize, pub usize, pub F);

    impl<F: Fn(usize, usize) -> c64> Crosses for Entrywise<F> {
        fn rows(&self) -> usize {
            self.0
        }
        fn cols(&self) -> usize {
            self.1
        }
        fn row(&mut self, i: usize, out: &mut [c64]) {
            out.iter_mut().enumerate().for_each(|(j, o)| *o = (self.2)(i, j));
        }
        fn col(&mut self, j: usize, out: &mut [c64]) {
            out.iter_mut().enumerate().for_each(|(i, o)| *o = (self.2)(i, j));
        }
    }

    #[test]
    fn aca_recovers_a_smooth_kernel_block_to_its_tolerance() {
        // e^{ik|x−y|}/|x−y| between two separated point rows: numerically low rank.
        let xs: Vec<f64> = (0..60).map(|i| i as f64 * 0.01).collect();
        let ys: Vec<f64> = (0..80).map(|j| 2.0 + j as f64 * 0.0125).collect();
        let k = 10.0;
        let f = |i: usize, j: usize| {
            let r = ys[j] - xs[i];
            c64::new((k * r).cos(), (k * r).sin()) / r
        };
        let (u, v) = aca(&mut Entrywise(60, 80, f), 30).expect("low rank");
        assert!(u.len() < 15, "rank {}", u.len());
        let (mut err, mut size) = (0.0, 0.0);
        for i in 0..60 {
            for j in 0..80 {
                let approx: c64 = u.iter().zip(&v).map(|(uk, vk)| uk[i] * vk[j]).sum();
                err += (approx - f(i, j)).norm_sqr();
                size += f(i, j).norm_sqr();
            }
        }
        let rel = (err / size).sqrt();
        assert!(rel < 10.0 * ACA_TOLERANCE, "relative error {rel}");
    }

    #[test]
    fn a_full_rank_block_gives_up() {
        let id = |i: usize, j: usize| c64::new(if i == j { 1.0 } else { 0.0 }, 0.0);
        let r = aca(&mut Entrywise(20, 20, id), 10);
        assert!(r.is_none());
    }
}

#[cfg(test)]
pub(crate) mod system_tests {
    use super::*;
    use crate::cluster::Clusters;
    use crate::kernels::Kernels;
    use crate::near::NearField;

    /// Two velocity fields on `mesh`: the normal velocity of a rigid motion
    /// along z, and the same plus an imaginary part varying along x.
    pub(crate) fn two_fields(mesh: &crate::geometry::BoundaryMesh) -> Vec<Vec<c64>> {
        [0.0, 1.0]
            .iter()
            .map(|s| mesh.panels.iter().map(|p| c64::new(p.normal[2], s * 30.0 * p.centroid[0])).collect())
            .collect()
    }

    /// A block completed from the rows and columns fetched so far holds the
    /// entries and right-hand side of a direct evaluation, bit for bit.
    #[test]
    fn fetched_rows_and_columns_complete_the_block_exactly() {
        let mesh = crate::geometry::tests::ellipsoid([0.1, 0.06, 0.04], 2);
        let near = NearField::new(&mesh);
        let k = 2.0 * std::f64::consts::PI * 3000.0 / 343.0;
        let clusters = Clusters::identity(mesh.len());
        let fields = two_fields(&mesh);
        let kern = Kernels::new(k);
        let asm = Assembly::new(&mesh, &near, &clusters, &kern, c64::new(0.0, 1.0 / k), &fields, true);
        let rows: Vec<usize> = (0..asm.len()).step_by(7).take(30).collect();
        let cols: Vec<usize> = (3..asm.len()).step_by(5).take(40).collect();
        let (m, n, nrhs) = (rows.len(), cols.len(), fields.len());
        let zero = c64::new(0.0, 0.0);
        let mut entries = Entries::new(&asm, &rows, &cols);
        for (i, c) in [(4, 9), (0, 0), (17, 39), (4, 21)] {
            entries.col(c);
            entries.row(i);
        }
        let (Data::Dense(d), rhs) = entries.dense() else { panic!("dense block expected") };
        let (mut a, mut parts) = (vec![zero; n], vec![zero; n * nrhs]);
        for (i, &row) in rows.iter().enumerate() {
            asm.row(row, &cols, &mut a, &mut parts);
            assert!(d[i * n..(i + 1) * n] == a[..], "row {i}");
            let b: Vec<c64> = (0..nrhs).map(|f| parts.chunks(nrhs).fold(zero, |s, p| s + p[f])).collect();
            assert!(rhs[i * nrhs..(i + 1) * nrhs] == b[..], "right-hand side of row {i}");
        }
        assert_eq!(d.len(), m * n);
    }
}
