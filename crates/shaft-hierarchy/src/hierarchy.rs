//! The shaft hierarchy over line space (paper 003, Section 6): from the shaft joining the two
//! roots, split the larger node until both are leaves, pruning a pair whose transfer is below a
//! fraction of every receiver vertex's radiance. Per frame, an object's box against the shafts
//! gives the sources it may occlude and the receivers it may darken (Section 6.1); the
//! representative set stands n source nodes for them (Section 8).

use std::collections::BinaryHeap;
use std::ops::Range;

use crate::shaft::{Meet, meets};
use crate::tree::{Node, SourceShape, Tree, receiver_octree, source_tree};
use crate::{Aabb, Shaft};

/// A receiver patch: its box and its vertices' columns of the transfer matrix.
#[derive(Clone, Debug, PartialEq)]
pub struct Receiver {
    /// Bounds of the patch.
    pub bounds: Aabb,
    /// Its vertices' columns in [`Transfers`] (each column belongs to one receiver).
    pub slots: Range<u32>,
}

/// Radiance transfers L_ij: what source j sends to receiver vertex i and that vertex reflects
/// towards the camera (luminance), and each vertex's total radiance L_i.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Transfers {
    /// Number of columns (receiver vertices).
    pub slots: usize,
    /// Row-major, one row of `slots` values per source.
    pub values: Vec<f32>,
    /// L_i per column: the radiance the pruning rule takes its fraction of.
    pub totals: Vec<f32>,
}

impl Transfers {
    /// Source j's row.
    #[must_use]
    pub fn row(&self, j: usize) -> &[f32] {
        &self.values[j * self.slots..(j + 1) * self.slots]
    }
}

/// Knobs of the hierarchy.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// Receiver patches per octree leaf at most (the paper: 8).
    pub leaf_size: usize,
    /// A pair is pruned when its transfer is below this fraction of the radiance of every
    /// receiver vertex it reaches (the paper: 2 %).
    pub prune_fraction: f32,
    /// How far a distant source's shafts reach beyond each receiver, in scene units: objects
    /// further than this along the light are not found. `None`: twice the diagonal of the
    /// receivers' and local sources' bounds.
    pub distant_reach: Option<f32>,
}

impl Settings {
    /// The paper's: 8 patches a leaf, 2 % pruning.
    pub const PAPER: Self = Self { leaf_size: 8, prune_fraction: 0.02, distant_reach: None };
}

impl Default for Settings {
    fn default() -> Self {
        Self::PAPER
    }
}

/// What a shaft node is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Split into the source node's children (`shafts[child..child + children]`, the
    /// pruned ones left out).
    SplitSource,
    /// Split into the receiver node's children.
    SplitReceiver,
    /// Both nodes are leaves: one source, at most `leaf_size` receivers.
    Leaf,
}

/// A node of the shaft hierarchy: a pair of a source node and a receiver node. Its planes are
/// not stored; they are recomputed from the two nodes' boxes when traversed. Pairs the pruning
/// rule removed are not nodes: their parent marks them in `pruned`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShaftNode {
    /// Source-tree node.
    pub source: u32,
    /// Receiver-tree node.
    pub receiver: u32,
    /// Split nodes: the first stored child shaft. Leaves: the index of their transfer in
    /// [`ShaftHierarchy::leaf_transfer`].
    pub child: u32,
    /// Split nodes: number of stored (not pruned) children.
    pub children: u8,
    /// Split nodes: bit c set when the split node's c-th tree child was pruned.
    pub pruned: u8,
    /// How it splits, or a leaf.
    pub kind: Kind,
}

/// Errors of [`ShaftHierarchy::build`].
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum BuildError {
    /// The transfer matrix does not match the sources and receivers.
    #[error("transfers: {0}")]
    Transfers(String),
    /// A box or transfer is not finite.
    #[error("not finite: {0}")]
    NotFinite(String),
    /// The built hierarchy fails [`ShaftHierarchy::validate`] (a bug, reported in words).
    #[error("the hierarchy is broken: {0}")]
    Broken(String),
}

