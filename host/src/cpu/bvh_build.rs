//! The binary bounding volume hierarchy, built top-down with the binned surface-area heuristic
//! (Wald, "On fast Construction of SAH-based Bounding Volume Hierarchies", 2007; pbrt-v4 7.3).
//! [`super::bvh::Bvh`] collapses it into the 4-wide tree that is traversed.

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

impl BinaryBvh {
    /// Builds the tree over primitives with these bounds. O(n log n): each level partitions
    /// with a linear binning pass.
    pub fn build(bounds: &[Aabb]) -> BinaryBvh {
        let n = bounds.len();
        let centroids: Vec<Vec3> = bounds.iter().map(Aabb::centroid).collect();
        let mut prims: Vec<u32> = (0..n as u32).collect();
        let mut nodes = Vec::with_capacity(2 * n.max(1));
        nodes.push(Node {
            bounds: Aabb::EMPTY,
            first: 0,
            count: n as u32,
        });
        // Iterative build: (node index, range start, range end, depth).
        let mut work = vec![(0usize, 0usize, n, 0usize)];
        while let Some((node, start, end, depth)) = work.pop() {
            let b = prims[start..end]
                .iter()
                .fold(Aabb::EMPTY, |a, &p| a.union(bounds[p as usize]));
            nodes[node].bounds = b;
            let count = end - start;
            if count <= MAX_LEAF {
                nodes[node].first = start as u32;
                nodes[node].count = count as u32;
                continue;
            }
            let cb = prims[start..end]
                .iter()
                .fold(Aabb::EMPTY, |a, &p| a.grow(centroids[p as usize]));
            // Past SAH_MAX_DEPTH only median splits, which bound the depth by log2(n).
            let split = if depth < SAH_MAX_DEPTH {
                best_split(&prims[start..end], bounds, &centroids, &cb, b.half_area())
            } else {
                None
            };
            let mid = match split {
                Some((axis, plane)) => {
                    let slice = &mut prims[start..end];
                    let mut i = 0;
                    for j in 0..slice.len() {
                        if centroids[slice[j] as usize][axis] < plane {
                            slice.swap(i, j);
                            i += 1;
                        }
                    }
                    start + i
                }
                None if count <= SAH_LEAF_MAX && depth < SAH_MAX_DEPTH => {
                    // A leaf is cheaper than any split.
                    nodes[node].first = start as u32;
                    nodes[node].count = count as u32;
                    continue;
                }
                None => start,
            };
            let mid = if mid == start || mid == end {
                // Median split along the widest centroid axis.
                let axis = (cb.max - cb.min).max_position();
                prims[start..end].sort_by(|&a, &b| {
                    centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis])
                });
                start + count / 2
            } else {
                mid
            };
            let left = nodes.len();
            nodes.push(Node {
                bounds: Aabb::EMPTY,
                first: 0,
                count: 0,
            });
            nodes.push(Node {
                bounds: Aabb::EMPTY,
                first: 0,
                count: 0,
            });
            nodes[node].first = left as u32;
            nodes[node].count = 0;
            work.push((left + 1, mid, end, depth + 1));
            work.push((left, start, mid, depth + 1));
        }
        BinaryBvh { nodes, prims }
    }
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
