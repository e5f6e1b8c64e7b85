//! The wrapper kinds and a set of Wrapper Trees built together.

use super::hull::{Hull, hull_tree_until};
use super::obb::{Obb, obb_tree_until};
use super::sphere::{SphereMethod, sphere_tree_until};
use crate::geom::Aabb;
use crate::geom::Sphere;
use crate::grouping::SubsetTree;
use crate::scene::Scene;
use crate::stop::{Interrupted, Stop};

/// A kind of wrapper (`--wrapper`).
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Eq,
    PartialOrd,
    Ord,
    Hash,
    clap::ValueEnum,
    serde::Serialize,
    serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum WrapperKind {
    /// Bounding spheres.
    Sphere,
    /// Convex hulls.
    Hull,
    /// Axis-aligned boxes (the Subset Tree's own p-set boxes).
    #[value(alias = "aabb")]
    #[serde(alias = "aabb")]
    Box,
    /// Oriented boxes (principal axes).
    Obb,
}

impl WrapperKind {
    /// Every kind, in order.
    pub const ALL: [WrapperKind; 4] = [
        WrapperKind::Sphere,
        WrapperKind::Hull,
        WrapperKind::Box,
        WrapperKind::Obb,
    ];

    /// The name used on the command line and in JSON.
    pub fn name(self) -> &'static str {
        match self {
            WrapperKind::Sphere => "sphere",
            WrapperKind::Hull => "hull",
            WrapperKind::Box => "box",
            WrapperKind::Obb => "obb",
        }
    }

    /// Parses one name (`aabb` is accepted for `box`, case-insensitive).
    pub fn parse(s: &str) -> Result<WrapperKind, String> {
        let t = s.trim().to_ascii_lowercase();
        if t == "aabb" {
            return Ok(WrapperKind::Box);
        }
        WrapperKind::ALL
            .into_iter()
            .find(|k| k.name() == t)
            .ok_or_else(|| {
                format!("unknown wrapper '{s}' (valid: sphere, hull, box (or aabb), obb)")
            })
    }

    /// Parses a comma list like `sphere,hull`, sorted and without repeats; empty is an error.
    pub fn parse_list(s: &str) -> Result<Vec<WrapperKind>, String> {
        let mut v = s
            .split(',')
            .map(WrapperKind::parse)
            .collect::<Result<Vec<_>, _>>()?;
        v.sort();
        v.dedup();
        Ok(v)
    }
}

/// Wrapper Trees of several kinds for one Subset Tree; each vector has one wrapper per node
/// (index = node id). A kind not asked for is `None`.
///
/// ```no_run
/// # fn demo(tree: &wraptree_core::grouping::SubsetTree, scene: &wraptree_core::scene::Scene) {
/// use wraptree_core::wrap::{SphereMethod, WrapperKind, Wrappers, hull_tree, level_tightness};
/// let kinds = WrapperKind::parse_list("sphere,hull").unwrap();
/// let w = Wrappers::build(tree, scene, &kinds, SphereMethod::Minimum);
/// let hulls = w.hulls.as_deref().unwrap();
/// for t in w.trees() {
///     let (samples, stop) = (wraptree_core::wrap::DEFAULT_SAMPLES, wraptree_core::stop::Stop::new());
///     let stats = level_tightness(tree, scene, t, hulls, samples, &stop).expect("not stopped");
///     println!("{}: {:?}", t.kind().name(), stats.last());
/// }
/// # }
/// ```
#[derive(Clone, Debug, Default)]
pub struct Wrappers {
    /// Bounding spheres.
    pub spheres: Option<Vec<Sphere>>,
    /// Convex hulls.
    pub hulls: Option<Vec<Hull>>,
    /// Axis-aligned boxes.
    pub boxes: Option<Vec<Aabb>>,
    /// Oriented boxes.
    pub obbs: Option<Vec<Obb>>,
}

/// One kind of Wrapper Tree, borrowed.
#[derive(Clone, Copy, Debug)]
pub enum WrapperTree<'a> {
    /// Bounding spheres.
    Spheres(&'a [Sphere]),
    /// Convex hulls.
    Hulls(&'a [Hull]),
    /// Axis-aligned boxes.
    Boxes(&'a [Aabb]),
    /// Oriented boxes.
    Obbs(&'a [Obb]),
}

impl WrapperTree<'_> {
    /// Number of wrappers.
    pub fn len(&self) -> usize {
        match self {
            WrapperTree::Spheres(w) => w.len(),
            WrapperTree::Hulls(w) => w.len(),
            WrapperTree::Boxes(w) => w.len(),
            WrapperTree::Obbs(w) => w.len(),
        }
    }

    /// Whether there are no wrappers.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Its kind.
    pub fn kind(&self) -> WrapperKind {
        match self {
            WrapperTree::Spheres(_) => WrapperKind::Sphere,
            WrapperTree::Hulls(_) => WrapperKind::Hull,
            WrapperTree::Boxes(_) => WrapperKind::Box,
            WrapperTree::Obbs(_) => WrapperKind::Obb,
        }
    }
}

impl Wrappers {
    /// Builds the Wrapper Trees of `kinds` (spheres by `sphere`; OBB axes from the hulls when
    /// hulls are built too).
    pub fn build(
        tree: &SubsetTree,
        scene: &Scene,
        kinds: &[WrapperKind],
        sphere: SphereMethod,
    ) -> Wrappers {
        match Wrappers::build_until(tree, scene, kinds, sphere, &Stop::new()) {
            Ok(w) => w,
            Err(Interrupted) => unreachable!("a new stop token is never set"),
        }
    }

    /// [`Wrappers::build`], each tree's builder checking `stop` as it goes.
    pub fn build_until(
        tree: &SubsetTree,
        scene: &Scene,
        kinds: &[WrapperKind],
        sphere: SphereMethod,
        stop: &Stop,
    ) -> Result<Wrappers, Interrupted> {
        let want = |k| kinds.contains(&k);
        let hulls = want(WrapperKind::Hull)
            .then(|| hull_tree_until(tree, scene, stop))
            .transpose()?;
        let spheres = want(WrapperKind::Sphere)
            .then(|| sphere_tree_until(tree, scene, sphere, stop))
            .transpose()?;
        let obbs = want(WrapperKind::Obb)
            .then(|| obb_tree_until(tree, scene, hulls.as_deref(), stop))
            .transpose()?;
        Ok(Wrappers {
            spheres,
            boxes: want(WrapperKind::Box).then(|| tree.aabb.clone()),
            obbs,
            hulls,
        })
    }

    /// The trees present, in [`WrapperKind`] order.
    pub fn trees(&self) -> Vec<WrapperTree<'_>> {
        let mut v = Vec::new();
        if let Some(w) = &self.spheres {
            v.push(WrapperTree::Spheres(w));
        }
        if let Some(w) = &self.hulls {
            v.push(WrapperTree::Hulls(w));
        }
        if let Some(w) = &self.boxes {
            v.push(WrapperTree::Boxes(w));
        }
        if let Some(w) = &self.obbs {
            v.push(WrapperTree::Obbs(w));
        }
        v
    }

    /// The tree of `kind`, if built.
    pub fn get(&self, kind: WrapperKind) -> Option<WrapperTree<'_>> {
        self.trees().into_iter().find(|t| t.kind() == kind)
    }
}
