//! Adaptive cubature over rectangles, for the tests' expected values of peaked integrands
//! (microfacet lobes far narrower than a histogram bin or an integration domain).

/// 3-point Gauss-Legendre nodes and weights on [-1, 1].
const GL: [(f64, f64); 3] = [
    (-0.774_596_669_241_483_4, 5.0 / 9.0),
    (0.0, 8.0 / 9.0),
    (0.774_596_669_241_483_4, 5.0 / 9.0),
];

/// The integral of `f(x, y)` over [x0, x1] x [y0, y1]: the product Gauss-Legendre rule on the
/// rectangle and on its four quarters; where they differ by more than `tol`, each quarter is
/// integrated the same way with half the tolerance, at most `depth` levels down.
pub fn integrate(
    f: &dyn Fn(f64, f64) -> f64,
    x: (f64, f64),
    y: (f64, f64),
    tol: f64,
    depth: u32,
) -> f64 {
    let rule = |x: (f64, f64), y: (f64, f64)| {
        let (hx, hy) = ((x.1 - x.0) / 2.0, (y.1 - y.0) / 2.0);
        let (mx, my) = ((x.1 + x.0) / 2.0, (y.1 + y.0) / 2.0);
        let mut s = 0.0;
        for (a, wa) in GL {
            for (b, wb) in GL {
                s += wa * wb * f(mx + hx * a, my + hy * b);
            }
        }
        s * hx * hy
    };
    let whole = rule(x, y);
    let (xm, ym) = ((x.0 + x.1) / 2.0, (y.0 + y.1) / 2.0);
    let quarters = [
        ((x.0, xm), (y.0, ym)),
        ((xm, x.1), (y.0, ym)),
        ((x.0, xm), (ym, y.1)),
        ((xm, x.1), (ym, y.1)),
    ];
    let parts: f64 = quarters.iter().map(|&(x, y)| rule(x, y)).sum();
    if depth == 0 || (parts - whole).abs() <= tol {
        return parts;
    }
    quarters
        .iter()
        .map(|&(x, y)| integrate(f, x, y, tol / 2.0, depth - 1))
        .sum()
}
