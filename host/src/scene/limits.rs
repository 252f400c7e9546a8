//! The ranges of values a scene may hold, whatever its format: what the kernel's f32
//! arithmetic and the film support (property tests), checked where a scene is read.

/// Largest coordinate magnitude (and sphere radius) accepted: the kernel's f32 arithmetic
/// squares distances, and (3.5e15)^2 stays far below f32's 3.4e38 (property tests).
pub const MAX_COORDINATE: f32 = 1e15;
/// Smallest sphere radius accepted: below it, 1 / (4 pi r^2) overflows f32.
pub const MIN_RADIUS: f32 = 1e-15;

/// Largest image side accepted (a typo like 1e9 must not try to allocate the film).
pub const MAX_IMAGE_SIDE: i64 = 1 << 15;
/// Largest GGX roughness accepted: alpha 1 is already rougher than a Lambertian surface looks.
pub const MAX_ALPHA: f32 = 1.0;
/// Range of a dielectric's index of refraction (relative to the outside) accepted.
pub const IOR_RANGE: (f32, f32) = (0.1, 10.0);
