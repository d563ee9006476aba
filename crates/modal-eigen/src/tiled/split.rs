//! Two-core split of the tiled sweeps along the supernodal elimination tree.
//!
//! Supernodes in different subtrees never touch each other's unknowns: in the forward
//! sweep a supernode updates only its ancestors, in the backward sweep it reads only them.
//! So the tree is cut into a *top* (a few supernodes near the root, on the nested-dissection
//! separators) and disjoint subtrees below it, dealt to two *bins* of about equal work:
//!
//! - forward: the bins run in parallel, bin 1 on a private copy of the right-hand sides
//!   whose top rows start at zero (so they collect exactly bin 1's updates, added afterwards);
//!   then the top runs;
//! - backward: the top runs first; then the bins in parallel, bin 1 again on its copy.
//!
//! The cut depends on the factor's structure only, so the arithmetic — and the result, bit for
//! bit — is the same whether the bins run on two threads or one after the other.

use std::ops::Range;

/// Below this many factor values the sweeps are not split (copies would dominate).
pub const MIN_SPLIT_VALUES: usize = 1 << 20;
/// Stop refining the cut when the bins differ by less than this share of all work.
const BALANCE: f64 = 0.02;
/// Refinement steps (each moves one subtree root into the top).
const MAX_STEPS: usize = 64;

/// The cut: the supernodes of each bin and of the top (ascending runs of indices: children
/// come before parents), and the rows (permuted unknowns) of bin 1 and of the top.
pub struct Split {
    /// Per bin, its supernodes.
    pub bins: [Vec<Range<usize>>; 2],
    /// The top supernodes.
    pub top: Vec<Range<usize>>,
    /// Rows of bin 1's supernodes.
    pub bin1_rows: Vec<Range<usize>>,
    /// Rows of the top supernodes.
    pub top_rows: Vec<Range<usize>>,
}

/// Cuts the tree given, per supernode, its first column, column count, parent (`None` at a
/// root; always a later supernode) and work (factor values). `None` if the factor has fewer
/// than `min_values` values or no cut beats running on one core.
pub fn split(
    starts: &[usize],
    ncols: &[usize],
    parent: &[Option<usize>],
    work: &[usize],
    min_values: usize,
) -> Option<Split> {
    let count = starts.len();
    let total: usize = work.iter().sum();
    if total < min_values {
        return None;
    }
    let mut children = vec![Vec::new(); count];
    let mut roots = Vec::new();
    let mut subtree_work = work.to_vec();
    for s in 0..count {
        match parent[s] {
            Some(p) if p > s => {
                children[p].push(s);
                subtree_work[p] += subtree_work[s];
            }
            Some(_) => return None,
            None => roots.push(s),
        }
    }
    let (mut top, mut frontier) = (Vec::new(), roots);
    // (estimated time, top, bins) of the best cut seen.
    let mut best: Option<(f64, Vec<usize>, [Vec<usize>; 2])> = None;
    for _ in 0..MAX_STEPS {
        let bins = deal(&frontier, &subtree_work);
        let load = |b: &Vec<usize>| b.iter().map(|&r| subtree_work[r]).sum::<usize>() as f64;
        let (w0, w1) = (load(&bins[0]), load(&bins[1]));
        let top_work = top.iter().map(|&s| work[s]).sum::<usize>() as f64;
        let time = w0.max(w1) + top_work;
        if best.as_ref().is_none_or(|b| time < b.0) {
            best = Some((time, top.clone(), bins.clone()));
        }
        if (w0 - w1).abs() <= BALANCE * total as f64 {
            break;
        }
        // Open the largest subtree that has children.
        let Some(pos) = (0..frontier.len())
            .filter(|&i| !children[frontier[i]].is_empty())
            .max_by_key(|&i| subtree_work[frontier[i]])
        else {
            break;
        };
        let root = frontier.swap_remove(pos);
        top.push(root);
        frontier.extend(&children[root]);
    }
    let (time, top, bins) = best?;
    if time >= 0.9 * total as f64 || bins.iter().any(Vec::is_empty) {
        return None;
    }
    // Supernode lists in ascending order (children before parents), as runs of indices.
    let subtrees = |roots: &[usize]| -> Vec<Range<usize>> {
        let mut nodes = Vec::new();
        let mut stack = roots.to_vec();
        while let Some(s) = stack.pop() {
            nodes.push(s);
            stack.extend(&children[s]);
        }
        runs(nodes)
    };
    // A run of supernodes covers consecutive columns.
    let rows = |nodes: &[Range<usize>]| -> Vec<Range<usize>> {
        nodes.iter().map(|r| starts[r.start]..starts[r.end - 1] + ncols[r.end - 1]).collect()
    };
    let bins = [subtrees(&bins[0]), subtrees(&bins[1])];
    let top = runs(top);
    Some(Split { bin1_rows: rows(&bins[1]), top_rows: rows(&top), bins, top })
}

/// Sorted runs of consecutive indices: [3, 4, 5, 9] → [3..6, 9..10].
fn runs(mut nodes: Vec<usize>) -> Vec<Range<usize>> {
    nodes.sort_unstable();
    let mut out: Vec<Range<usize>> = Vec::new();
    for s in nodes {
        match out.last_mut() {
            Some(r) if r.end == s => r.end += 1,
            _ => out.push(s..s + 1),
        }
    }
    out
}

/// Longest-processing-time deal of subtrees to two bins.
fn deal(roots: &[usize], subtree_work: &[usize]) -> [Vec<usize>; 2] {
    let mut sorted = roots.to_vec();
    sorted.sort_by_key(|&r| (std::cmp::Reverse(subtree_work[r]), r));
    let mut bins = [Vec::new(), Vec::new()];
    let mut load = [0usize; 2];
    for r in sorted {
        let b = usize::from(load[1] < load[0]);
        load[b] += subtree_work[r];
        bins[b].push(r);
    }
    bins
}
