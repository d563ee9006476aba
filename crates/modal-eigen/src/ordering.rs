//! Fill-reducing orderings for the sparse factorization of `K − σM`.
//!
//! Nested dissection (George 1973) via METIS `METIS_NodeND` on the *node* graph: the
//! stiffness of 3D elasticity couples all 3 DOFs of two nodes, so ordering the node graph
//! (1/9 of the DOF graph's entries) and expanding node `p` to DOFs `3p, 3p+1, 3p+2`
//! gives the same quality in a ninth of the time. The permutation convention follows
//! faer and METIS: `fwd[new] = old`, `inv[old] = new`.

use faer::sparse::SymbolicSparseColMatRef;

/// A permutation pair: `fwd[new] = old`, `inv[old] = new`.
#[derive(Clone, Debug)]
pub struct Permutation {
    /// New position → old index.
    pub fwd: Vec<usize>,
    /// Old index → new position.
    pub inv: Vec<usize>,
}

/// METIS nested dissection of the node graph of a matrix with 3 DOFs per node
/// (DOF `3i + c` belongs to node `i`). Returns `None` if the DOF count is not a
/// multiple of 3, the graph is too large for METIS' 32-bit indices, or METIS fails.
pub fn metis_node_ordering(pattern: SymbolicSparseColMatRef<'_, usize>) -> Option<Permutation> {
    let n = pattern.nrows();
    if n == 0 || n % 3 != 0 {
        return None;
    }
    let nodes = n / 3;
    let (xadj, adjncy) = node_graph(pattern, nodes)?;
    let node_perm = metis_nd(nodes, xadj, adjncy)?;
    let mut fwd = Vec::with_capacity(n);
    for &node in &node_perm {
        fwd.extend([3 * node, 3 * node + 1, 3 * node + 2]);
    }
    let mut inv = vec![0usize; n];
    for (new, &old) in fwd.iter().enumerate() {
        inv[old] = new;
    }
    Some(Permutation { fwd, inv })
}

/// Node adjacency (CSR, no self loops, deduplicated) in METIS' 32-bit format, from the
/// upper (or full) DOF pattern. Each node's lower neighbours are found once with a stamp
/// per node (no sorting) and entered in both directions; two passes (degrees, then lists)
/// build the arrays in place.
fn node_graph(pattern: SymbolicSparseColMatRef<'_, usize>, nodes: usize) -> Option<(Vec<i32>, Vec<i32>)> {
    // Calls `edge(a, b)` once per node pair a > b coupled by some entry.
    let each_edge = |edge: &mut dyn FnMut(usize, usize)| {
        let mut stamp = vec![usize::MAX; nodes];
        for a in 0..nodes {
            for j in 3 * a..3 * a + 3 {
                for r in pattern.row_idx_of_col(j) {
                    let b = r / 3;
                    if b < a && stamp[b] != a {
                        stamp[b] = a;
                        edge(a, b);
                    }
                }
            }
        }
    };
    let mut degree = vec![0usize; nodes];
    each_edge(&mut |a, b| {
        degree[a] += 1;
        degree[b] += 1;
    });
    let mut xadj = Vec::with_capacity(nodes + 1);
    xadj.push(0usize);
    for d in &degree {
        xadj.push(xadj.last().copied().unwrap_or(0) + d);
    }
    let total = *xadj.last()?;
    if total > i32::MAX as usize {
        return None;
    }
    let mut fill = xadj[..nodes].to_vec();
    let mut adjncy = vec![0i32; total];
    each_edge(&mut |a, b| {
        adjncy[fill[a]] = b as i32;
        fill[a] += 1;
        adjncy[fill[b]] = a as i32;
        fill[b] += 1;
    });
    Some((xadj.into_iter().map(|x| x as i32).collect(), adjncy))
}

/// METIS keeps its random number generator in process-wide statics (GKlib's `random.c`,
/// reseeded at the start of every call): two calls at once race on it (undefined behaviour,
/// and orderings — hence eigenvectors — that change with whatever else runs). Calls take
/// turns; the lock is held for the 0.1 s an ordering takes.
static METIS_LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Calls `METIS_NodeND`; returns `perm` with `perm[new] = old`.
fn metis_nd(nodes: usize, mut xadj: Vec<i32>, mut adjncy: Vec<i32>) -> Option<Vec<usize>> {
    let mut nvtxs = i32::try_from(nodes).ok()?;
    let mut options = vec![0i32; metis_sys::METIS_NOPTIONS as usize];
    let mut perm = vec![0i32; nodes];
    let mut iperm = vec![0i32; nodes];
    // A poisoned lock only means another ordering panicked; METIS reseeds on entry.
    let _turn = METIS_LOCK.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    // SAFETY: all arrays are sized as METIS documents (xadj: nvtxs+1, adjncy: xadj[nvtxs],
    // options: METIS_NOPTIONS, perm/iperm: nvtxs) and live across the calls; METIS_LOCK
    // serializes METIS' global state.
    let status = unsafe {
        metis_sys::METIS_SetDefaultOptions(options.as_mut_ptr());
        options[metis_sys::moptions_et_METIS_OPTION_NUMBERING as usize] = 0;
        metis_sys::METIS_NodeND(
            &mut nvtxs,
            xadj.as_mut_ptr(),
            adjncy.as_mut_ptr(),
            std::ptr::null_mut(),
            options.as_mut_ptr(),
            perm.as_mut_ptr(),
            iperm.as_mut_ptr(),
        )
    };
    if status != metis_sys::rstatus_et_METIS_OK {
        return None;
    }
    let perm: Vec<usize> = perm.iter().map(|&p| p as usize).collect();
    // Validate: must be a permutation of 0..nodes.
    let mut seen = vec![false; nodes];
    for &p in &perm {
        if p >= nodes || seen[p] {
            return None;
        }
        seen[p] = true;
    }
    Some(perm)
}
