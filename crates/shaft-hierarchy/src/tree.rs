//! The two patch hierarchies: a binary KD-tree over sources (one source a leaf, so the
//! representative set can be refined one node at a time) and an octree over receivers (at most
//! `leaf_size` patches a leaf: broad and shallow). Both are flat arrays; every node's items are
//! one contiguous range of a permutation.

use glam::Vec3;

use crate::Aabb;

/// Where a source's light comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SourceShape {
    /// A patch of the scene, bounded by this box.
    Local(Aabb),
    /// A distant source (a light of the environment map), bounded by a box of the unit
    /// directions towards it.
    Distant(Aabb),
}

/// A node of either tree.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Node {
    /// Bounds of the node's local items (`Aabb::EMPTY` when it has none).
    pub bounds: Aabb,
    /// Its items: `order[first..first + count]`.
    pub first: u32,
    /// Number of items.
    pub count: u32,
    /// Its children: `nodes[child..child + children]`; none for a leaf.
    pub child: u32,
    /// Number of children (0, 2, or up to 8).
    pub children: u8,
}

impl Node {
    /// True for a leaf.
    #[must_use]
    pub fn is_leaf(&self) -> bool {
        self.children == 0
    }
}

/// A hierarchy: nodes (the root first) and the item permutation they index.
#[derive(Clone, Debug, Default)]
pub struct Tree {
    /// Nodes, the root at 0; a node's children are consecutive.
    pub nodes: Vec<Node>,
    /// Item indices, grouped so that each node's items are one range.
    pub order: Vec<u32>,
    /// Per node, the bounds of its distant sources' unit directions (`Aabb::EMPTY` for none);
    /// empty when no item is distant (receivers, local-only sources).
    pub directions: Vec<Aabb>,
}

impl Tree {
    /// The items under `node`.
    #[must_use]
    pub fn items(&self, node: u32) -> &[u32] {
        let n = &self.nodes[node as usize];
        &self.order[n.first as usize..(n.first + n.count) as usize]
    }

    /// The bounds of `node`'s distant directions (`Aabb::EMPTY` when none).
    #[must_use]
    pub fn directions(&self, node: u32) -> Aabb {
        self.directions.get(node as usize).copied().unwrap_or(Aabb::EMPTY)
    }

    /// The children of `node`.
    pub fn children(&self, node: u32) -> impl Iterator<Item = u32> + use<> {
        let n = self.nodes[node as usize];
        n.child..n.child + u32::from(n.children)
    }

    /// Checks the hierarchy's invariants: children partition their parent's items, bounds hold
    /// their items' and children's, every item appears once. `shape(i)` is item i's (local
    /// bounds, direction bounds).
    ///
    /// # Errors
    /// The first broken invariant, in words.
    pub fn validate(&self, items: usize, shape: impl Fn(u32) -> (Aabb, Aabb)) -> Result<(), String> {
        let mut seen = vec![false; items];
        if self.order.len() != items {
            return Err(format!("{} items ordered, {items} given", self.order.len()));
        }
        for &i in &self.order {
            if seen.get(i as usize).copied() != Some(false) {
                return Err(format!("item {i} twice or out of range"));
            }
            seen[i as usize] = true;
        }
        if items > 0 && (self.nodes.is_empty() || self.nodes[0].count as usize != items) {
            return Err("the root does not hold every item".into());
        }
        for (k, n) in self.nodes.iter().enumerate() {
            for &i in self.items(k as u32) {
                let (b, d) = shape(i);
                let dirs = self.directions(k as u32);
                if !(b.is_empty() || n.bounds.contains(&b)) || !(d.is_empty() || dirs.contains(&d)) {
                    return Err(format!("node {k} does not bound item {i}"));
                }
            }
            if n.is_leaf() {
                continue;
            }
            let mut next = n.first;
            for c in self.children(k as u32) {
                let ch = self.nodes.get(c as usize).ok_or_else(|| format!("node {k}: child {c} out of range"))?;
                if c as usize <= k {
                    return Err(format!("node {k}: child {c} before its parent"));
                }
                if ch.first != next {
                    return Err(format!("node {k}: children do not partition its items"));
                }
                next += ch.count;
            }
            if next != n.first + n.count {
                return Err(format!("node {k}: children hold {} of {} items", next - n.first, n.count));
            }
        }
        Ok(())
    }
}

