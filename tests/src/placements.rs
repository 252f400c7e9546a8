//! Random geometry for the robustness tests (`reintersection.rs` under IEEE arithmetic,
//! `vulkan_precision.rs` under a model of Vulkan's): placements at every scale and the ray
//! toward a random point of a random triangle or quad, drawn the same way by both.

use crate::SplitMix;
use glam::Vec3;

/// Edge-favouring inputs on top of [`SplitMix`].
pub struct Placements(pub SplitMix);

impl Placements {
    pub fn unit(&mut self) -> f32 {
        self.0.unit()
    }
    /// 10^U(lo, hi).
    pub fn pow10(&mut self, lo: f32, hi: f32) -> f32 {
        10f32.powf(lo + (hi - lo) * self.unit())
    }
    /// A unit direction, uniform on the sphere ([`SplitMix::direction`]).
    pub fn dir(&mut self) -> Vec3 {
        self.0.direction()
    }
    /// A random placement: scale 10^U(-4, 5), translated by up to 10^3 times that.
    pub fn placement(&mut self) -> (f32, Vec3) {
        let s = self.pow10(-4.0, 5.0);
        let t = self.dir() * s * self.pow10(-4.0, 5.0).min(1e3);
        (s, t)
    }

    /// An instance's object-to-world map as `instances.rs` draws them, and its largest stretch:
    /// scale 10^U(-3, 3), anisotropy 10^U(-1, 1) along two axes, a rotation about a random axis,
    /// mirrored in half, translated by up to 10^U(0, 4) scales (at most 10^4).
    pub fn instance_map(&mut self) -> (glam::DMat4, f64) {
        use glam::{DMat4, DVec3};
        let scale = 10f64.powf(-3.0 + 6.0 * self.unit() as f64);
        let ax = 10f64.powf(2.0 * self.unit() as f64 - 1.0);
        let aniso = DVec3::new(ax, 10f64.powf(2.0 * self.unit() as f64 - 1.0), 1.0);
        let mirror = if self.unit() < 0.5 { -1.0 } else { 1.0 };
        let axis = self.dir().as_dvec3();
        let angle = self.unit() as f64 * std::f64::consts::TAU;
        let (direction, length) = (self.dir().as_dvec3(), self.unit() as f64);
        let shift = direction * length * (scale * 10f64.powf(4.0 * self.unit() as f64)).min(1e4);
        let m = DMat4::from_translation(shift)
            * DMat4::from_axis_angle(axis, angle)
            * DMat4::from_scale(scale * aniso * DVec3::new(mirror, 1.0, 1.0));
        (m, scale * aniso.max_element())
    }

    /// A triangle (or, for a quad, the loader's two triangles sharing the diagonal) placed at
    /// random, and a ray from 0.1 to 100 sizes away toward a random point of it: (size, origin,
    /// unit direction, the triangles as (p0, edge1, edge2)). None for a degenerate shape.
    /// Half are oriented at random; a quarter lie in a plane normal to an axis (the floors and
    /// walls of modelled scenes, whose points are exact along that axis), half of those tilted
    /// out of it by 10^U(-8, -2) of their size; a quarter are slivers, edges 10^U(-4, -1)
    /// radians apart, half of those in a plane normal to an axis.
    pub fn triangle_case(&mut self, quad: bool) -> Option<TriangleCase> {
        let (s, t) = self.placement();
        let p0 = t + self.dir() * s;
        let kind = (self.unit() * 4.0) as u32;
        let axis = ((self.unit() * 3.0) as usize).min(2);
        let flat = |v: Vec3| {
            let mut v = v;
            v[axis] = 0.0;
            v
        };
        let (e1, e2) = match kind {
            0 | 1 => (
                self.dir() * s * self.pow10(-1.0, 0.0),
                self.dir() * s * self.pow10(-1.0, 0.0),
            ),
            2 => {
                let (mut e1, e2) = (
                    flat(self.dir()) * s * self.pow10(-1.0, 0.0),
                    flat(self.dir()) * s * self.pow10(-1.0, 0.0),
                );
                if self.unit() < 0.5 {
                    let sign = if self.unit() < 0.5 { -1.0 } else { 1.0 };
                    e1[axis] = sign * e1.length() * self.pow10(-8.0, -2.0);
                }
                (e1, e2)
            }
            _ => {
                let in_plane = self.unit() < 0.5;
                let pick = |g: &mut Self| if in_plane { flat(g.dir()) } else { g.dir() };
                let along = pick(self).normalize();
                let other = pick(self);
                let across = (other - along * other.dot(along)).normalize();
                let angle = self.pow10(-4.0, -1.0);
                let e1 = along * s * self.pow10(-1.0, 0.0);
                let e2 = (along * angle.cos() + across * angle.sin()) * s * self.pow10(-1.0, 0.0);
                (e1, e2)
            }
        };
        if !e1.cross(e2).normalize().is_finite() {
            return None;
        }
        let (a, b) = (self.unit(), self.unit());
        let (a, b) = if !quad && a + b > 1.0 {
            (1.0 - a, 1.0 - b)
        } else {
            (a, b)
        };
        let target = p0 + e1 * a + e2 * b;
        let origin = target + self.dir() * s * self.pow10(-1.0, 2.0);
        let triangles = if quad {
            vec![(p0, e1, e1 + e2), (p0, e1 + e2, e2)]
        } else {
            vec![(p0, e1, e2)]
        };
        Some(TriangleCase {
            size: s,
            origin,
            dir: (target - origin).normalize(),
            triangles,
        })
    }

