//! The parameters of a grouping run: the Cost [`Weights`] of eq. (2), the initial DLimit and
//! GLimit (resolved from the scene by [`Params::resolve`]), the p-set wrapper and the [`Mode`]
//! (schedule, pre-grouping, size measure).

use crate::geom::Aabb;
use crate::grouping::partitioned::Chunking;
use crate::scene::Scene;
use rayon::prelude::*;

/// The p-set wrapper bodies carry while grouping.
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum PSet {
    /// Axis-aligned boxes, diagonal as diameter, L∞ gaps (the paper's fast variant).
    #[default]
    Aabb,
    /// Convex hulls (parry), largest vertex distance as diameter, L2 gaps (GJK).
    Hull,
}

/// The Cost weights of eq. (2).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Weights {
    /// Exponent A on the diameter.
    pub a: f64,
    /// Weight B on Fill.
    pub b: f64,
    /// Weight C on Balance.
    pub c: f64,
}

impl Weights {
    /// Cost = diameter^A × (B·Fill + C·Balance). When B = C = 0 the bracket would vanish for
    /// every pair; it is then taken as 1, so the cost is diameter^A.
    #[inline]
    pub fn cost(&self, diameter: f64, fill: f64, balance: f64) -> f64 {
        self.cost_scaled(self.scale(diameter), fill, balance)
    }

    /// The form of diameter^A: the one place that tells A = 1, A = 0 and any other A apart.
    #[inline(always)]
    pub fn exponent(&self) -> Exponent {
        if self.a == 1.0 {
            Exponent::One
        } else if self.a == 0.0 {
            Exponent::Zero
        } else {
            Exponent::Other
        }
    }

    /// diameter^A, without `powf` for A = 1 and A = 0.
    #[inline(always)]
    pub fn scale(&self, diameter: f64) -> f64 {
        match self.exponent() {
            Exponent::One => diameter,
            Exponent::Zero => 1.0,
            Exponent::Other => diameter.powf(self.a),
        }
    }

    /// Checks that A, B and C are finite and ≥ 0; the error names the weight (`a`, `b`, `c`).
    pub fn check(&self) -> Result<(), String> {
        for (name, v) in [("a", self.a), ("b", self.b), ("c", self.c)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("{name} must be a finite number ≥ 0, got {v}"));
            }
        }
        Ok(())
    }

    /// The cost given `scale` = diameter^A already computed.
    #[inline(always)]
    pub fn cost_scaled(&self, scale: f64, fill: f64, balance: f64) -> f64 {
        if self.b == 0.0 && self.c == 0.0 {
            scale
        } else {
            scale * (self.b * fill + self.c * balance)
        }
    }
}

/// The form of the Cost's factor diameter^A ([`Weights::exponent`]), chosen once per run: the
/// grouping's scans are compiled for each ([`Exponent::code`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Exponent {
    /// A = 1: the diameter itself.
    One,
    /// A = 0: every pair's factor is 1.
    Zero,
    /// Any other A: `powf`.
    Other,
}

impl Exponent {
    /// The form as the const parameter of the specialised scans: 1, 0, or 2 for any other A.
    pub const fn code(self) -> u8 {
        match self {
            Exponent::One => 1,
            Exponent::Zero => 0,
            Exponent::Other => 2,
        }
    }
}

/// How the grouping phase is scheduled over the scene: the schedule carries its chunking.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Schedule {
    /// The literal §2.2 run over all bodies at once (the default; what users debug step by step).
    #[default]
    Exact,
    /// The same grouping step run inside the chunks of a top-down Morton split, bottom-up
    /// (approximate agglomerative clustering), in parallel, split as the [`Chunking`] says.
    Partitioned(Chunking),
}

impl Schedule {
    /// The partitioned schedule with its default chunking ([`Chunking::DEFAULT`]).
    pub const PARTITIONED: Schedule = Schedule::Partitioned(Chunking::DEFAULT);

    /// The fast path's schedule (`--fast`): the partitioned one with [`Chunking::FAST`].
    pub const FAST: Schedule = Schedule::Partitioned(Chunking::FAST);