/// The shaft hierarchy between a source KD-tree and a receiver octree.
#[derive(Clone, Debug)]
pub struct ShaftHierarchy {
    /// The sources, as given.
    pub sources: Vec<SourceShape>,
    /// The receivers, as given.
    pub receivers: Vec<Receiver>,
    /// KD-tree over sources.
    pub source_tree: Tree,
    /// Octree over receivers.
    pub receiver_tree: Tree,
    /// Shaft nodes; the root (both roots) at 0; children consecutive. Empty when there is
    /// nothing to join, or when the root pair itself is pruned (`root_pruned`).
    pub shafts: Vec<ShaftNode>,
    /// Per source, the source-tree leaf holding it.
    pub source_leaf: Vec<u32>,
    /// Per leaf shaft, its source's transfer to its receivers' vertices (summed).
    pub leaf_transfer: Vec<f32>,
    /// True when the whole transfer is below the pruning threshold.
    pub root_pruned: bool,
    /// Per source-tree node, per receiver vertex: the node's summed transfer.
    node_transfer: Vec<f32>,
    slots: usize,
    totals: Vec<f32>,
    reach: f32,
    settings: Settings,
}

/// What a frame's object may occlude.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Occlusion {
    /// Sources it may occlude, each once.
    pub sources: Vec<u32>,
    /// Receiver patches it may darken, each once.
    pub receivers: Vec<u32>,
    /// Leaf shafts it meets.
    pub leaf_shafts: Vec<u32>,
    /// Pruned pairs (source node, receiver node) whose parent shaft it meets: their transfer
    /// is below the threshold, so it is not reported as occluded.
    pub pruned: Vec<(u32, u32)>,
    /// Shaft nodes tested.
    pub tested: usize,
}

/// Reusable per-frame state: the frame tags (paper 003's counters) and stacks.
#[derive(Clone, Debug, Default)]
pub struct Traversal {
    frame: u32,
    source_tag: Vec<u32>,
    receiver_tag: Vec<u32>,
    stack: Vec<(u32, bool)>,
}

/// One node of a representative set (paper 003, Section 8).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Representative {
    /// Source-tree node.
    pub node: u32,
    /// The occluded sources under it that it stands for.
    pub sources: u32,
    /// Their summed transfer to the frame's receiver vertices.
    pub transfer: f64,
    /// The source its shadow map is rendered from: the one among them that sends the most.
    pub origin: u32,
}