    /// A needle: a right triangle whose legs differ by 10^U(1, 5) in length (its other two
    /// angles 10^U(-5, -1) radians and nearly 90 degrees), placed as [`Self::triangle_case`]
    /// places its shapes (half oriented at random, half in a plane normal to an axis), its
    /// vertices listed from any of the three, and a ray toward a random point of it. Long thin
    /// triangles are common in modelled meshes (a wall or a strip triangulated edge to edge),
    /// and they are where a watertight test's distance is least accurate.
    pub fn needle_case(&mut self) -> Option<TriangleCase> {
        let (s, t) = self.placement();
        let corner = t + self.dir() * s;
        let axis = ((self.unit() * 3.0) as usize).min(2);
        let flat = (self.unit() < 0.5).then_some(axis);
        let (long, short, _) = self.needle_legs(s, flat, -5.0)?;
        let mut v = [corner, corner + long, corner + short];
        v.rotate_left(((self.unit() * 3.0) as usize).min(2));
        let (a, b) = (self.unit(), self.unit());
        let (a, b) = if a + b > 1.0 {
            (1.0 - a, 1.0 - b)
        } else {
            (a, b)
        };
        let target = v[0] + (v[1] - v[0]) * a + (v[2] - v[0]) * b;
        let origin = target + self.dir() * s * self.pow10(-1.0, 2.0);
        Some(TriangleCase {
            size: s,
            origin,
            dir: (target - origin).normalize(),
            triangles: vec![(v[0], v[1] - v[0], v[2] - v[0])],
        })
    }

    /// The legs of a right-angled needle at a placement of size `s`: (long, short, the unit
    /// direction of short). The long leg is 10^U(-1, 0) of `s` along a random direction, the
    /// short one across it, 10^U(`shortest`, -1) of the long one; with `flat` an axis, both lie
    /// in a plane normal to it (their component there is 0). None where they are degenerate.
    fn needle_legs(
        &mut self,
        s: f32,
        flat: Option<usize>,
        shortest: f32,
    ) -> Option<(Vec3, Vec3, Vec3)> {
        let mut pick = || {
            let mut v = self.dir();
            if let Some(axis) = flat {
                v[axis] = 0.0;
            }
            v
        };
        let along = pick().normalize();
        let other = pick();
        let across = (other - along * other.dot(along)).normalize();
        let long = along * s * self.pow10(-1.0, 0.0);
        let short = across * long.length() * self.pow10(shortest, -1.0);
        long.cross(short)
            .normalize()
            .is_finite()
            .then_some((long, short, across))
    }

    /// A right-angled needle and a well-shaped neighbour that shares its long leg, both in a
    /// plane normal to an axis (so that they are coplanar in `f32`, as a modelled floor's
    /// triangles are), and a ray toward a point of the neighbour 10^U(-6, -1) of its height from
    /// the shared leg: the triangles (needle first, vertices listed from any corner), where a
    /// ray leaving the neighbour may meet the needle's plane just behind its origin. The
    /// needle's short leg is 10^U(-4, -1) of its long one, the neighbour's apex 0.2 to 1 of it
    /// from the leg. None for a degenerate shape.
    pub fn needle_neighbour_case(&mut self) -> Option<TriangleCase> {
        let (s, t) = self.placement();
        let corner = t + self.dir() * s;
        let axis = ((self.unit() * 3.0) as usize).min(2);
        let (long, short, across) = self.needle_legs(s, Some(axis), -4.0)?;
        let apex = -across * long.length() * (0.2 + 0.8 * self.unit());
        let mut needle = [corner, corner + long, corner + short];
        needle.rotate_left(((self.unit() * 3.0) as usize).min(2));
        let mut neighbour = [corner, corner + long, corner + apex];
        neighbour.rotate_left(((self.unit() * 3.0) as usize).min(2));
        let (a, b) = (self.unit(), self.pow10(-6.0, -1.0));
        let target = corner + long * a * (1.0 - b) + apex * b;
        let origin = target + self.dir() * s * self.pow10(-1.0, 2.0);
        let edges = |v: [Vec3; 3]| (v[0], v[1] - v[0], v[2] - v[0]);
        Some(TriangleCase {
            size: s,
            origin,
            dir: (target - origin).normalize(),
            triangles: vec![edges(needle), edges(neighbour)],
        })
    }
}

/// A ray toward a random point of a triangle or a quad ([`Placements::triangle_case`]).
pub struct TriangleCase {
    pub size: f32,
    pub origin: Vec3,
    pub dir: Vec3,
    pub triangles: Vec<(Vec3, Vec3, Vec3)>,
}

impl TriangleCase {
    /// The triangles as a renderer holds them: vertices (p0, p0 + edge1, p0 + edge2), rounded
    /// to `f32` as a scene's vertex data are, for the device's test ([`crate::watertight`]),
    /// and the kernel's (p0, p1 - p0, p2 - p0) computed from them, as the host computes a
    /// triangle's edges.
    pub fn loaded(&self) -> Vec<([Vec3; 3], (Vec3, Vec3, Vec3))> {
        self.triangles
            .iter()
            .map(|&(p0, e1, e2)| {
                let (p1, p2) = (p0 + e1, p0 + e2);
                ([p0, p1, p2], (p0, p1 - p0, p2 - p0))
            })
            .collect()
    }
}

/// The linear map that stretches space by `stretch` along unit `normal` and keeps the plane
/// normal to it: I + (stretch - 1) n n^T. A triangle in that plane keeps its shape while its
/// normal's world direction is squeezed, so directions near the plane turn toward it.
pub fn stretch_along(normal: glam::DVec3, stretch: f64) -> glam::DMat3 {
    let n = normal;
    glam::DMat3::IDENTITY + glam::DMat3::from_cols(n * n.x, n * n.y, n * n.z) * (stretch - 1.0)
}
