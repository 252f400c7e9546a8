//! A bounding volume hierarchy over spheres and triangles, built top-down with the binned
//! surface-area heuristic (Wald, "On fast Construction of SAH-based Bounding Volume
//! Hierarchies", 2007; pbrt-v4 7.3), traversed iteratively nearest child first.

use glam::Vec3;
use kernel::geometry::{
    intersect_sphere, intersect_triangle, intersect_triangle_uv, reproject_to_sphere,
    sphere_point_error, triangle_normal, triangle_point, triangle_point_error,
};
use kernel::scene::{Sphere, Triangle, NONE};
use kernel::SurfaceHit;

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
struct Node {
    bounds: Aabb,
    first: u32,
    count: u32,
}

/// Geometry plus its hierarchy. Primitive ids below `spheres.len()` are spheres, the rest
/// triangles.
pub struct Bvh {
    nodes: Vec<Node>,
    prims: Vec<u32>,
    pub spheres: Vec<Sphere>,
    pub triangles: Vec<Triangle>,
}

const BINS: usize = 16;
const MAX_LEAF: usize = 4;
/// Largest leaf the SAH may prefer to splitting.
const SAH_LEAF_MAX: usize = 16;
/// Depth after which the build splits at the median only (depth < SAH_MAX_DEPTH + log2 n).
const SAH_MAX_DEPTH: usize = 96;
/// Traversal stack: deeper than any tree the build makes (SAH_MAX_DEPTH + 32 for 2^32 prims).
const STACK: usize = 128;
/// 1 + 2 gamma(3): widening of a slab test's far distance so rounding never culls a box the
/// ray touches (pbrt-v4 6.8.2; gamma(n) = n u / (1 - n u), u = 2^-24).
const SLAB_PAD: f32 = 1.0 + 2.0 * (3.0 * 5.960_464_5e-8) / (1.0 - 3.0 * 5.960_464_5e-8);

fn prim_bounds(spheres: &[Sphere], triangles: &[Triangle], id: u32) -> Aabb {
    let id = id as usize;
    if id < spheres.len() {
        let s = &spheres[id];
        let c = Vec3::from(s.center);
        Aabb {
            min: c - Vec3::splat(s.radius),
            max: c + Vec3::splat(s.radius),
        }
    } else {
        let t = &triangles[id - spheres.len()];
        let p0 = Vec3::from(t.p0);
        Aabb::EMPTY
            .grow(p0)
            .grow(p0 + Vec3::from(t.edge1))
            .grow(p0 + Vec3::from(t.edge2))
    }
}

impl Bvh {
    /// Builds the hierarchy. O(n log n): each level partitions with a linear binning pass.
    pub fn build(spheres: Vec<Sphere>, triangles: Vec<Triangle>) -> Bvh {
        let n = spheres.len() + triangles.len();
        let bounds: Vec<Aabb> = (0..n as u32)
            .map(|i| prim_bounds(&spheres, &triangles, i))
            .collect();
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
                best_split(&prims[start..end], &bounds, &centroids, &cb, b.half_area())
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
        Bvh {
            nodes,
            prims,
            spheres,
            triangles,
        }
    }

    /// Number of nodes (for statistics).
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Closest hit along `origin + t dir`, t in (0, t_max).
    pub fn closest_hit(&self, origin: Vec3, dir: Vec3, t_max: f32) -> SurfaceHit {
        let mut best_t = t_max;
        let mut best: u32 = NONE;
        self.traverse(
            origin,
            dir,
            t_max,
            |id, t_limit| {
                let t = self.intersect(id, origin, dir, t_limit);
                if t >= 0.0 && t < best_t {
                    best_t = t;
                    best = id;
                    Some(t)
                } else {
                    None
                }
            },
            false,
        );
        if best == NONE {
            return SurfaceHit::miss();
        }
        self.surface(best, origin, dir, best_t)
    }

    /// Whether anything is hit along `origin + t dir`, t in (0, t_max).
    pub fn any_hit(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        let mut found = false;
        self.traverse(
            origin,
            dir,
            t_max,
            |id, t_limit| {
                if self.intersect(id, origin, dir, t_limit) >= 0.0 {
                    found = true;
                    Some(0.0)
                } else {
                    None
                }
            },
            true,
        );
        found
    }

