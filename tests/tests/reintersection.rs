//! Re-intersection (in the style of pbrt-v4's `Reintersect` tests): random spheres, quads and
//! triangles (oriented at random, in or just off a plane normal to an axis, or slivers:
//! `Placements::triangle_case`) at scales 10^U(-4, 5) under random translations; a ray hits a
//! random point; rays
//! spawned from that hit (continuation rays in random directions on the side they leave from,
//! and shadow rays toward random points on that side) never hit the same surface again. And a
//! shadow ray toward a point sampled on a sphere light never hits that light.
//!
//! Hits are computed as the renderer computes them: triangle points from barycentrics with the
//! heights of `triangle_offsets`, sphere points re-projected with `sphere_point_error` (times
//! |n|_1 as the height), origins by `continuation_origin` and `shadow_segment`, shadow-ray ends
//! by `shadow_ray_end`.
//!
//! The CPU meets triangles with the kernel's Moller-Trumbore test; a GPU with its own, which
//! `twinpath_tests::watertight` models (the watertight test in single precision), and whose
//! any-hit shaders reject the hits on a triangle whose plane the ray certainly leaves
//! (`kernel::plane_side`). Rays leaving triangles, quads and needles (long thin triangles,
//! whose watertight test errs most: `docs/robustness.md`, "Needles under a watertight test")
//! are held to both, and their own triangle to the same test with every rounding at its worst
//! (`worst_case_watertight_hit`), in each case where the plane-side test does not reject it.

use glam::Vec3;
use kernel::geometry::{
    continuation_origin, intersect_sphere, intersect_triangle, intersect_triangle_uv,
    lift_ray_origin, reproject_to_sphere, shadow_ray_end, shadow_segment, sphere_point_error,
    triangle_normal, triangle_offsets, triangle_point, GRAZING_COS,
};
use kernel::plane_side::ray_leaves_triangle_plane;
use kernel::sampling::{sample_cosine_hemisphere, sample_sphere_cone};

use twinpath_tests::device_inverse::as_devices_invert;
use twinpath_tests::placements::Placements as Gen;
use twinpath_tests::watertight::{watertight_triangle, worst_case_watertight_hit};

