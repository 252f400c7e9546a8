//! Ray/primitive intersection, the geometry factor, and where a new ray starts.

#[cfg(target_arch = "spirv")]
use crate::Float;
use spirv_std::glam::Vec3;

/// Seed: `GeometryFactor(A, B)`. |(n_a . d)(n_b . d)| / (d . d)^2 with d = p_a - p_b: the
/// cosines at both ends over the squared distance, i.e. the Jacobian between the product of the
/// two areas and the projected solid angle (Veach's thesis, eq. 8.4). Zero for coincident points.
#[inline]
pub fn geometry_factor(p_a: Vec3, n_a: Vec3, p_b: Vec3, n_b: Vec3) -> f32 {
    let d = p_a - p_b;
    let d2 = d.dot(d);
    if d2 > 0.0 {
        let g = (n_a.dot(d) * n_b.dot(d)).abs() / (d2 * d2);
        if g.is_finite() {
            g
        } else {
            0.0
        }
    } else {
        0.0
    }
}

/// Converts a density per unit area at light point `p_light` (unit normal `n_light`) into a
/// density per unit solid angle seen from `p`: pdf_A * |d|^2 / |cos theta_light| (pbrt-v4 4.2.3).
/// Only the light's cosine belongs here: the receiver's cosine stays in the integrand.
/// Returns 0 when the conversion is undefined (coincident points, grazing light).
#[inline]
pub fn area_to_solid_angle_pdf(pdf_area: f32, p: Vec3, p_light: Vec3, n_light: Vec3) -> f32 {
    let d = p_light - p;
    let d2 = d.dot(d);
    let cos_light = n_light.dot(d).abs() / d2.sqrt();
    let pdf = pdf_area * d2 / cos_light;
    if d2 > 0.0 && cos_light > 0.0 && pdf.is_finite() {
        pdf
    } else {
        0.0
    }
}

/// Closest root t in (t_min, t_max) of |o + t d - c|^2 = r^2, or a negative value for none.
/// `d` need not be unit length. The discriminant is computed as
/// a (r^2 - |f - (f.d / a) d|^2) with f = o - c, which avoids the b^2 - 4ac cancellation, and the
/// roots by the stable quadratic formula q = -(b + sign(b) sqrt(disc)), t0 = q / a, t1 = c / q
/// (Haines, Guenther, Akenine-Moller, "Precision Improvements for Ray/Sphere Intersection",
/// Ray Tracing Gems, ch. 7, 2019).
#[inline]
pub fn intersect_sphere(
    origin: Vec3,
    dir: Vec3,
    center: Vec3,
    radius: f32,
    t_min: f32,
    t_max: f32,
) -> f32 {
    let f = origin - center;
    let a = dir.dot(dir);
    let b = f.dot(dir); // half of the usual b
    let perp = f - (b / a) * dir;
    let r2 = radius * radius;
    let disc = a * (r2 - perp.dot(perp));
    if !(disc >= 0.0) || !(a > 0.0) {
        return -1.0;
    }
    let c = f.dot(f) - r2;
    let sq = disc.sqrt();
    let q = if b >= 0.0 { -(b + sq) } else { -(b - sq) };
    let t_a = q / a;
    let t_b = if q != 0.0 { c / q } else { t_a };
    let t_near = t_a.min(t_b);
    let t_far = t_a.max(t_b);
    if t_near > t_min && t_near < t_max {
        t_near
    } else if t_far > t_min && t_far < t_max {
        t_far
    } else {
        -1.0
    }
}

/// Moves a point computed as o + t d onto the sphere's surface along the radius, removing most
/// of its rounding error (pbrt-v4 `Sphere::InteractionFromIntersection`).
#[inline]
pub fn reproject_to_sphere(p: Vec3, center: Vec3, radius: f32) -> Vec3 {
    let v = p - center;
    let len = v.length();
    if len > 0.0 {
        center + v * (radius / len)
    } else {
        p
    }
}

/// Ray/triangle intersection (Moller and Trumbore, "Fast, Minimum Storage Ray/Triangle
/// Intersection", JGT 1997), two-sided. Returns t in (t_min, t_max) or a negative value.
#[inline]
pub fn intersect_triangle(
    origin: Vec3,
    dir: Vec3,
    p0: Vec3,
    edge1: Vec3,
    edge2: Vec3,
    t_min: f32,
    t_max: f32,
) -> f32 {
    let pvec = dir.cross(edge2);
    let det = edge1.dot(pvec);
    if det == 0.0 || !det.is_finite() {
        return -1.0;
    }
    let inv_det = 1.0 / det;
    let tvec = origin - p0;
    let u = tvec.dot(pvec) * inv_det;
    if u < 0.0 || u > 1.0 {
        return -1.0;
    }
    let qvec = tvec.cross(edge1);
    let v = dir.dot(qvec) * inv_det;
    if v < 0.0 || u + v > 1.0 {
        return -1.0;
    }
    let t = edge2.dot(qvec) * inv_det;
    if t > t_min && t < t_max {
        t
    } else {
        -1.0
    }
}

/// Unit geometric normal of a triangle, (edge1 x edge2) normalised.
#[inline]
pub fn triangle_normal(edge1: Vec3, edge2: Vec3) -> Vec3 {
    edge1.cross(edge2).normalize()
}

/// The origin for a ray leaving a surface at `p` toward the side of unit normal `n`: offsets `p`
/// by a few hundred ULPs per component in the direction of `n` (integer arithmetic on the float
/// bits), and by a small absolute amount for components near zero, where ULPs vanish (Wachter and
/// Binder, "A Fast and Robust Method for Avoiding Self-Intersection", Ray Tracing Gems, ch. 6).
/// Rays then start at t = 0 with no epsilon of their own.
#[inline]
pub fn offset_ray_origin(p: Vec3, n: Vec3) -> Vec3 {
    const ORIGIN: f32 = 1.0 / 32.0;
    const FLOAT_SCALE: f32 = 1.0 / 65536.0;
    const INT_SCALE: f32 = 256.0;
    Vec3::new(
        offset_component(p.x, n.x, ORIGIN, FLOAT_SCALE, INT_SCALE),
        offset_component(p.y, n.y, ORIGIN, FLOAT_SCALE, INT_SCALE),
        offset_component(p.z, n.z, ORIGIN, FLOAT_SCALE, INT_SCALE),
    )
}

#[inline]
fn offset_component(p: f32, n: f32, origin: f32, float_scale: f32, int_scale: f32) -> f32 {
    if p.abs() < origin {
        p + float_scale * n
    } else {
        let of_i = (int_scale * n) as i32;
        let bits = p.to_bits() as i32;
        let moved = if p < 0.0 {
            bits.wrapping_sub(of_i)
        } else {
            bits.wrapping_add(of_i)
        };
        f32::from_bits(moved as u32)
    }
}

/// Where a shadow ray toward `target` stops: short of the target by a relative 2^-12 of the
/// segment, so the light's own surface never occludes its sampled point.
#[inline]
pub fn shadow_ray_end(origin: Vec3, target: Vec3) -> Vec3 {
    origin + (target - origin) * (1.0 - 1.0 / 4096.0)
}
