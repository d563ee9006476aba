//! Assembly of the clustered Burton–Miller system of [`crate::bem`]:
//!
//! `Σ_c A_ic p_c = b_i`, `A_ic = ⟨Σ_{j∈c} ∫_j [½δ − ∂G/∂n_y − α ∂²G/∂n_x∂n_y] dS⟩_i`,
//! `b_i = −⟨Σ_j ∫_j [G + α(½δ + ∂G/∂n_x)] dS q_j⟩_i`,
//!
//! `⟨·⟩_i` the area-weighted mean over the collocation points (member
//! centroids) of cluster `i` for panels near it, its centre and mean normal
//! beyond ([`CLUSTER_NEAR_RATIO`]); `δ` marks a panel's own centroid.
//!
//! Each panel integral takes the cheapest rule that meets its error:
//!
//! - own centroid: polar coordinates ([`Kernels::self_integrals`]);
//! - near pairs ([`crate::near`], `r < 3h`): static part once per mesh plus
//!   the 7-point remainder;
//! - 3 to 8 diameters: the 3-point rule; beyond: the centroid
//!   ([`FAR_POINT_RATIO`], [`MID_POINT_RATIO`]);
//! - **whole clusters far from the point** ([`AGGREGATE_RATIO`]): the
//!   kernels are linear in the source normal, so the matrix entry of source
//!   cluster `c` (area centroid `y_c`, radius `ρ_c`) is one kernel at `y_c`
//!   with the summed normal, `Σ_j A_j K(x, y_j; n_j) ≈ K(x, y_c; Σ_j A_j n_j)`;
//!   the right-hand side, whose `q_j` varies inside the cluster, keeps its
//!   first two moments `Q = Σ A_j q_j`, `D = Σ A_j q_j (c_j − y_c)`:
//!   `Σ_j A_j q_j F(x, y_j) ≈ Q F(x, y_c) + D·∇_y F(x, y_c)` for
//!   `F = G + α ∂G/∂n_x`, where `D·∇_y G` and `D·∇_y ∂G/∂n_x` are the
//!   double-layer and hypersingular kernels with `n_y = D`. The error is
//!   `O((ρ_c/r)²)` of the cluster's contribution, like the centroid rule on
//!   one panel, and the far part costs one `sincos` per pair of clusters
//!   instead of one per (cluster, panel): `n²` instead of `n·N`.
//!
//! The kernel points of the fixed rules (centroid, 3-point, the near
//! remainder's 7 points, the far clusters' centroids) are gathered as a
//! row is swept and evaluated together in SIMD lanes ([`crate::batch`]).
//! A source cluster whose every panel takes the same far rule from the
//! row's centre (decided once from the cluster's bounds,
//! [`Assembly::uniform_far_rule`]) is read in place from columns kept for
//! the whole assembly instead of being tested and gathered panel by panel:
//! the same points, bits and order of sums.
//!
//! Rows are assembled in parallel, each by one thread in a fixed order:
//! bit-identical for any thread count.

use faer::c64;
use rayon::prelude::*;

use crate::batch::{Formula, SourceColumns, SourcePoints};
use crate::cluster::Clusters;
use crate::geometry::{dot, norm, sub, BoundaryMesh, Panel};
use crate::kernels::{CoupledKernels, Kernels, REMAINDER_MAX_KH};
use crate::near::NearField;
use crate::quadrature::{on_triangle, TRIANGLE_3, TRIANGLE_7};

/// Panels closer than this many (cluster radius + panel diameter) to a
/// cluster's centre are tested at every member centroid; farther ones at
/// the cluster's centre alone (the mean of a smooth kernel over the
/// cluster, to second order in its size). Also every panel within the
/// cluster radius plus [`MID_POINT_RATIO`] of its diameters, so that every
/// pair of the near field ([`crate::near`]) is met at its member point and
/// the cluster's centre never needs the adaptive rule.
pub const CLUSTER_NEAR_RATIO: f64 = 1.5;

/// Panels farther than this many diameters from the point (and with
/// `k·h ≤ 1`) are integrated by their centroid alone: relative error
/// `O((h/r)²)` of the smooth kernel: measured ≤ 0.4 % at k·h = 0, ≤ 2 %
/// at k·h = 1 (the phase across the panel).
pub const FAR_POINT_RATIO: f64 = 8.0;

