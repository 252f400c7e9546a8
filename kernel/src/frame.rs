//! Orthonormal frames around a unit vector.

use crate::real::{select, Real, V3};
use spirv_std::glam::Vec3;

/// Two unit vectors `(t, b)` such that `(t, b, n)` is a right-handed orthonormal basis
/// (t x b = n), for unit `n`. Branch-free except for the sign, and accurate up to and including
/// n = -Z: Duff, Burgess, Christensen, Hery, Kensler, Liani, Villemin, "Building an Orthonormal
/// Basis, Revisited", JCGT 6(1), 2017, Listing 3.
#[inline]
pub fn orthonormal_basis(n: Vec3) -> (Vec3, Vec3) {
    let (t, b) = orthonormal_basis_v3(V3::from(n));
    (t.into(), b.into())
}

/// [`orthonormal_basis`] of one vector, or of one per lane ([`Real`]).
#[inline]
pub fn orthonormal_basis_v3<R: Real>(n: V3<R>) -> (V3<R>, V3<R>) {
    let one = R::splat(1.0);
    let sign = select(n.z.at_least(R::splat(0.0)), one, -one);
    let a = -one / (sign + n.z);
    let b = n.x * n.y * a;
    let t = V3::new(one + sign * n.x * n.x * a, sign * b, -sign * n.x);
    let bt = V3::new(b, sign + n.y * n.y * a, -n.y);
    (t, bt)
}
