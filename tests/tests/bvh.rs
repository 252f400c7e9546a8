//! The CPU backend's 4-wide BVH against brute force: for every ray, the closest hit's t is
//! bit-identical to the minimum over all primitives of the kernel's scalar intersection, the
//! primitive returned really is hit at that t, and any-hit agrees with it. Scenes that stress
//! the build and the traversal: random soups with spheres, a dense generated mesh, an
//! axis-aligned grid (flat boxes, rays in their planes), thousands of identical triangles (the
//! median-split fallback), and 0 to 5 primitives (a root that is a leaf). Memory is checked to
//! grow linearly with the triangle count. Of primitives hit at exactly the same t the smallest
//! id is returned (thousands of identical triangles, a grid's shared edges), so the answer does
//! not depend on the traversal order. The packets of sixteen rays, against every primitive of a
//! small scene and through the BVH, are held to the same brute force.

#![feature(portable_simd)]

use glam::Vec3;
use kernel::rng::SampleRng;
use kernel::scene::{Sphere, Triangle, NONE};
use twinpath::bench::rays::{knot_mesh, to_triangles};
use twinpath::cpu::Bvh;

/// Uniform numbers from the kernel's hash (a fixed stream per test).
struct Uniform(SampleRng);

impl Uniform {
    fn new(stream: u32) -> Self {
        Uniform(SampleRng::new(0x5eed, stream, 0))
    }
    fn f(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.0.next_f32()
    }
    fn point(&mut self, lo: f32, hi: f32) -> Vec3 {
        Vec3::new(self.f(lo, hi), self.f(lo, hi), self.f(lo, hi))
    }
    /// Directions: a third exactly along an axis (zero components: infinite 1/d), the rest
    /// uniform on the sphere.
    fn dir(&mut self) -> Vec3 {
        let k = self.0.next_u32() % 9;
        if k < 6 {
            let s = if k.is_multiple_of(2) { 1.0 } else { -1.0 };
            [Vec3::X, Vec3::Y, Vec3::Z][k as usize / 2] * s
        } else {
            let z = self.f(-1.0, 1.0);
            let phi = self.f(0.0, std::f32::consts::TAU);
            let r = (1.0 - z * z).max(0.0).sqrt();
            Vec3::new(r * phi.cos(), r * phi.sin(), z)
        }
    }
}

fn sphere(center: Vec3, radius: f32) -> Sphere {
    Sphere {
        center: center.to_array(),
        radius,
        material: 0,
        light: NONE,
        _pad: [0; 2],
    }
}

/// The closest hit by testing every primitive with the kernel's scalar functions.
fn brute_force(bvh: &Bvh, o: Vec3, d: Vec3, t_max: f32) -> (u32, f32) {
    let n = (bvh.spheres.len() + bvh.triangles.len()) as u32;
    let (mut best, mut best_t) = (NONE, t_max);
    for id in 0..n {
        let t = bvh.intersect_prim(id, o, d, best_t);
        if t >= 0.0 && t < best_t {
            (best, best_t) = (id, t);
        }
    }
    (best, best_t)
}

/// The centre of primitive `k` (a sphere's centre, a triangle's centroid): where rays aim so
/// that they hit something in scenes that are mostly empty.
fn centre(bvh: &Bvh, k: usize) -> Vec3 {
    if k < bvh.spheres.len() {
        Vec3::from(bvh.spheres[k].center)
    } else {
        let t = &bvh.triangles[k - bvh.spheres.len()];
        Vec3::from(t.p0) + (Vec3::from(t.edge1) + Vec3::from(t.edge2)) / 3.0
    }
}

/// Asserts that `uv` are, bit for bit, the barycentrics the kernel's scalar
/// `intersect_triangle_uv` gives where the ray meets primitive `prim` when that is a triangle.
fn assert_kernel_barycentrics(
    bvh: &Bvh,
    prim: u32,
    origin: Vec3,
    dir: Vec3,
    (u, v): (f32, f32),
    label: &str,
) {
    if prim == NONE || (prim as usize) < bvh.spheres.len() {
        return;
    }
    let tri = &bvh.triangles[prim as usize - bvh.spheres.len()];
    let h = kernel::geometry::intersect_triangle_uv(
        origin,
        dir,
        Vec3::from(tri.p0),
        Vec3::from(tri.edge1),
        Vec3::from(tri.edge2),
        0.0,
        f32::INFINITY,
    );
    assert_eq!(
        (u.to_bits(), v.to_bits()),
        (h.u.to_bits(), h.v.to_bits()),
        "{label}: barycentrics"
    );
}