    fn intersect(&self, id: u32, origin: Vec3, dir: Vec3, t_max: f32) -> f32 {
        let id = id as usize;
        if id < self.spheres.len() {
            let s = &self.spheres[id];
            intersect_sphere(origin, dir, Vec3::from(s.center), s.radius, 0.0, t_max)
        } else {
            let t = &self.triangles[id - self.spheres.len()];
            intersect_triangle(
                origin,
                dir,
                Vec3::from(t.p0),
                Vec3::from(t.edge1),
                Vec3::from(t.edge2),
                0.0,
                t_max,
            )
        }
    }

    /// The hit record, computed as the GPU's closest-hit shaders do.
    fn surface(&self, id: u32, origin: Vec3, dir: Vec3, t: f32) -> SurfaceHit {
        let id = id as usize;
        if id < self.spheres.len() {
            let s = &self.spheres[id];
            let c = Vec3::from(s.center);
            let p = reproject_to_sphere(origin + t * dir, c, s.radius);
            SurfaceHit {
                position: p,
                t,
                normal: (p - c) / s.radius,
                material: s.material,
                light: s.light,
                error: sphere_point_error(c, s.radius),
            }
        } else {
            let tri = &self.triangles[id - self.spheres.len()];
            let (p0, e1, e2) = (
                Vec3::from(tri.p0),
                Vec3::from(tri.edge1),
                Vec3::from(tri.edge2),
            );
            // The winning triangle again, for its barycentrics (once per ray).
            let h = intersect_triangle_uv(origin, dir, p0, e1, e2, 0.0, f32::INFINITY);
            SurfaceHit {
                position: triangle_point(p0, e1, e2, h.u, h.v),
                t,
                normal: triangle_normal(e1, e2),
                material: tri.material,
                light: NONE,
                error: triangle_point_error(p0, e1, e2, h.u, h.v),
            }
        }
    }

    /// Visits leaves front to back; `visit(prim, t_limit)` returns the new closest t on a hit.
    /// With `stop_at_first`, any hit ends the traversal.
    #[inline]
    fn traverse(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        mut visit: impl FnMut(u32, f32) -> Option<f32>,
        stop_at_first: bool,
    ) {
        if self.prims.is_empty() {
            return;
        }
        let inv = dir.recip();
        let mut t_limit = t_max;
        let mut stack = [0u32; STACK];
        let mut sp = 0;
        let mut node = 0usize;
        if slab(&self.nodes[0].bounds, origin, inv, t_limit).is_none() {
            return;
        }
        loop {
            let n = &self.nodes[node];
            if n.count > 0 {
                for &p in &self.prims[n.first as usize..(n.first + n.count) as usize] {
                    if let Some(t) = visit(p, t_limit) {
                        if stop_at_first {
                            return;
                        }
                        t_limit = t;
                    }
                }
            } else {
                let a = n.first as usize;
                let b = a + 1;
                let ta = slab(&self.nodes[a].bounds, origin, inv, t_limit);
                let tb = slab(&self.nodes[b].bounds, origin, inv, t_limit);
                match (ta, tb) {
                    (Some(x), Some(y)) => {
                        let (near, far) = if x <= y { (a, b) } else { (b, a) };
                        // The build bounds the depth below STACK, so this never overflows.
                        stack[sp] = far as u32;
                        sp += 1;
                        node = near;
                        continue;
                    }
                    (Some(_), None) => {
                        node = a;
                        continue;
                    }
                    (None, Some(_)) => {
                        node = b;
                        continue;
                    }
                    (None, None) => {}
                }
            }
            // Pop the next node still in front of the closest hit.
            loop {
                if sp == 0 {
                    return;
                }
                sp -= 1;
                let cand = stack[sp] as usize;
                if slab(&self.nodes[cand].bounds, origin, inv, t_limit).is_some() {
                    node = cand;
                    break;
                }
            }
        }
    }
}

/// Entry distance of the ray into the box within (0, t_max), if it enters.
#[inline]
fn slab(b: &Aabb, origin: Vec3, inv: Vec3, t_max: f32) -> Option<f32> {
    let t0 = (b.min - origin) * inv;
    let t1 = (b.max - origin) * inv;
    let near = t0.min(t1).max_element().max(0.0);
    let far = t0.max(t1).min_element().min(t_max);
    let far = far * SLAB_PAD;
    if near <= far {
        Some(near)
    } else {
        None
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
