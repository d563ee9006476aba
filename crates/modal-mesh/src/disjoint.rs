//! Disjoint sets (union–find) over `0..n`, with path halving. A set's root is
//! its smallest member, so numbering sets in the order of their roots is
//! numbering them by their first member.

/// Disjoint sets over `0..n`, each element alone at first.
#[derive(Clone, Debug)]
pub struct DisjointSets {
    parent: Vec<usize>,
}

impl DisjointSets {
    /// `n` sets of one element each.
    pub fn new(n: usize) -> Self {
        Self { parent: (0..n).collect() }
    }

    /// The root of `x`'s set: its smallest member.
    pub fn root(&mut self, mut x: usize) -> usize {
        while self.parent[x] != x {
            self.parent[x] = self.parent[self.parent[x]];
            x = self.parent[x];
        }
        x
    }

    /// Joins the sets of `a` and `b`.
    pub fn join(&mut self, a: usize, b: usize) {
        let (a, b) = (self.root(a), self.root(b));
        self.parent[a.max(b)] = a.min(b);
        debug_assert!(self.parent[a.min(b)] == a.min(b), "the smaller root stays a root");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn joined_sets_share_their_smallest_member_as_root() {
        let mut s = DisjointSets::new(6);
        s.join(4, 5);
        s.join(5, 2);
        s.join(0, 1);
        assert_eq!((0..6).map(|x| s.root(x)).collect::<Vec<_>>(), vec![0, 0, 2, 3, 2, 2]);
        s.join(1, 4);
        assert_eq!((0..6).map(|x| s.root(x)).collect::<Vec<_>>(), vec![0, 0, 0, 3, 0, 0]);
    }
}