/// Panels between this many and [`FAR_POINT_RATIO`] diameters from the
/// point (and with `k·h ≤ 1`) are integrated by the 3-point rule (degree
/// 2); closer ones from the near field or by the adaptive 7-point rule.
/// Relative error of the four kernels against the adaptive rule from 3
/// diameters on: ≤ 6.8·10⁻⁴ (k·d ≤ 1), against ≤ 2·10⁻² for the centroid
/// rule beyond [`FAR_POINT_RATIO`] (test `far_rules_meet_their_stated_error`).
pub const MID_POINT_RATIO: f64 = 3.0;

/// Panels with `1 < k·h ≤` this, farther than [`MID_POINT_RATIO`]
/// diameters, are integrated by the 3-point rule at any distance (the
/// centroid rule's phase error, `O((k·h)²)`, is too large for them).
/// The 3-point rule's error grows like `(k·h)³` (the phase across the
/// panel): measured ≤ 6·10⁻³ at `k·h = 2` from 3 to 16 diameters, below
/// the centroid rule's 2·10⁻² budget, against 2·10⁻⁵ for the 7-point rule
/// they used to get, at 3 kernel evaluations instead of 7 (test
/// `far_rules_meet_their_stated_error`). Beyond it the 7-point rule.
pub const THREE_POINT_MAX_KH: f64 = 2.0;

/// A source cluster is summed as one point (module doc) when the row's
/// point is farther than this many of its radii `ρ_c` from its centroid
/// (and `k·ρ_c ≤ 1`, and no member is near the row's cluster).
pub const AGGREGATE_RATIO: f64 = 8.0;

/// A source panel as the far rules read it, stored in cluster order so
/// that a row's sweep over a cluster reads consecutive memory: centroid, normal,
/// area, diameter, the points of the 3-point rule and its index in the mesh.
struct SourcePanel {
    centroid: [f64; 3],
    normal: [f64; 3],
    area: f64,
    diameter: f64,
    points: [[f64; 3]; 3],
    index: usize,
}

impl SourcePanel {
    fn new(mesh: &BoundaryMesh, index: usize) -> SourcePanel {
        let p = &mesh.panels[index];
        let t = p.corners.map(|i| mesh.vertices[i]);
        let points = TRIANGLE_3.map(|(b, _)| on_triangle(b, t));
        SourcePanel {
            centroid: p.centroid,
            normal: p.normal,
            area: p.area,
            diameter: p.diameter,
            points,
            index,
        }
    }
}

/// A cluster as test region and as source: its panels with area weights,
/// its area-weighted centre and normal, its radius about the centre
/// (member centroid distance plus diameter), its area, the area-weighted
/// sum of its normals, its largest and smallest panel diameters, and its
/// panels' range in [`Assembly::sources`].
struct Region {
    members: Vec<(usize, f64)>,
    centre: [f64; 3],
    normal: [f64; 3],
    radius: f64,
    normal_sum: [f64; 3],
    max_diameter: f64,
    min_diameter: f64,
    span: std::ops::Range<usize>,
}

/// The regions of `clusters` and the source panels in cluster order.
fn regions(mesh: &BoundaryMesh, clusters: &Clusters) -> (Vec<Region>, Vec<SourcePanel>) {
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); clusters.len()];
    for (p, &c) in clusters.of_panel.iter().enumerate() {
        members[c].push(p);
    }
    let mut regions = members
        .into_iter()
        .map(|m| {
            let area: f64 = m.iter().map(|&p| mesh.panels[p].area).sum();
            let sum = |f: &dyn Fn(&Panel) -> [f64; 3]| {
                [0, 1, 2].map(|k| m.iter().map(|&p| mesh.panels[p].area * f(&mesh.panels[p])[k]).sum::<f64>())
            };
            let centre = sum(&|p| p.centroid).map(|x| x / area);
            let normal_sum = sum(&|p| p.normal);
            let len = norm(normal_sum);
            let radius = m
                .iter()
                .map(|&p| norm(sub(mesh.panels[p].centroid, centre)) + mesh.panels[p].diameter)
                .fold(0.0, f64::max);
            let max_diameter = m.iter().map(|&p| mesh.panels[p].diameter).fold(0.0, f64::max);
            let min_diameter = m.iter().map(|&p| mesh.panels[p].diameter).fold(f64::INFINITY, f64::min);
            let members = m.iter().map(|&p| (p, mesh.panels[p].area / area)).collect();
            let normal = normal_sum.map(|x| x / len);
            Region { members, centre, normal, radius, normal_sum, max_diameter, min_diameter, span: 0..0 }
        })
        .collect::<Vec<_>>();
    let mut sources = Vec::with_capacity(mesh.len());
    for region in &mut regions {
        let first = sources.len();
        sources.extend(region.members.iter().map(|&(j, _)| SourcePanel::new(mesh, j)));
        region.span = first..sources.len();
    }
    (regions, sources)
}

