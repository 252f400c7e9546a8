//! The sheen table of `kernel::bsdf::sheen` derived from its physical model: the source text of
//! `host/src/scene/sheen_ltc_table.rs` (written by the example `sheen_ltc_table`, compared with
//! the committed file at sampled nodes by `tests/sheen.rs`).
//!
//! The model (Zeltner, Burley and Chiang, "Practical Multiple-Scattering Sheen Using Linearly
//! Transformed Cosines", SIGGRAPH 2022 talk, the model Cycles' Principled sheen renders): a
//! layer of unit thickness and unit density of fibres standing along the normal, each a
//! specular microflake of the SGGX distribution (Heitz et al., "The SGGX Microflake
//! Distribution", 2015) with matrix S = diag(1, 1, s^2) in the normal's frame, s = alpha^2
//! (alpha the sheen roughness), white (albedo 1), nothing beneath it; light leaves it upward or
//! is lost below it, and a walk ends after [`MAX_BOUNCES`] scatterings. Its reflection is
//! tabulated per view cosine mu and roughness alpha as a linearly transformed cosine (Heitz et
//! al., "Real-Time Polygonal-Light Shading with Linearly Transformed Cosines", 2016): the
//! reflectance R (the probability that light arriving from the view's direction leaves
//! upward, [`volume_reflectance`], a random walk) and the matrix M^-1 = [[A, 0, B], [0, A, 0],
//! [0, 0, 1]] whose transformed cosine R D(M^-1 w / |M^-1 w|) A^2 / |M^-1 w|^3 is closest (L3,
//! as the talk's fit) to the layer's f cos over a 32 x 32 grid of directions ([`fit`]): the
//! single scattering in closed form ([`single_scattering`]) plus the rest by next-event
//! estimation along random walks ([`multiple_scattering`]).
//!
//! The SGGX fibre: the microflake is the ellipsoid with semi-axes (s, s, 1) (its normals have
//! density D(m) = 1 / (pi s (m_x^2 + m_y^2 + m_z^2 / s^2)^2), its projected area along w is
//! pi x sigma(w), sigma(w) = sqrt(w_x^2 + w_y^2 + s^2 w_z^2) = sqrt(w^T S w)); light travelling
//! along d meets flakes at the rate sigma(d) per unit length and is mirrored by a flake normal
//! drawn from the normals visible from -d ([`sample_visible_normal`]). The layer's single
//! scattering from wi (light arriving, mu_i) toward wo (mu_o), with lambda = sigma / mu:
//!
//! ```text
//! f cos_o = D(h) (1 - exp(-(lambda_i + lambda_o))) / (4 mu_i (lambda_i + lambda_o))
//! ```
//!
//! (the scattering rate sigma(wi) times the specular phase function D(h) / (4 sigma(wi)),
//! integrated over the depth z in [0, 1] with the attenuation exp(-z (lambda_i + lambda_o))).

use crate::SplitMix;
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::PI;
use twinpath::scene::sheen_ltc::{cosine_of, roughness_of, COSINES, ROUGHNESSES};

/// Scatterings after which a walk ends (the talk's layer: 16); it counts as reflected if the
/// last direction points up.
pub const MAX_BOUNCES: u32 = 16;
/// Random walks per node for the reflectance R.
pub const REFLECTANCE_WALKS: u32 = 200_000;
/// Random walks per node for the multiple scattering of the fitted shape.
pub const SHAPE_WALKS: u32 = 2_000;
/// Directions of the fit: a grid of this many polar by this many azimuth angles (cell
/// centres; the azimuth over [0, pi), the lobe being symmetric about the view's plane).
pub const FIT_GRID: usize = 32;
/// Below this reflectance a node keeps the neighbouring (rougher) node's matrix: its lobe
/// carries no light worth a shape.
pub const NEGLIGIBLE_REFLECTANCE: f64 = 3e-6;

/// The fibre's cross-section parameter s of roughness `alpha` (s = alpha^2).
fn cross_section(alpha: f64) -> f64 {
    alpha * alpha
}

/// sigma(w) = sqrt(w^T S w): the flakes' projected area along `w` over pi.
pub fn projected_area(w: DVec3, s: f64) -> f64 {
    (w.x * w.x + w.y * w.y + s * s * w.z * w.z).max(0.0).sqrt()
}