impl ShaftHierarchy {
    /// Builds the trees and the shaft hierarchy.
    ///
    /// # Errors
    /// When the transfer matrix's shape does not match (`sources.len()` rows, a column per
    /// receiver slot, slot ranges inside it), or a box or value is not finite.
    pub fn build(
        sources: &[SourceShape],
        receivers: &[Receiver],
        transfers: &Transfers,
        settings: &Settings,
    ) -> Result<Self, BuildError> {
        let slots = transfers.slots;
        if transfers.values.len() != sources.len() * slots || transfers.totals.len() != slots {
            return Err(BuildError::Transfers(format!(
                "{} values and {} totals for {} sources x {slots} slots",
                transfers.values.len(),
                transfers.totals.len(),
                sources.len()
            )));
        }
        if let Some((k, r)) =
            receivers.iter().enumerate().find(|(_, r)| r.slots.end as usize > slots || r.slots.start > r.slots.end)
        {
            return Err(BuildError::Transfers(format!("receiver {k}: slots {:?} outside 0..{slots}", r.slots)));
        }
        let finite_box = |b: &Aabb| b.min.is_finite() && b.max.is_finite();
        if let Some(k) = receivers.iter().position(|r| !finite_box(&r.bounds)) {
            return Err(BuildError::NotFinite(format!("receiver {k}'s box")));
        }
        if let Some(k) = sources.iter().position(|s| match s {
            SourceShape::Local(b) | SourceShape::Distant(b) => !finite_box(b),
        }) {
            return Err(BuildError::NotFinite(format!("source {k}'s box")));
        }
        if transfers.values.iter().chain(&transfers.totals).any(|v| !v.is_finite()) {
            return Err(BuildError::NotFinite("a transfer or total".into()));
        }
        let source_tree = source_tree(sources);
        let mut source_leaf = vec![0u32; sources.len()];
        for (k, n) in source_tree.nodes.iter().enumerate() {
            if n.is_leaf() {
                for &j in source_tree.items(k as u32) {
                    source_leaf[j as usize] = k as u32;
                }
            }
        }
        let receiver_boxes: Vec<Aabb> = receivers.iter().map(|r| r.bounds).collect();
        let receiver_tree = receiver_octree(&receiver_boxes, settings.leaf_size);
        let reach = settings.distant_reach.unwrap_or_else(|| {
            let local = sources.iter().fold(Aabb::EMPTY, |b, s| match s {
                SourceShape::Local(x) => b.union(x),
                SourceShape::Distant(_) => b,
            });
            let all = receiver_boxes.iter().fold(local, |b, r| b.union(r));
            if all.is_empty() { 1.0 } else { 2.0 * all.size().length().max(f32::MIN_POSITIVE) }
        });
        // node sums, children before parents (children come after their parent in the array)
        let mut node_transfer = vec![0.0f32; source_tree.nodes.len() * slots];
        for k in (0..source_tree.nodes.len()).rev() {
            let n = source_tree.nodes[k];
            let (head, tail) = node_transfer.split_at_mut((k + 1) * slots);
            let row = &mut head[k * slots..];
            if n.is_leaf() {
                for &j in source_tree.items(k as u32) {
                    for (r, v) in row.iter_mut().zip(transfers.row(j as usize)) {
                        *r += v;
                    }
                }
            } else {
                for c in source_tree.children(k as u32) {
                    let off = (c as usize - k - 1) * slots;
                    for (r, v) in row.iter_mut().zip(&tail[off..off + slots]) {
                        *r += v;
                    }
                }
            }
        }
        let mut h = Self {
            sources: sources.to_vec(),
            receivers: receivers.to_vec(),
            source_tree,
            receiver_tree,
            shafts: Vec::new(),
            source_leaf,
            leaf_transfer: Vec::new(),
            root_pruned: false,
            node_transfer,
            slots,
            totals: transfers.totals.clone(),
            reach,
            settings: *settings,
        };
        if !sources.is_empty() && !receivers.is_empty() {
            h.build_shafts();
        }
        Ok(h)
    }

    /// Breadth first, so that each node's children are consecutive.
    fn build_shafts(&mut self) {
        if self.negligible(0, 0) {
            self.root_pruned = true;
            return;
        }
        self.shafts.push(ShaftNode { source: 0, receiver: 0, child: 0, children: 0, pruned: 0, kind: Kind::Leaf });
        let mut k = 0;
        while k < self.shafts.len() {
            let ShaftNode { source, receiver, .. } = self.shafts[k];
            let (s, r) = (self.source_tree.nodes[source as usize], self.receiver_tree.nodes[receiver as usize]);
            if s.is_leaf() && r.is_leaf() {
                let sum = self.pair_transfer(source, receiver) as f32;
                self.shafts[k].kind = Kind::Leaf;
                self.shafts[k].child = self.leaf_transfer.len() as u32;
                self.leaf_transfer.push(sum);
                k += 1;
                continue;
            }
            let split_source =
                !s.is_leaf() && (r.is_leaf() || self.source_size(source, &r) >= r.bounds.size().length());
            self.shafts[k].kind = if split_source { Kind::SplitSource } else { Kind::SplitReceiver };
            let pairs = self.child_pairs(&self.shafts[k]);
            let child = self.shafts.len() as u32;
            let mut pruned = 0u8;
            for (c, &(cs, cr)) in pairs.iter().enumerate() {
                if self.negligible(cs, cr) {
                    pruned |= 1 << c;
                } else {
                    self.shafts.push(ShaftNode {
                        source: cs,
                        receiver: cr,
                        child: 0,
                        children: 0,
                        pruned: 0,
                        kind: Kind::Leaf,
                    });
                }
            }
            let children = (self.shafts.len() as u32 - child) as u8;
            let node = &mut self.shafts[k];
            node.child = child;
            node.children = children;
            node.pruned = pruned;
            k += 1;
        }
    }

