//! An orthographic camera for Z-up scenes, and the named views.

use crate::geom::{P3, V3};

/// A named view direction (the eye's azimuth around +Z from −Y, and elevation above the XY plane).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    /// Azimuth 45°, elevation 35.26° (an isometric view from +X −Y +Z).
    Iso,
    /// From −Y, horizontal: +X right, +Z up.
    Front,
    /// From +X, horizontal: +Y right, +Z up.
    Side,
    /// From +Z, straight down: +X right, +Y up.
    Top,
}

impl View {
    /// Every view with its command-line name.
    pub const ALL: [(&'static str, View); 4] = [
        ("iso", View::Iso),
        ("front", View::Front),
        ("side", View::Side),
        ("top", View::Top),
    ];

    /// Parses a view name; the error lists the valid names.
    pub fn parse(s: &str) -> Result<View, String> {
        View::ALL
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(s))
            .map(|&(_, v)| v)
            .ok_or_else(|| format!("unknown view '{s}' (valid: iso, front, side, top)"))
    }

    /// (azimuth, elevation) in degrees.
    pub fn angles(self) -> (f64, f64) {
        match self {
            View::Iso => (45.0, 35.264_389_682_754_654),
            View::Front => (0.0, 0.0),
            View::Side => (90.0, 0.0),
            View::Top => (0.0, 90.0),
        }
    }
}

/// An orthographic camera: world → image pixels (y down) plus a view depth (larger = farther).
///
/// Orthographic, not perspective, so sizes at different depths compare directly, as in the
/// paper's figures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    right: V3,
    up: V3,
    /// Unit vector from the eye into the scene.
    forward: V3,
    scale: f64,
    offset: (f64, f64),
    /// Image width and height in pixels.
    pub size: (u32, u32),
}

impl Camera {
    /// A camera looking from `azimuth`/`elevation` (degrees; elevation clamped to ±90) that maps
    /// the view-plane rectangle holding `points` (plus `radius` around each) into a `size` image
    /// with a `margin` fraction left free on each side. Degenerate extents (nothing, a point)
    /// fall back to a unit square around the points' centre.
    pub fn fit(
        azimuth: f64,
        elevation: f64,
        size: (u32, u32),
        margin: f64,
        points: impl IntoIterator<Item = (P3, f64)>,
    ) -> Camera {
        let (az, el) = (
            azimuth.to_radians(),
            elevation.clamp(-90.0, 90.0).to_radians(),
        );
        let eye = V3::new(el.cos() * az.sin(), -el.cos() * az.cos(), el.sin());
        let right = V3::new(az.cos(), az.sin(), 0.0);
        let up = eye.cross(&right).normalize();
        let mut cam = Camera {
            right,
            up,
            forward: -eye,
            scale: 1.0,
            offset: (0.0, 0.0),
            size,
        };
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for (p, r) in points {
            let (x, y) = (p.coords.dot(&cam.right), p.coords.dot(&cam.up));
            if !(x.is_finite() && y.is_finite() && r.is_finite()) {
                continue;
            }
            lo = [lo[0].min(x - r), lo[1].min(y - r)];
            hi = [hi[0].max(x + r), hi[1].max(y + r)];
        }
        if lo[0] > hi[0] {
            (lo, hi) = ([-0.5; 2], [0.5; 2]);
        }
        let (w, h) = ((hi[0] - lo[0]).max(1e-12), (hi[1] - lo[1]).max(1e-12));
        let (iw, ih) = (size.0.max(1) as f64, size.1.max(1) as f64);
        let free = (1.0 - 2.0 * margin).clamp(0.05, 1.0);
        cam.scale = (iw * free / w).min(ih * free / h);
        let (cx, cy) = ((lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0);
        cam.offset = (iw / 2.0 - cx * cam.scale, ih / 2.0 + cy * cam.scale);
        cam
    }

    /// Image position (x right, y down, pixels) and view depth of `p`.
    pub fn project(&self, p: &P3) -> (f64, f64, f64) {
        let v = p.coords;
        (
            self.offset.0 + v.dot(&self.right) * self.scale,
            self.offset.1 - v.dot(&self.up) * self.scale,
            v.dot(&self.forward),
        )
    }

    /// Pixels per world unit.
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// Unit vector from the eye into the scene.
    pub fn forward(&self) -> V3 {
        self.forward
    }

    /// The light direction used for shading: from over the viewer's upper left shoulder.
    pub fn light(&self) -> V3 {
        (-self.forward * 1.0 + self.up * 0.6 - self.right * 0.4).normalize()
    }
}
