//! Fill and Balance of a would-be merge (§2.2).

/// Fill and Balance of a would-be parent of diameter `d` over children of diameters `dx`, `dy`.
///
/// Point-like children (diameter 0) get documented fallbacks: Fill = 1 when both children are
/// points, and Balance uses the smaller diameter floored at 1e-12 × the larger (so it is at
/// most 1e12) and is 1 when both are points.
#[inline]
pub(in crate::grouping) fn fill_balance(d: f64, dx: f64, dy: f64) -> (f64, f64) {
    let sum = dx + dy;
    let fill = if sum > 0.0 { d / sum } else { 1.0 };
    let (lo, hi) = if dx < dy { (dx, dy) } else { (dy, dx) };
    let balance = if hi > 0.0 {
        hi / lo.max(hi * 1e-12)
    } else {
        1.0
    };
    (fill, balance)
}
