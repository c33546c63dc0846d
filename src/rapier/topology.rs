//! Which links of a scene a Rapier multibody can hold: a spanning forest of the spring and
//! constraint graph (the multibody joints) and the edges that close loops or exceed the size cap
//! (left to impulse joints). Pure graph code, no Rapier types.

use crate::model::System;
use std::collections::VecDeque;

/// Largest number of particles in one multibody. Rapier factorises a dense generalized mass
/// matrix per multibody every step (cost ~ ndofs³), so a 1024-particle cloth as one tree would
/// take seconds per step; past this size a new tree starts and the joining edge falls back.
pub const MAX_TREE_PARTICLES: usize = 32;

/// The tree cap for scenes whose loops leave impulse joints attached to multibody links: each
/// such joint is solved against its trees' dense mass matrices, so big trees make every
/// closing edge expensive (a 32×32 cloth took ~0.3 s per frame with 32-particle trees).
pub const MAX_TREE_PARTICLES_WITH_LOOPS: usize = 8;

/// The tree cap used for `sys`: [`MAX_TREE_PARTICLES`] unless some edge closes a loop.
pub fn tree_cap(sys: &System) -> usize {
    let full = Topology::of(sys, MAX_TREE_PARTICLES);
    if full
        .fallback
        .iter()
        .any(|(_, r)| *r == FallbackReason::Loop)
    {
        MAX_TREE_PARTICLES_WITH_LOOPS
    } else {
        MAX_TREE_PARTICLES
    }
}

/// What an edge of the particle graph stands for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EdgeKind {
    /// Index into `System::springs`.
    Spring(usize),
    /// Index into `System::constraints`.
    Constraint(usize),
}

/// One spring or constraint between particles `a` (parent in a tree) and `b` (child).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Edge {
    /// Parent particle (tree edges) or first particle.
    pub a: usize,
    /// Child particle (tree edges) or second particle.
    pub b: usize,
    /// The spring or constraint it stands for.
    pub kind: EdgeKind,
}

/// Why an edge is not a multibody joint.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FallbackReason {
    /// Both ends already belong to trees: the edge closes a loop (or joins two fixed anchors).
    Loop,
    /// The child's tree reached [`MAX_TREE_PARTICLES`].
    SizeCap,
}

/// The spanning forest: tree edges in insertion order (parents before children) and the rest.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Topology {
    /// Edges that become multibody joints, parent first.
    pub tree: Vec<Edge>,
    /// Edges that stay impulse joints, with the reason.
    pub fallback: Vec<(Edge, FallbackReason)>,
    /// Number of trees (multibodies) with at least one joint.
    pub trees: usize,
    /// Joints (links) of each of those trees, in the order they were grown.
    pub links: Vec<usize>,
    /// The tree (index into `links`) each particle belongs to; `None` outside every tree.
    pub tree_of: Vec<Option<usize>>,
    /// The tree size cap this forest was built with.
    pub cap: usize,
}

