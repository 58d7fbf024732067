//! The interaction graph: the triangulated Laman check (SPEC §3), neighbour lists and
//! edges, all by agent index (position in the scenario's agent list).

use std::collections::{BTreeSet, HashMap, HashSet};

/// Compressed adjacency lists: `of(i)` is agent `i`'s sorted neighbour indices.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Adjacency {
    start: Vec<usize>,
    list: Vec<usize>,
}

impl Adjacency {
    /// Builds the lists of `n` agents from undirected pairs (duplicates are merged).
    pub fn from_pairs(n: usize, pairs: impl IntoIterator<Item = [usize; 2]>) -> Self {
        let mut sets: Vec<BTreeSet<usize>> = vec![BTreeSet::new(); n];
        for [a, b] in pairs {
            if a != b && a < n && b < n {
                sets[a].insert(b);
                sets[b].insert(a);
            }
        }
        let mut start = Vec::with_capacity(n + 1);
        let mut list = Vec::new();
        start.push(0);
        for s in &sets {
            list.extend(s.iter().copied());
            start.push(list.len());
        }
        Self { start, list }
    }

    /// Builds the lists as given (each already sorted).
    pub fn from_lists(lists: &[Vec<usize>]) -> Self {
        let mut start = Vec::with_capacity(lists.len() + 1);
        let mut list = Vec::with_capacity(lists.iter().map(Vec::len).sum());
        start.push(0);
        for l in lists {
            list.extend_from_slice(l);
            start.push(list.len());
        }
        Self { start, list }
    }

    /// Agent `i`'s neighbours (sorted).
    #[inline]
    pub fn of(&self, i: usize) -> &[usize] {
        match (self.start.get(i), self.start.get(i + 1)) {
            (Some(&a), Some(&b)) => self.list.get(a..b).unwrap_or(&[]),
            _ => &[],
        }
    }

    /// Number of agents.
    pub fn len(&self) -> usize {
        self.start.len().saturating_sub(1)
    }

    /// No agents.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Largest number of neighbours of one agent.
    pub fn max_degree(&self) -> usize {
        (0..self.len()).map(|i| self.of(i).len()).max().unwrap_or(0)
    }

    /// Total number of (directed) neighbour entries.
    pub fn total(&self) -> usize {
        self.list.len()
    }
}

/// The graph of a scenario, by agent index.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Graph {
    /// Undirected edges `[i, j]` with `i < j`, sorted.
    pub edges: Vec<[usize; 2]>,
    /// Triangle neighbours (the agents each one measures bearings to).
    pub triangle: Adjacency,
    /// Radio neighbours: triangle neighbours plus the leader partner.
    pub radio: Adjacency,
    /// Each agent's triangles (indices, ascending: scenario order).
    pub membership: Adjacency,
}

impl Graph {
    /// Builds the graph of `n` agents with these triangles and optional leader pair.
    pub fn new(n: usize, triangles: &[[usize; 3]], leader: Option<[usize; 2]>) -> Self {
        let tri_pairs = || {
            triangles
                .iter()
                .flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[0], t[2]]])
        };
        let mut edges: BTreeSet<[usize; 2]> = BTreeSet::new();
        for [a, b] in tri_pairs() {
            edges.insert([a.min(b), a.max(b)]);
        }
        let triangle = Adjacency::from_pairs(n, tri_pairs());
        let radio = Adjacency::from_pairs(n, tri_pairs().chain(leader));
        let mut lists: Vec<Vec<usize>> = vec![Vec::new(); n];
        for (k, t) in triangles.iter().enumerate() {
            for &v in t {
                if let Some(l) = lists.get_mut(v) {
                    if l.last() != Some(&k) {
                        l.push(k);
                    }
                }
            }
        }
        Self {
            edges: edges.into_iter().collect(),
            triangle,
            radio,
            membership: Adjacency::from_lists(&lists),
        }
    }
}

/// Why the triangles are not a triangulated Laman graph.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum LamanError {
    /// No triangles at all.
    Empty,
    /// This agent is in no triangle.
    Isolated(usize),
    /// `N ≠ M + 2`.
    Count {
        /// Agents.
        agents: usize,
        /// Triangles.
        triangles: usize,
    },
    /// These triangles (indices) cannot be added: none of them joins exactly one new agent
    /// to an existing edge.
    Unattached(Vec<usize>),
}

