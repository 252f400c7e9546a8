//! Whether a triangle mesh bounds a solid with its normals outward: what a dielectric needs,
//! since the kernel takes a surface's inside from its normal (edge1 x edge2 for triangles).

use std::collections::HashMap;

/// Ok if every edge of `triangles` is shared by exactly two of them, traversed in opposite
/// directions (a closed, consistently wound surface: vertices compared by their exact
/// coordinates), and the enclosed signed volume is positive (counter-clockwise winding seen
/// from outside, so edge1 x edge2 points out). Else what is wrong, for the scene error.
pub fn check_closed_outward(triangles: &[[[f32; 3]; 3]]) -> Result<(), String> {
    let key = |p: [f32; 3]| p.map(|c| (c + 0.0).to_bits());
    let mut directed: HashMap<([u32; 3], [u32; 3]), u32> = HashMap::new();
    for t in triangles {
        for i in 0..3 {
            *directed
                .entry((key(t[i]), key(t[(i + 1) % 3])))
                .or_default() += 1;
        }
    }
    for (&(a, b), &count) in &directed {
        let back = directed.get(&(b, a)).copied().unwrap_or(0);
        let at = |k: [u32; 3]| k.map(f32::from_bits);
        if count != 1 || back != 1 {
            return Err(format!(
                "is not a closed, consistently wound surface: the edge {:?} -> {:?} is used {count} \
                 time(s) and its reverse {back} (a dielectric needs a closed mesh)",
                at(a),
                at(b)
            ));
        }
    }
    // The divergence theorem: the volume is the sum of the signed tetrahedra to the origin.
    let volume: f64 = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|p| p.map(f64::from));
            let cross = [
                b[1] * c[2] - b[2] * c[1],
                b[2] * c[0] - b[0] * c[2],
                b[0] * c[1] - b[1] * c[0],
            ];
            (a[0] * cross[0] + a[1] * cross[1] + a[2] * cross[2]) / 6.0
        })
        .sum();
    if !(volume > 0.0) {
        return Err(format!(
            "encloses a signed volume of {volume:e}: its triangles wind clockwise seen from \
             outside (normals inward); reverse their order"
        ));
    }
    Ok(())
}
