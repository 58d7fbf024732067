//! One-byte wire ids: a distance-2 colouring of the interaction graph.
//!
//! A radio frame names its sender with one byte. A receiver must tell apart itself and
//! every agent it hears, and two agents that a third one hears must differ too, so ids
//! need only be unique within two hops (plus any extra conflict pairs, e.g. agents that
//! can hear each other without being neighbours). That is a proper colouring of the
//! square of the graph.
//!
//! Greedy colouring in *smallest-last* order (Matula–Beck): repeatedly take out an agent
//! of least remaining conflict degree, then colour in the reverse order with the smallest
//! free colour. Each agent then sees at most the graph's degeneracy of coloured conflicts,
//! so at most `degeneracy + 1` colours are used (optimal on trees, strips and many
//! lattices); deterministic, O(N + |conflicts|). For a graph with at most NB neighbours
//! per agent, an agent has at most NB² conflicts, so NB ≤ 15 always fits in 256 ids.

use thiserror::Error;

/// Ids a byte can hold.
pub const MAX_COLOURS: usize = 256;

/// Why no colouring was found.
#[derive(Clone, Debug, PartialEq, Eq, Error)]
pub enum ColouringError {
    /// An adjacency list or conflict pair names an agent that does not exist.
    #[error("agent index {index} in {place} is out of range: there are {n} agents")]
    BadIndex {
        /// The index.
        index: usize,
        /// Where it was found.
        place: String,
        /// Number of agents.
        n: usize,
    },
    /// More than 256 ids are needed.
    #[error(
        "wire ids: agent index {agent} has {conflicts} agents within two hops or in a \
         conflict pair, and those coloured before it already use all {MAX_COLOURS} one-byte \
         ids; lower the neighbours per agent or the conflict pairs"
    )]
    TooManyColours {
        /// The agent that found no free id.
        agent: usize,
        /// Its conflicts.
        conflicts: usize,
    },
}

/// Adjacency lists of `n` agents from triangles (sorted, no duplicates).
pub fn adjacency_from_triangles(n: usize, triangles: &[[usize; 3]]) -> Vec<Vec<usize>> {
    let mut adj = vec![Vec::new(); n];
    for t in triangles {
        for (x, y) in [(t[0], t[1]), (t[1], t[2]), (t[0], t[2])] {
            if x < n && y < n && x != y {
                adj[x].push(y);
                adj[y].push(x);
            }
        }
    }
    for l in &mut adj {
        l.sort_unstable();
        l.dedup();
    }
    adj
}

/// The conflict lists: neighbours, neighbours of neighbours and extra pairs.
fn conflicts(adj: &[Vec<usize>], extra: &[[usize; 2]]) -> Result<Vec<Vec<u32>>, ColouringError> {
    let n = adj.len();
    let check = |index: usize, place: String| {
        if index < n {
            Ok(())
        } else {
            Err(ColouringError::BadIndex { index, place, n })
        }
    };
    for (v, l) in adj.iter().enumerate() {
        for &u in l {
            check(u, format!("the neighbours of agent index {v}"))?;
        }
    }
    let mut h: Vec<Vec<u32>> = vec![Vec::new(); n];
    for (k, &[a, b]) in extra.iter().enumerate() {
        check(a, format!("conflict pair {k}"))?;
        check(b, format!("conflict pair {k}"))?;
        if a != b {
            h[a].push(b as u32);
            h[b].push(a as u32);
        }
    }
    for (v, hv) in h.iter_mut().enumerate() {
        for &u in &adj[v] {
            hv.push(u as u32);
            hv.extend(adj[u].iter().map(|&w| w as u32));
        }
        hv.retain(|&w| w as usize != v);
        hv.sort_unstable();
        hv.dedup();
    }
    // Symmetric already: u ∈ N(v) ⇔ v ∈ N(u) is assumed of `adj`; make sure.
    let mut missing = Vec::new();
    for (v, hv) in h.iter().enumerate() {
        for &u in hv {
            if h[u as usize].binary_search(&(v as u32)).is_err() {
                missing.push((u, v as u32));
            }
        }
    }
    for (u, v) in missing {
        h[u as usize].push(v);
    }
    for hv in &mut h {
        hv.sort_unstable();
        hv.dedup();
    }
    Ok(h)
}

