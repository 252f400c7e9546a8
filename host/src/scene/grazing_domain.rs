//! Triangles that rays may leave higher than the kernel's offsets are derived for: a note for
//! the user, naming the mesh and where one such triangle lies.
//!
//! A ray leaving a triangle within `kernel::geometry::GRAZING_COS` of its plane clears a
//! device's own triangle test only while it starts within `GRAZING_DOMAIN` E of the plane (E the
//! longest edge; `kernel::geometry::triangle_grazing_offset_v3`, docs/robustness.md, "Known
//! limits"). Two kinds of triangle let it start higher: needles, whose grazing offset grows with
//! the ratio of their length to their width, and triangles small against the rounding of their
//! coordinates (or, instanced, against their instance's round trip). A ray grazing one of them
//! may meet it again; nothing else changes, so the scene renders, and the note says where.
//!
//! The height checked is what the kernel computes, with its own functions, at the triangle's
//! corners (where the offsets' rounding terms are largest; they are linear in the barycentrics),
//! plus the watertight term's largest value over the triangle, the point's rounding bound
//! counted twice (the origin lies up to that far off the offset it is given) and the grid the
//! origin is rounded to. A triangle is flagged when that exceeds `GRAZING_DOMAIN` E. The check
//! is meant to flag more than it must, never less: `tests/tests/reintersection.rs` finds no
//! ray beyond the domain from a triangle it passes, plain or instanced.

use super::flat_scene::{Scene, TriangleGroup};
use glam::Vec3;
use kernel::geometry::{
    longest_edge, triangle_offsets_v3, triangle_point, triangle_watertight_error_bound,
    ShapeFactors, TriangleShape, GRAZING_DOMAIN,
};
use kernel::instance::{
    carries_heights, condition_number, instanced_offset_v3, normal_to_world, point_to_world,
    translation_norm, world_point_error_v3, ObjectLeaving, DEVICE_INVERSE_CONDITION_LIMIT,
    SQRT_3_ABOVE,
};
use kernel::real::V3;
use kernel::scene::{Instance, Triangle};
use rayon::prelude::*;

/// The barycentrics of a triangle's corners, where the offsets' rounding terms peak.
const CORNERS: [(f32, f32); 3] = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)];

/// The largest height above a triangle's plane, in the triangle's own space, at which a ray
/// leaving it may start, split into the part the point's rounding gives (the offset and the
/// origin's own distance from it, up to the offset again) and the grazing offset, with the
/// triangle's longest edge E.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LeavingHeight {
    pub rounding: f32,
    pub grazing: f32,
    pub longest: f32,
}

impl LeavingHeight {
    /// Whether a ray may leave higher than `GRAZING_DOMAIN` E, or the height is not a number.
    pub fn beyond_domain(&self) -> bool {
        !(self.rounding + self.grazing <= GRAZING_DOMAIN * self.longest)
    }

    /// The height of world-space triangle `tri`, from `kernel::geometry::triangle_offsets_v3`
    /// and the grid the origin is rounded to: `kernel::geometry::lift_ray_origin` rounds the
    /// lifted point and then steps each component one ULP away from the surface, at most 1.5 ULP
    /// <= 1.5 eps of the component's magnitude, which is what a ray leaving a floor far from the
    /// origin rises by whatever its offset (counted as 2 eps).
    pub fn of_world(tri: &Triangle) -> Self {
        let (p0, e1, e2) = corners(tri);
        let factors = ShapeFactors::<f32>::of(V3::from(e1), V3::from(e2));
        let normal = Vec3::from(factors.normal).abs();
        let grazing = factors.grazing;
        let (mut offset, mut coordinates) = (0.0f32, 0.0f32);
        for (u, v) in CORNERS {
            let (o, _) = triangle_offsets_v3(p0.into(), e1.into(), e2.into(), u, v, &factors);
            offset = offset.max(o);
            let corner = triangle_point(p0, e1, e2, u, v);
            coordinates = coordinates.max(corner.abs().dot(normal));
        }
        // Where the offset is the point's bound (slivers), its watertight part peaks inside.
        let watertight = triangle_watertight_error_bound(e1, e2) * normal.element_sum();
        let lift = 2.0 * (offset + watertight);
        let grid = 2.0 * f32::EPSILON * (coordinates + (lift + grazing) * normal.element_sum());
        Self {
            rounding: lift + grid,
            grazing,
            longest: longest_edge(e1, e2),
        }
    }
}

