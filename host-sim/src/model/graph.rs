//! The interaction graph: the triangulated Laman check (SPEC §3), neighbour lists and
//! edges, all by agent index (position in the scenario's agent list).

use std::collections::BTreeSet;

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
        Self {
            edges: edges.into_iter().collect(),
            triangle,
            radio,
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
    let first = triangles.first().ok_or(LamanError::Empty)?;
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
    let mut placed = vec![false; n];
    let mut edges: BTreeSet<[usize; 2]> = BTreeSet::new();
    let key = |a: usize, b: usize| [a.min(b), a.max(b)];
    let add = |t: &[usize; 3], placed: &mut Vec<bool>, edges: &mut BTreeSet<[usize; 2]>| {
        for &v in t {
            if let Some(p) = placed.get_mut(v) {
                *p = true;
            }
        }
        edges.insert(key(t[0], t[1]));
        edges.insert(key(t[1], t[2]));
        edges.insert(key(t[0], t[2]));
    };
    add(first, &mut placed, &mut edges);
    let mut order = vec![0];
    let mut remaining: Vec<usize> = (1..triangles.len()).collect();
    // Each pass adds every triangle that attaches now; a valid 2-tree grows from any
    // of its triangles, so the greedy order is complete when one exists.
    loop {
        let before = remaining.len();
        remaining.retain(|&ti| {
            let t = &triangles[ti];
            let new: Vec<usize> = t.iter().copied().filter(|&v| !placed[v]).collect();
            if new.len() != 1 {
                return true;
            }
            let old: Vec<usize> = t.iter().copied().filter(|&v| placed[v]).collect();
            if old.len() == 2 && edges.contains(&key(old[0], old[1])) {
                add(t, &mut placed, &mut edges);
                order.push(ti);
                false
            } else {
                true
            }
        });
        if remaining.is_empty() {
            return Ok(order);
        }
        if remaining.len() == before {
            return Err(LamanError::Unattached(remaining));
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