/// Casts `rays` rays (origins in [lo, hi]^3, some on the grid's planes, and finite and
/// infinite t_max) and compares the BVH with brute force; returns how many hit.
fn check_against_brute_force(
    name: &str,
    bvh: &Bvh,
    stream: u32,
    rays: u32,
    lo: f32,
    hi: f32,
) -> u32 {
    let mut rng = Uniform::new(stream);
    let mut hits = 0;
    for i in 0..rays {
        let mut o = rng.point(lo, hi);
        if i % 5 == 0 {
            // On a lattice plane, where the grid scene's flat boxes lie.
            o.y = o.y.round();
        }
        let d = rng.dir();
        let t_max = if i % 3 == 0 {
            rng.f(0.0, hi - lo)
        } else {
            f32::INFINITY
        };
        let (want, want_t) = brute_force(bvh, o, d, t_max);
        let twinpath::cpu::PrimHit {
            prim: got,
            t: got_t,
            ..
        } = bvh.closest_prim(o, d, t_max);
        assert_eq!(
            got_t.to_bits(),
            want_t.to_bits(),
            "{name}: ray {i} from {o} along {d}: BVH t {got_t} (prim {got}), brute force {want_t} (prim {want})"
        );
        // Of primitives at exactly the same t the smallest id, as brute force finds it.
        assert_eq!(
            got, want,
            "{name}: ray {i} from {o} along {d}: BVH prim {got}, brute force {want} (t {got_t})"
        );
        assert_eq!(
            bvh.any_hit(o, d, t_max),
            want != NONE,
            "{name}: ray {i} from {o} along {d}, t_max {t_max}: any-hit disagrees"
        );
        hits += (want != NONE) as u32;
    }
    hits
}

fn random_soup(stream: u32, triangles: usize, spheres: usize) -> Bvh {
    let mut rng = Uniform::new(stream);
    let tris: Vec<[Vec3; 3]> = (0..triangles)
        .map(|_| {
            let c = rng.point(-10.0, 10.0);
            let size = rng.f(0.05, 2.0);
            [
                c + size * rng.point(-1.0, 1.0),
                c + size * rng.point(-1.0, 1.0),
                c + size * rng.point(-1.0, 1.0),
            ]
        })
        .collect();
    let sph = (0..spheres)
        .map(|_| sphere(rng.point(-10.0, 10.0), rng.f(0.01, 1.5)))
        .collect();
    Bvh::build(sph, to_triangles(&tris, 0))
}

#[test]
fn random_soups_with_spheres_match_brute_force() {
    for (k, (tris, spheres)) in [(3000, 40), (500, 0), (0, 300), (7, 2)]
        .into_iter()
        .enumerate()
    {
        let bvh = random_soup(k as u32, tris, spheres);
        let hits = check_against_brute_force(
            &format!("soup {tris}+{spheres}"),
            &bvh,
            100 + k as u32,
            4000,
            -12.0,
            12.0,
        );
        if tris + spheres > 100 {
            assert!(
                hits > 400,
                "soup {tris}+{spheres}: only {hits} of 4000 rays hit; the test would be weak"
            );
        }
    }
}

#[test]
fn dense_mesh_matches_brute_force() {
    let tris = to_triangles(&knot_mesh(20_000, Vec3::ZERO, 4.0), 0);
    let bvh = Bvh::build(vec![sphere(Vec3::ZERO, 0.3)], tris);
    let hits = check_against_brute_force("knot 20k", &bvh, 7, 3000, -2.5, 2.5);
    assert!(
        hits > 300,
        "knot: only {hits} of 3000 rays hit; the test would be weak"
    );
}

/// Unit squares (two triangles each) in the planes y = 0, 1, 2 over [-4, 4]^2.
fn grid_triangles() -> Vec<[Vec3; 3]> {
    let mut tris = Vec::new();
    for y in 0..3 {
        for x in -4..4 {
            for z in -4..4 {
                let p = |dx: i32, dz: i32| Vec3::new((x + dx) as f32, y as f32, (z + dz) as f32);
                tris.push([p(0, 0), p(1, 0), p(1, 1)]);
                tris.push([p(0, 0), p(1, 1), p(0, 1)]);
            }
        }
    }
    tris
}

#[test]
fn axis_aligned_grid_with_rays_in_its_planes_matches_brute_force() {
    // Unit squares in the planes y = 0, 1, 2: every triangle's box is flat in y, and a fifth of
    // the rays start on those planes (some running inside them).
    let bvh = Bvh::build(Vec::new(), to_triangles(&grid_triangles(), 0));
    let hits = check_against_brute_force("grid", &bvh, 11, 6000, -5.0, 5.0);
    assert!(
        hits > 500,
        "grid: only {hits} of 6000 rays hit; the test would be weak"
    );
}