    /// The schedule's name, as `--schedule` and recordings' metadata spell it.
    pub fn name(&self) -> &'static str {
        match self {
            Schedule::Exact => "exact",
            Schedule::Partitioned(_) => "partitioned",
        }
    }

    /// The chunking of a partitioned schedule.
    pub fn chunking(&self) -> Option<&Chunking> {
        match self {
            Schedule::Exact => None,
            Schedule::Partitioned(c) => Some(c),
        }
    }

    /// Whether this is the partitioned schedule.
    pub fn is_partitioned(&self) -> bool {
        matches!(self, Schedule::Partitioned(_))
    }
}

/// Which components are grouped on their own before the top level (the paper's §1.3 speed-up).
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum Pregroup {
    /// No pre-grouping: the literal §2.2 run.
    #[default]
    None,
    /// The file's own `o`/`g` objects are the components.
    Objects,
    /// Primitives joined by shared (welded) vertices are the components.
    Connected,
}

/// The size measure in the Cost: the paper's diameter, or a surface-area alternative.
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum CostMeasure {
    /// Cost = diameter^A × (B·Fill + C·Balance), eq. (2) of the paper.
    #[default]
    Diameter,
    /// The surface area of the merged box in place of the diameter (Walter et al. 2008).
    Area,
}

/// How a grouping run is organised beyond its Cost weights and limits. The default is the
/// literal §2.2 run; every other setting is recorded in recordings' metadata so that
/// `replay --verify` re-runs the same mode.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct Mode {
    /// Exact or partitioned schedule (with its chunking).
    pub schedule: Schedule,
    /// Components grouped first, if any.
    pub pregroup: Pregroup,
    /// Whether rigid copies of a component reuse its Subset Tree shape.
    pub instancing: bool,
    /// The size measure in the Cost.
    pub cost: CostMeasure,
}

impl Mode {
    /// Checks that the settings fit together with the p-set `pset`: instancing needs
    /// pre-grouping (copies are found among components), pre-grouping needs the AABB p-set,
    /// and a partitioned schedule's chunking is valid ([`Chunking::check`]). The errors name
    /// the CLI flags.
    pub fn check(&self, pset: PSet) -> Result<(), String> {
        if self.instancing && self.pregroup == Pregroup::None {
            return Err(
                "--instancing needs --pregroup objects or --pregroup connected (copies are \
                 found among components)"
                    .to_string(),
            );
        }
        if self.pregroup != Pregroup::None && pset != PSet::Aabb {
            return Err("--pregroup needs --pset aabb (parts are grouped as boxes)".to_string());
        }
        match &self.schedule {
            Schedule::Partitioned(c) => c.check(),
            Schedule::Exact => Ok(()),
        }
    }
}

/// User-facing parameters; `None` limits are derived from the scene by [`Params::resolve`].
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Params {
    /// Cost weights.
    pub weights: Weights,
    /// Initial DLimit (default: median primitive diameter).
    pub dlimit: Option<f64>,
    /// Initial GLimit (default: DLimit / 4).
    pub glimit: Option<f64>,
    /// P-set wrapper kind.
    pub pset: PSet,
    /// Seed for randomised tie-breaking (`None`: ties break by id).
    pub seed: Option<u64>,
    /// Schedule, pre-grouping, instancing and Cost measure.
    #[serde(default)]
    pub mode: Mode,
}

impl Default for Params {
    /// A = 1, B = 1, C = 0: cost = diameter × Fill. The calibration runs found Balance (C > 0)
    /// worsened SAH on every scene and could produce degenerate trees with small GLimit.
    fn default() -> Self {
        Params {
            weights: Weights {
                a: 1.0,
                b: 1.0,
                c: 0.0,
            },
            dlimit: None,
            glimit: None,
            pset: PSet::Aabb,
            seed: None,
            mode: Mode::default(),
        }
    }
}

/// Parameters with every limit fixed, as recorded in recordings' metadata.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ResolvedParams {
    /// Cost weights.
    pub weights: Weights,
    /// DLimit of the first round.
    pub dlimit0: f64,
    /// GLimit of the first round.
    pub glimit0: f64,
    /// P-set wrapper kind.
    pub pset: PSet,
    /// Seed for randomised ties, if any.
    pub seed: Option<u64>,
    /// Schedule, pre-grouping, instancing and Cost measure.
    #[serde(default)]
    pub mode: Mode,
}

