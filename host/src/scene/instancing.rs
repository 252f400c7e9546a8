//! Instancing: a mesh used in several places is stored once, in object space, and placed by
//! instance records (`kernel::scene::Instance`). Here are when a loader instances a mesh (and
//! when it flattens a placement of it instead), the record of a placement, and the world-space
//! box the instances fill.

use super::transform::Transform;
use glam::{DMat4, Vec3};
use kernel::instance::{
    condition_number, DEVICE_INVERSE_CONDITION_LIMIT, DEVICE_INVERSE_EPS_PER_DETERMINANT_CONDITION,
};
use kernel::scene::{Instance, Triangle};

/// Fewest triangles a mesh used more than once needs to be instanced rather than flattened
/// into world space. An instance record (116 bytes) and the ray's map into object space cost
/// about what a couple of flattened triangles do (48 bytes each and their BVH share), so a tiny
/// mesh is cheaper flattened; from here on, instancing saves memory in proportion to the mesh.
pub const INSTANCE_MIN_TRIANGLES: usize = 16;

/// Most instances a scene may have: the GPU names an instance by its 24-bit custom index.
pub const MAX_INSTANCES: usize = 1 << 24;

/// The largest determinant condition (`kernel::scene::Instance::determinant_condition`) of a
/// placement that is instanced: there the device's term for it
/// (`kernel::instance::DEVICE_INVERSE_EPS_PER_DETERMINANT_CONDITION` H eps) is at most what the
/// condition number's term is at `kernel::instance::DEVICE_INVERSE_CONDITION_LIMIT`.
pub const DETERMINANT_CONDITION_LIMIT: f32 =
    DEVICE_INVERSE_CONDITION_LIMIT / DEVICE_INVERSE_EPS_PER_DETERMINANT_CONDITION;

/// Why a placement of a mesh, whose record ([`instance_record`]) is `placement`, is flattened
/// into world space instead of instanced, or None where it is instanced. A device maps rays
/// into an instance's object space by its own inverse of the map, which Vulkan does not
/// specify: past a condition number of `kernel::instance::DEVICE_INVERSE_CONDITION_LIMIT` its
/// error may turn a grazing ray into the triangle it leaves, and past a determinant condition
/// of [`DETERMINANT_CONDITION_LIMIT`] an inverse by the adjugate (RADV's, ANV's) scales the
/// mesh it sees by up to 6 eps H and the heights of leaving rays with it (docs/instancing.md).
/// A flattened placement involves no device inverse.
pub fn flattening_reason(placement: &Instance) -> Option<String> {
    let condition = condition_number(placement);
    if !(condition <= DEVICE_INVERSE_CONDITION_LIMIT) {
        return Some(format!(
            "its map's condition number ||M|| ||M^-1|| is {condition:.0}, above \
             {DEVICE_INVERSE_CONDITION_LIMIT}"
        ));
    }
    let determinant = placement.determinant_condition;
    if !(determinant <= DETERMINANT_CONDITION_LIMIT) {
        return Some(format!(
            "its map's determinant condition perm(|A|) / |det A| is {determinant:.0}, above \
             {DETERMINANT_CONDITION_LIMIT} (a scale along turned axes)"
        ));
    }
    None
}

/// The most placements of one mesh the loaders flatten for [`flattening_reason`], and the most
/// triangles those copies may hold together: further placements stay instanced, so that what
/// flattening costs stays within this per mesh. The heights of rays leaving them still hold a
/// device's inverse by the determinant's term; past the condition limit the grazing-domain
/// check names their meshes.
pub const MAX_FLATTENED_PLACEMENTS: usize = 64;
pub const MAX_FLATTENED_TRIANGLES: usize = 1 << 20;

/// The placements of one mesh that [`flattening_reason`] would flatten: how many were flattened
/// (within [`MAX_FLATTENED_PLACEMENTS`] and [`MAX_FLATTENED_TRIANGLES`]), how many stayed
/// instanced beyond them, and the first one's reason.
pub struct FlattenedCopies {
    pub name: String,
    pub reason: String,
    pub flattened: usize,
    pub triangles: usize,
    pub kept: usize,
}

impl FlattenedCopies {
    /// Mesh `name`'s record before any placement is counted, with the first one's `reason`.
    pub fn new(name: &str, reason: String) -> Self {
        Self {
            name: name.to_string(),
            reason,
            flattened: 0,
            triangles: 0,
            kept: 0,
        }
    }

    /// Whether one more placement, of `triangles` triangles, is flattened; counted either way.
    pub fn admit(&mut self, triangles: usize) -> bool {
        let fits = self.flattened < MAX_FLATTENED_PLACEMENTS
            && self.triangles + triangles <= MAX_FLATTENED_TRIANGLES;
        if fits {
            self.flattened += 1;
            self.triangles += triangles;
        } else {
            self.kept += 1;
        }
        fits
    }