/// Checks that `triangles` form a triangulated Laman graph on agents `0..n` (SPEC §3:
/// start from one edge; every new agent joins two agents that already share an edge) and
/// returns a construction order of the triangles.
pub fn laman_order(n: usize, triangles: &[[usize; 3]]) -> Result<Vec<usize>, LamanError> {
    if triangles.is_empty() {
        return Err(LamanError::Empty);
    }
    let mut in_some = vec![false; n];
    for t in triangles {
        for &v in t {
            if let Some(x) = in_some.get_mut(v) {
                *x = true;
            }
        }
    }
    if let Some(i) = in_some.iter().position(|x| !x) {
        return Err(LamanError::Isolated(i));
    }
    if n != triangles.len() + 2 {
        return Err(LamanError::Count {
            agents: n,
            triangles: triangles.len(),
        });
    }
    // Event driven, O(M): a triangle can attach only when one of its edges appears
    // (both its ends are then placed), so each new edge looks at the triangles on it.
    let key = |a: usize, b: usize| [a.min(b), a.max(b)];
    let sides = |t: &[usize; 3]| [key(t[0], t[1]), key(t[1], t[2]), key(t[0], t[2])];
    let mut on_edge: HashMap<[usize; 2], Vec<usize>> = HashMap::with_capacity(3 * triangles.len());
    for (ti, t) in triangles.iter().enumerate().skip(1) {
        for e in sides(t) {
            on_edge.entry(e).or_default().push(ti);
        }
    }
    let mut st = Growth {
        placed: vec![false; n],
        added: vec![false; triangles.len()],
        edges: HashSet::with_capacity(2 * n),
        pending: Vec::new(),
        order: Vec::with_capacity(triangles.len()),
    };
    st.add(0, triangles);
    while let Some(e) = st.pending.pop() {
        for &ti in on_edge.get(&e).map_or(&[][..], Vec::as_slice) {
            let t = &triangles[ti];
            let unplaced = t
                .iter()
                .filter(|&&v| !st.placed.get(v).copied().unwrap_or(true))
                .count();
            if !st.added[ti] && unplaced == 1 {
                st.add(ti, triangles);
            }
        }
    }
    let (added, order) = (st.added, st.order);
    let remaining: Vec<usize> = (0..triangles.len()).filter(|&ti| !added[ti]).collect();
    if remaining.is_empty() {
        Ok(order)
    } else {
        Err(LamanError::Unattached(remaining))
    }
}

/// The state of [`laman_order`]'s growth.
struct Growth {
    placed: Vec<bool>,
    added: Vec<bool>,
    edges: HashSet<[usize; 2]>,
    pending: Vec<[usize; 2]>,
    order: Vec<usize>,
}

impl Growth {
    fn add(&mut self, ti: usize, triangles: &[[usize; 3]]) {
        let t = triangles[ti];
        self.added[ti] = true;
        self.order.push(ti);
        for v in t {
            if let Some(p) = self.placed.get_mut(v) {
                *p = true;
            }
        }
        for [a, b] in [[t[0], t[1]], [t[1], t[2]], [t[0], t[2]]] {
            let e = [a.min(b), a.max(b)];
            if self.edges.insert(e) {
                self.pending.push(e);
            }
        }
    }
}

/// A triangulated strip of `n ≥ 3` agents: triangles `(i, i+1, i+2)` (for benchmarks and
/// scaling tests).
pub fn strip_triangles(n: usize) -> Vec<[usize; 3]> {
    (0..n.saturating_sub(2))
        .map(|i| [i, i + 1, i + 2])
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_graph_is_laman() {
        let t = [[0, 1, 2], [1, 2, 3]];
        assert_eq!(laman_order(4, &t), Ok(vec![0, 1]));
        let g = Graph::new(4, &t, Some([0, 1]));
        assert_eq!(g.edges, vec![[0, 1], [0, 2], [1, 2], [1, 3], [2, 3]]);
        assert_eq!(g.triangle.of(0), &[1, 2]);
        assert_eq!(g.triangle.of(3), &[1, 2]);
    }

    #[test]
    fn strip_from_the_middle() {
        let mut t = strip_triangles(8);
        t.swap(0, 3);
        assert!(laman_order(8, &t).is_ok());
    }

    #[test]
    fn rejects_non_laman() {
        // Two triangles sharing only a vertex.
        assert!(matches!(
            laman_order(5, &[[0, 1, 2], [2, 3, 4]]),
            Err(LamanError::Count { .. })
        ));
        // A triangle through three placed agents, and a free-floating one.
        assert!(matches!(
            laman_order(5, &[[0, 1, 2], [0, 1, 3], [2, 3, 4]]),
            Err(LamanError::Unattached(_))
        ));
        assert_eq!(laman_order(4, &[[0, 1, 2]]), Err(LamanError::Isolated(3)));
    }
}
