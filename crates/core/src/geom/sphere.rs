//! Spheres: the bounding sphere wrapper's shape, shared by the Wrapper Tree builders
//! (`wrap::sphere`) and the exact minimum enclosing sphere (`wrap::welzl`).

use super::P3;

/// A sphere; radius 0 is allowed (a point-like leaf).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre.
    pub center: P3,
    /// Radius (≥ 0).
    pub radius: f64,
}

impl Sphere {
    /// The smallest sphere holding both spheres.
    pub fn merge(&self, o: &Sphere) -> Sphere {
        let d = o.center - self.center;
        let dist = d.norm();
        if dist + o.radius <= self.radius {
            return *self;
        }
        if dist + self.radius <= o.radius {
            return *o;
        }
        let radius = (dist + self.radius + o.radius) / 2.0;
        let center = self.center + d * ((radius - self.radius) / dist);
        Sphere { center, radius }
    }

    /// Volume (0 for radius 0).
    pub fn volume(&self) -> f64 {
        4.0 / 3.0 * std::f64::consts::PI * self.radius.powi(3)
    }

    /// Whether `p` lies inside, with `tol` of slack.
    pub fn contains(&self, p: &P3, tol: f64) -> bool {
        (p - self.center).norm() <= self.radius + tol
    }
}