#[test]
fn identical_triangles_and_tiny_scenes_match_brute_force() {
    // 5000 copies of one triangle: no SAH split separates them (median splits do).
    let one = [
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ];
    let bvh = Bvh::build(Vec::new(), to_triangles(&vec![one; 5000], 0));
    check_against_brute_force("5000 identical", &bvh, 21, 2000, -2.0, 2.0);
    for n in 0..=5 {
        let bvh = random_soup(50 + n, n as usize, (n % 2) as usize);
        check_against_brute_force(&format!("{n} triangles"), &bvh, 60 + n, 2000, -12.0, 12.0);
    }
    let empty = Bvh::build(Vec::new(), Vec::new());
    assert_eq!(
        empty.closest_prim(Vec3::ZERO, Vec3::X, f32::INFINITY).prim,
        NONE
    );
    assert!(!empty.any_hit(Vec3::ZERO, Vec3::X, f32::INFINITY));
}

#[test]
fn memory_grows_linearly_with_the_triangle_count() {
    let bytes_per_triangle = |n: usize| {
        let tris: Vec<Triangle> = to_triangles(&knot_mesh(n, Vec3::ZERO, 4.0), 0);
        let count = tris.len();
        let bvh = Bvh::build(Vec::new(), tris);
        assert!(
            bvh.node_count() <= count,
            "{} nodes for {count} triangles",
            bvh.node_count()
        );
        bvh.hierarchy_bytes() as f64 / count as f64
    };
    let small = bytes_per_triangle(10_000);
    let large = bytes_per_triangle(200_000);
    // Nodes and packed leaves are a bounded number of bytes per triangle, whatever n:
    // one 160-byte block per 1 to 4 triangles, at most one 256-byte node per leaf.
    assert!(
        small < 300.0 && large < 300.0,
        "bytes per triangle: {small:.1} at 10k, {large:.1} at 200k"
    );
    assert!(
        (large / small - 1.0).abs() < 0.25,
        "bytes per triangle: {small:.1} at 10k, {large:.1} at 200k"
    );
}

