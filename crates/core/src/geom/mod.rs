//! Small f64 geometry used by every stage: axis-aligned boxes, their diameter and L∞ gap.
//!
//! Everything that decides the tree is computed in `f64` so that scenes offset by 1e7 keep
//! millimetre detail; parry (which is `f32`) is only handed coordinates relative to a local
//! origin (see [`to_glam_local`]).

pub mod distance;
pub mod hull;
pub mod morton;
pub mod pca;
pub mod sphere;

pub use sphere::Sphere;

use nalgebra::{Point3, Vector3};

/// A point in scene coordinates.
pub type P3 = Point3<f64>;
/// A vector in scene coordinates.
pub type V3 = Vector3<f64>;

/// An axis-aligned bounding box: the AABB p-set wrapper of a body (§2.2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Lower corner.
    pub min: P3,
    /// Upper corner.
    pub max: P3,
}

impl Aabb {
    /// The empty box: `merge` with it is the identity.
    pub const EMPTY: Aabb = Aabb {
        min: Point3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY),
        max: Point3::new(f64::NEG_INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY),
    };

    /// The smallest box holding `points` (`EMPTY` when there are none).
    pub fn from_points<'a>(points: impl IntoIterator<Item = &'a P3>) -> Aabb {
        points.into_iter().fold(Aabb::EMPTY, |b, p| b.grow(p))
    }

    /// This box grown to hold `p`.
    #[inline]
    pub fn grow(&self, p: &P3) -> Aabb {
        Aabb {
            min: self.min.inf(p),
            max: self.max.sup(p),
        }
    }

    /// The smallest box holding both boxes.
    #[inline]
    pub fn merge(&self, o: &Aabb) -> Aabb {
        Aabb {
            min: self.min.inf(&o.min),
            max: self.max.sup(&o.max),
        }
    }

    /// Centre of the box.
    #[inline]
    pub fn center(&self) -> P3 {
        nalgebra::center(&self.min, &self.max)
    }

    /// Edge lengths.
    #[inline]
    pub fn extents(&self) -> V3 {
        self.max - self.min
    }

    /// The body diameter used by the AABB p-set: the length of the box diagonal.
    ///
    /// The diagonal is the diameter of the box itself (its two farthest points), so it bounds
    /// the diameter of the set inside and is what the paper's Fill and Balance ratios compare.
    #[inline]
    pub fn diameter(&self) -> f64 {
        self.extents().norm()
    }

    /// L∞ gap between two boxes: the largest per-axis separation, 0 when they touch or overlap.
    #[inline]
    pub fn gap_linf(&self, o: &Aabb) -> f64 {
        let mut g: f64 = 0.0;
        for k in 0..3 {
            g = g.max(o.min[k] - self.max[k]).max(self.min[k] - o.max[k]);
        }
        g
    }

    /// Whether `o` lies inside this box, allowing `tol` of slack on every side.
    pub fn contains_aabb(&self, o: &Aabb, tol: f64) -> bool {
        (0..3).all(|k| o.min[k] >= self.min[k] - tol && o.max[k] <= self.max[k] + tol)
    }

    /// Whether `p` lies inside this box, allowing `tol` of slack.
    pub fn contains_point(&self, p: &P3, tol: f64) -> bool {
        (0..3).all(|k| p[k] >= self.min[k] - tol && p[k] <= self.max[k] + tol)
    }

    /// Volume (0 for flat or empty boxes).
    pub fn volume(&self) -> f64 {
        let e = self.extents();
        if e.iter().any(|x| *x <= 0.0) {
            0.0
        } else {
            e.x * e.y * e.z
        }
    }
}

/// Surface area of a box with extents `e`: the one area formula of the crate (SAH, the
/// Cost's `--cost area`, the split's SAH cuts, the peers).
#[inline(always)]
pub fn surface_area(e: &V3) -> f64 {
    2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
}

/// Surface area of `b` (0 for an empty box).
pub fn area(b: &Aabb) -> f64 {
    let e = b.extents();
    if e.iter().any(|x| x.is_nan() || *x < 0.0) {
        return 0.0;
    }
    surface_area(&e)
}

/// Converts a scene point to parry's `f32` glam vector relative to `origin`.
///
/// parry3d ≥ 0.26 speaks glam; subtracting a local origin first keeps `f32` precise for
/// scenes far from the world origin.
#[inline]
pub fn to_glam_local(p: &P3, origin: &P3) -> parry3d::math::Vector {
    let d = p - origin;
    parry3d::math::Vector::new(d.x as f32, d.y as f32, d.z as f32)
}

/// Converts a parry `f32` glam vector given relative to `origin` back to a scene point.
#[inline]
pub fn from_glam_local(v: parry3d::math::Vector, origin: &P3) -> P3 {
    origin + V3::new(v.x as f64, v.y as f64, v.z as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gap_and_diameter() {
        let a = Aabb::from_points(&[P3::new(0.0, 0.0, 0.0), P3::new(1.0, 1.0, 1.0)]);
        let b = Aabb::from_points(&[P3::new(3.0, 0.5, 0.0), P3::new(4.0, 2.0, 1.0)]);
        assert_eq!(a.gap_linf(&b), 2.0);
        assert_eq!(b.gap_linf(&a), 2.0);
        assert_eq!(a.gap_linf(&a), 0.0);
        assert!((a.diameter() - 3f64.sqrt()).abs() < 1e-15);
        let m = a.merge(&b);
        assert!(m.contains_aabb(&a, 0.0) && m.contains_aabb(&b, 0.0));
    }
}