    /// A pair's summed transfer: the source node's to every vertex of the receiver node.
    fn pair_transfer(&self, source: u32, receiver: u32) -> f64 {
        self.receiver_tree
            .items(receiver)
            .iter()
            .flat_map(|&p| self.receivers[p as usize].slots.clone())
            .map(|i| f64::from(self.node_transfer(source, i)))
            .sum()
    }

    /// The (source node, receiver node) pairs a split node's tree children make, in order.
    fn child_pairs(&self, n: &ShaftNode) -> Vec<(u32, u32)> {
        match n.kind {
            Kind::SplitSource => self.source_tree.children(n.source).map(|c| (c, n.receiver)).collect(),
            Kind::SplitReceiver => self.receiver_tree.children(n.receiver).map(|c| (n.source, c)).collect(),
            Kind::Leaf => Vec::new(),
        }
    }

    /// The pruning rule: the pair's transfer is at most `prune_fraction` of every reached
    /// vertex's radiance.
    fn negligible(&self, source: u32, receiver: u32) -> bool {
        let row = &self.node_transfer[source as usize * self.slots..(source as usize + 1) * self.slots];
        self.receiver_tree.items(receiver).iter().all(|&p| {
            let slots = self.receivers[p as usize].slots.clone();
            slots.into_iter().all(|i| row[i as usize] <= self.settings.prune_fraction * self.totals[i as usize])
        })
    }

    /// How wide a source node's end of a shaft to `r` is.
    fn source_size(&self, s: u32, r: &Node) -> f32 {
        self.source_box(s, &r.bounds).size().length()
    }

    /// A source node's end of the shaft to receiver box `r`: its local sources' box, and for its
    /// distant sources the proxy box `r ⊕ reach · directions`, which holds every segment's far
    /// end.
    fn source_box(&self, s: u32, r: &Aabb) -> Aabb {
        let mut b = self.source_tree.nodes[s as usize].bounds;
        let dirs = self.source_tree.directions(s);
        if !dirs.is_empty() {
            let proxy = Aabb { min: r.min + dirs.min * self.reach, max: r.max + dirs.max * self.reach };
            b = b.union(&proxy);
        }
        b
    }

    /// The shaft of a node.
    #[must_use]
    pub fn shaft(&self, k: u32) -> Shaft {
        let n = self.shafts[k as usize];
        let (a, b) = self.ends(n.source, n.receiver);
        Shaft::new(&a, &b)
    }

    /// The two boxes a (source node, receiver node) pair's shaft joins.
    fn ends(&self, source: u32, receiver: u32) -> (Aabb, Aabb) {
        let r = self.receiver_tree.nodes[receiver as usize].bounds;
        (self.source_box(source, &r), r)
    }

    /// How far distant sources' shafts reach.
    #[must_use]
    pub fn reach(&self) -> f32 {
        self.reach
    }

    /// The settings it was built with.
    #[must_use]
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Number of leaf shafts (kept pairs).
    #[must_use]
    pub fn leaf_shafts(&self) -> usize {
        self.leaf_transfer.len()
    }

    /// Number of pruned pairs (not stored as nodes).
    #[must_use]
    pub fn pruned_pairs(&self) -> usize {
        self.shafts.iter().map(|s| s.pruned.count_ones() as usize).sum::<usize>() + usize::from(self.root_pruned)
    }

