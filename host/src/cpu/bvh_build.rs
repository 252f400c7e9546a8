//! The binary bounding volume hierarchy, built top-down with the binned surface-area heuristic
//! (Wald, "On fast Construction of SAH-based Bounding Volume Hierarchies", 2007; pbrt-v4 7.3).
//! [`super::bvh::Bvh`] collapses it into the 8-wide tree that is traversed.
//!
//! The heuristic counts a leaf's cost in the tests traversal makes: its triangles and spheres
//! are tested four to a SIMD block, so g of them cost ceil(g / 4) tests, and each instance one
//! (at least: its own tree's traversal), as Embree's builders count blocks. Counting primitives
//! instead made leaves whose last block was mostly empty (a leaf of five costs two blocks).

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

/// What the build reads of the primitives: their boxes, the boxes' centres, and the index from
/// which on they are instances (the ones before it are triangles and spheres).
struct Primitives<'a> {
    bounds: &'a [Aabb],
    centroids: Vec<Vec3>,
    first_instance: usize,
}

impl Primitives<'_> {
    /// Whether primitive `p` is an instance.
    fn is_instance(&self, p: u32) -> bool {
        p as usize >= self.first_instance
    }
}

/// The tests a leaf of `geometry` triangles and spheres and `instances` instances costs.
fn leaf_tests((geometry, instances): (usize, usize)) -> f32 {
    (geometry.div_ceil(4) + instances) as f32
}

impl BinaryBvh {
    /// Builds the tree over primitives with these bounds, of which those from `first_instance`
    /// on are instances. O(n log n): each level partitions with a linear binning pass. The two
    /// halves of large ranges are built in parallel; the tree is the same on any number of
    /// threads (every split depends on its range only).
    pub fn build(bounds: &[Aabb], first_instance: usize) -> BinaryBvh {
        let (primitives, mut prims) = Self::inputs(bounds, first_instance);
        let nodes = build_subtree(&primitives, &mut prims, 0, 0);
        BinaryBvh { nodes, prims }
    }

    /// The same tree built on the calling thread alone, in depth-first node order: the
    /// reference the parallel build is tested against.
    #[cfg(feature = "test-support")]
    pub fn build_one_thread(bounds: &[Aabb], first_instance: usize) -> BinaryBvh {
        let (primitives, mut prims) = Self::inputs(bounds, first_instance);
        let nodes = build_serial(&primitives, &mut prims, 0, 0);
        BinaryBvh { nodes, prims }
    }

    fn inputs(bounds: &[Aabb], first_instance: usize) -> (Primitives<'_>, Vec<u32>) {
        let primitives = Primitives {
            bounds,
            centroids: bounds.iter().map(Aabb::centroid).collect(),
            first_instance,
        };
        (primitives, (0..bounds.len() as u32).collect())
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
fn divide(prims: &mut [u32], primitives: &Primitives, b: &Aabb, depth: usize) -> Division {
    let centroids = &primitives.centroids;
    let count = prims.len();
    if count <= MAX_LEAF {
        return Division::Leaf;
    }
    let cb = prims
        .iter()
        .fold(Aabb::EMPTY, |a, &p| a.grow(centroids[p as usize]));
    // Past SAH_MAX_DEPTH only median splits, which bound the depth by log2(n).
    let split = if depth < SAH_MAX_DEPTH {
        best_split(prims, primitives, &cb, b.half_area())
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
    primitives: &Primitives,
    prims: &mut [u32],
    offset: usize,
    depth: usize,
) -> Vec<Node> {
    if prims.len() < PARALLEL_MIN {
        return build_serial(primitives, prims, offset, depth);
    }
    let b = bounds_of(prims, primitives.bounds);
    let Division::At(mid) = divide(prims, primitives, &b, depth) else {
        unreachable!("ranges this large always split");
    };
    let (lp, rp) = prims.split_at_mut(mid);
    let (left, right) = rayon::join(
        || build_subtree(primitives, lp, offset, depth + 1),
        || build_subtree(primitives, rp, offset + mid, depth + 1),
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
    primitives: &Primitives,
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
        let b = bounds_of(range, primitives.bounds);
        nodes[node].bounds = b;
        match divide(range, primitives, &b, depth) {
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
    primitives: &Primitives,
    cb: &Aabb,
    parent_half_area: f32,
) -> Option<(usize, f32)> {
    let (bounds, centroids) = (primitives.bounds, &primitives.centroids);
    let mut best: Option<(f32, usize, f32)> = None;
    // (triangles and spheres, instances) in `prims`, as the binning counts them.
    let mut total = (0, 0);
    for axis in 0..3 {
        let lo = cb.min[axis];
        let extent = cb.max[axis] - lo;
        if !(extent > 0.0) {
            continue;
        }
        let mut bin_bounds = [Aabb::EMPTY; BINS];
        // (triangles and spheres, instances) per bin.
        let mut bin_count = [(0usize, 0usize); BINS];
        let scale = BINS as f32 / extent;
        for &p in prims {
            let b = (((centroids[p as usize][axis] - lo) * scale) as usize).min(BINS - 1);
            if primitives.is_instance(p) {
                bin_count[b].1 += 1;
            } else {
                bin_count[b].0 += 1;
            }
            bin_bounds[b] = bin_bounds[b].union(bounds[p as usize]);
        }
        let add = |(g, i): (usize, usize), (h, j): (usize, usize)| (g + h, i + j);
        // Sweep: cost of splitting after bin i.
        let mut right_area = [0.0f32; BINS];
        let mut right_count = [(0usize, 0usize); BINS];
        let mut acc = Aabb::EMPTY;
        let mut cnt = (0, 0);
        for i in (1..BINS).rev() {
            acc = acc.union(bin_bounds[i]);
            cnt = add(cnt, bin_count[i]);
            right_area[i] = acc.half_area();
            right_count[i] = cnt;
        }
        total = add(bin_count[0], right_count[1]);
        let mut left = Aabb::EMPTY;
        let mut left_count = (0, 0);
        for i in 0..BINS - 1 {
            left = left.union(bin_bounds[i]);
            left_count = add(left_count, bin_count[i]);
            if left_count == (0, 0) || right_count[i + 1] == (0, 0) {
                continue;
            }
            let cost = left.half_area() * leaf_tests(left_count)
                + right_area[i + 1] * leaf_tests(right_count[i + 1]);
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, lo + (i + 1) as f32 / scale));
            }
        }
    }
    let (cost, axis, plane) = best?;
    // Leaf cost: test all; split cost: traversal (~1/2 of a test) + expected tests.
    let leaf_cost = leaf_tests(total);
    let split_cost = 0.5 + cost / parent_half_area.max(f32::MIN_POSITIVE);
    if split_cost < leaf_cost || prims.len() > SAH_LEAF_MAX {
        Some((axis, plane))
    } else {
        None
    }
}