/// What the checks of an instanced triangle need of the object triangle alone, computed once
/// per triangle and used under each of its instances: the exact height
/// ([`InstancedBound::exact`]) and a bound on it that is cheap per instance
/// ([`InstancedBound::may_be_beyond`]); a scene placing a mesh 10^3 times would otherwise spend
/// seconds in the exact check.
pub struct InstancedBound {
    /// What the offsets read of the triangle at its corners, each point's error bound with the
    /// watertight term at its largest added.
    corners: [ObjectLeaving<f32>; 3],
    /// The largest of the corners' error bounds.
    error: f32,
    /// The largest absolute coordinate of the corners.
    coordinates: f32,
    normal: Vec3,
    grazing: f32,
    /// The sum of the triangle's plane weights (`kernel::geometry::TriangleShape`), which the
    /// carried height reads.
    weight_sum: f32,
    longest: f32,
}

impl InstancedBound {
    pub fn of(tri: &Triangle) -> Self {
        let (p0, e1, e2) = corners(tri);
        let shape = TriangleShape::of(e1, e2);
        let watertight = triangle_watertight_error_bound(e1, e2);
        let corners = CORNERS.map(|(u, v)| {
            let mut corner = ObjectLeaving::of_triangle((p0, e1, e2), (u, v), &shape);
            corner.error += watertight;
            corner
        });
        Self {
            corners,
            error: corners.iter().fold(0.0, |m, c| c.error.max(m)),
            coordinates: corners
                .iter()
                .fold(0.0, |m, c| Vec3::from(c.point).abs().max_element().max(m)),
            normal: shape.normal,
            grazing: shape.grazing,
            weight_sum: shape.weights.element_sum(),
            longest: longest_edge(e1, e2),
        }
    }

    /// The height under `instance`, in object units: the world height of
    /// `kernel::instance::instanced_offset_v3` at the corners times the length of the world
    /// normal before normalising (a world move H along it maps back to at most about H |M^-T n_o|
    /// along the object normal). Infinite where the carried height is not proven
    /// (`kernel::instance::carries_heights`: the map or the triangle's shape may turn its
    /// computed world normal too far), or where the instance is conditioned beyond what the
    /// heights are shown to hold of a device's own inverse
    /// (`kernel::instance::DEVICE_INVERSE_CONDITION_LIMIT`).
    pub fn exact(&self, instance: &Instance) -> LeavingHeight {
        let world_normal = normal_to_world(instance, self.normal);
        let length = world_normal.length();
        let normal = world_normal / length;
        let (mut rounding, mut lifted) = (0.0f32, 0.0f32);
        for corner in self.corners {
            let p_world = point_to_world(instance, Vec3::from(corner.point));
            let at = |grazing: f32| {
                let object = ObjectLeaving { grazing, ..corner };
                instanced_offset_v3(
                    instance,
                    &object,
                    (V3::from(p_world), V3::from(normal), length),
                )
            };
            let bare = at(0.0);
            rounding = rounding.max(bare);
            lifted = lifted.max(at(self.grazing) - bare);
        }
        if !carries_heights(instance, length, self.weight_sum) || beyond_the_device_limit(instance)
        {
            lifted = f32::INFINITY;
        }
        LeavingHeight {
            rounding: 2.0 * rounding * length,
            grazing: lifted * length,
            longest: self.longest,
        }
    }