/// The KD-tree over sources: local and distant sources apart at the root, then median splits
/// along the widest axis of the centres (positions, or directions), down to one source a leaf.
#[must_use]
pub fn source_tree(sources: &[SourceShape]) -> Tree {
    let mut tree = Tree { nodes: Vec::new(), order: (0..sources.len() as u32).collect(), directions: Vec::new() };
    if sources.is_empty() {
        return tree;
    }
    // local first, then distant: the root's split
    tree.order.sort_by_key(|&i| matches!(sources[i as usize], SourceShape::Distant(_)));
    let locals = tree.order.iter().take_while(|&&i| matches!(sources[i as usize], SourceShape::Local(_))).count();
    let centre = |i: u32| match sources[i as usize] {
        SourceShape::Local(b) | SourceShape::Distant(b) => b.center(),
    };
    let distant = sources.len() - locals;
    let push = |tree: &mut Tree, first: usize, count: usize| {
        let (node, dirs) = source_node(sources, &tree.order, first, count);
        tree.nodes.push(node);
        if distant > 0 {
            tree.directions.push(dirs);
        }
    };
    push(&mut tree, 0, sources.len());
    let mut stack = vec![0u32];
    while let Some(k) = stack.pop() {
        let n = tree.nodes[k as usize];
        let (first, count) = (n.first as usize, n.count as usize);
        if count <= 1 {
            continue;
        }
        let mid = if k == 0 && locals > 0 && locals < count {
            locals
        } else {
            let slice = &mut tree.order[first..first + count];
            let bounds = Aabb::from_points(slice.iter().map(|&i| centre(i)));
            let axis = bounds.size().max_position();
            let half = count / 2;
            slice.select_nth_unstable_by(half, |&a, &b| centre(a)[axis].total_cmp(&centre(b)[axis]));
            first + half
        };
        let child = tree.nodes.len() as u32;
        push(&mut tree, first, mid - first);
        push(&mut tree, mid, first + count - mid);
        let node = &mut tree.nodes[k as usize];
        node.child = child;
        node.children = 2;
        stack.extend([child, child + 1]);
    }
    tree
}

fn source_node(sources: &[SourceShape], order: &[u32], first: usize, count: usize) -> (Node, Aabb) {
    let (mut bounds, mut directions) = (Aabb::EMPTY, Aabb::EMPTY);
    for &i in &order[first..first + count] {
        match sources[i as usize] {
            SourceShape::Local(b) => bounds = bounds.union(&b),
            SourceShape::Distant(d) => directions = directions.union(&d),
        }
    }
    (Node { bounds, first: first as u32, count: count as u32, child: 0, children: 0 }, directions)
}

/// The octree over receiver patches (their boxes): a node splits at its centre into up to 8
/// children by patch centre while it holds more than `leaf_size` patches. A split that would
/// leave every patch in one octant (coincident centres) stops instead.
#[must_use]
pub fn receiver_octree(receivers: &[Aabb], leaf_size: usize) -> Tree {
    let leaf_size = leaf_size.max(1);
    let mut tree = Tree { nodes: Vec::new(), order: (0..receivers.len() as u32).collect(), directions: Vec::new() };
    if receivers.is_empty() {
        return tree;
    }
    let node = |order: &[u32], first: usize, count: usize| Node {
        bounds: order[first..first + count].iter().fold(Aabb::EMPTY, |b, &i| b.union(&receivers[i as usize])),
        first: first as u32,
        count: count as u32,
        child: 0,
        children: 0,
    };
    tree.nodes.push(node(&tree.order, 0, receivers.len()));
    let mut stack = vec![0u32];
    while let Some(k) = stack.pop() {
        let n = tree.nodes[k as usize];
        let (first, count) = (n.first as usize, n.count as usize);
        if count <= leaf_size {
            continue;
        }
        let centres =
            Aabb::from_points(tree.order[first..first + count].iter().map(|&i| receivers[i as usize].center()));
        let mid = centres.center();
        let octant = |i: u32| {
            let c = receivers[i as usize].center();
            usize::from(c.x > mid.x) | usize::from(c.y > mid.y) << 1 | usize::from(c.z > mid.z) << 2
        };
        let slice = &mut tree.order[first..first + count];
        slice.sort_by_key(|&i| octant(i));
        let mut bins = [0usize; 8];
        for &i in slice.iter() {
            bins[octant(i)] += 1;
        }
        if bins.iter().filter(|&&b| b > 0).count() < 2 {
            continue;
        }
        let child = tree.nodes.len() as u32;
        let mut start = first;
        for b in bins.into_iter().filter(|&b| b > 0) {
            tree.nodes.push(node(&tree.order, start, b));
            start += b;
        }
        let children = (tree.nodes.len() as u32 - child) as u8;
        let parent = &mut tree.nodes[k as usize];
        parent.child = child;
        parent.children = children;
        stack.extend(child..child + u32::from(children));
    }
    tree
}

/// A box of unit directions within `half_angle` of `axis` (conservative: the cap's bounds).
#[must_use]
pub fn cone_direction_bounds(axis: Vec3, half_angle: f32) -> Aabb {
    let a = axis.normalize();
    // the cap {d : d·a >= c}: per coordinate e, d·e ranges over cos(angle(a, e) ∓ half_angle)
    let mut min = Vec3::ZERO;
    let mut max = Vec3::ZERO;
    for i in 0..3 {
        let ai = a[i].clamp(-1.0, 1.0);
        let theta = ai.acos();
        let lo = (theta + half_angle).min(std::f32::consts::PI).cos();
        let hi = (theta - half_angle).max(0.0).cos();
        min[i] = lo;
        max[i] = hi;
    }
    // outward by a few ulps: the directions are normalized in f32
    Aabb { min: min - Vec3::splat(4.0 * f32::EPSILON), max: max + Vec3::splat(4.0 * f32::EPSILON) }
}