/// Colours the agents (`adj[v]`: the neighbours of agent `v`; `extra`: pairs that must
/// also differ) so that agents within two hops, and every extra pair, get different ids
/// in `0..=255`.
pub fn distance2_colouring(
    adj: &[Vec<usize>],
    extra: &[[usize; 2]],
) -> Result<Vec<u8>, ColouringError> {
    let h = conflicts(adj, extra)?;
    let n = h.len();
    // Smallest-last order with a lazy bucket queue (stale entries are skipped).
    let mut deg: Vec<usize> = h.iter().map(Vec::len).collect();
    let top = deg.iter().copied().max().unwrap_or(0);
    let mut buckets: Vec<Vec<u32>> = vec![Vec::new(); top + 1];
    for v in (0..n).rev() {
        buckets[deg[v]].push(v as u32);
    }
    let mut gone = vec![false; n];
    let mut order = Vec::with_capacity(n);
    let mut cur = 0;
    while order.len() < n {
        let Some(v) = buckets.get_mut(cur).and_then(Vec::pop) else {
            cur += 1;
            continue;
        };
        let v = v as usize;
        if gone[v] || deg[v] != cur {
            continue;
        }
        gone[v] = true;
        order.push(v);
        for &u in &h[v] {
            let u = u as usize;
            if !gone[u] {
                deg[u] -= 1;
                buckets[deg[u]].push(u as u32);
                cur = cur.min(deg[u]);
            }
        }
    }
    let mut colour: Vec<Option<u8>> = vec![None; n];
    let mut seen = [usize::MAX; MAX_COLOURS];
    for &v in order.iter().rev() {
        for &u in &h[v] {
            if let Some(c) = colour[u as usize] {
                seen[c as usize] = v;
            }
        }
        let free =
            (0..MAX_COLOURS)
                .find(|&c| seen[c] != v)
                .ok_or(ColouringError::TooManyColours {
                    agent: v,
                    conflicts: h[v].len(),
                })?;
        colour[v] = Some(free as u8);
    }
    Ok(colour.into_iter().map(|c| c.unwrap_or(0)).collect())
}

/// Checks a colouring: `Err([u, w])` names two agents within two hops (or an extra pair)
/// that share an id.
pub fn check_distance2(
    adj: &[Vec<usize>],
    extra: &[[usize; 2]],
    colours: &[u8],
) -> Result<(), [usize; 2]> {
    let same = |u: usize, w: usize| u != w && colours.get(u) == colours.get(w);
    for (v, l) in adj.iter().enumerate() {
        for (k, &u) in l.iter().enumerate() {
            if same(v, u) {
                return Err([v, u]);
            }
            for &w in &l[k + 1..] {
                if same(u, w) {
                    return Err([u, w]);
                }
            }
        }
    }
    match extra.iter().find(|&&[a, b]| same(a, b)) {
        Some(&p) => Err(p),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn strip(n: usize) -> Vec<Vec<usize>> {
        let t: Vec<[usize; 3]> = (0..n - 2).map(|i| [i, i + 1, i + 2]).collect();
        adjacency_from_triangles(n, &t)
    }

    #[test]
    fn strip_needs_five_ids() {
        // In a strip (i, i+1, i+2), agents up to 4 places apart are within two hops.
        let adj = strip(1000);
        let c = distance2_colouring(&adj, &[]).unwrap();
        check_distance2(&adj, &[], &c).unwrap();
        assert_eq!(c.iter().copied().max(), Some(4));
    }

    #[test]
    fn extra_pairs_are_separated() {
        let adj = strip(20);
        let extra = [[0, 19], [3, 10]];
        let c = distance2_colouring(&adj, &extra).unwrap();
        check_distance2(&adj, &extra, &c).unwrap();
        assert_ne!(c[0], c[19]);
    }

    #[test]
    fn checker_finds_a_clash() {
        let adj = strip(6);
        let mut c = distance2_colouring(&adj, &[]).unwrap();
        c[2] = c[4];
        assert_eq!(check_distance2(&adj, &[], &c), Err([2, 4]));
    }

    #[test]
    fn a_star_of_256_leaves_needs_257_ids() {
        let mut adj = vec![Vec::new(); 257];
        for leaf in 1..257 {
            adj[0].push(leaf);
            adj[leaf].push(0);
        }
        let e = distance2_colouring(&adj, &[]).unwrap_err();
        assert!(
            matches!(e, ColouringError::TooManyColours { conflicts: 256, .. }),
            "{e}"
        );
        assert!(e.to_string().contains("256 one-byte ids"));
        adj[0].pop();
        adj[256].clear();
        let c = distance2_colouring(&adj, &[]).unwrap();
        check_distance2(&adj, &[], &c).unwrap();
    }

    #[test]
    fn bad_index() {
        let e = distance2_colouring(&[vec![1], vec![0]], &[[0, 5]]).unwrap_err();
        assert!(e.to_string().contains("conflict pair 0"), "{e}");
    }
}
