//! The binary bounding volume hierarchy, built top-down with the binned surface-area heuristic
//! (Wald, "On fast Construction of SAH-based Bounding Volume Hierarchies", 2007; pbrt-v4 7.3).
//! [`super::bvh::Bvh`] collapses it into the 8-wide tree that is traversed.

use glam::Vec3;

/// Axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };
    pub fn union(self, o: Aabb) -> Aabb {
        Aabb {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }
    pub fn grow(self, p: Vec3) -> Aabb {
        Aabb {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }
    pub fn centroid(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }
    pub fn half_area(&self) -> f32 {
        let d = (self.max - self.min).max(Vec3::ZERO);
        d.x * d.y + d.y * d.z + d.z * d.x
    }
}

/// A node: a leaf if `count > 0` (primitives `first..first + count` of the reordered list),
/// else an interior node whose children are nodes `first` and `first + 1`.
#[derive(Clone, Copy, Debug)]
pub struct Node {
    pub bounds: Aabb,
    pub first: u32,
    pub count: u32,
}

/// The tree and the primitive order its leaves index.
pub struct BinaryBvh {
    pub nodes: Vec<Node>,
    pub prims: Vec<u32>,
}

const BINS: usize = 16;
const MAX_LEAF: usize = 4;
/// Largest leaf the SAH may prefer to splitting.
const SAH_LEAF_MAX: usize = 16;
/// Depth after which the build splits at the median only (depth < SAH_MAX_DEPTH + log2 n).
pub const SAH_MAX_DEPTH: usize = 96;

/// Subtrees over at least this many primitives are built on two threads (`rayon::join`);
/// smaller ones by one thread into one vector.
const PARALLEL_MIN: usize = 4096;

impl BinaryBvh {
    /// Builds the tree over primitives with these bounds. O(n log n): each level partitions
    /// with a linear binning pass. The two halves of large ranges are built in parallel; the
    /// tree is the same on any number of threads (every split depends on its range only).
    pub fn build(bounds: &[Aabb]) -> BinaryBvh {
        let centroids: Vec<Vec3> = bounds.iter().map(Aabb::centroid).collect();
        let mut prims: Vec<u32> = (0..bounds.len() as u32).collect();
        let nodes = build_subtree(bounds, &centroids, &mut prims, 0, 0);
        BinaryBvh { nodes, prims }
    }

    /// The same tree built on the calling thread alone, in depth-first node order: the
    /// reference the parallel build is tested against.
    #[cfg(feature = "test-support")]
    pub fn build_one_thread(bounds: &[Aabb]) -> BinaryBvh {
        let centroids: Vec<Vec3> = bounds.iter().map(Aabb::centroid).collect();
        let mut prims: Vec<u32> = (0..bounds.len() as u32).collect();
        let nodes = build_serial(bounds, &centroids, &mut prims, 0, 0);
        BinaryBvh { nodes, prims }
    }
}

/// How a range of primitives is divided.
enum Division {
    /// Make it one leaf.
    Leaf,
    /// Split after this many (the range is reordered so that they come first).
    At(usize),
}

/// Decides the node over `prims` with bounds `b` at `depth` (reordering `prims` for a split).
fn divide(
    prims: &mut [u32],
    bounds: &[Aabb],
    centroids: &[Vec3],
    b: &Aabb,
    depth: usize,
) -> Division {
    let count = prims.len();
    if count <= MAX_LEAF {
        return Division::Leaf;
    }
    let cb = prims
        .iter()
        .fold(Aabb::EMPTY, |a, &p| a.grow(centroids[p as usize]));
    // Past SAH_MAX_DEPTH only median splits, which bound the depth by log2(n).
    let split = if depth < SAH_MAX_DEPTH {
        best_split(prims, bounds, centroids, &cb, b.half_area())
    } else {
        None
    };
    let mid = match split {
        Some((axis, plane)) => {
            let mut i = 0;
            for j in 0..count {
                if centroids[prims[j] as usize][axis] < plane {
                    prims.swap(i, j);
                    i += 1;
                }
            }
            i
        }
        // A leaf is cheaper than any split.
        None if count <= SAH_LEAF_MAX && depth < SAH_MAX_DEPTH => return Division::Leaf,
        None => 0,
    };
    if mid == 0 || mid == count {
        // Median split along the widest centroid axis.
        let axis = (cb.max - cb.min).max_position();
        prims.sort_by(|&a, &b| centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis]));
        Division::At(count / 2)
    } else {
        Division::At(mid)
    }
}

fn bounds_of(prims: &[u32], bounds: &[Aabb]) -> Aabb {
    prims
        .iter()
        .fold(Aabb::EMPTY, |a, &p| a.union(bounds[p as usize]))
}