    /// Bytes the hierarchy needs at traversal: shaft nodes, tree nodes and permutations (the
    /// transfers, needed for the representative set, are [`ShaftHierarchy::transfer_bytes`]).
    #[must_use]
    pub fn bytes(&self) -> usize {
        use std::mem::size_of;
        self.shafts.len() * size_of::<ShaftNode>()
            + self.leaf_transfer.len() * size_of::<f32>()
            + (self.source_tree.nodes.len() + self.receiver_tree.nodes.len()) * size_of::<Node>()
            + (self.source_tree.directions.len() + self.receiver_tree.directions.len()) * size_of::<Aabb>()
            + (self.source_tree.order.len() + self.receiver_tree.order.len()) * size_of::<u32>()
    }

    /// Bytes of the per-node transfer sums.
    #[must_use]
    pub fn transfer_bytes(&self) -> usize {
        self.node_transfer.len() * std::mem::size_of::<f32>()
    }

    /// Source node `s`'s summed transfer to vertex `i`.
    #[must_use]
    pub fn node_transfer(&self, s: u32, i: u32) -> f32 {
        self.node_transfer[s as usize * self.slots + i as usize]
    }

    /// Checks every invariant: both trees; each inner shaft's children split exactly one of its
    /// nodes into that node's children; leaves pair two leaves; every shaft holds both its
    /// boxes; and for every receiver vertex, the transfer of the leaf and pruned shafts that
    /// reach it sums to its total transfer (the leaves partition line space).
    ///
    /// # Errors
    /// The first broken invariant, in words.
    pub fn validate(&self) -> Result<(), String> {
        let shape = |s: &SourceShape| match *s {
            SourceShape::Local(b) => (b, Aabb::EMPTY),
            SourceShape::Distant(d) => (Aabb::EMPTY, d),
        };
        self.source_tree
            .validate(self.sources.len(), |i| shape(&self.sources[i as usize]))
            .map_err(|e| format!("source tree: {e}"))?;
        self.receiver_tree
            .validate(self.receivers.len(), |i| (self.receivers[i as usize].bounds, Aabb::EMPTY))
            .map_err(|e| format!("receiver tree: {e}"))?;
        let mut reached = vec![0.0f64; self.slots];
        let mut reach_pair = |source: u32, receiver: u32| {
            for &p in self.receiver_tree.items(receiver) {
                for i in self.receivers[p as usize].slots.clone() {
                    reached[i as usize] += f64::from(self.node_transfer(source, i));
                }
            }
        };
        if self.root_pruned {
            if !self.shafts.is_empty() {
                return Err("a pruned root with shafts".into());
            }
            reach_pair(0, 0);
        }
        let mut leaves = 0;
        for (k, n) in self.shafts.iter().enumerate() {
            let (s, r) = (self.source_tree.nodes[n.source as usize], self.receiver_tree.nodes[n.receiver as usize]);
            let shaft = self.shaft(k as u32);
            let (a, b) = self.ends(n.source, n.receiver);
            if [a, b].iter().any(|bx| !bx.is_empty() && !(0..8).all(|c| shaft.contains_point(bx.corner(c)))) {
                return Err(format!("shaft {k} does not hold its boxes"));
            }
            if n.kind == Kind::Leaf {
                if !(s.is_leaf() && r.is_leaf()) {
                    return Err(format!("leaf shaft {k} joins an inner node"));
                }
                if n.child as usize != leaves {
                    return Err(format!("leaf shaft {k}: transfer index {} out of order", n.child));
                }
                let sum = self.pair_transfer(n.source, n.receiver);
                let stored = f64::from(self.leaf_transfer[leaves]);
                if (sum - stored).abs() > 1e-4 * sum.abs().max(1e-30) {
                    return Err(format!("leaf shaft {k}: stored transfer {stored}, summed {sum}"));
                }
                leaves += 1;
                reach_pair(n.source, n.receiver);
                continue;
            }
            let pairs = self.child_pairs(n);
            if pairs.is_empty() || n.child as usize <= k || pairs.len() > 8 {
                return Err(format!("shaft {k}: splits a leaf, or its children come first"));
            }
            let mut stored = n.child as usize;
            for (c, &(cs, cr)) in pairs.iter().enumerate() {
                if n.pruned & (1 << c) != 0 {
                    reach_pair(cs, cr);
                } else {
                    let kid = self.shafts.get(stored).ok_or_else(|| format!("shaft {k}: child {stored} missing"))?;
                    if (kid.source, kid.receiver) != (cs, cr) {
                        return Err(format!("shaft {k}: children do not split one of its nodes"));
                    }
                    stored += 1;
                }
            }
            if stored - n.child as usize != usize::from(n.children) {
                return Err(format!(
                    "shaft {k}: {} children stored, {} expected",
                    n.children,
                    stored - n.child as usize
                ));
            }
        }
        if leaves != self.leaf_transfer.len() {
            return Err(format!("{leaves} leaf shafts, {} leaf transfers", self.leaf_transfer.len()));
        }
        if !self.shafts.is_empty() || self.root_pruned {
            for p in &self.receivers {
                for i in p.slots.clone() {
                    let total = f64::from(self.node_transfer(0, i));
                    if (reached[i as usize] - total).abs() > 1e-4 * total.abs().max(1e-30) {
                        return Err(format!(
                            "vertex {i}: leaf and pruned shafts carry {} of {total}",
                            reached[i as usize]
                        ));
                    }
                }
            }
        }
        Ok(())
    }

