//! Principal axes of a point set (nalgebra `SymmetricEigen`, `f64`), shared by the flat-hull
//! fallback and the oriented boxes.

use crate::geom::{P3, V3};
use nalgebra::Matrix3;

/// A right-handed orthonormal frame: the principal axes by decreasing variance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// Centroid of the points.
    pub origin: P3,
    /// Unit axes as columns (determinant +1).
    pub axes: Matrix3<f64>,
}

impl Frame {
    /// The principal frame of `points`. Degenerate covariances (fewer than two distinct points,
    /// non-finite values) give the world axes; repeated eigenvalues give some orthonormal frame
    /// of the eigenspace. Offsets are taken from the first point, so the axes of a small set
    /// far from the origin are as accurate as near it.
    pub fn principal(points: &[P3]) -> Frame {
        let n = points.len().max(1) as f64;
        // Shifted data: offsets from the first point keep a tiny set far from the world origin
        // (a 1e-6 triangle at 1e6) from being tilted by the rounding of a large mean.
        let base = points.first().copied().unwrap_or_else(P3::origin);
        let mean = points.iter().map(|p| p - base).sum::<V3>() / n;
        let origin = base + mean;
        let cov = points
            .iter()
            .map(|p| {
                let d = (p - base) - mean;
                d * d.transpose()
            })
            .sum::<Matrix3<f64>>()
            / n;
        let world = Frame {
            origin,
            axes: Matrix3::identity(),
        };
        if !cov.iter().all(|x| x.is_finite()) || cov.norm() == 0.0 {
            return world;
        }
        let eig = cov.symmetric_eigen();
        let mut order = [0usize, 1, 2];
        order.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
        let e0: V3 = eig.eigenvectors.column(order[0]).into();
        let e1: V3 = eig.eigenvectors.column(order[1]).into();
        let Some(a0) = e0.try_normalize(1e-12) else {
            return world;
        };
        let Some(a1) = (e1 - a0 * a0.dot(&e1)).try_normalize(1e-12) else {
            return world;
        };
        let a2 = a0.cross(&a1);
        Frame {
            origin,
            axes: Matrix3::from_columns(&[a0, a1, a2]),
        }
    }

    /// Coordinates of `p` along the axes.
    pub fn local(&self, p: &P3) -> V3 {
        self.axes.transpose() * (p - self.origin)
    }

    /// Scene point of local coordinates `l`.
    pub fn world(&self, l: &V3) -> P3 {
        self.origin + self.axes * l
    }

    /// Smallest and largest local coordinates of `points` along each axis.
    pub fn bounds(&self, points: &[P3]) -> (V3, V3) {
        let mut lo = V3::repeat(f64::INFINITY);
        let mut hi = V3::repeat(f64::NEG_INFINITY);
        for p in points {
            let l = self.local(p);
            lo = lo.inf(&l);
            hi = hi.sup(&l);
        }
        (lo, hi)
    }
}