    /// The note the loader shows for this mesh.
    pub fn note(&self) -> String {
        let kept = if self.kept > 0 {
            format!(
                "; {} more stay instanced, beyond the {MAX_FLATTENED_PLACEMENTS} copies or \
                 {MAX_FLATTENED_TRIANGLES} triangles a mesh's flattened placements may take",
                self.kept
            )
        } else {
            String::new()
        };
        format!(
            "{}: {} placements flattened into world space instead of instanced: {}, beyond \
             what a device's own inverse of an instance's map is shown to keep{kept} \
             (docs/instancing.md)",
            self.name, self.flattened, self.reason
        )
    }
}

/// The record of a placement of the mesh whose triangles start at `first_triangle`, by the
/// affine `transform`: both matrices (the inverse computed in f64, then rounded), their
/// infinity norms and the handedness.
pub fn instance_record(transform: &Transform, first_triangle: u32) -> Instance {
    let m: DMat4 = transform.matrix();
    let inv = m.inverse();
    let rows = |a: DMat4| -> [f32; 12] {
        let mut r = [0.0f32; 12];
        for i in 0..3 {
            let row = a.row(i);
            r[4 * i..4 * i + 4].copy_from_slice(&[
                row.x as f32,
                row.y as f32,
                row.z as f32,
                row.w as f32,
            ]);
        }
        r
    };
    let norm = |r: &[f32; 12]| {
        (0..3)
            .map(|i| r[4 * i].abs() + r[4 * i + 1].abs() + r[4 * i + 2].abs())
            .fold(0.0f32, f32::max)
    };
    let object_to_world = rows(m);
    let world_to_object = rows(inv);
    Instance {
        object_to_world,
        world_to_object,
        first_triangle,
        forward_norm: norm(&object_to_world),
        inverse_norm: norm(&world_to_object),
        handedness: if transform.mirrors() { -1.0 } else { 1.0 },
        determinant_condition: determinant_condition(&object_to_world),
    }
}

/// perm(|A|) / |det A| for the linear part A of the stored 3 x 4 matrix `m`, in f64 and
/// rounded up to the next `f32` (`kernel::scene::Instance::determinant_condition`): at least 1,
/// since every term of the determinant is one of the permanent's. Infinite for a singular A.
pub fn determinant_condition(m: &[f32; 12]) -> f32 {
    let a = |r: usize, c: usize| m[4 * r + c] as f64;
    // The six products of the determinant's expansion, one per permutation, with their signs.
    let permutations = [
        ([0, 1, 2], 1.0),
        ([1, 2, 0], 1.0),
        ([2, 0, 1], 1.0),
        ([0, 2, 1], -1.0),
        ([2, 1, 0], -1.0),
        ([1, 0, 2], -1.0),
    ];
    let (mut permanent, mut determinant) = (0.0f64, 0.0f64);
    for (p, sign) in permutations {
        let term = a(0, p[0]) * a(1, p[1]) * a(2, p[2]);
        permanent += term.abs();
        determinant += sign * term;
    }
    let ratio = permanent / determinant.abs();
    let rounded = ratio as f32;
    if (rounded as f64) < ratio {
        rounded.next_up()
    } else {
        rounded
    }
    .max(1.0)
}

/// The object-space box of `triangles`.
pub fn mesh_box(triangles: &[Triangle]) -> (Vec3, Vec3) {
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for t in triangles {
        let p0 = Vec3::from(t.p0);
        for p in [p0, p0 + Vec3::from(t.edge1), p0 + Vec3::from(t.edge2)] {
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    (lo, hi)
}

/// The world-space box of an object-space box `(lo, hi)` placed by `instance`: the box of its
/// eight corners mapped (`kernel::instance::point_to_world`).
pub fn instance_box(instance: &Instance, (lo, hi): (Vec3, Vec3)) -> (Vec3, Vec3) {
    let (mut wlo, mut whi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for corner in 0..8 {
        let c = Vec3::new(
            if corner & 1 == 0 { lo.x } else { hi.x },
            if corner & 2 == 0 { lo.y } else { hi.y },
            if corner & 4 == 0 { lo.z } else { hi.z },
        );
        let p = kernel::instance::point_to_world(instance, c);
        wlo = wlo.min(p);
        whi = whi.max(p);
    }
    (wlo, whi)
}

/// The world-space box of every instance (empty without instances): `mesh_boxes` are the
/// meshes' object-space boxes, `instance_meshes[i]` is instance i's mesh.
pub fn instances_box(
    mesh_boxes: &[(Vec3, Vec3)],
    instances: &[Instance],
    instance_meshes: &[u32],
) -> (Vec3, Vec3) {
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for (inst, &mesh) in instances.iter().zip(instance_meshes) {
        let (a, b) = instance_box(inst, mesh_boxes[mesh as usize]);
        lo = lo.min(a);
        hi = hi.max(b);
    }
    (lo, hi)
}