    /// The shafts `object` meets: the sources it may occlude and the receivers it may darken,
    /// each once. A shaft inside the object's box (and so every shaft below it) is descended
    /// without further tests; the pruned children of a shaft it meets are listed untested.
    pub fn traverse(&self, object: &Aabb, scratch: &mut Traversal, out: &mut Occlusion) {
        self.traverse_boxes(std::slice::from_ref(object), scratch, out);
    }

    /// As [`ShaftHierarchy::traverse`] for an object bounded by several boxes (its own small
    /// hierarchy's leaves): a shaft is met when any box meets it, and covered when one box
    /// covers it. Tighter than one box around them all.
    pub fn traverse_boxes(&self, boxes: &[Aabb], scratch: &mut Traversal, out: &mut Occlusion) {
        out.sources.clear();
        out.receivers.clear();
        out.leaf_shafts.clear();
        out.pruned.clear();
        out.tested = 0;
        let object = boxes.iter().fold(Aabb::EMPTY, |u, b| u.union(b));
        if object.is_empty() {
            return;
        }
        let meet = |a: &Aabb, b: &Aabb| {
            let mut verdict = Meet::Outside;
            for o in boxes.iter().filter(|o| !o.is_empty()) {
                match meets(a, b, o) {
                    Meet::Covers => return Meet::Covers,
                    Meet::Partial => verdict = Meet::Partial,
                    Meet::Outside => {}
                }
            }
            verdict
        };
        if self.root_pruned {
            let (a, b) = self.ends(0, 0);
            out.tested = 1;
            if meet(&a, &b) != Meet::Outside {
                out.pruned.push((0, 0));
            }
            return;
        }
        if self.shafts.is_empty() {
            return;
        }
        scratch.frame = scratch.frame.wrapping_add(1);
        if scratch.frame == 0
            || scratch.source_tag.len() != self.sources.len()
            || scratch.receiver_tag.len() != self.receivers.len()
        {
            scratch.source_tag = vec![0; self.sources.len()];
            scratch.receiver_tag = vec![0; self.receivers.len()];
            scratch.frame = 1;
        }
        let frame = scratch.frame;
        scratch.stack.clear();
        scratch.stack.push((0, false));
        while let Some((k, inside)) = scratch.stack.pop() {
            let n = self.shafts[k as usize];
            let inside = inside || {
                out.tested += 1;
                let (a, b) = self.ends(n.source, n.receiver);
                match meet(&a, &b) {
                    Meet::Outside => continue,
                    Meet::Partial => false,
                    Meet::Covers => true,
                }
            };
            if n.kind == Kind::Leaf {
                out.leaf_shafts.push(k);
                for &j in self.source_tree.items(n.source) {
                    if scratch.source_tag[j as usize] != frame {
                        scratch.source_tag[j as usize] = frame;
                        out.sources.push(j);
                    }
                }
                for &p in self.receiver_tree.items(n.receiver) {
                    if scratch.receiver_tag[p as usize] != frame {
                        scratch.receiver_tag[p as usize] = frame;
                        out.receivers.push(p);
                    }
                }
                continue;
            }
            let mut stored = n.child;
            let split = if n.kind == Kind::SplitSource { n.source } else { n.receiver };
            let tree = if n.kind == Kind::SplitSource { &self.source_tree } else { &self.receiver_tree };
            for (c, child) in tree.children(split).enumerate() {
                if n.pruned & (1 << c) != 0 {
                    out.pruned.push(if n.kind == Kind::SplitSource { (child, n.receiver) } else { (n.source, child) });
                } else {
                    scratch.stack.push((stored, inside));
                    stored += 1;
                }
            }
        }
    }