/// Cases per test: 10^6 by default; `REINTERSECT_CASES=10000000` for the long run.
fn cases() -> usize {
    std::env::var("REINTERSECT_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000_000)
}

/// The rays spawned from a hit at `p` (normal `n_side` on the leaving side, heights `offset`
/// and `grazing` as the hit gives them, size of the surface `size`), each as (origin,
/// direction, t_max): a continuation ray in a cosine-distributed direction (from
/// `continuation_origin`), and a shadow ray toward a point on the leaving side, as far as 10
/// sizes (from `shadow_segment`); `None` where the direction does not leave, or the target is
/// not farther from the surface than the heights (closer, which side it is on is not defined
/// in f32).
fn spawned_rays(
    g: &mut Gen,
    p: Vec3,
    n_side: Vec3,
    (offset, grazing): (f32, f32),
    size: f32,
) -> [Option<(Vec3, Vec3, f32)>; 2] {
    let w = sample_cosine_hemisphere(n_side, g.unit(), g.unit());
    let continuation = (w.dot(n_side) > 0.0).then(|| {
        (
            continuation_origin(p, n_side, w, offset, grazing),
            w,
            f32::INFINITY,
        )
    });
    let target = p + (n_side * g.unit().max(1e-3) + g.dir() * 0.5) * size * g.pow10(-2.0, 1.0);
    let leaving = lift_ray_origin(p, n_side, offset);
    let (o, _) = shadow_segment(
        p,
        n_side,
        leaving,
        (offset, offset + grazing),
        (target, Vec3::ZERO, 0.0),
    );
    let shadow = ((target - p).dot(n_side) > offset + grazing).then_some((o, target - o, 1.0));
    [continuation, shadow]
}

/// [`spawned_rays`]: whether the continuation ray and the shadow ray hit the surface again
/// (`hits`).
fn spawned_self_hits(
    g: &mut Gen,
    p: Vec3,
    n_side: Vec3,
    heights: (f32, f32),
    size: f32,
    hits: &dyn Fn(Vec3, Vec3, f32) -> bool,
) -> (bool, bool) {
    let [c, s] =
        spawned_rays(g, p, n_side, heights, size).map(|r| r.is_some_and(|(o, d, t)| hits(o, d, t)));
    (c, s)
}

/// The first of `triangles` (p0, edge1, edge2) that the ray `origin + t dir` meets, with the
/// kernel's hit record of it, as the CPU finds it, and its place among them.
fn first_hit(
    origin: Vec3,
    dir: Vec3,
    triangles: impl Iterator<Item = (Vec3, Vec3, Vec3)>,
) -> Option<(kernel::geometry::TriangleHit, usize, Vec3, Vec3, Vec3)> {
    triangles
        .enumerate()
        .map(|(i, (q, f1, f2))| {
            let h = intersect_triangle_uv(origin, dir, q, f1, f2, 0.0, f32::INFINITY);
            (h, i, q, f1, f2)
        })
        .filter(|(h, ..)| h.t >= 0.0)
        .min_by(|a, b| a.0.t.total_cmp(&b.0.t))
}

#[test]
fn rays_leaving_triangles_and_quads_never_hit_them_again() {
    let mut g = Gen(twinpath_tests::SplitMix(1));
    let (mut tested, mut cont_fail, mut shadow_fail) = (0, 0, 0);
    for case in 0..cases() {
        // A quad is two triangles sharing the diagonal, as the scene loader makes it.
        let Some(c) = g.triangle_case(case % 2 == 0) else {
            continue;
        };
        let (s, origin, dir, tris) = (c.size, c.origin, c.dir, c.triangles);
        let hit = |o: Vec3, d: Vec3, t_max: f32| {
            tris.iter()
                .any(|&(q, f1, f2)| intersect_triangle(o, d, q, f1, f2, 0.0, t_max) >= 0.0)
        };
        let Some((h, _, q, f1, f2)) = first_hit(origin, dir, tris.iter().copied()) else {
            continue; // the ray slipped past an edge
        };
        tested += 1;
        let p = triangle_point(q, f1, f2, h.u, h.v);
        // The hit triangle's own normal, as the renderer stores it.
        let nn = triangle_normal(f1, f2);
        let n_side = if nn.dot(dir) < 0.0 { nn } else { -nn };
        let heights = triangle_offsets(q, f1, f2, h.u, h.v);
        let (c, sh) = spawned_self_hits(&mut g, p, n_side, heights, s, &hit);
        cont_fail += c as usize;
        shadow_fail += sh as usize;
    }
    println!("triangles/quads: {tested} hits, {cont_fail} continuation and {shadow_fail} shadow rays hit their own surface again");
    assert!(tested > cases() / 2);
    assert_eq!((cont_fail, shadow_fail), (0, 0));
}

/// What rays spawned from a random hit on each case of `case` meet again: (hits tested, then
/// per [continuation, shadow] ray: those that hit a triangle of the case again under the CPU's
/// test, the same under the watertight test a GPU runs, those of them left where hits on a
/// triangle whose plane the ray certainly leaves are rejected (`kernel::plane_side`, as the
/// GPU's any-hit shaders reject them: robustness.md's "Hits a ray cannot make"), and those that
/// the worst-case watertight test ([`worst_case_watertight_hit`]) could meet the hit triangle
/// itself with where the plane-side test does not reject the hit). The offset holds the CPU's
/// test; the device's own test may meet the triangle again (the second count), and the
/// plane-side test or, for grazing rays, the grazing offset must leave none of those.
/// The triangles are the renderer's: vertices in `f32`, the kernel's edges their differences
/// ([`twinpath_tests::placements::TriangleCase::loaded`]).
fn leaving_triangles(
    seed: u64,
    case: &mut dyn FnMut(&mut Gen, usize) -> Option<twinpath_tests::placements::TriangleCase>,
) -> (usize, [usize; 2], [usize; 2], [usize; 2], [usize; 2]) {
    let mut g = Gen(twinpath_tests::SplitMix(seed));
    let (mut tested, mut cpu, mut gpu, mut kept, mut worst) = (0, [0; 2], [0; 2], [0; 2], [0; 2]);
    for k in 0..cases() {
        let Some(c) = case(&mut g, k) else {
            continue;
        };
        let tris = c.loaded();
        let Some((h, index, q, f1, f2)) = first_hit(c.origin, c.dir, tris.iter().map(|t| t.1))
        else {
            continue; // the ray slipped past an edge
        };
        tested += 1;
        let p = triangle_point(q, f1, f2, h.u, h.v);
        let nn = triangle_normal(f1, f2);
        let n_side = if nn.dot(c.dir) < 0.0 { nn } else { -nn };
        let heights = triangle_offsets(q, f1, f2, h.u, h.v);
        let own = tris[index].0;
        let on_cpu = |(o, d, t_max): (Vec3, Vec3, f32)| {
            tris.iter()
                .any(|&(_, (q, f1, f2))| intersect_triangle(o, d, q, f1, f2, 0.0, t_max) >= 0.0)
        };
        // Whether the watertight test meets a triangle again, and whether it meets one that the
        // plane-side test does not reject (each triangle met once).
        let on_gpu = |(o, d, t_max): (Vec3, Vec3, f32)| {
            tris.iter()
                .fold((false, false), |(met, left), &(v, (q, f1, f2))| {
                    let v = v.map(kernel::real::V3::<f32>::from);
                    if watertight_triangle(o.into(), d.into(), d, v, 0.0, t_max).is_none() {
                        return (met, left);
                    }
                    (true, left || !ray_leaves_triangle_plane(o, d, q, f1, f2))
                })
        };
        for (k, ray) in spawned_rays(&mut g, p, n_side, heights, c.size)
            .into_iter()
            .enumerate()
        {
            if let Some((o, d, t_max)) = ray {
                cpu[k] += on_cpu((o, d, t_max)) as usize;
                let (met, left) = on_gpu((o, d, t_max));
                gpu[k] += met as usize;
                kept[k] += left as usize;
                worst[k] += (worst_case_watertight_hit(o, d, own, n_side, t_max)
                    && !ray_leaves_triangle_plane(o, d, q, f1, f2))
                    as usize;
            }
        }
    }
    (tested, cpu, gpu, kept, worst)
}

/// The GPU's side of [`rays_leaving_triangles_and_quads_never_hit_them_again`]: the same
/// shapes, met by the watertight test a device runs.
#[test]
fn rays_leaving_triangles_and_quads_miss_them_under_a_watertight_test_too() {
    let (tested, cpu, gpu, kept, worst) =
        leaving_triangles(5, &mut |g, k| g.triangle_case(k % 2 == 0));
    println!("triangles/quads: {tested} hits; [continuation, shadow] rays that hit their own surface again: {cpu:?} under Moller-Trumbore, {gpu:?} under a watertight test ({kept:?} left once rejected by the plane-side test), {worst:?} their own triangle under the worst-case watertight test, not rejected");
    assert!(tested > cases() / 2);
    assert_eq!((cpu, kept, worst), ([0, 0], [0, 0], [0, 0]));
}

/// Needles (`Placements::needle_case`), under both tests. Without the offset's watertight term
/// (`geometry::triangle_watertight_error_v3`) about 1.4% of these rays met their needle again
/// under the watertight test, none under Moller-Trumbore.
#[test]
fn rays_leaving_needles_never_hit_them_again() {
    let (tested, cpu, gpu, kept, worst) = leaving_triangles(6, &mut |g, _| g.needle_case());
    println!("needles: {tested} hits; [continuation, shadow] rays that hit their own needle again: {cpu:?} under Moller-Trumbore, {gpu:?} under a watertight test ({kept:?} left once rejected by the plane-side test), {worst:?} under the worst-case watertight test, not rejected");
    assert!(tested > cases() / 2);
    assert_eq!((cpu, kept, worst), ([0, 0], [0, 0], [0, 0]));
}

/// A needle's well-shaped neighbour (`Placements::needle_neighbour_case`): rays leaving either
/// triangle never meet either again under the CPU's test, nor their own triangle under the
/// worst-case watertight test. A single-precision watertight test meets the needle behind a ray
/// leaving its neighbour (`docs/robustness.md`, "Neighbours under a watertight test"), a hole
/// such a device would otherwise have; the plane-side test (`kernel::plane_side`) rejects every
/// such hit, so none is left once rejected (the cure, which the GPU's any-hit shaders apply).
/// That the watertight test does meet them here is asserted too: else the case would not test
/// the rejection.
#[test]
fn rays_leaving_a_needles_neighbour_never_hit_either_once_rejected() {
    let (tested, cpu, gpu, kept, worst) =
        leaving_triangles(7, &mut |g, _| g.needle_neighbour_case());
    println!("needle neighbours: {tested} hits; [continuation, shadow] rays that hit either triangle again: {cpu:?} under Moller-Trumbore, {gpu:?} under a watertight test, {kept:?} of those left once rejected by the plane-side test (the cure the GPU's any-hit shaders apply); {worst:?} their own triangle under the worst-case watertight test");
    assert!(tested > cases() / 2);
    assert!(gpu[0] > 0 && gpu[1] > 0, "{gpu:?}");
    assert_eq!((cpu, kept, worst), ([0, 0], [0, 0], [0, 0]));
}

/// The scene record of triangle (`p0`, `edge1`, `edge2`): material 0, no light, no shading.
fn plain_triangle(p0: Vec3, edge1: Vec3, edge2: Vec3) -> kernel::scene::Triangle {
    kernel::scene::Triangle {
        p0: p0.into(),
        material: 0,
        edge1: edge1.into(),
        light: kernel::scene::NONE,
        edge2: edge2.into(),
        shading: kernel::scene::NONE,
    }
}

/// A triangle of the grazing tests and a point near its corner.
struct CornerCase {
    /// (p0, edge1, edge2).
    triangle: (Vec3, Vec3, Vec3),
    /// The point's barycentrics.
    uv: (f32, f32),
    /// The size of the placement it was drawn at.
    size: f32,
}

/// The [`CornerCase`] of case `k`: a triangle or quad (`k` even, a quad every fourth) or a
/// needle, its first triangle, with p0 moved to the origin but for every third case, and
/// barycentrics of 10^U(-4, 0) each. None where the shape is degenerate or u + v > 1.
fn corner_case(g: &mut Gen, k: usize) -> Option<CornerCase> {
    let case = if k.is_multiple_of(2) {
        g.triangle_case(k.is_multiple_of(4))
    } else {
        g.needle_case()
    }?;
    let (_, (q, f1, f2)) = case.loaded()[0];
    let q = if k.is_multiple_of(3) { q } else { Vec3::ZERO };
    let (u, v) = (g.pow10(-4.0, 0.0), g.pow10(-4.0, 0.0));
    (u + v <= 1.0).then_some(CornerCase {
        triangle: (q, f1, f2),
        uv: (u, v),
        size: case.size,
    })
}

/// Continuation rays that graze the triangle they leave (cosines 10^-10 to 10^-2.5 with the
/// leaving side's normal, across [`GRAZING_COS`]), on the shapes of triangles, quads and
/// needles, from points near the corner p0 (barycentrics 10^-4 to 1) of triangles placed as
/// drawn or with p0 at the origin, half of them along the direction from p0 (where the height
/// is smallest and the backward ray crosses the triangle), and shadow segments along the same
/// directions (`shadow_segment`). The plane-side test cannot be sure of a direction below about
/// 15 eps of the plane's weights, and a grazing ray is met, if at all, where its backward line
/// crosses the triangle, far from the point it leaves. Asserted, at the worst rounding
/// ([`worst_case_watertight_hit`]) where the plane-side test does not reject the hit: no
/// continuation ray is met, at or above [`GRAZING_COS`] (at the offset alone) nor below it (at
/// the grazing offset, the device's rounding anywhere on the triangle); no shadow segment is
/// met whose target lies farther from the plane than the lift; and below [`GRAZING_COS`] some
/// are met with the watertight term at the point left instead (`triangle_watertight_error_v3`,
/// the grazing offset of the first version) or without a grazing offset, so the test can fail.
#[test]
fn grazing_rays_leave_at_the_watertight_height() {
    let mut g = Gen(twinpath_tests::SplitMix(8));
    let (mut tested, mut above, mut with_rule, mut without, mut before) = (0, 0, 0, 0, 0);
    let (mut shadow_above, mut shadow_below, mut shadow_within) = (0, 0, 0);
    for k in 0..cases() / 4 {
        let Some(CornerCase {
            triangle: (q, f1, f2),
            uv: (u, v),
            size,
        }) = corner_case(&mut g, k)
        else {
            continue;
        };
        let p = triangle_point(q, f1, f2, u, v);
        let nn = triangle_normal(f1, f2);
        let n_side = if g.unit() < 0.5 { nn } else { -nn };
        let (offset, grazing) = triangle_offsets(q, f1, f2, u, v);
        let a = if k % 5 < 2 {
            g.dir()
        } else {
            (p - q) * (g.unit() - 0.5)
        };
        let tangent = (a - n_side * a.dot(n_side)).normalize();
        let cos = g.pow10(-10.0, -2.5);
        let w = (n_side * cos + tangent * (1.0 - cos * cos).sqrt()).normalize();
        if !(w.dot(n_side) > 0.0 && tangent.is_finite() && nn.is_finite()) {
            continue;
        }
        tested += 1;
        let own = [q, q + f1, q + f2];
        let met_along = |o: Vec3, d: Vec3, t_max: f32| {
            worst_case_watertight_hit(o, d, own, n_side, t_max)
                && !ray_leaves_triangle_plane(o, d, q, f1, f2)
        };
        let met = |o: Vec3| met_along(o, w, f32::INFINITY);
        // A shadow segment along w to a point 10^-2 to 10 sizes away, from `shadow_segment`.
        let target = p + w * size * g.pow10(-2.0, 1.0);
        let leaving = lift_ray_origin(p, n_side, offset);
        let (from, _) = shadow_segment(
            p,
            n_side,
            leaving,
            (offset, offset + grazing),
            (target, Vec3::ZERO, 0.0),
        );
        let d = target - from;
        let shadow = met_along(from, d, 1.0) as usize;
        if d.dot(n_side) >= GRAZING_COS * d.length() {
            shadow_above += shadow;
        } else if (target - p).dot(n_side) > offset + grazing {
            shadow_below += shadow;
        } else {
            shadow_within += shadow; // a target no higher than the lift: the segment descends
        }
        let met_by_rule = met(continuation_origin(p, n_side, w, offset, grazing));
        if w.dot(n_side) >= GRAZING_COS {
            above += met_by_rule as usize;
            continue;
        }
        with_rule += met_by_rule as usize;
        without += met(continuation_origin(p, n_side, w, offset, 0.0)) as usize;
        let shape = kernel::geometry::TriangleShape::of(f1, f2);
        let at_point = kernel::geometry::triangle_watertight_error_v3(
            f1.into(),
            f2.into(),
            u,
            v,
            shape.watertight_scale,
        );
        before += met(continuation_origin(p, n_side, w, offset, at_point)) as usize;
    }
    println!("grazing continuation rays: {tested}; met again at the worst rounding and not rejected: {above} at or above GRAZING_COS; below it {with_rule} with the grazing offset, {without} without it, {before} with the watertight term at the point left; shadow segments along them (shadow_segment): {shadow_above} at or above GRAZING_COS, {shadow_below} below it, {shadow_within} to targets no higher than the lift");
    assert!(tested > cases() / 8);
    assert_eq!((above, with_rule, shadow_above, shadow_below), (0, 0, 0, 0));
    assert!(
        before > 0 && without > 0,
        "the grazing offset is not shown to be needed"
    );
}

/// The kernel's instanced hit (`hit::SurfaceHit::instanced_triangle`) on `tri` (of shape
/// `shape`) under `inst` at barycentrics (`u`, `v`), and the side a ray leaves toward, drawn at
/// random: (the hit, the unit world normal on that side, the object normal on that side).
fn instanced_hit_on_a_side(
    g: &mut Gen,
    tri: &kernel::scene::Triangle,
    shape: kernel::geometry::TriangleShape,
    inst: &kernel::scene::Instance,
    (u, v): (f32, f32),
) -> (kernel::hit::SurfaceHit, Vec3, Vec3) {
    let hit = kernel::hit::SurfaceHit::instanced_triangle(tri, shape, inst, 0, g.dir(), 1.0, u, v);
    let n = hit.normal;
    if g.unit() < 0.5 {
        (hit, n, shape.normal)
    } else {
        (hit, -n, -shape.normal)
    }
}

/// The grazing rays of `grazing_rays_leave_at_the_watertight_height`, leaving a triangle of an
/// instance: the kernel's instanced hit (`hit::SurfaceHit::instanced_triangle`) at a point near
/// a corner, a world ray within 10^-10 to 10^-2.5 of the world plane from
/// `continuation_origin`, mapped into object space as each kind of device the tests model maps
/// it (`twinpath_tests::device_inverse::as_devices_invert`: Gaussian elimination in `f32`, the
/// adjugate under Vulkan arithmetic), against the worst-case watertight test there, kept where
/// the plane-side test, on the ray mapped by the stored inverse as the any-hit shader maps it
/// (`instance::ray_to_object`), does not reject it. Transforms as `instances.rs` draws them: scale
/// 10^U(-3, 3), anisotropy up to 100, any rotation, mirrored in half, translated. Rays start at
/// the kernel's heights (`instance::instanced_offsets_v3`: the plane height where the map turns
/// directions little and the ray does not graze the world plane, else the height that lifts by
/// the object triangle's grazing offset, `instanced_offset_v3`). Held to none met where the origin lies within
/// `GRAZING_DOMAIN` of the longest edge above the object triangle, where the offset is derived;
/// the rays that leave higher (the world bound's round trip, large against a small object
/// triangle) are counted and printed, and the loader's check
/// (`twinpath::scene::grazing_domain`) must flag the triangle under that instance for each; the
/// cheap bound it checks first must not pass a triangle its exact check flags. The count without
/// the grazing offset (from `instanced_offset_v3`'s height) must not be 0; the count with it for
/// world-grazing rays only is printed. From each point within the domain a steeper ray too
/// (world cosine 10^-2.5 to 1), held to none met; the counts without the grazing offset and at
/// the plane height whatever the map are printed (the maps that need the gate are rare here:
/// `rays_a_map_turns_toward_the_object_plane_start_at_the_grazing_height` draws them).
#[test]
fn grazing_rays_leave_instanced_triangles_at_the_watertight_height() {
    use kernel::geometry::{longest_edge, TriangleShape, GRAZING_DOMAIN};
    use kernel::instance::{
        instanced_offset_v3, instanced_plane_height_v3, normal_to_world, point_to_world,
        ray_to_object, world_height_v3, ObjectLeaving,
    };
    use kernel::real::V3;
    use twinpath::scene::grazing_domain::InstancedBound;
    use twinpath::scene::instancing::instance_record;
    use twinpath::scene::transform::Transform;
    let mut g = Gen(twinpath_tests::SplitMix(9));
    let (mut tested, mut met, mut without, mut world_rule) = (0, 0, 0, 0);
    let (mut beyond, mut beyond_met, mut beyond_unflagged, mut within_flagged) = (0, 0, 0, 0);
    let (mut bound_missed, mut bound_flagged) = (0, 0);
    let mut g_steep = Gen(twinpath_tests::SplitMix(90));
    let (mut steep_tested, mut steep_met, mut steep_without, mut steep_ungated) = (0, 0, 0, 0);
    let mut steady = 0;
    let (mut shadow_met, mut shadow_within) = (0, 0);
    for k in 0..cases() / 4 {
        let (m, stretch) = g.instance_map();
        let Ok(Some(transform)) = Transform::affine(m) else {
            continue;
        };
        let inst = instance_record(&transform, 0);
        let Some(CornerCase {
            triangle: (q, f1, f2),
            uv: (u, v),
            size,
        }) = corner_case(&mut g, k)
        else {
            continue;
        };
        let tri = plain_triangle(q, f1, f2);
        let shape = TriangleShape::of(f1, f2);
        let (hit, n_side, n_object) = instanced_hit_on_a_side(&mut g, &tri, shape, &inst, (u, v));
        let (p, n) = (hit.position, hit.normal);
        let a = if k % 5 < 2 {
            g.dir()
        } else {
            (p - point_to_world(&inst, q)) * (g.unit() - 0.5)
        };
        let tangent = (a - n_side * a.dot(n_side)).normalize();
        let cos = g.pow10(-10.0, -2.5);
        let w = (n_side * cos + tangent * (1.0 - cos * cos).sqrt()).normalize();
        if !(w.dot(n_side) > 0.0 && tangent.is_finite() && n.is_finite() && hit.offset.is_finite())
        {
            continue;
        }
        let own = [q, q + f1, q + f2];
        let devices = as_devices_invert(&inst);
        let met_along = |o: Vec3, d: Vec3, t_max: f32| {
            let (oo, od) = ray_to_object(&inst, o, d);
            !ray_leaves_triangle_plane(oo, od, q, f1, f2)
                && devices.iter().any(|device| {
                    let (device_o, device_d) = ray_to_object(device, o, d);
                    worst_case_watertight_hit(device_o, device_d, own, n_object, t_max)
                })
        };
        let met_from = |o: Vec3| met_along(o, w, f32::INFINITY) as usize;
        let origin = continuation_origin(p, n_side, w, hit.offset, hit.grazing_offset);
        let m = met_from(origin);
        // How far above the object triangle's plane the origin lies, in object space.
        let height = (ray_to_object(&inst, origin, w).0 - q).dot(n_object);
        let longest = longest_edge(f1, f2);
        if height > GRAZING_DOMAIN * longest {
            beyond += 1;
            beyond_met += m;
            beyond_unflagged += InstancedBound::of(&tri).beyond(&inst).is_none() as usize;
            continue;
        }
        tested += 1;
        met += m;
        let checks = InstancedBound::of(&tri);
        let exact = checks.exact(&inst).beyond_domain();
        within_flagged += exact as usize;
        // The cheap bound must pass no triangle that the exact check flags.
        let bound = checks.may_be_beyond(&inst);
        bound_missed += (exact && !bound) as usize;
        bound_flagged += bound as usize;
        // The height every ray took before the plane height (`instanced_offset_v3`, the
        // grazing offset folded in), and that height without the fold.
        let world_normal = normal_to_world(&inst, shape.normal);
        let object = ObjectLeaving::of_triangle((q, f1, f2), (u, v), &shape);
        let world = (V3::from(p), V3::from(n), world_normal.length());
        let every = instanced_offset_v3(&inst, &object, world);
        // The plane height for every ray, whatever the map (the gate forced open).
        let ungated = instanced_plane_height_v3(&inst, &object, world);
        let carried = world_height_v3(
            &inst,
            world_normal.length(),
            object.weight_sum,
            object.grazing,
        );
        let bare = every - carried;
        steady += (hit.offset < every) as usize;
        without += met_from(continuation_origin(p, n_side, w, bare, 0.0));
        world_rule += met_from(continuation_origin(p, n_side, w, bare, carried));
        // A steeper ray from the same point, cosine 10^-2.5 to 1 (drawn from a stream of its
        // own, so that the grazing rays' draws stay as they were): not met either.
        let steep_cos = g_steep.pow10(-2.5, 0.0);
        let steep =
            (n_side * steep_cos + tangent * (1.0 - steep_cos * steep_cos).sqrt()).normalize();
        if steep.dot(n_side) > 0.0 {
            let from = |offset: f32, grazing: f32| {
                met_along(
                    continuation_origin(p, n_side, steep, offset, grazing),
                    steep,
                    f32::INFINITY,
                ) as usize
            };
            steep_tested += 1;
            steep_met += from(hit.offset, hit.grazing_offset);
            steep_without += from(bare, 0.0);
            steep_ungated += from(ungated, every - ungated);
        }
        // A shadow segment along w to a point 10^-2 to 10 sizes away, from `shadow_segment`.
        let size = size * stretch as f32;
        let target = p + w * size * g.pow10(-2.0, 1.0);
        let leaving = lift_ray_origin(p, n_side, hit.offset);
        let grazing_height = hit.offset + hit.grazing_offset;
        let (from, _) = shadow_segment(
            p,
            n_side,
            leaving,
            (hit.offset, grazing_height),
            (target, Vec3::ZERO, 0.0),
        );
        let shadow = met_along(from, target - from, 1.0) as usize;
        if (target - p).dot(n_side) > grazing_height {
            shadow_met += shadow;
        } else {
            shadow_within += shadow; // a target no higher than the lift: the segment descends
        }
    }
    println!("grazing rays leaving instanced triangles: {tested} within GRAZING_DOMAIN; met again at the worst rounding and not rejected: {met} (shadow segments along them: {shadow_met}, and {shadow_within} to targets no higher than the lift); without the grazing offset {without}, with it for world-grazing rays only {world_rule}; beyond GRAZING_DOMAIN {beyond}, of which {beyond_met} met and {beyond_unflagged} not flagged by the loader's check ({within_flagged} flagged within; its cheap bound passes {bound_missed} that the exact check flags, and flags {bound_flagged} within); steeper rays (cosines 10^-2.5 to 1) from the same points: {steep_tested}, met {steep_met}, without the grazing offset {steep_without}, at the plane height whatever the map {steep_ungated}; rays leaving at the plane height: {steady} of {tested}");
    // A floor on the draws within the domain: a tenth to an eighth of the cases land there (the
    // rest miss, or lie beyond it).
    assert!(tested > cases() / 10, "{tested}");
    assert_eq!(
        (met, shadow_met, beyond_unflagged, bound_missed),
        (0, 0, 0, 0)
    );
    assert!(beyond > 0);
    assert!(steep_tested > tested / 2, "{steep_tested}");
    assert_eq!(steep_met, 0);
    assert!(
        without > 0,
        "the grazing offset is not shown to be needed on instances"
    );
}

/// Rays leaving an instanced triangle under a map that stretches it along its normal by
/// 10^U(0, 4): a world cosine just above [`GRAZING_COS`] (1 to 4 times it) becomes an object
/// cosine up to 10^4 times smaller, where the plane-side test cannot be sure of the direction
/// and the device's own test decides. Well-shaped triangles of unit size, rotated and
/// translated, points anywhere on them, world rays in a random tangent direction or back along
/// the direction from the corner p0 (where the backward line crosses the triangle). The device
/// maps the ray by its own inverse (each kind `twinpath_tests::device_inverse::as_devices_invert`
/// models: Gaussian elimination in `f32`, the adjugate under Vulkan arithmetic) and tests it at the
/// worst rounding ([`worst_case_watertight_hit`]); its any-hit shader rejects the hit where the
/// ray mapped by the stored inverse certainly leaves the plane. Asserted for maps conditioned
/// to `instance::DEVICE_INVERSE_CONDITION_LIMIT`: none is met at the kernel's heights
/// (`instance::instanced_offsets_v3`, whose gate `turns_directions_little` sends such rays to
/// the height every instanced ray took before). Beyond the limit the rays met are counted and
/// printed (the device's inverse turns their object direction toward the plane) and the
/// loader's check must flag each one's triangle under its instance. For a device whose inverse
/// is the stored one (as accurate as the CPU's map), at every condition: none is met, and some
/// are met at the plane height given to every ray whatever the map (the gate open:
/// `instance::instanced_plane_height_v3`), so the gate is shown to be needed.
#[test]
fn rays_a_map_turns_toward_the_object_plane_start_at_the_grazing_height() {
    use glam::DMat4;
    use kernel::geometry::TriangleShape;
    use kernel::instance::{
        condition_number, instanced_offset_v3, instanced_plane_height_v3, normal_to_world,
        point_to_world, ray_to_object, ObjectLeaving, DEVICE_INVERSE_CONDITION_LIMIT,
    };
    use kernel::real::V3;
    use kernel::scene::Instance;
    use twinpath::scene::grazing_domain::InstancedBound;
    use twinpath::scene::instancing::instance_record;
    use twinpath::scene::transform::Transform;
    use twinpath_tests::placements::stretch_along;
    let mut g = Gen(twinpath_tests::SplitMix(12));
    let (mut tested, mut met, mut open, mut plane_height) = (0, 0, 0, 0);
    let (mut beyond, mut beyond_met, mut beyond_unflagged, mut accurate_met) = (0, 0, 0, 0);
    let mut least_met = f32::INFINITY;
    for k in 0..cases() / 4 {
        let (q, f1, f2) = (g.dir() * 0.3, g.dir(), g.dir());
        let q = if k % 3 == 0 { q } else { Vec3::ZERO };
        if f1.cross(f2).length() < 0.3 {
            continue;
        }
        let shape = TriangleShape::of(f1, f2);
        let n_o = shape.normal.as_dvec3();
        let stretch = 10f64.powf(4.0 * g.unit() as f64);
        let linear = stretch_along(n_o, stretch);
        let shift = if k % 4 == 0 { 10.0 } else { 0.0 };
        let m = DMat4::from_translation(g.dir().as_dvec3() * shift)
            * DMat4::from_axis_angle(g.dir().as_dvec3(), g.unit() as f64 * std::f64::consts::TAU)
            * DMat4::from_mat3(linear);
        let Ok(Some(transform)) = Transform::affine(m) else {
            continue;
        };
        let inst = instance_record(&transform, 0);
        let (u, v) = (g.pow10(-4.0, 0.0), g.pow10(-4.0, 0.0));
        if u + v > 1.0 {
            continue;
        }
        let tri = plain_triangle(q, f1, f2);
        let (hit, n_side, n_object) = instanced_hit_on_a_side(&mut g, &tri, shape, &inst, (u, v));
        let (p, n) = (hit.position, hit.normal);
        let a = if k % 2 == 0 {
            g.dir()
        } else {
            (p - point_to_world(&inst, q)) * (g.unit() - 0.5)
        };
        let tangent = (a - n_side * a.dot(n_side)).normalize();
        let cos = GRAZING_COS * g.pow10(0.0, 0.6);
        let w = (n_side * cos + tangent * (1.0 - cos * cos).sqrt()).normalize();
        if !(w.dot(n_side) >= GRAZING_COS && tangent.is_finite() && hit.offset.is_finite()) {
            continue;
        }
        let own = [q, q + f1, q + f2];
        let devices = as_devices_invert(&inst);
        let met_from = |device: &Instance, offset: f32, grazing: f32| {
            let o = continuation_origin(p, n_side, w, offset, grazing);
            let (device_o, device_d) = ray_to_object(device, o, w);
            let (oo, od) = ray_to_object(&inst, o, w);
            (worst_case_watertight_hit(device_o, device_d, own, n_object, f32::INFINITY)
                && !ray_leaves_triangle_plane(oo, od, q, f1, f2)) as usize
        };
        let object = ObjectLeaving::of_triangle((q, f1, f2), (u, v), &shape);
        let world = (
            V3::from(p),
            V3::from(n),
            normal_to_world(&inst, shape.normal).length(),
        );
        let every = instanced_offset_v3(&inst, &object, world);
        let ungated = instanced_plane_height_v3(&inst, &object, world);
        let met_here = devices
            .iter()
            .any(|device| met_from(device, hit.offset, hit.grazing_offset) > 0)
            as usize;
        accurate_met += met_from(&inst, hit.offset, hit.grazing_offset);
        open += met_from(&inst, ungated, every - ungated);
        if condition_number(&inst) > DEVICE_INVERSE_CONDITION_LIMIT {
            beyond += 1;
            beyond_met += met_here;
            if met_here > 0 {
                least_met = least_met.min(condition_number(&inst));
            }
            if met_here > 0 {
                beyond_unflagged += InstancedBound::of(&tri).beyond(&inst).is_none() as usize;
            }
            continue;
        }
        tested += 1;
        plane_height += (hit.offset < every) as usize;
        met += met_here;
    }
    println!("rays a map turns toward the object plane (stretched 10^0 to 10^4 along its normal, world cosines 1 to 4 GRAZING_COS): mapped back by each device's inverse (Gaussian elimination in f32, the adjugate under Vulkan arithmetic), conditions to DEVICE_INVERSE_CONDITION_LIMIT: {tested}, of which {plane_height} leave at the plane height, met at the worst rounding and not rejected: {met}; beyond the limit {beyond}, met {beyond_met} (the least condition met {least_met:.0}), of which not flagged by the loader's check {beyond_unflagged}. Mapped back by the stored inverse, every condition: met {accurate_met}; at the plane height whatever the map: {open}");
    assert!(tested > cases() / 16, "{tested}");
    assert!(plane_height > 0 && plane_height < tested, "{plane_height}");
    assert_eq!((met, accurate_met, beyond_unflagged), (0, 0, 0));
    assert!(open > 0, "the gate is not shown to be needed");
}

/// Rays leaving an instanced triangle at the plane height, far from the origin, under maps that
/// stretch space along a direction in the triangle's plane by 10^U(0, 3) (conditions to 10^3,
/// `instance::DEVICE_INVERSE_CONDITION_LIMIT`; the world normal keeps the object normal's
/// direction, so `turns_directions_little` passes), rotated and translated 10^U(2, 4) away.
/// Rays at world cosines 10^U(log10 `GRAZING_COS`, 0) toward a random side. The device maps the
/// ray by its own inverse (each kind `twinpath_tests::device_inverse::as_devices_invert` models)
/// and tests it at the worst
/// rounding ([`worst_case_watertight_hit`]); the any-hit shader rejects the hit where the ray
/// mapped by the stored inverse certainly leaves the plane (`shaders::any_hit_instance`).
/// Asserted: none is met at the kernel's heights; and some are met where the plane-side test
/// reads the device's own object ray instead (a mutation), whose inverse
/// errs by about eps times the condition number while the plane height counts only the stored
/// inverse's rounding (`instance::MAPPED_BACK_EPS`), so the stored inverse's side is shown to be
/// needed.
#[test]
fn rays_leaving_far_instanced_triangles_are_sided_by_the_stored_inverse() {
    use glam::{DMat4, DVec3};
    use kernel::geometry::TriangleShape;
    use kernel::instance::{instanced_offset_v3, normal_to_world, ray_to_object, ObjectLeaving};
    use kernel::real::V3;
    use twinpath::scene::instancing::instance_record;
    use twinpath::scene::transform::Transform;
    use twinpath_tests::placements::stretch_along;
    let mut g = Gen(twinpath_tests::SplitMix(13));
    let (mut tested, mut plane_height, mut met, mut device_sided) = (0, 0, 0, 0);
    for _ in 0..cases() / 2 {
        let (q, f1, f2) = (g.dir() * 0.3, g.dir(), g.dir());
        if f1.cross(f2).length() < 0.3 {
            continue;
        }
        let shape = TriangleShape::of(f1, f2);
        let n_o = shape.normal.as_dvec3();
        let across = n_o.cross(g.dir().as_dvec3()).normalize();
        let shift = 10f64.powf(2.0 + 2.0 * g.unit() as f64);
        let m = DMat4::from_translation(g.dir().as_dvec3() * shift)
            * DMat4::from_axis_angle(g.dir().as_dvec3(), g.unit() as f64 * std::f64::consts::TAU)
            * DMat4::from_mat3(stretch_along(across, 10f64.powf(3.0 * g.unit() as f64)));
        let Ok(Some(transform)) = Transform::affine(m) else {
            continue;
        };
        if !across.is_finite() || across == DVec3::ZERO {
            continue;
        }
        let inst = instance_record(&transform, 0);
        let (u, v) = (g.unit(), g.unit());
        let (u, v) = if u + v > 1.0 {
            (1.0 - u, 1.0 - v)
        } else {
            (u, v)
        };
        let tri = plain_triangle(q, f1, f2);
        let (hit, n_side, n_object) = instanced_hit_on_a_side(&mut g, &tri, shape, &inst, (u, v));
        let (p, n) = (hit.position, hit.normal);
        let tangent = (g.dir() - n_side * g.dir().dot(n_side)).normalize();
        let cos = g.pow10(GRAZING_COS.log10(), 0.0);
        let w = (n_side * cos + tangent * (1.0 - cos * cos).sqrt()).normalize();
        if !(w.dot(n_side) >= GRAZING_COS && tangent.is_finite() && hit.offset.is_finite()) {
            continue;
        }
        let own = [q, q + f1, q + f2];
        let o = continuation_origin(p, n_side, w, hit.offset, hit.grazing_offset);
        let (oo, od) = ray_to_object(&inst, o, w);
        // Whether some device meets the ray, and whether one meets it on a ray its own object
        // ray does not certainly leave the plane along.
        let (mut device_met, mut met_on_its_own_side) = (false, false);
        for device in as_devices_invert(&inst) {
            let (device_o, device_d) = ray_to_object(&device, o, w);
            if worst_case_watertight_hit(device_o, device_d, own, n_object, f32::INFINITY) {
                device_met = true;
                met_on_its_own_side |= !ray_leaves_triangle_plane(device_o, device_d, q, f1, f2);
            }
        }
        let object = ObjectLeaving::of_triangle((q, f1, f2), (u, v), &shape);
        let world = (
            V3::from(p),
            V3::from(n),
            normal_to_world(&inst, shape.normal).length(),
        );
        tested += 1;
        plane_height += (hit.offset < instanced_offset_v3(&inst, &object, world)) as usize;
        met += (device_met && !ray_leaves_triangle_plane(oo, od, q, f1, f2)) as usize;
        device_sided += met_on_its_own_side as usize;
    }
    println!("rays leaving far instanced triangles (maps stretched in the plane by 10^0 to 10^3, 10^2 to 10^4 from the origin): {tested}, of which {plane_height} leave at the plane height; met at the worst rounding of a device (inverting by Gaussian elimination or the adjugate) and not rejected: {met}; with the plane-side test on the device's object ray: {device_sided}");
    assert!(tested > cases() / 4, "{tested}");
    assert!(plane_height > tested / 2, "{plane_height}");
    assert_eq!(met, 0);
    assert!(
        device_sided > 0,
        "the stored inverse's side is not shown to be needed"
    );
}

#[test]
fn rays_leaving_spheres_never_hit_them_again() {
    let mut g = Gen(twinpath_tests::SplitMix(2));
    let (mut tested, mut cont_fail, mut shadow_fail) = (0, 0, 0);
    for _ in 0..cases() {
        let (s, t) = g.placement();
        let (c, r) = (t, s);
        let target = c + g.dir() * r;
        let origin = target + g.dir() * r * g.pow10(-1.0, 2.0);
        let dir = (target - origin).normalize();
        let th = intersect_sphere(origin, dir, c, r, 0.0, f32::INFINITY);
        if th < 0.0 {
            continue;
        }
        tested += 1;
        let p = reproject_to_sphere(origin + th * dir, c, r);
        let n = (p - c) / r;
        // Rays arriving from outside leave outward; from inside, inward.
        let n_side = if n.dot(dir) < 0.0 { n } else { -n };
        let err = sphere_point_error(c, r);
        let inward = n_side.dot(n) < 0.0;
        let hits = |o: Vec3, d: Vec3, tm: f32| {
            let t = intersect_sphere(o, d, c, r, 0.0, tm);
            // From inside, the far wall is a legitimate hit: only a hit within a few error
            // bounds of the start counts as a self-hit.
            if inward {
                t >= 0.0 && t * d.length() <= 4.0 * err
            } else {
                t >= 0.0
            }
        };
        let height = err * n_side.abs().element_sum();
        let (cf, sf) = spawned_self_hits(&mut g, p, n_side, (height, 0.0), r, &hits);
        cont_fail += cf as usize;
        shadow_fail += sf as usize;
    }
    println!("spheres: {tested} hits, {cont_fail} continuation and {shadow_fail} shadow rays hit their own surface again");
    assert!(tested > cases() / 2);
    assert_eq!((cont_fail, shadow_fail), (0, 0));
}

#[test]
fn shadow_rays_never_hit_the_light_they_sample() {
    let mut g = Gen(twinpath_tests::SplitMix(3));
    let mut fails = 0;
    for _ in 0..cases() {
        let (s, t) = g.placement();
        let (c, r) = (t, s);
        // Receivers from 1e-3 radii off the surface to 1e4 radii away.
        let x = c + g.dir() * r * (1.0 + g.pow10(-3.0, 4.0));
        let ls = sample_sphere_cone(c, r, x, g.unit(), g.unit());
        let end = shadow_ray_end(
            x,
            ls.point.position,
            ls.point.normal,
            sphere_point_error(c, r),
        );
        if intersect_sphere(x, end - x, c, r, 0.0, 1.0) >= 0.0 {
            fails += 1;
        }
    }
    println!(
        "light samples: {fails} of {} shadow rays hit their own light",
        cases()
    );
    assert_eq!(fails, 0);
}

/// The same for triangle lights: a shadow ray toward a point sampled on a triangle light (by
/// area or as a spherical triangle, one- and two-sided, with the light's own error bound as the
/// renderer builds it) never hits that triangle, under the CPU's test or a GPU's watertight
/// one (at its worst rounding too), for receivers 1e-3 to 1e4 sizes away on the side the light faces (the renderer casts no
/// shadow ray where cos theta_light <= 0).
#[test]
fn shadow_rays_never_hit_the_triangle_light_they_sample() {
    use kernel::light::triangle::sample as sample_triangle_light;
    use kernel::scene::light_sampling;
    let mut g = Gen(twinpath_tests::SplitMix(4));
    let (mut fails, mut tested) = (0, 0);
    for k in 0..cases() {
        let (s, t) = g.placement();
        let (p0, e1, e2) = (t, g.dir() * s, g.dir() * s);
        if e1.cross(e2).length() < 1e-3 * s * s {
            continue;
        }
        let tri = plain_triangle(p0, e1, e2);
        let mut l = twinpath::scene::light_table::triangle_light(&tri, [1.0; 3], k % 2 == 0);
        l.select_pmf = 1.0;
        let centroid = p0 + (e1 + e2) / 3.0;
        let x = centroid + g.dir() * s * g.pow10(-3.0, 4.0);
        let mode = if k % 3 == 0 {
            light_sampling::AREA
        } else {
            light_sampling::SOLID_ANGLE
        };
        let ls = sample_triangle_light(&l, 0, mode, x, g.unit(), g.unit());
        let y = ls.point.position;
        if !(ls.pdf_solid_angle > 0.0) || ls.point.normal.dot(x - y) <= 0.0 {
            continue;
        }
        tested += 1;
        let end = shadow_ray_end(x, y, ls.point.normal, l.point_error);
        // The CPU's test, and a GPU's (a watertight test of the light's vertices), also with
        // every rounding at its worst.
        let corners = [p0, p0 + e1, p0 + e2];
        let vertices = corners.map(kernel::real::V3::<f32>::from);
        let d = end - x;
        if intersect_triangle(x, d, p0, e1, e2, 0.0, 1.0) >= 0.0
            || watertight_triangle(x.into(), d.into(), d, vertices, 0.0, 1.0).is_some()
            || worst_case_watertight_hit(x, d, corners, ls.point.normal, 1.0)
        {
            fails += 1;
        }
    }
    println!("triangle light samples: {fails} of {tested} shadow rays hit their own light");
    assert!(tested > cases() / 3);
    assert_eq!(fails, 0);
}

/// The loader's check of the grazing domain (`twinpath::scene::grazing_domain`) flags every
/// triangle that a grazing ray leaves higher than `GRAZING_DOMAIN` times its longest edge above
/// (the height measured in f64 from the plane of its f32 vertices): needles whose short leg is
/// 10^U(-7, -2) of the long one, placed as `placement` places shapes, and the shapes of
/// `triangle_case` moved 10^U(2, 6) of their size from the origin, at uniform and near-corner
/// points, on either side, along directions within 10^-10 to [`GRAZING_COS`] of the plane,
/// from `continuation_origin`. Shapes of both kinds must be found beyond the domain, and the
/// share of triangles flagged whose sampled rays stayed within is printed (the check's bound
/// over the whole triangle is not tight). Halved, the check's rounding term (the offset, the
/// origin's own distance from it, and the grid the origin is rounded to) must miss some.
#[test]
fn the_grazing_domain_check_flags_every_triangle_rays_leave_too_high() {
    use kernel::geometry::GRAZING_DOMAIN;
    use twinpath::scene::grazing_domain::LeavingHeight;
    let mut g = Gen(twinpath_tests::SplitMix(10));
    let (mut beyond, mut beyond_kinds, mut missed) = (0, [0, 0], 0);
    let (mut within_flagged, mut within, mut halved_missed) = (0, 0, 0);
    for k in 0..cases() / 40 {
        let needle = k.is_multiple_of(2);
        let (q, f1, f2) = if needle {
            let (s, t) = g.placement();
            let long = g.dir() * s;
            let other = g.dir();
            let across = (other - long * other.dot(long) / long.length_squared()).normalize();
            let short = across * s * g.pow10(-7.0, -2.0);
            (t + g.dir() * s, long, short)
        } else {
            let Some(case) = g.triangle_case(false) else {
                continue;
            };
            let (_, (q, f1, f2)) = case.loaded()[0];
            (q + g.dir() * case.size * g.pow10(2.0, 6.0), f1, f2)
        };
        let tri = plain_triangle(q, f1, f2);
        let n = triangle_normal(f1, f2);
        if !n.is_finite() || f1.cross(f2).length() == 0.0 {
            continue;
        }
        let (d1, d2) = (f1.as_dvec3(), f2.as_dvec3());
        let n64 = d1.cross(d2).normalize();
        let longest = d1.length().max(d2.length()).max((d2 - d1).length());
        let check = LeavingHeight::of_world(&tri);
        let mut highest = 0.0f64;
        for j in 0..8 {
            let (u, v) = if j < 4 {
                let (a, b) = (g.unit(), g.unit());
                if a + b > 1.0 {
                    (1.0 - a, 1.0 - b)
                } else {
                    (a, b)
                }
            } else {
                // A corner or the long edge's midpoint, moved toward the centroid by up to 10^-4.
                let corner: (f32, f32) = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (0.5, 0.5)][j - 4];
                let d = 1e-4 * g.unit();
                (
                    corner.0 + (1.0 / 3.0 - corner.0) * d,
                    corner.1 + (1.0 / 3.0 - corner.1) * d,
                )
            };
            let p = triangle_point(q, f1, f2, u, v);
            let (offset, grazing) = triangle_offsets(q, f1, f2, u, v);
            let n_side = if g.unit() < 0.5 { n } else { -n };
            let a = g.dir();
            let tangent = (a - n_side * a.dot(n_side)).normalize();
            let cos = g.pow10(-10.0, GRAZING_COS.log10());
            let w = (n_side * cos + tangent * (1.0 - cos * cos).sqrt()).normalize();
            if !(w.dot(n_side) > 0.0 && tangent.is_finite()) {
                continue;
            }
            let origin = continuation_origin(p, n_side, w, offset, grazing);
            let height = (origin.as_dvec3() - q.as_dvec3()).dot(n64).abs();
            highest = highest.max(height);
        }
        if highest > GRAZING_DOMAIN as f64 * longest {
            beyond += 1;
            beyond_kinds[needle as usize] += 1;
            missed += !check.beyond_domain() as usize;
            let halved = LeavingHeight {
                rounding: 0.5 * check.rounding,
                ..check
            };
            halved_missed += !halved.beyond_domain() as usize;
        } else {
            within += 1;
            within_flagged += check.beyond_domain() as usize;
        }
    }
    println!("grazing domain check: {beyond} triangles left beyond GRAZING_DOMAIN ({} needles, {} far from the origin), {missed} not flagged (with the rounding term halved: {halved_missed}); {within_flagged} of {within} flagged whose sampled rays stayed within", beyond_kinds[1], beyond_kinds[0]);
    assert!(
        beyond_kinds[0] > 100 && beyond_kinds[1] > 100,
        "{beyond_kinds:?}"
    );
    assert_eq!(missed, 0);
    assert!(
        halved_missed > 0,
        "the rounding term is not shown to be needed"
    );
}