    /// Whether the triangle may be beyond the domain under `instance`: false only where
    /// [`InstancedBound::exact`] is within it. The bound takes each of its terms at its
    /// largest over the triangle and the object normal's direction, by the instance's infinity
    /// norms m = ||M||, w = ||M^-1||:
    /// - the world point, |p_w| <= m |p_o| + |T| (`kernel::instance::world_point_error_v3`
    ///   depends on the points only through their largest components);
    /// - |n_world|_1 times the normal's length, |M^-T n_o|_1 <= sqrt(3) w;
    /// - the grazing offset's carried factor times the normal's computed length L:
    ///   (1 + 4 eps) L / L_low, with L_low = L (1 - 4 eps - b) - a, a = eps w (16 + 7 s) (s the
    ///   weight sum), b = 2 eps m w (`kernel::instance::world_height_v3`), which falls as L
    ///   grows; and L >= (l - a) (1 - 4 eps) / (1 + b), l = 1 / (sqrt(3) m) <= 1 / ||M||_2
    ///   <= |M^-T n_o|, less the computed vector's deviation and the length's rounding. Where
    ///   that leaves no positive L_low the triangle may be beyond (the exact check decides).
    ///
    /// Each carries a spare of 16 to 64 eps for its own rounding.
    pub fn may_be_beyond(&self, instance: &Instance) -> bool {
        if beyond_the_device_limit(instance) {
            return true;
        }
        let eps = f32::EPSILON;
        let (m, w) = (instance.forward_norm, instance.inverse_norm);
        let translation = translation_norm(&instance.object_to_world);
        let world = (m * self.coordinates + translation) * (1.0 + 8.0 * eps);
        let error = world_point_error_v3(
            instance,
            V3::from(Vec3::new(self.coordinates, 0.0, 0.0)),
            self.error,
            V3::from(Vec3::new(world, 0.0, 0.0)),
        );
        let normal = SQRT_3_ABOVE * w * (1.0 + 16.0 * eps);
        let spare = 1.0 + 16.0 * eps;
        let a = eps * w * (16.0 + 7.0 * self.weight_sum) * spare;
        let b = 2.0 * eps * m * w * spare;
        let shortest =
            (1.0 / (SQRT_3_ABOVE * m * spare) - a) * (1.0 - 4.0 * eps) / (1.0 + b) / spare;
        let shrunk = (1.0 - 4.0 * eps - b) - a / shortest;
        if !(shortest > 0.0 && shrunk > 0.0) {
            return true;
        }
        let carried = (1.0 + 4.0 * eps) / shrunk * spare;
        let height = (2.0 * error * normal + self.grazing * carried) * (1.0 + 64.0 * eps);
        !(height <= GRAZING_DOMAIN * self.longest)
    }

    /// The triangle's [`InstancedBound::exact`] height where it is beyond the domain under
    /// `instance`, checked exactly only where [`InstancedBound::may_be_beyond`] says it may be.
    pub fn beyond(&self, instance: &Instance) -> Option<LeavingHeight> {
        if !self.may_be_beyond(instance) {
            return None;
        }
        Some(self.exact(instance)).filter(LeavingHeight::beyond_domain)
    }
}

/// Whether `instance`'s condition number (`kernel::instance::condition_number`) exceeds
/// `kernel::instance::DEVICE_INVERSE_CONDITION_LIMIT`.
fn beyond_the_device_limit(instance: &Instance) -> bool {
    !(condition_number(instance) <= DEVICE_INVERSE_CONDITION_LIMIT)
}

/// A triangle's p0 and edges.
fn corners(tri: &Triangle) -> (Vec3, Vec3, Vec3) {
    (
        Vec3::from(tri.p0),
        Vec3::from(tri.edge1),
        Vec3::from(tri.edge2),
    )
}