/// `twinpath rays`' measurement on a small scene: the reported counts are those of the rays it
/// made (the paths' sets: the rays the renderer counts), and the ray file (what
/// `scripts/embree_rays.c` reads) holds the scene's primitives, all four ray sets, and for every
/// ray exactly the hit the BVH finds.
#[test]
fn ray_measurement_and_ray_file_hold_what_was_traced() {
    use twinpath::bench::rays::{add_knot_mesh, measure};
    let mut scene = twinpath::scene::SceneFile::builtin_default();
    add_knot_mesh(&mut scene.scene, 3000);
    assert!(
        scene.scene.name.ends_with("+knot3k"),
        "{}",
        scene.scene.name
    );
    let dir = std::env::temp_dir().join(format!("twinpath-rays-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("small.rays");
    let report = measure(&scene.scene, &scene.settings, 48, 32, 1, Some(&path)).unwrap();
    assert_eq!(report.triangles, scene.scene.triangles.len());
    assert_eq!(report.spheres, scene.scene.spheres.len());
    assert_eq!(report.sets.len(), 4);
    assert_eq!(report.sets[0].rays, 48 * 32);
    // One bounce ray per camera ray that hit.
    assert_eq!(report.sets[1].rays, report.sets[0].hits);
    // The paths' rays are those the renderer counts at 1 spp of the same image.
    let mut image = scene.clone();
    (image.scene.camera.width, image.scene.camera.height) = (48, 32);
    image.settings.packets = false;
    let rendered = twinpath_tests::render_output(&image, twinpath::render::Backend::Cpu, 1)
        .rays
        .unwrap();
    assert_eq!(
        (report.sets[2].rays as u64, report.sets[3].rays as u64),
        (rendered.closest, rendered.shadow)
    );
    assert!(report.sets[2].rays > report.sets[0].rays && report.sets[3].rays > 0);
    assert!(report
        .sets
        .iter()
        .all(|s| s.closest_per_second > 0.0 && s.occluded_per_second > 0.0));

    let bytes = std::fs::read(&path).unwrap();
    std::fs::remove_dir_all(&dir).ok();
    let mut at = 0usize;
    let mut take = |n: usize| {
        let s = &bytes[at..at + n];
        at += n;
        s
    };
    let u32_at = |s: &[u8]| u32::from_le_bytes(s.try_into().unwrap());
    let f32_at = |s: &[u8]| f32::from_le_bytes(s.try_into().unwrap());
    assert_eq!(take(8), b"TPRAYS1\0");
    let (ntri, nsph, nsets) = (u32_at(take(4)), u32_at(take(4)), u32_at(take(4)));
    assert_eq!(
        (ntri as usize, nsph as usize, nsets),
        (scene.scene.triangles.len(), scene.scene.spheres.len(), 4)
    );
    for t in &scene.scene.triangles {
        let v: Vec<f32> = (0..9).map(|_| f32_at(take(4))).collect();
        let p0 = Vec3::from(t.p0);
        assert_eq!(&v[0..3], &p0.to_array());
        assert_eq!(&v[3..6], &(p0 + Vec3::from(t.edge1)).to_array());
        assert_eq!(&v[6..9], &(p0 + Vec3::from(t.edge2)).to_array());
    }
    for s in &scene.scene.spheres {
        let v: Vec<f32> = (0..4).map(|_| f32_at(take(4))).collect();
        assert_eq!(v, [s.center[0], s.center[1], s.center[2], s.radius]);
    }
    let bvh = Bvh::build(scene.scene.spheres.clone(), scene.scene.triangles.clone());
    for set in &report.sets {
        let name = take(32);
        assert!(name.starts_with(set.name.as_bytes()));
        let n = u32_at(take(4)) as usize;
        assert_eq!(n, set.rays);
        let rays: Vec<[f32; 7]> = (0..n)
            .map(|_| std::array::from_fn(|_| f32_at(take(4))))
            .collect();
        let mut hits = 0;
        for r in &rays {
            let (prim, t) = (u32_at(take(4)), f32_at(take(4)));
            let (o, d) = (Vec3::new(r[0], r[1], r[2]), Vec3::new(r[3], r[4], r[5]));
            let twinpath::cpu::PrimHit {
                prim: want,
                t: want_t,
                ..
            } = bvh.closest_prim(o, d, r[6]);
            assert_eq!((prim, t.to_bits()), (want, want_t.to_bits()));
            hits += (prim != NONE) as usize;
        }
        assert_eq!(hits, set.hits);
    }
    assert_eq!(at, bytes.len(), "trailing bytes in the ray file");
}

#[test]
fn parallel_build_gives_the_one_thread_tree() {
    use twinpath::cpu::internals::{Aabb, BinaryBvh};
    // Large enough for several levels of parallel halves (PARALLEL_MIN = 4096).
    let tris = to_triangles(&knot_mesh(60_000, Vec3::ZERO, 4.0), 0);
    let bounds: Vec<Aabb> = tris
        .iter()
        .map(|t| {
            let p0 = Vec3::from(t.p0);
            [p0 + Vec3::from(t.edge1), p0 + Vec3::from(t.edge2)]
                .into_iter()
                .fold(Aabb::EMPTY.grow(p0), Aabb::grow)
        })
        .collect();
    let parallel = BinaryBvh::build(&bounds, bounds.len());
    let serial = BinaryBvh::build_one_thread(&bounds, bounds.len());
    assert_eq!(parallel.prims, serial.prims, "different primitive order");
    assert_eq!(parallel.nodes.len(), serial.nodes.len());
    // The same tree node for node, walked from both roots (the node order differs).
    let mut stack = vec![(0usize, 0usize)];
    let mut visited = 0;
    while let Some((a, b)) = stack.pop() {
        let (na, nb) = (parallel.nodes[a], serial.nodes[b]);
        assert_eq!(
            (na.bounds, na.count),
            (nb.bounds, nb.count),
            "nodes {a} / {b}"
        );
        visited += 1;
        if na.count > 0 {
            assert_eq!(na.first, nb.first, "leaf {a} / {b}");
        } else {
            let (ca, cb) = (na.first as usize, nb.first as usize);
            stack.push((ca, cb));
            stack.push((ca + 1, cb + 1));
        }
    }
    assert_eq!(visited, serial.nodes.len(), "some nodes are unreachable");
}

/// Sixteen rays at a time against every primitive (`cpu::packet`, what the renderer uses for
/// scenes of at most `MAX_PRIMITIVES`): each lane's t bit-identical to brute force, the
/// primitive hit there (the first in id order of a tie), a triangle's barycentrics bit-identical
/// to the kernel's, and any-hit in agreement; lanes with
/// finite and infinite t_max, axis-aligned directions, and 0 to 32 primitives.
#[test]
fn packets_of_sixteen_rays_match_brute_force() {
    use std::simd::Simd;
    use twinpath::cpu::{RayPacket, SmallScene, LANES, MAX_PRIMITIVES};
    let mut hits = 0;
    let mut rays = 0;
    for n in 0..=MAX_PRIMITIVES {
        let bvh = random_soup(200 + n as u32, n - n / 4, n / 4);
        let small = SmallScene::new(&bvh.spheres, &bvh.triangles);
        let mut rng = Uniform::new(300 + n as u32);
        for packet in 0..64 {
            let mut p = RayPacket::zero();
            let mut t_max = [f32::INFINITY; LANES];
            let mut lanes = Vec::new();
            for (lane, lane_t_max) in t_max.iter_mut().enumerate() {
                let origin = rng.point(-12.0, 12.0);
                // Half the rays aim at a primitive's centre (random soups are mostly empty).
                let dir = if lane % 2 == 0 && n > 0 {
                    let target = centre(&bvh, (rng.0.next_u32() as usize) % n);
                    (target - origin).normalize()
                } else {
                    rng.dir()
                };
                if (packet + lane) % 3 == 0 {
                    *lane_t_max = rng.f(0.0, 24.0);
                }
                p.set(lane, origin, dir);
                lanes.push((origin, dir));
            }
            let found = small.closest(&p, Simd::from_array(t_max));
            let (prims, ts) = (found.prim.to_array(), found.t.to_array());
            let (us, vs) = (found.u.to_array(), found.v.to_array());
            let occluded = small.occluded(&p, Simd::from_array(t_max)).to_array();
            for (lane, &(origin, dir)) in lanes.iter().enumerate() {
                let (want, want_t) = brute_force(&bvh, origin, dir, t_max[lane]);
                let label = format!("{n} primitives, packet {packet}, lane {lane}: ray from {origin} along {dir}, t_max {}", t_max[lane]);
                assert_eq!(ts[lane].to_bits(), want_t.to_bits(), "{label}: t");
                assert_eq!(prims[lane], want, "{label}: primitive");
                assert_eq!(occluded[lane], want != NONE, "{label}: any-hit");
                assert_kernel_barycentrics(&bvh, want, origin, dir, (us[lane], vs[lane]), &label);
                hits += (want != NONE) as u32;
                rays += 1;
            }
        }
    }
    assert!(
        hits > rays / 4,
        "only {hits} of {rays} rays hit; the test would be weak"
    );
}

/// Sixteen rays at a time through the BVH (`cpu::bvh_packet`, what the renderer uses for larger
/// scenes): per lane, the primitive, t and barycentrics bit-identical to brute force (the
/// smallest id of a tie) and any-hit in agreement. Packets both coherent (origins close
/// together, directions in a narrow cone: they stay together deep into the tree) and incoherent
/// (lanes split early and finish one ray at a time), lanes without a ray (t_max 0), finite and
/// infinite t_max, on random soups with spheres, the dense knot, the grid (rays in its planes,
/// ties on its diagonals), identical triangles and trees of 1 to 5 primitives.
#[test]
fn bvh_packets_of_sixteen_rays_match_brute_force() {
    let knot = Bvh::build(
        vec![sphere(Vec3::ZERO, 0.3)],
        to_triangles(&knot_mesh(20_000, Vec3::ZERO, 4.0), 0),
    );
    let grid = grid_triangles();
    let one = [
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ];
    let mut scenes = vec![
        ("soup 3000+40", random_soup(400, 3000, 40), 12.0),
        ("soup 0+300", random_soup(401, 0, 300), 12.0),
        ("knot 20k", knot, 2.5),
        ("grid", Bvh::build(Vec::new(), to_triangles(&grid, 0)), 5.0),
        (
            "2000 identical",
            Bvh::build(Vec::new(), to_triangles(&vec![one; 2000], 0)),
            2.0,
        ),
    ];
    for n in 1..=5 {
        scenes.push((
            "tiny",
            random_soup(410 + n, n as usize, (n % 2) as usize),
            12.0,
        ));
    }
    for (k, (name, bvh, extent)) in scenes.iter().enumerate() {
        let (hits, rays, ties) = check_bvh_packets(name, bvh, 500 + k as u32, *extent);
        assert!(
            hits > rays / 5,
            "{name}: only {hits} of {rays} rays hit; the test would be weak"
        );
        if *name == "2000 identical" {
            assert!(
                ties > 100,
                "{name}: only {ties} ties; the test would be weak"
            );
        }
    }
}

/// Packet number `packet` of sixteen rays, lane by lane `ray(rng, lane)`, with t_max infinite,
/// drawn up to `reach`, or 0 (no ray in the lane) by a fixed pattern over (packet, lane): the
/// packet, its t_max and the rays.
fn ray_packet(
    rng: &mut Uniform,
    packet: usize,
    reach: f32,
    mut ray: impl FnMut(&mut Uniform, usize) -> (Vec3, Vec3),
) -> (
    twinpath::cpu::RayPacket,
    [f32; twinpath::cpu::LANES],
    Vec<(Vec3, Vec3)>,
) {
    let mut p = twinpath::cpu::RayPacket::zero();
    let mut t_max = [f32::INFINITY; twinpath::cpu::LANES];
    let mut lanes = Vec::new();
    for (lane, lane_t_max) in t_max.iter_mut().enumerate() {
        let (origin, dir) = ray(rng, lane);
        if (packet + lane) % 7 == 3 {
            *lane_t_max = 0.0; // no ray in this lane
        } else if (packet + lane).is_multiple_of(3) {
            *lane_t_max = rng.f(0.0, reach);
        }
        p.set(lane, origin, dir);
        lanes.push((origin, dir));
    }
    (p, t_max, lanes)
}

/// 96 packets against `bvh` and brute force; returns the rays that hit, the rays, and the ties
/// (hits where another primitive is hit at exactly the same t).
fn check_bvh_packets(name: &str, bvh: &Bvh, stream: u32, extent: f32) -> (u32, u32, u32) {
    use std::simd::Simd;
    let n = bvh.spheres.len() + bvh.triangles.len();
    let mut rng = Uniform::new(stream);
    let (mut hits, mut rays, mut ties) = (0, 0, 0);
    for packet in 0..96 {
        let coherent = packet % 2 == 0;
        let base = rng.point(-extent, extent);
        let target = centre(bvh, (rng.0.next_u32() as usize) % n);
        let (p, t_max, lanes) = ray_packet(&mut rng, packet, 2.0 * extent, |rng, lane| {
            if coherent {
                let o = base + 0.01 * extent * rng.point(-1.0, 1.0);
                let aim = target + 0.05 * extent * rng.point(-1.0, 1.0);
                (o, (aim - o).normalize())
            } else {
                let o = rng.point(-extent, extent);
                let d = if lane % 2 == 0 {
                    (target - o).normalize()
                } else {
                    rng.dir()
                };
                (o, d)
            }
        });
        let found = bvh.closest_packet(&p, Simd::from_array(t_max));
        let occluded = bvh.occluded_packet(&p, Simd::from_array(t_max)).to_array();
        for (lane, &(origin, dir)) in lanes.iter().enumerate() {
            let label = format!(
                "{name}, packet {packet}, lane {lane}: ray from {origin} along {dir}, t_max {}",
                t_max[lane]
            );
            let (want, want_t) = if t_max[lane] > 0.0 {
                brute_force(bvh, origin, dir, t_max[lane])
            } else {
                (NONE, 0.0)
            };
            assert_eq!(found.t[lane].to_bits(), want_t.to_bits(), "{label}: t");
            assert_eq!(found.prim[lane], want, "{label}: primitive");
            assert_eq!(occluded[lane], want != NONE, "{label}: any-hit");
            let uv = (found.u[lane], found.v[lane]);
            assert_kernel_barycentrics(bvh, want, origin, dir, uv, &label);
            if want != NONE {
                hits += 1;
                let tied = (0..n as u32)
                    .filter(|&id| id != want)
                    .any(|id| bvh.intersect_prim(id, origin, dir, f32::INFINITY) == want_t);
                ties += tied as u32;
            }
            rays += (t_max[lane] > 0.0) as u32;
        }
    }
    (hits, rays, ties)
}

/// Rays straight down onto a grid of unit squares (two triangles each, in shuffled id order)
/// at its vertices, shared edges and diagonals, where two to six triangles are hit at exactly
/// the same t: the one-ray traversal and the packets both report the smallest id, as brute
/// force does, whatever order they visit the leaves in.
#[test]
fn ties_on_shared_edges_give_the_smallest_id() {
    use std::simd::Simd;
    use twinpath::cpu::{RayPacket, LANES};
    let mut tris = Vec::new();
    for x in -6..6 {
        for z in -6..6 {
            let p = |dx: i32, dz: i32| Vec3::new((x + dx) as f32, 0.0, (z + dz) as f32);
            tris.push([p(0, 0), p(1, 0), p(1, 1)]);
            tris.push([p(0, 0), p(1, 1), p(0, 1)]);
        }
    }
    // A fixed shuffle (Fisher-Yates on the kernel's hash) so ids do not follow the tree's order.
    let mut rng = Uniform::new(77);
    for i in (1..tris.len()).rev() {
        tris.swap(i, rng.0.next_u32() as usize % (i + 1));
    }
    let bvh = Bvh::build(Vec::new(), to_triangles(&tris, 0));
    let mut origins = Vec::new();
    for x in -5..5 {
        for z in -5..5 {
            let (x, z) = (x as f32, z as f32);
            // A vertex, the middles of two shared edges, and a point on a diagonal.
            origins.extend([(x, z), (x, z + 0.5), (x + 0.5, z), (x + 0.25, z + 0.25)]);
        }
    }
    let rays: Vec<(Vec3, Vec3)> = origins
        .iter()
        .map(|&(x, z)| (Vec3::new(x, 3.0, z), Vec3::NEG_Y))
        .collect();
    let mut ties = 0;
    for (i, &(o, d)) in rays.iter().enumerate() {
        let (want, want_t) = brute_force(&bvh, o, d, f32::INFINITY);
        let got = bvh.closest_prim(o, d, f32::INFINITY);
        assert_eq!(
            (got.prim, got.t.to_bits()),
            (want, want_t.to_bits()),
            "ray {i} from {o}"
        );
        let tied = (0..tris.len() as u32)
            .filter(|&id| bvh.intersect_prim(id, o, d, f32::INFINITY) == want_t)
            .count();
        ties += (tied > 1) as u32;
    }
    assert!(
        ties > 300,
        "only {ties} of {} rays meet a tie; the test would be weak",
        rays.len()
    );
    for chunk in rays.chunks(LANES) {
        let mut p = RayPacket::zero();
        let mut t_max = [0.0; LANES];
        for (lane, &(o, d)) in chunk.iter().enumerate() {
            p.set(lane, o, d);
            t_max[lane] = f32::INFINITY;
        }
        let found = bvh.closest_packet(&p, Simd::from_array(t_max));
        for (lane, &(o, d)) in chunk.iter().enumerate() {
            let (want, want_t) = brute_force(&bvh, o, d, f32::INFINITY);
            assert_eq!(
                (found.prim[lane], found.t[lane].to_bits()),
                (want, want_t.to_bits()),
                "packet lane {lane}: ray from {o}"
            );
        }
    }
}

/// Packets through a two-level tree match brute force, bit for bit, lane by lane, as the
/// one-ray traversal does: a grid placed twice at the same place (so that two instances are hit
/// at exactly the same t) and also stored at the top level (so that the top level ties with
/// them), twelve knots placed by random rotations, scales and translations, and a sphere. The
/// answer is the least (t, instance, id) over every primitive of every instance (the top
/// level's own counting as instance `NONE`), whatever order either traversal visits them in;
/// any-hit agrees too. Rays straight down onto the grid's vertices and edges, toward random
/// primitives and anywhere, with t_max finite, infinite or 0 (no ray).
#[test]
fn bvh_packets_through_instances_match_brute_force() {
    use glam::DMat4;
    use kernel::instance::ray_to_object;
    use std::simd::Simd;
    use twinpath::scene::instancing::instance_record;
    use twinpath::scene::transform::Transform;
    let grid = to_triangles(&grid_triangles(), 0);
    let knot = to_triangles(&knot_mesh(3_000, Vec3::ZERO, 1.5), 0);
    let meshes = [knot, grid.clone()];
    let mut rng = Uniform::new(900);
    let mut placements = vec![(1u32, DMat4::IDENTITY), (1, DMat4::IDENTITY)];
    for _ in 0..12 {
        let axis = rng.dir().as_dvec3();
        let angle = rng.f(0.0, 6.3) as f64;
        let scale = rng.f(0.3, 1.5) as f64;
        let at = rng.point(-4.0, 4.0).as_dvec3();
        let m = DMat4::from_translation(at)
            * DMat4::from_axis_angle(axis, angle)
            * DMat4::from_scale(glam::DVec3::splat(scale));
        placements.push((0, m));
    }
    let instances: Vec<_> = placements
        .iter()
        .map(|&(_, m)| instance_record(&Transform::affine(m).unwrap().unwrap_or_default(), 0))
        .collect();
    let instance_meshes: Vec<u32> = placements.iter().map(|p| p.0).collect();
    let build_meshes = || {
        meshes
            .iter()
            .map(|m| Bvh::build(Vec::new(), m.clone()))
            .collect()
    };
    let lamp = sphere(Vec3::new(0.5, 3.0, -0.5), 0.4);
    let bvh = Bvh::build_with_instances(
        vec![lamp],
        grid.clone(),
        build_meshes(),
        instances.clone(),
        instance_meshes.clone(),
    );
    let top = Bvh::build(vec![lamp], grid);
    let mesh_trees: Vec<Bvh> = build_meshes();
    // The least (t, instance, id) of every primitive hit within (0, t_max).
    let brute_force = |o: Vec3, d: Vec3, t_max: f32| -> (u32, u32, f32) {
        let mut best = (f32::INFINITY, NONE, NONE);
        let mut consider = |t: f32, instance: u32, id: u32| {
            if t >= 0.0 && t < t_max && (t, instance, id) < best {
                best = (t, instance, id);
            }
        };
        for id in 0..(1 + top.triangles.len()) as u32 {
            consider(top.intersect_prim(id, o, d, t_max), NONE, id);
        }
        for (i, inst) in instances.iter().enumerate() {
            let (oo, od) = ray_to_object(inst, o, d);
            let mesh = &mesh_trees[instance_meshes[i] as usize];
            for id in 0..mesh.triangles.len() as u32 {
                consider(mesh.intersect_prim(id, oo, od, t_max), i as u32, id);
            }
        }
        if best.1 == NONE && best.2 == NONE {
            (NONE, NONE, t_max)
        } else {
            (best.2, best.1, best.0)
        }
    };
    let (mut hits, mut rays, mut on_instances, mut ties) = (0, 0, 0, 0);
    for packet in 0..64 {
        let (p, t_max, lanes) = ray_packet(&mut rng, packet, 8.0, |rng, lane| {
            match packet % 3 {
                // Straight down onto the grid's vertices, edge middles and diagonals.
                0 => {
                    let (x, z) = (
                        (rng.0.next_u32() % 8) as f32 - 4.0,
                        (rng.0.next_u32() % 8) as f32 - 4.0,
                    );
                    let offset = [(0.0, 0.0), (0.5, 0.0), (0.0, 0.5), (0.25, 0.25)][lane % 4];
                    (Vec3::new(x + offset.0, 2.5, z + offset.1), Vec3::NEG_Y)
                }
                1 => {
                    let o = rng.point(-5.0, 5.0);
                    (o, (rng.point(-3.0, 3.0) - o).normalize())
                }
                _ => (rng.point(-5.0, 5.0), rng.dir()),
            }
        });
        let found = bvh.closest_packet(&p, Simd::from_array(t_max));
        let occluded = bvh.occluded_packet(&p, Simd::from_array(t_max)).to_array();
        for (lane, &(origin, dir)) in lanes.iter().enumerate() {
            let label = format!(
                "packet {packet}, lane {lane}: ray from {origin} along {dir}, t_max {}",
                t_max[lane]
            );
            if t_max[lane] == 0.0 {
                assert_eq!(found.prim[lane], NONE, "{label}: no ray, yet a hit");
                assert!(!occluded[lane], "{label}: no ray, yet occluded");
                continue;
            }
            rays += 1;
            let (prim, instance, t) = brute_force(origin, dir, t_max[lane]);
            let one = bvh.closest_prim(origin, dir, t_max[lane]);
            assert_eq!(
                (one.prim, one.instance, one.t.to_bits()),
                (prim, instance, t.to_bits()),
                "{label}: one ray against brute force"
            );
            assert_eq!(
                (
                    found.prim[lane],
                    found.instance[lane],
                    found.t[lane].to_bits()
                ),
                (prim, instance, t.to_bits()),
                "{label}: packet against brute force"
            );
            assert_eq!(occluded[lane], prim != NONE, "{label}: any-hit");
            assert_eq!(
                bvh.any_hit(origin, dir, t_max[lane]),
                prim != NONE,
                "{label}"
            );
            if prim != NONE {
                hits += 1;
                on_instances += (instance != NONE) as u32;
                // Another instance, or the top level, hit at exactly the same t.
                let other = |i: u32| {
                    let (o, d) = ray_to_object(&instances[i as usize], origin, dir);
                    let mesh = &mesh_trees[instance_meshes[i as usize] as usize];
                    i != instance && mesh.closest_prim(o, d, f32::INFINITY).t == t
                };
                let top_tie =
                    instance != NONE && top.closest_prim(origin, dir, f32::INFINITY).t == t;
                ties += ((0..instances.len() as u32).any(other) || top_tie) as u32;
            }
        }
    }
    println!("instances in packets: {hits} of {rays} rays hit, {on_instances} on instances, {ties} at exactly the t of another instance or the top level");
    assert!(
        on_instances > rays / 4,
        "only {on_instances} hits on instances: the test would be weak"
    );
    assert!(
        ties > 100,
        "only {ties} ties across instances: the test would be weak"
    );
}