/// `Σ A_j q_j` and `Σ A_j q_j (c_j − y_c)` (real and imaginary parts) of one
/// velocity field over one cluster.
#[derive(Clone, Copy)]
struct Moments {
    q: c64,
    d_re: [f64; 3],
    d_im: [f64; 3],
}

/// The operators of one solve: the geometry, the kernels at one wavenumber,
/// the velocity fields, and per cluster its region and velocity moments.
/// Gives the system's entries and each source cluster's part of the
/// right-hand sides, for any rows and source clusters ([`Assembly::row`]):
/// all of them (the dense assembly) or blocks ([`crate::hmatrix`]).
pub(crate) struct Assembly<'a> {
    mesh: &'a BoundaryMesh,
    near_field: &'a NearField,
    kern: &'a Kernels,
    alpha: c64,
    q: &'a [Vec<c64>],
    aggregate: bool,
    coupled: CoupledKernels,
    regions: Vec<Region>,
    sources: Vec<SourcePanel>,
    moments: Vec<Vec<Moments>>,
    /// The source panels' centroid-rule points and 3-point-rule points
    /// (three per panel) as columns, in [`Assembly::sources`] order, and
    /// the velocity fields in that order: the far panels of a source
    /// cluster seen from one point ([`Assembly::add_far_panels`]).
    centroid_points: SourceColumns,
    three_points: SourceColumns,
    q_in_source_order: Vec<Vec<c64>>,
}