/// The SGGX density of flake normals `m` (unit).
pub fn normal_density(m: DVec3, s: f64) -> f64 {
    let q = m.x * m.x + m.y * m.y + m.z * m.z / (s * s);
    1.0 / (PI * s * q * q)
}

/// A flake normal seen from `w` (unit), drawn with density max(0, w . m) D(m) / sigma(w) from
/// (u1, u2): the ellipsoid x = A u, A = diag(s, s, 1), is the unit sphere stretched, lines
/// along w become lines along A^-1 w, and a projected area is scaled by a constant; so a point
/// uniform in projected area on the sphere's half seen from A^-1 w (a uniform disk point
/// lifted onto it) maps to one uniform in projected area on the ellipsoid, whose normal there is
/// A^-T u.
pub fn sample_visible_normal(w: DVec3, s: f64, u1: f64, u2: f64) -> DVec3 {
    let ws = DVec3::new(w.x / s, w.y / s, w.z).normalize();
    let (e1, e2) = ws.any_orthonormal_pair();
    let (r, phi) = (u1.sqrt(), 2.0 * PI * u2);
    let (t1, t2) = (r * phi.cos(), r * phi.sin());
    let u = t1 * e1 + t2 * e2 + (1.0 - t1 * t1 - t2 * t2).max(0.0).sqrt() * ws;
    DVec3::new(u.x / s, u.y / s, u.z).normalize()
}

/// The specular microflake phase function from `wi` (the direction light came from, unit)
/// to `wo`: D(h) / (4 sigma(wi)), h the half vector.
pub fn phase(wi: DVec3, wo: DVec3, s: f64) -> f64 {
    let h = (wi + wo).normalize();
    normal_density(h, s) / (4.0 * projected_area(wi, s))
}

/// The layer's single scattering f cos_o from `wi` to `wo` (module doc), zero below.
pub fn single_scattering(wi: DVec3, wo: DVec3, s: f64) -> f64 {
    if !(wi.z > 0.0 && wo.z > 0.0) {
        return 0.0;
    }
    let li = projected_area(wi, s) / wi.z;
    let lo = projected_area(wo, s) / wo.z;
    let t = li + lo;
    normal_density((wi + wo).normalize(), s) * (-(-t).exp_m1()) / (4.0 * wi.z * t)
}

/// One random walk into the layer from the view direction at cosine `mu` (light arriving from
/// wi = (sqrt(1 - mu^2), 0, mu)); `visit` sees each scattering event's depth, the direction
/// the light travelled and its order (1, 2, ...). Returns whether the light left upward.
fn walk(mu: f64, s: f64, numbers: &mut SplitMix, mut visit: impl FnMut(f64, DVec3, u32)) -> bool {
    let mut dir = -DVec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let mut depth = 0.0;
    for order in 1..=MAX_BOUNCES {
        let rate = projected_area(dir, s);
        let distance = -(1.0 - numbers.unit_f64()).ln() / rate;
        depth += distance * -dir.z;
        if depth < 0.0 {
            return true;
        }
        if depth > 1.0 {
            return false;
        }
        visit(depth, dir, order);
        let m = sample_visible_normal(-dir, s, numbers.unit_f64(), numbers.unit_f64());
        dir = 2.0 * m.dot(-dir) * m + dir;
    }
    dir.z > 0.0
}

/// The layer's reflectance R from the view at cosine `mu` (the fraction of [`walk`]s that
/// leave upward; `seed` selects the stream of numbers, one per node, so that the table does not
/// depend on how rayon schedules the nodes).
pub fn volume_reflectance(mu: f64, alpha: f64, walks: u32, seed: u64) -> f64 {
    let s = cross_section(alpha);
    let mut numbers = SplitMix(seed);
    let up = (0..walks)
        .filter(|_| walk(mu, s, &mut numbers, |_, _, _| {}))
        .count();
    up as f64 / walks as f64
}

/// The fit's directions (row-major: polar angle, then azimuth), cell centres.
pub fn fit_directions() -> Vec<DVec3> {
    let n = FIT_GRID;
    (0..n * n)
        .map(|k| {
            let theta = ((k / n) as f64 + 0.5) / n as f64 * 0.5 * PI;
            let phi = ((k % n) as f64 + 0.5) / n as f64 * PI;
            DVec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            )
        })
        .collect()
}