/// The subtree over `prims` (entries `offset..` of the whole primitive list) at `depth`, root
/// first; an interior node's children are adjacent. Large ranges build their halves in
/// parallel and concatenate them as [root, left root, right root, left rest, right rest].
fn build_subtree(
    bounds: &[Aabb],
    centroids: &[Vec3],
    prims: &mut [u32],
    offset: usize,
    depth: usize,
) -> Vec<Node> {
    if prims.len() < PARALLEL_MIN {
        return build_serial(bounds, centroids, prims, offset, depth);
    }
    let b = bounds_of(prims, bounds);
    let Division::At(mid) = divide(prims, bounds, centroids, &b, depth) else {
        unreachable!("ranges this large always split");
    };
    let (lp, rp) = prims.split_at_mut(mid);
    let (left, right) = rayon::join(
        || build_subtree(bounds, centroids, lp, offset, depth + 1),
        || build_subtree(bounds, centroids, rp, offset + mid, depth + 1),
    );
    // Node i >= 1 of a part moves to base + i - 1; its root to slot 1 or 2.
    let (base_left, base_right) = (3, 3 + left.len() - 1);
    let moved = |n: Node, base: usize| {
        if n.count > 0 {
            n
        } else {
            Node {
                first: (base + n.first as usize - 1) as u32,
                ..n
            }
        }
    };
    let mut nodes = Vec::with_capacity(1 + left.len() + right.len());
    nodes.push(Node {
        bounds: b,
        first: 1,
        count: 0,
    });
    nodes.push(moved(left[0], base_left));
    nodes.push(moved(right[0], base_right));
    nodes.extend(left[1..].iter().map(|&n| moved(n, base_left)));
    nodes.extend(right[1..].iter().map(|&n| moved(n, base_right)));
    nodes
}

/// [`build_subtree`] on one thread: an explicit stack, nodes appended in pairs.
fn build_serial(
    bounds: &[Aabb],
    centroids: &[Vec3],
    prims: &mut [u32],
    offset: usize,
    depth: usize,
) -> Vec<Node> {
    let empty = Node {
        bounds: Aabb::EMPTY,
        first: 0,
        count: 0,
    };
    let mut nodes = Vec::with_capacity(2 * prims.len().max(1));
    nodes.push(empty);
    // (node index, range start, range end, depth), ranges local to `prims`.
    let mut work = vec![(0usize, 0usize, prims.len(), depth)];
    while let Some((node, start, end, depth)) = work.pop() {
        let range = &mut prims[start..end];
        let b = bounds_of(range, bounds);
        nodes[node].bounds = b;
        match divide(range, bounds, centroids, &b, depth) {
            Division::Leaf => {
                nodes[node].first = (offset + start) as u32;
                nodes[node].count = (end - start) as u32;
            }
            Division::At(mid) => {
                let left = nodes.len();
                nodes.push(empty);
                nodes.push(empty);
                nodes[node].first = left as u32;
                work.push((left + 1, start + mid, end, depth + 1));
                work.push((left, start, start + mid, depth + 1));
            }
        }
    }
    nodes
}

// `axis` indexes the bounds, the centroids and the bins' vectors alike.
#[allow(clippy::needless_range_loop)]
/// The best binned-SAH split of `prims` as (axis, centroid plane), or None when a leaf is cheaper.
fn best_split(
    prims: &[u32],
    bounds: &[Aabb],
    centroids: &[Vec3],
    cb: &Aabb,
    parent_half_area: f32,
) -> Option<(usize, f32)> {
    let mut best: Option<(f32, usize, f32)> = None;
    for axis in 0..3 {
        let lo = cb.min[axis];
        let extent = cb.max[axis] - lo;
        if !(extent > 0.0) {
            continue;
        }
        let mut bin_bounds = [Aabb::EMPTY; BINS];
        let mut bin_count = [0usize; BINS];
        let scale = BINS as f32 / extent;
        for &p in prims {
            let b = (((centroids[p as usize][axis] - lo) * scale) as usize).min(BINS - 1);
            bin_count[b] += 1;
            bin_bounds[b] = bin_bounds[b].union(bounds[p as usize]);
        }
        // Sweep: cost of splitting after bin i.
        let mut right_area = [0.0f32; BINS];
        let mut right_count = [0usize; BINS];
        let mut acc = Aabb::EMPTY;
        let mut cnt = 0;
        for i in (1..BINS).rev() {
            acc = acc.union(bin_bounds[i]);
            cnt += bin_count[i];
            right_area[i] = acc.half_area();
            right_count[i] = cnt;
        }
        let mut left = Aabb::EMPTY;
        let mut left_count = 0;
        for i in 0..BINS - 1 {
            left = left.union(bin_bounds[i]);
            left_count += bin_count[i];
            if left_count == 0 || right_count[i + 1] == 0 {
                continue;
            }
            let cost = left.half_area() * left_count as f32
                + right_area[i + 1] * right_count[i + 1] as f32;
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, lo + (i + 1) as f32 / scale));
            }
        }
    }
    let (cost, axis, plane) = best?;
    // Leaf cost: intersect all; split cost: traversal (~1) + expected intersections.
    let leaf_cost = prims.len() as f32;
    let split_cost = 0.5 + cost / parent_half_area.max(f32::MIN_POSITIVE);
    if split_cost < leaf_cost || prims.len() > SAH_LEAF_MAX {
        Some((axis, plane))
    } else {
        None
    }
}