impl<'a> Assembly<'a> {
    /// The system at wavenumber `kern.k()` with Burton–Miller coupling
    /// `alpha` for the panel densities `q` (one field per entry,
    /// `q_j = iωρ₀ v_j`); `aggregate` allows the far cluster sums (module
    /// doc), off every panel is integrated on its own.
    pub(crate) fn new(
        mesh: &'a BoundaryMesh,
        near_field: &'a NearField,
        clusters: &Clusters,
        kern: &'a Kernels,
        alpha: c64,
        q: &'a [Vec<c64>],
        aggregate: bool,
    ) -> Assembly<'a> {
        let zero = c64::new(0.0, 0.0);
        let (regions, sources) = regions(mesh, clusters);
        let moments = regions
            .iter()
            .map(|src| {
                q.iter()
                    .map(|qf| {
                        let mut m = Moments { q: zero, d_re: [0.0; 3], d_im: [0.0; 3] };
                        for &(j, _) in &src.members {
                            let p = &mesh.panels[j];
                            let aq = qf[j] * p.area;
                            let d = sub(p.centroid, src.centre);
                            m.q += aq;
                            for ((re, im), dc) in m.d_re.iter_mut().zip(&mut m.d_im).zip(d) {
                                *re += aq.re * dc;
                                *im += aq.im * dc;
                            }
                        }
                        m
                    })
                    .collect()
            })
            .collect();
        let coupled = CoupledKernels::new(kern.k(), alpha);
        let (mut centroid_points, mut three_points) = (SourceColumns::default(), SourceColumns::default());
        for src in &sources {
            // The weights exactly as the gathered rules form them (`1·A`, `1·w_q·A`).
            centroid_points.push(src.centroid, src.normal, src.area);
            for (y, (_, wq)) in src.points.iter().zip(TRIANGLE_3) {
                three_points.push(*y, src.normal, wq * src.area);
            }
        }
        debug_assert_eq!(three_points.len(), 3 * centroid_points.len());
        let q_in_source_order = q.iter().map(|qf| sources.iter().map(|s| qf[s.index]).collect()).collect();
        Assembly {
            mesh,
            near_field,
            kern,
            alpha,
            q,
            aggregate,
            coupled,
            regions,
            sources,
            moments,
            centroid_points,
            three_points,
            q_in_source_order,
        }
    }

    /// Number of unknowns (clusters).
    pub(crate) fn len(&self) -> usize {
        self.regions.len()
    }

    /// The velocity fields `q`.
    pub(crate) fn fields(&self) -> &[Vec<c64>] {
        self.q
    }

    /// Centre of cluster `c` and the box of its panels' corners (low, high).
    pub(crate) fn bounds(&self, c: usize) -> ([f64; 3], [f64; 3], [f64; 3]) {
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for &(j, _) in &self.regions[c].members {
            for v in self.mesh.panels[j].corners.map(|i| self.mesh.vertices[i]) {
                for k in 0..3 {
                    lo[k] = lo[k].min(v[k]);
                    hi[k] = hi[k].max(v[k]);
                }
            }
        }
        (self.regions[c].centre, lo, hi)
    }

    /// Row `i` of `A` over the source clusters `sources`, written into `row`
    /// (one entry per source), and each source's part of the right-hand sides,
    /// `R_f(i, c) = Σ_{j∈c} op_ij q_fj`, into `b` (row-major, one row of
    /// `nrhs` per source: `b_i = Σ_c R(i, c)`). Far source clusters are
    /// summed as points when `aggregate` (module doc).
    pub(crate) fn row(&self, i: usize, sources: &[usize], row: &mut [c64], b: &mut [c64]) {
        GATHERED.with(|cell| self.row_gathered(i, sources, row, b, &mut cell.borrow_mut()));
    }

    /// [`Assembly::row`]: the source points of the centroid, 3-point and
    /// near-remainder rules are gathered into `g` and evaluated in SIMD
    /// lanes ([`crate::batch`]) after the rest of the row.
    fn row_gathered(&self, i: usize, sources: &[usize], row: &mut [c64], b: &mut [c64], g: &mut Gathered) {
        let k = self.kern.k();
        let region = &self.regions[i];
        let nrhs = self.q.len().max(1);
        g.coupled.clear();
        g.remainder.clear();
        g.far.clear();
        for (slot_index, ((slot, &c), b)) in row.iter_mut().zip(sources).zip(b.chunks_mut(nrhs)).enumerate() {
            *slot = c64::new(0.0, 0.0);
            b.fill(c64::new(0.0, 0.0));
            let src = &self.regions[c];
            let r = norm(sub(src.centre, region.centre));
            let clear = r - src.radius;
            let far_cluster = self.aggregate
                && k * src.radius <= 1.0
                && r > AGGREGATE_RATIO * src.radius
                && clear >= CLUSTER_NEAR_RATIO * (region.radius + src.max_diameter)
                && clear >= region.radius + MID_POINT_RATIO * src.max_diameter;
            if far_cluster {
                g.far.push((region.centre, region.normal), src.centre, [0.0; 3], 1.0, slot_index, c);
                continue;
            }
            if let Some(rule) = self.uniform_far_rule(region, src, r) {
                self.add_far_panels(region, src, rule, slot, b);
                continue;
            }
            for panel in &self.sources[src.span.clone()] {
                let (a, op) = self.pair(i, panel, slot_index, g);
                *slot += a;
                for (bf, qf) in b.iter_mut().zip(self.q) {
                    *bf += op * qf[panel.index];
                }
            }
        }
        self.add_gathered(&mut g.coupled, Formula::Coupled, row, b);
        self.add_gathered(&mut g.remainder, Formula::Remainder, row, b);
        self.add_far_clusters(i, &mut g.far, row, b);
    }

    /// The one rule [`Assembly::off_panel`] would take for every panel of
    /// source cluster `src` (centre `r` from `region`'s) seen from
    /// `region`'s centre, when there is one: every panel is then off the
    /// near tests ([`is_near`]) and integrated by its centroid, or every
    /// panel by the 3-point rule. Each panel's centroid is at least
    /// `r − ρ_src + h_j` from the centre, so bounds on the cluster decide for
    /// all of its panels at once.
    fn uniform_far_rule(&self, region: &Region, src: &Region, r: f64) -> Option<OffRule> {
        let (clear, h_max) = (r - src.radius, src.max_diameter);
        let off_near = region.members.len() > 1
            && clear >= CLUSTER_NEAR_RATIO * (region.radius + h_max)
            && clear >= region.radius + MID_POINT_RATIO * h_max;
        if !off_near {
            return None;
        }
        let k = self.kern.k();
        if k * h_max <= 1.0 && clear > FAR_POINT_RATIO * h_max {
            Some(OffRule::Centroid)
        } else if k * src.min_diameter > 1.0
            && k * h_max <= THREE_POINT_MAX_KH
            && clear > MID_POINT_RATIO * h_max
        {
            Some(OffRule::ThreePoint)
        } else {
            None
        }
    }

    /// Adds source cluster `src`'s panels, every one by `rule` seen from
    /// `region`'s centre ([`Assembly::uniform_far_rule`]), to the row entry
    /// `slot` and its right-hand-side parts `b`: the points are read from
    /// the assembly's columns instead of gathered, and summed in the order
    /// (and with the bits) the gathered path would sum them.
    fn add_far_panels(&self, region: &Region, src: &Region, rule: OffRule, slot: &mut c64, b: &mut [c64]) {
        let (columns, per_panel) = match rule {
            OffRule::Centroid => (&self.centroid_points, 1),
            OffRule::ThreePoint => (&self.three_points, 3),
            OffRule::Adaptive => unreachable!("uniform_far_rule never gives the adaptive rule"),
        };
        debug_assert!(self.sources[src.span.clone()].iter().all(|panel| {
            let dist = norm(sub(panel.centroid, region.centre));
            !is_near(region, panel, dist) && self.off_rule(panel, dist) == rule
        }));
        let range = per_panel * src.span.start..per_panel * src.span.end;
        columns.for_each_coupled(&self.coupled, (region.centre, region.normal), range, |p, a, op| {
            *slot += a;
            for (bf, qf) in b.iter_mut().zip(&self.q_in_source_order) {
                *bf += op * qf[p / per_panel];
            }
        });
    }

    /// Evaluates the far source clusters gathered in `pts` (one point at
    /// each centroid, owner = its cluster) and adds each as the module doc
    /// says: the matrix entry `a(Σ A_j n_j)`, the right-hand sides
    /// `op·Q + a(D)` (`a` linear in the normal, [`Formula::Linear`]).
    fn add_far_clusters(&self, i: usize, pts: &mut SourcePoints, row: &mut [c64], b: &mut [c64]) {
        if pts.len() == 0 {
            return;
        }
        let region = &self.regions[i];
        let nrhs = self.q.len().max(1);
        pts.evaluate(&self.coupled, Formula::Linear);
        for (p, (slot, c)) in pts.owners().enumerate() {
            let (dn, nn, op) = pts.linear_weights(p);
            let src = &self.regions[c];
            let d = sub(src.centre, region.centre);
            let a = |n: [f64; 3]| dn * dot(d, n) + nn * dot(region.normal, n);
            row[slot] += a(src.normal_sum);
            for (bf, m) in b[slot * nrhs..(slot + 1) * nrhs].iter_mut().zip(&self.moments[c]) {
                *bf += op * m.q + a(m.d_re) + c64::new(0.0, 1.0) * a(m.d_im);
            }
        }
    }

    /// Evaluates the gathered points `pts` by `formula` and adds each to
    /// its row entry and right-hand-side parts.
    fn add_gathered(&self, pts: &mut SourcePoints, formula: Formula, row: &mut [c64], b: &mut [c64]) {
        if pts.len() == 0 {
            return;
        }
        let nrhs = self.q.len().max(1);
        pts.evaluate(&self.coupled, formula);
        for (p, (slot, panel)) in pts.owners().enumerate() {
            let (a, op) = pts.weights(p);
            row[slot] += a;
            for (bf, qf) in b[slot * nrhs..(slot + 1) * nrhs].iter_mut().zip(self.q) {
                *bf += op * qf[panel];
            }
        }
    }

    /// Panel `src`'s weights in row `i` (`slot` in the row): its term of
    /// `A_ic` (`c` its cluster) and its factor `op` in `b_i += op·q_j`.
    /// Returns the part integrated here; the points of the fixed rules
    /// go to `g`, to be added by [`Assembly::add_gathered`].
    fn pair(&self, i: usize, src: &SourcePanel, slot: usize, g: &mut Gathered) -> (c64, c64) {
        let (kern, mesh, alpha) = (self.kern, self.mesh, self.alpha);
        let zero = c64::new(0.0, 0.0);
        let region = &self.regions[i];
        let dist = norm(sub(src.centroid, region.centre));
        if !is_near(region, src, dist) {
            return self.off_panel(src, (region.centre, region.normal), dist, 1.0, slot, g);
        }
        let j = src.index;
        let pj = &mesh.panels[j];
        let (mut a, mut op) = (zero, zero);
        for &(t, w) in &region.members {
            let pt = &mesh.panels[t];
            let seen_from = (pt.centroid, pt.normal);
            let (panels, statics) = self.near_field.row(t);
            // The near field holds exactly the panels with |c_j − c_t| < 3 h_j
            // (crate::near): only those can be found in t's row.
            let d = sub(src.centroid, pt.centroid);
            let reach = MID_POINT_RATIO * src.diameter;
            let in_reach = t != j && dot(d, d) < reach * reach;
            let near_index = if in_reach { panels.binary_search(&(j as u32)).ok() } else { None };
            let (ints, half) = if t == j {
                (kern.self_integrals(mesh, pj), 0.5)
            } else if let Some(s) = near_index {
                let (da, dop) = self.near_remainder(src, seen_from, w, slot, g);
                a += da;
                op += dop;
                (statics[s].at(kern.k()), 0.0)
            } else {
                let (da, dop) = self.off_panel(src, seen_from, norm(d), w, slot, g);
                a += da;
                op += dop;
                continue;
            };
            a += (c64::new(half, 0.0) - ints.dg_dny - alpha * ints.d2g) * w;
            // −(L + α(½ + K')) q_j
            op -= (ints.g + alpha * (ints.dg_dnx + half)) * w;
        }
        (a, op)
    }

    /// `w ×` the remainder term of near panel `src` seen from `seen_from`
    /// (point, normal): its seven points gathered, or when the remainder
    /// must be split (`k·h >` [`REMAINDER_MAX_KH`]) integrated here.
    fn near_remainder(
        &self,
        src: &SourcePanel,
        seen_from: ([f64; 3], [f64; 3]),
        w: f64,
        slot: usize,
        g: &mut Gathered,
    ) -> (c64, c64) {
        let panel = &self.mesh.panels[src.index];
        if self.kern.k() * panel.diameter > REMAINDER_MAX_KH {
            let ints = self.kern.remainder(self.mesh, panel, seen_from.0, seen_from.1);
            return ((-ints.dg_dny - self.alpha * ints.d2g) * w, -(ints.g + self.alpha * ints.dg_dnx) * w);
        }
        let t = panel.corners.map(|c| self.mesh.vertices[c]);
        for (b, wq) in TRIANGLE_7 {
            g.remainder.push(seen_from, on_triangle(b, t), src.normal, w * wq * src.area, slot, src.index);
        }
        (c64::new(0.0, 0.0), c64::new(0.0, 0.0))
    }

    /// `w × (a, op)` of panel `src` seen from `seen_from` (point, normal)
    /// at distance `r` from its centroid, off its near field, by
    /// [`Assembly::off_rule`]: the points of the centroid and 3-point rules
    /// gathered, the adaptive rule integrated here.
    fn off_panel(
        &self,
        src: &SourcePanel,
        seen_from: ([f64; 3], [f64; 3]),
        r: f64,
        w: f64,
        slot: usize,
        g: &mut Gathered,
    ) -> (c64, c64) {
        let zero = c64::new(0.0, 0.0);
        match self.off_rule(src, r) {
            OffRule::Centroid => {
                g.coupled.push(seen_from, src.centroid, src.normal, w * src.area, slot, src.index);
                (zero, zero)
            }
            OffRule::ThreePoint => {
                for (y, (_, wq)) in src.points.iter().zip(TRIANGLE_3) {
                    g.coupled.push(seen_from, *y, src.normal, w * wq * src.area, slot, src.index);
                }
                (zero, zero)
            }
            OffRule::Adaptive => {
                let ints = self.kern.panel(self.mesh, &self.mesh.panels[src.index], seen_from.0, seen_from.1);
                ((-ints.dg_dny - self.alpha * ints.d2g) * w, -(ints.g + self.alpha * ints.dg_dnx) * w)
            }
        }
    }

    /// The rule [`Assembly::off_panel`] integrates panel `src` by at
    /// distance `r` from its centroid: its centroid alone when far
    /// ([`FAR_POINT_RATIO`]) and `k·h ≤ 1`, three points at mid range
    /// ([`MID_POINT_RATIO`]) or when far with `k·h ≤`
    /// [`THREE_POINT_MAX_KH`], the adaptive rule otherwise.
    fn off_rule(&self, src: &SourcePanel, r: f64) -> OffRule {
        let kh = self.kern.k() * src.diameter;
        if kh <= 1.0 && r > FAR_POINT_RATIO * src.diameter {
            OffRule::Centroid
        } else if kh <= THREE_POINT_MAX_KH && r > MID_POINT_RATIO * src.diameter {
            OffRule::ThreePoint
        } else {
            OffRule::Adaptive
        }
    }
}