impl ResolvedParams {
    /// Checks what the round loop relies on: valid weights and finite, positive initial limits
    /// (with GLimit0 = 0 a scene of several components would never finish). Parameters from
    /// [`Params::resolve`] always pass; ones read from a file may not.
    pub fn check(&self) -> Result<(), String> {
        self.weights.check()?;
        self.mode.check(self.pset)?;
        for (name, v) in [("dlimit0", self.dlimit0), ("glimit0", self.glimit0)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("{name} must be a finite number > 0, got {v}"));
            }
        }
        Ok(())
    }
}

impl Params {
    /// Checks values as a user gives them: valid weights, a given DLimit and GLimit finite and
    /// positive, and a mode the p-set supports. The error names the command-line flag (`--a`,
    /// `--dlimit`, …).
    pub fn check(&self) -> Result<(), String> {
        self.weights.check().map_err(|e| format!("--{e}"))?;
        for (name, v) in [("--dlimit", self.dlimit), ("--glimit", self.glimit)] {
            if let Some(v) = v
                && !(v.is_finite() && v > 0.0)
            {
                return Err(format!("{name} must be a finite number > 0, got {v}"));
            }
        }
        self.mode.check(self.pset)
    }

    /// Fixes the initial limits: DLimit0 = the median primitive diameter (AABB diagonal) and
    /// GLimit0 = DLimit0 / 4. When that median is 0 (point-like primitives) DLimit0 falls back
    /// to 1e-6 × the scene diagonal, and to 1 for a scene that is a single point. A given
    /// DLimit ≤ 0 (or not finite) becomes 1; a given GLimit ≤ 0 becomes 1e-9 × DLimit0, since
    /// the paper's GLimit must be positive for scenes of several connected components. The
    /// partitioned schedule's δ of 0 becomes the one for the scene's size ([`Chunking::for_size`]).
    pub fn resolve(&self, scene: &Scene) -> ResolvedParams {
        self.resolve_with(
            scene.len(),
            || {
                (0..scene.len())
                    .map(|i| scene.prim_aabb(i).diameter())
                    .collect()
            },
            || scene.aabb().diameter(),
        )
    }

    /// [`Params::resolve`] for the primitives' boxes `boxes` (those of [`Scene::prim_aabb`] give
    /// the same values): the median of their diagonals, and the diagonal of their union as the
    /// scene's.
    pub fn resolve_boxes(&self, boxes: &[Aabb]) -> ResolvedParams {
        self.resolve_with(
            boxes.len(),
            || {
                boxes
                    .par_iter()
                    .with_min_len(super::PAR_MIN_LEN)
                    .map(Aabb::diameter)
                    .collect()
            },
            || boxes.iter().fold(Aabb::EMPTY, |u, b| u.merge(b)).diameter(),
        )
    }

    /// The resolution for `n` primitives from their diameters and the scene's diagonal, each
    /// computed only when needed.
    fn resolve_with(
        &self,
        n: usize,
        diameters: impl FnOnce() -> Vec<f64>,
        diagonal: impl FnOnce() -> f64,
    ) -> ResolvedParams {
        let dlimit0 = match self.dlimit {
            Some(d) => d,
            None => {
                let mut d = diameters();
                let median = if d.is_empty() {
                    0.0
                } else {
                    let mid = d.len() / 2;
                    *d.select_nth_unstable_by(mid, f64::total_cmp).1
                };
                if median > 0.0 {
                    median
                } else {
                    let diag = diagonal();
                    if diag.is_finite() && diag > 0.0 {
                        diag * 1e-6
                    } else {
                        1.0
                    }
                }
            }
        };
        let dlimit0 = if dlimit0.is_finite() && dlimit0 > 0.0 {
            dlimit0
        } else {
            1.0
        };
        // GLimit must be positive or disconnected scenes would never finish (doubling 0 stays 0).
        let glimit0 = match self.glimit {
            Some(g) if g.is_finite() && g > 0.0 => g,
            Some(_) => dlimit0 * 1e-9,
            None => dlimit0 / 4.0,
        };
        ResolvedParams {
            weights: self.weights,
            dlimit0,
            glimit0,
            pset: self.pset,
            seed: self.seed,
            mode: match self.mode.schedule {
                Schedule::Partitioned(c) => Mode {
                    schedule: Schedule::Partitioned(c.for_size(n)),
                    ..self.mode
                },
                Schedule::Exact => self.mode,
            },
        }
    }
}