impl Topology {
    /// Breadth-first spanning forest: fixed particles are roots first (a fixed body can only be
    /// a multibody root), then free particles in index order. Deterministic. Edges between two
    /// fixed particles are dropped (neither moves, so they have no effect).
    pub fn of(sys: &System, max_tree: usize) -> Topology {
        let n = sys.len();
        let mut edges = Vec::new();
        for s in 0..sys.springs.len() {
            let (a, b) = (sys.springs.i[s] as usize, sys.springs.j[s] as usize);
            edges.push(Edge {
                a,
                b,
                kind: EdgeKind::Spring(s),
            });
        }
        for (c, dc) in sys.constraints.iter().enumerate() {
            edges.push(Edge {
                a: dc.i,
                b: dc.j,
                kind: EdgeKind::Constraint(c),
            });
        }
        edges.retain(|e| sys.free[e.a] || sys.free[e.b]);
        let mut adj: Vec<Vec<usize>> = vec![Vec::new(); n];
        for (k, e) in edges.iter().enumerate() {
            adj[e.a].push(k);
            adj[e.b].push(k);
        }
        let mut used = vec![false; edges.len()];
        let mut capped = vec![false; edges.len()];
        let mut visited = vec![false; n];
        let mut topo = Topology {
            cap: max_tree,
            tree_of: vec![None; n],
            ..Topology::default()
        };
        let roots = (0..n)
            .filter(|&p| !sys.free[p])
            .chain((0..n).filter(|&p| sys.free[p]));
        for root in roots {
            if visited[root] {
                continue;
            }
            visited[root] = true;
            let mut size = 1;
            let mut joints = 0;
            let mut members = vec![root];
            let mut queue = VecDeque::from([root]);
            while let Some(p) = queue.pop_front() {
                if !sys.free[p] && p != root {
                    continue;
                }
                for &k in &adj[p] {
                    if used[k] {
                        continue;
                    }
                    let e = edges[k];
                    let q = if e.a == p { e.b } else { e.a };
                    if visited[q] || !sys.free[q] {
                        continue;
                    }
                    if size >= max_tree {
                        capped[k] = true;
                        continue;
                    }
                    visited[q] = true;
                    used[k] = true;
                    size += 1;
                    joints += 1;
                    members.push(q);
                    topo.tree.push(Edge {
                        a: p,
                        b: q,
                        kind: e.kind,
                    });
                    queue.push_back(q);
                }
            }
            if joints > 0 {
                for p in members {
                    topo.tree_of[p] = Some(topo.links.len());
                }
                topo.links.push(joints);
                topo.trees += 1;
            }
        }
        for (k, e) in edges.iter().enumerate() {
            if !used[k] {
                let why = if capped[k] {
                    FallbackReason::SizeCap
                } else {
                    FallbackReason::Loop
                };
                topo.fallback.push((*e, why));
            }
        }
        topo
    }

    /// A one-line account for users: how many edges are multibody joints and how many fell back.
    pub fn describe(&self) -> String {
        let loops = self
            .fallback
            .iter()
            .filter(|(_, r)| *r == FallbackReason::Loop)
            .count();
        let cap = self.fallback.len() - loops;
        if self.fallback.is_empty() {
            format!(
                "multibody: {} joint(s) in {} tree(s), no fallback",
                self.tree.len(),
                self.trees
            )
        } else {
            format!(
                "multibody: {} joint(s) in {} tree(s); {} edge(s) fell back to impulse joints ({} closing loops, {} past the {}-particle tree cap)",
                self.tree.len(),
                self.trees,
                self.fallback.len(),
                loops,
                cap,
                self.cap
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::Scenario;

    fn scene(toml: &str) -> System {
        Scenario::from_toml_str(toml, "t.toml").unwrap().build()
    }

    // Oracle: a triangle of springs has 3 edges and 3 vertices; a spanning tree has 2 edges,
    // so exactly one edge closes the loop.
    #[test]
    fn triangle_has_one_closing_edge() {
        let mut t = String::new();
        for p in ["[0.0,0.0,0.0]", "[1.0,0.0,0.0]", "[0.0,1.0,0.0]"] {
            t += &format!("[[particle]]\nposition={p}\nmass=1.0\n");
        }
        for (a, b) in [(0, 1), (1, 2), (2, 0)] {
            t += &format!("[[spring]]\nbetween=[{a},{b}]\nstiffness=1.0\n");
        }
        let topo = Topology::of(&scene(&t), MAX_TREE_PARTICLES);
        assert_eq!(topo.tree.len(), 2);
        assert_eq!(topo.fallback.len(), 1);
        assert_eq!(topo.fallback[0].1, FallbackReason::Loop);
    }

    // Oracle: a chain of n particles is a tree (n-1 edges, none left over) unless capped.
    #[test]
    fn chain_is_a_tree_until_capped() {
        let mut t = String::new();
        for p in 0..5 {
            t += &format!(
                "[[particle]]\nposition=[{p}.0,0.0,0.0]\nmass=1.0\nfixed={}\n",
                p == 0
            );
        }
        for a in 0..4 {
            t += &format!("[[spring]]\nbetween=[{a},{}]\nstiffness=1.0\n", a + 1);
        }
        let sys = scene(&t);
        let topo = Topology::of(&sys, 32);
        assert_eq!(
            (topo.tree.len(), topo.fallback.len(), topo.trees),
            (4, 0, 1)
        );
        assert_eq!(topo.tree[0].a, 0);
        let capped = Topology::of(&sys, 3);
        assert_eq!(capped.tree.len(), 3);
        assert_eq!(capped.fallback.len(), 1);
        assert_eq!(capped.fallback[0].1, FallbackReason::SizeCap);
        assert_eq!(capped.trees, 2);
    }
}