/// How a panel off its near field is integrated ([`Assembly::off_rule`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum OffRule {
    Centroid,
    ThreePoint,
    Adaptive,
}

/// Whether source panel `src` at distance `dist` from `region`'s centre is
/// tested at every member centroid of `region` ([`CLUSTER_NEAR_RATIO`]);
/// otherwise at the centre alone.
fn is_near(region: &Region, src: &SourcePanel, dist: f64) -> bool {
    region.members.len() == 1
        || dist < CLUSTER_NEAR_RATIO * (region.radius + src.diameter)
        || dist < region.radius + MID_POINT_RATIO * src.diameter
}

/// A row's gathered source points ([`crate::batch`]): of the coupled
/// kernels (centroid and 3-point rules), of the near remainders, and the
/// far clusters' centroids.
#[derive(Default)]
struct Gathered {
    coupled: SourcePoints,
    remainder: SourcePoints,
    far: SourcePoints,
}

thread_local! {
    /// Each thread's gathered source points, reused from row to row.
    static GATHERED: std::cell::RefCell<Gathered> = std::cell::RefCell::new(Gathered::default());
}

/// The dense system of an [`Assembly`]: row `i` (cluster `i`) of `A` is
/// stored as column `i` of the returned `at` (column-major `n × n`, i.e.
/// `at = Aᵀ`); the right-hand sides come back row-major `n × nrhs`.
pub(crate) fn assemble_dense(asm: &Assembly<'_>) -> (Vec<c64>, Vec<c64>) {
    let n = asm.len();
    let nrhs = asm.q.len();
    let zero = c64::new(0.0, 0.0);
    let sources: Vec<usize> = (0..n).collect();
    let mut at = vec![zero; n * n];
    let mut rhs = vec![zero; n * nrhs];
    at.par_chunks_mut(n).zip(rhs.par_chunks_mut(nrhs.max(1))).enumerate().for_each(|(i, (row, b))| {
        let mut parts = vec![zero; n * nrhs];
        asm.row(i, &sources, row, &mut parts);
        for part in parts.chunks(nrhs.max(1)) {
            for (bf, p) in b.iter_mut().zip(part) {
                *bf += p;
            }
        }
    });
    (at, rhs)
}

/// [`assemble_dense`] of a new [`Assembly`].
#[cfg(test)]
pub(crate) fn assemble(
    mesh: &BoundaryMesh,
    near_field: &NearField,
    clusters: &Clusters,
    kern: &Kernels,
    alpha: c64,
    q: &[Vec<c64>],
    aggregate: bool,
) -> (Vec<c64>, Vec<c64>) {
    assemble_dense(&Assembly::new(mesh, near_field, clusters, kern, alpha, q, aggregate))
}