    /// Paper 003's representative set: `n` source-tree nodes standing for every source in
    /// `occlusion` (0 reads as 1). From the root, repeatedly open the node whose occluded
    /// sources send the most (their transfer through the met leaf shafts) until `n` nodes are
    /// listed or all are single sources. Each keeps the summed transfer of the occluded
    /// sources under it, so the set accounts for all of them whatever `n`.
    #[must_use]
    pub fn representatives(&self, occlusion: &Occlusion, n: usize) -> Vec<Representative> {
        if occlusion.sources.is_empty() || self.source_tree.nodes.is_empty() {
            return Vec::new();
        }
        let nodes = &self.source_tree.nodes;
        // each occluded source's transfer through the met leaf shafts, summed up the tree
        let mut sum = vec![0.0f64; nodes.len()];
        let mut best = vec![(f64::NEG_INFINITY, u32::MAX); nodes.len()];
        let mut count = vec![0u32; nodes.len()];
        for &k in &occlusion.leaf_shafts {
            let s = self.shafts[k as usize];
            sum[s.source as usize] += f64::from(self.leaf_transfer[s.child as usize]);
        }
        for &j in &occlusion.sources {
            let leaf = self.source_leaf[j as usize] as usize;
            count[leaf] = 1;
            best[leaf] = (sum[leaf], j);
        }
        for k in (0..nodes.len()).rev() {
            if nodes[k].is_leaf() {
                continue;
            }
            for c in self.source_tree.children(k as u32) {
                let c = c as usize;
                sum[k] += sum[c];
                count[k] += count[c];
                if count[c] > 0 && best[c].0 > best[k].0 {
                    best[k] = best[c];
                }
            }
        }
        let key = |k: usize| Open { transfer: sum[k], node: k as u32 };
        let mut open = BinaryHeap::from([key(0)]);
        let mut done = Vec::new();
        while let Some(top) = open.pop() {
            let k = top.node;
            let splittable = !nodes[k as usize].is_leaf() && count[k as usize] > 1;
            if splittable && open.len() + done.len() + 1 < n.max(1) {
                open.extend(self.source_tree.children(k).filter(|&c| count[c as usize] > 0).map(|c| key(c as usize)));
            } else {
                done.push(k);
            }
        }
        done.into_iter()
            .map(|k| {
                let k = k as usize;
                Representative { node: k as u32, sources: count[k], transfer: sum[k], origin: best[k].1 }
            })
            .collect()
    }
}

/// A representative-set candidate, ordered by transfer.
#[derive(PartialEq)]
struct Open {
    transfer: f64,
    node: u32,
}

impl Eq for Open {}

impl PartialOrd for Open {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Open {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.transfer.total_cmp(&other.transfer).then_with(|| other.node.cmp(&self.node))
    }
}
