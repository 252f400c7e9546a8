//! Orthonormal frames around a unit vector.

use spirv_std::glam::Vec3;

/// Two unit vectors `(t, b)` such that `(t, b, n)` is a right-handed orthonormal basis
/// (t x b = n), for unit `n`. Branch-free except for the sign, and accurate up to and including
/// n = -Z: Duff, Burgess, Christensen, Hery, Kensler, Liani, Villemin, "Building an Orthonormal
/// Basis, Revisited", JCGT 6(1), 2017, Listing 3.
#[inline]
pub fn orthonormal_basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    let t = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    let bt = Vec3::new(b, sign + n.y * n.y * a, -n.y);
    (t, bt)
}