/// What the check found in one group of triangles: how many it flagged, and the first.
struct Flagged {
    count: usize,
    first: Option<(Triangle, LeavingHeight)>,
}

impl Flagged {
    /// The note for group `name` of `total` triangles, `placed` saying how they are placed,
    /// or None where none is flagged.
    fn note(&self, name: &str, total: usize, placed: &str) -> Option<String> {
        let (triangle, height) = self.first?;
        let corner = Vec3::from(triangle.p0);
        Some(format!(
            "{name}: {} of {total} triangles{placed} lie beyond the domain where rays leaving \
             them are proven not to meet them again (docs/robustness.md, \"Known limits\"): a \
             ray leaving one within 1/1024 of its plane may. E.g. the one at ({}, {}, {}), \
             longest edge {:.3e}: {}",
            self.count,
            corner.x,
            corner.y,
            corner.z,
            height.longest,
            reason(&triangle, &height)
        ))
    }

    /// The triangles of `group` that `flag` flags (giving the height it found too high).
    fn among(
        scene: &Scene,
        group: &TriangleGroup,
        flag: impl Fn(&Triangle) -> Option<LeavingHeight> + Sync,
    ) -> Self {
        let flagged: Vec<(usize, LeavingHeight)> = scene.triangles[group.range.clone()]
            .par_iter()
            .enumerate()
            .filter_map(|(k, tri)| flag(tri).map(|h| (k, h)))
            .collect();
        Self {
            count: flagged.len(),
            first: flagged
                .first()
                .map(|&(k, h)| (scene.triangles[group.range.start + k], h)),
        }
    }
}

/// Which kind of triangle `tri` (found at `height`) is, for the note: one whose placement is not
/// proven at all where its grazing height is infinite ([`InstancedBound::exact`]), a needle where
/// it is beyond the domain even with its first corner at the origin (its shape alone), else one
/// small against the rounding of its coordinates (or, instanced, of its placement).
fn reason(tri: &Triangle, height: &LeavingHeight) -> String {
    if height.grazing == f32::INFINITY {
        return format!(
            "its placement's map is conditioned beyond what the offsets are shown for \
             (||M|| ||M^-1|| above {DEVICE_INVERSE_CONDITION_LIMIT}, a device's own inverse \
             turning directions) or turns its normal too far"
        );
    }
    let at_origin = Triangle {
        p0: [0.0; 3],
        ..*tri
    };
    if LeavingHeight::of_world(&at_origin).beyond_domain() {
        "a needle, narrow against its length".into()
    } else {
        "small against the rounding of its coordinates or its placement".into()
    }
}

/// The notes for every mesh with triangles beyond the grazing domain: world-space triangles by
/// [`LeavingHeight::of_world`], instanced ones by [`InstancedBound::beyond`] under each
/// instance that places them (their first vertex given in object space).
pub fn notes(scene: &Scene) -> Vec<String> {
    let world = scene.world_triangle_count();
    let mut notes = Vec::new();
    for group in &scene.triangle_groups {
        if group.range.end <= world {
            let found = Flagged::among(scene, group, |tri| {
                Some(LeavingHeight::of_world(tri)).filter(LeavingHeight::beyond_domain)
            });
            notes.extend(found.note(&group.name, group.range.len(), ""));
        }
    }
    for (m, mesh) in scene.meshes.iter().enumerate() {
        let instances: Vec<&Instance> = scene
            .instances
            .iter()
            .zip(&scene.instance_meshes)
            .filter(|&(_, &of)| of as usize == m)
            .map(|(inst, _)| inst)
            .collect();
        let found = Flagged::among(scene, mesh, |tri| {
            let bound = InstancedBound::of(tri);
            instances.iter().find_map(|inst| bound.beyond(inst))
        });
        let placed = format!(" (object space, under {} instances)", instances.len());
        notes.extend(found.note(&mesh.name, mesh.range.len(), &placed));
    }
    notes
}