/// The layer's scattering of order two and more, f cos_o toward each of `directions`, by
/// next-event estimation at each such event of `walks` walks: the phase function toward wo
/// times the attenuation exp(-z sigma(wo) / mu_o) on the way up.
pub fn multiple_scattering(
    mu: f64,
    alpha: f64,
    directions: &[DVec3],
    walks: u32,
    seed: u64,
) -> Vec<f64> {
    let s = cross_section(alpha);
    let rates: Vec<f64> = directions
        .iter()
        .map(|&w| projected_area(w, s) / w.z)
        .collect();
    let mut sum = vec![0.0; directions.len()];
    let mut numbers = SplitMix(seed);
    for _ in 0..walks {
        walk(mu, s, &mut numbers, |depth, dir, order| {
            if order < 2 {
                return;
            }
            for (k, &wo) in directions.iter().enumerate() {
                sum[k] += phase(-dir, wo, s) * (-depth * rates[k]).exp();
            }
        });
    }
    sum.iter().map(|v| v / walks as f64).collect()
}

/// The linearly transformed cosine of `a`, `b` (M^-1 = [[a, 0, b], [0, a, 0], [0, 0, 1]]) at
/// `w`, normalised (it integrates to 1 over the sphere): D(w') |det M^-1| / |M^-1 w|^3 with
/// w' = M^-1 w / |M^-1 w| and D the clamped cosine over pi.
pub fn ltc(a: f64, b: f64, w: DVec3) -> f64 {
    let v = DVec3::new(a * w.x + b * w.z, a * w.y, w.z);
    let l = v.length();
    (v.z / l).max(0.0) / PI * a * a / (l * l * l)
}

/// Nelder and Mead's downhill simplex in two dimensions (reflection 1, expansion 2,
/// contraction 1/2, shrink 1/2; the first simplex x0 and x0 with each coordinate scaled by
/// 1.05, or 0.00025 where it is 0), stopped when the vertices lie within `tolerance` of the
/// best in both position and value, or after `iterations`.
pub fn downhill_simplex(
    f: impl Fn([f64; 2]) -> f64,
    x0: [f64; 2],
    tolerance: f64,
    iterations: usize,
) -> [f64; 2] {
    let mut simplex = vec![x0; 3];
    for (i, vertex) in simplex.iter_mut().skip(1).enumerate() {
        vertex[i] = if x0[i] != 0.0 { x0[i] * 1.05 } else { 0.00025 };
    }
    let mut values: Vec<f64> = simplex.iter().map(|&x| f(x)).collect();
    let along = |from: [f64; 2], to: [f64; 2], t: f64| {
        [
            from[0] + t * (to[0] - from[0]),
            from[1] + t * (to[1] - from[1]),
        ]
    };
    for _ in 0..iterations {
        let mut order = [0, 1, 2];
        order.sort_by(|&i, &j| values[i].total_cmp(&values[j]));
        simplex = order.iter().map(|&i| simplex[i]).collect();
        values = order.iter().map(|&i| values[i]).collect();
        let spread = (1..3)
            .map(|i| {
                (simplex[i][0] - simplex[0][0])
                    .abs()
                    .max((simplex[i][1] - simplex[0][1]).abs())
            })
            .fold(0.0, f64::max);
        let rise = (1..3)
            .map(|i| (values[i] - values[0]).abs())
            .fold(0.0, f64::max);
        if spread <= tolerance && rise <= tolerance {
            break;
        }
        let centre = along(simplex[0], simplex[1], 0.5);
        let reflected = along(simplex[2], centre, 2.0);
        let fr = f(reflected);
        if fr < values[0] {
            let expanded = along(simplex[2], centre, 3.0);
            let fe = f(expanded);
            (simplex[2], values[2]) = if fe < fr {
                (expanded, fe)
            } else {
                (reflected, fr)
            };
        } else if fr < values[1] {
            (simplex[2], values[2]) = (reflected, fr);
        } else {
            let contracted = if fr < values[2] {
                along(centre, reflected, 0.5)
            } else {
                along(centre, simplex[2], 0.5)
            };
            let fc = f(contracted);
            if fc < fr.min(values[2]) {
                (simplex[2], values[2]) = (contracted, fc);
            } else {
                for i in 1..3 {
                    simplex[i] = along(simplex[0], simplex[i], 0.5);
                    values[i] = f(simplex[i]);
                }
            }
        }
    }
    let best = (0..3)
        .min_by(|&i, &j| values[i].total_cmp(&values[j]))
        .expect("three vertices");
    simplex[best]
}

/// The layer's f cos toward each fit direction from the view at cosine `mu`: the closed-form
/// single scattering plus the walks' multiple scattering.
pub fn layer_values(mu: f64, alpha: f64, directions: &[DVec3], seed: u64) -> Vec<f64> {
    let wi = DVec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let s = cross_section(alpha);
    let multiple = multiple_scattering(mu, alpha, directions, SHAPE_WALKS, seed);
    directions
        .iter()
        .zip(multiple)
        .map(|(&wo, ms)| single_scattering(wi, wo, s) + ms)
        .collect()
}

/// (A, B) minimising the L3 distance between R x [`ltc`] and `values` over `directions`,
/// from `start`.
pub fn fit(values: &[f64], reflectance: f64, directions: &[DVec3], start: [f64; 2]) -> [f64; 2] {
    let distance = |x: [f64; 2]| -> f64 {
        directions
            .iter()
            .zip(values)
            .map(|(&w, &v)| (reflectance * ltc(x[0], x[1], w) - v).abs().powi(3))
            .sum()
    };
    downhill_simplex(distance, start, 1e-6, 10_000)
}

/// The stream of node (j, i)'s reflectance walks; its shape walks use the next one.
pub fn node_seed(j: usize, i: usize) -> u64 {
    2 * (j * ROUGHNESSES + i) as u64 + 1
}

/// The reflectance R at every node (rows: cosines, columns: roughnesses).
pub fn reflectances() -> Vec<Vec<f64>> {
    (0..COSINES)
        .into_par_iter()
        .map(|j| {
            (0..ROUGHNESSES)
                .map(|i| {
                    volume_reflectance(
                        cosine_of(j),
                        roughness_of(i),
                        REFLECTANCE_WALKS,
                        node_seed(j, i),
                    )
                })
                .collect()
        })
        .collect()
}

/// The table: (A, B, R) at every node, each row (cosine) fitted from the roughest node down,
/// each node starting from the rougher neighbour's (A, B) ((1, 0) at roughness 1), as the talk
/// fits (a smooth table); a node of negligible reflectance keeps its neighbour's.
pub fn table() -> Vec<Vec<[f64; 3]>> {
    let r = reflectances();
    let directions = fit_directions();
    (0..COSINES)
        .into_par_iter()
        .map(|j| {
            let mut row = vec![[0.0; 3]; ROUGHNESSES];
            let mut start = [1.0, 0.0];
            for i in (0..ROUGHNESSES).rev() {
                let reflectance = r[j][i];
                if reflectance >= NEGLIGIBLE_REFLECTANCE {
                    let (mu, alpha) = (cosine_of(j), roughness_of(i));
                    let values = layer_values(mu, alpha, &directions, node_seed(j, i) + 1);
                    start = fit(&values, reflectance, &directions, start);
                }
                row[i] = [start[0], start[1], reflectance];
            }
            row
        })
        .collect()
}

/// The file's text.
pub fn source() -> String {
    let t = table();
    let mut s = String::new();
    s += "//! Generated by `cargo run --release -p twinpath-tests --example sheen_ltc_table`: do not edit.\n";
    s += "//! The sheen table of `super::sheen_ltc` (`twinpath_tests::sheen_fit`, f64, rounded to f32).\n\n";
    s += "/// (A, B, R) at cosine mu = j / 31 (row j) and roughness alpha = i / 31 (column i).\n";
    s += "#[rustfmt::skip]\n";
    s += &format!("pub const LTC: [[[f32; 3]; {ROUGHNESSES}]; {COSINES}] = [\n");
    for row in &t {
        let cells: Vec<String> = row
            .iter()
            .map(|c| format!("[{:?}, {:?}, {:?}]", c[0] as f32, c[1] as f32, c[2] as f32))
            .collect();
        s += &format!("    [{}],\n", cells.join(", "));
    }
    s += "];\n";
    s
}
