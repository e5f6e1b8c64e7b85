//! The layouts the `.rrd` files open on (Rerun blueprints, [`tree`]), fitted to the run so that
//! every view is right on open, at any scale and while a large file still loads.
//!
//! A run's recording: on top, side by side, a 3D view of the scene and the grouping boxes (scrub
//! `merge` or `round`) and, when levels are written, a 3D view of the tree levels and the cover
//! (scrub `level`); below, the plots of the merge series (and a refined run's SAH on `refine`)
//! in two columns beside the log of rounds, doublings and refinement.
//!
//! Both 3D views open on the same eye, framing the scene's bounding sphere with a margin, so the
//! first screen shows the whole scene before any data has loaded. The plots span the whole run
//! (ticks 0 to the last merge) rather than follow the cursor. The layout is sent twice: at the
//! start (eye and ticks) and at the end, when the values are known, again with every plot's
//! value range from 0 ([`Fit::ranges`]). The time panel opens on `merge`, following.

pub(crate) mod tree;

use crate::geom::Aabb;
use crate::record::Detail;
pub(crate) use tree::{Eye, Layout, Node, View, ViewKind};

/// Vertical field of view of the viewer's 3D eye (its default, radians).
const FOV_Y: f32 = 55.0 * std::f32::consts::PI / 180.0;
/// The bounding sphere fills this share of the view's height.
const FILL: f32 = 0.95;
/// Direction from the scene's centre to the eye: front-right, above (Z up).
const EYE_DIRECTION: [f32; 3] = [0.55, -0.70, 0.45];

/// The eye that frames `bbox`: at its centre's distance where its bounding sphere fills 95 % of
/// a view's height, looking at the centre from the front-right and above. `None` for a box that
/// is empty, flat to a point or not finite (the viewer then frames what it has).
pub(crate) fn framing(bbox: &Aabb) -> Option<Eye> {
    let c = bbox.center();
    let r = (bbox.extents() / 2.0).norm() as f32;
    if !(r.is_finite() && r > 0.0 && c.iter().all(|x| x.is_finite())) {
        return None;
    }
    let d = r / (FILL * (FOV_Y / 2.0).sin());
    let n = EYE_DIRECTION.iter().map(|x| x * x).sum::<f32>().sqrt();
    let target = [c.x as f32, c.y as f32, c.z as f32];
    let position = std::array::from_fn(|i| target[i] + d * EYE_DIRECTION[i] / n);
    Some(Eye { position, target })
}

/// What a run's layout is fitted to.
#[derive(Clone, Debug, Default)]
pub(crate) struct Fit {
    /// The eye of the 3D views.
    pub eye: Option<Eye>,
    /// The last `merge` tick the plots show.
    pub last_merge: i64,
    /// Per plot of the merge series (Cost; diameter, DLimit, GLimit; Fill, Balance; MPairs
    /// length), the largest value: the y range is 0 to it plus 5 %. `None` until the run ended.
    pub ranges: Option<[f64; 4]>,
    /// Kept refinement steps (known at the end): the SAH plot spans `merge` ticks
    /// `last_merge ..= last_merge + refine_steps`, where the refinement continues the timeline.
    pub refine_steps: u32,
}

impl Fit {
    fn y(&self, plot: usize) -> Option<(f64, f64)> {
        let hi = self.ranges?[plot];
        (hi.is_finite() && hi > 0.0).then_some((0.0, hi * 1.05))
    }
}

fn spatial(name: &str, eye: Option<Eye>, contents: &[&str]) -> Node {
    Node::View(View {
        kind: ViewKind::Spatial(eye),
        name: name.into(),
        origin: "/".into(),
        contents: contents.iter().map(|c| c.to_string()).collect(),
    })
}

/// A plot of the entities `series` (paths under `/series`), over ticks `x`, values `y`.
pub(crate) fn plot(
    name: &str,
    series: &[String],
    x: Option<(i64, i64)>,
    y: Option<(f64, f64)>,
) -> Node {
    Node::View(View {
        kind: ViewKind::Plot { x, y },
        name: name.into(),
        origin: "/series".into(),
        contents: series.iter().map(|s| format!("+ /series/{s}")).collect(),
    })
}

/// A text log view of `origin`.
pub(crate) fn text_log(name: &str, origin: &str) -> Node {
    Node::View(View {
        kind: ViewKind::TextLog,
        name: name.into(),
        origin: origin.into(),
        contents: vec![format!("+ {origin}/**")],
    })
}

/// The layout of a run recorded at `detail`, with the SAH plot when the tree is `refined`.
pub(crate) fn layout(detail: Detail, refined: bool, fit: &Fit) -> Layout {
    let mut views = vec![spatial(
        "Grouping (timelines merge, round)",
        fit.eye,
        &["+ /scene/**", "+ /grouping/**", "+ /refine/**"],
    )];
    if detail.levels() {
        views.push(spatial(
            "Levels (timeline level)",
            fit.eye,
            &["+ /levels/**", "+ /cover/**"],
        ));
    }
    let x = Some((0, fit.last_merge.max(1)));
    let names = [
        ("Cost", "cost"),
        ("diameter, DLimit, GLimit", "limits"),
        ("Fill, Balance", "fill_balance"),
        ("MPairs length", "queue_len"),
    ];
    let mut plots: Vec<Node> = names
        .iter()
        .enumerate()
        .map(|(i, (name, s))| plot(name, &[s.to_string()], x, fit.y(i)))
        .collect();
    if refined {
        let x = (fit.ranges.is_some()).then_some((
            fit.last_merge,
            fit.last_merge + i64::from(fit.refine_steps.max(1)),
        ));
        plots.push(plot(
            "SAH during refinement (after the last merge)",
            &["refine_sah".into()],
            x,
            None,
        ));
    }
    let shares = vec![1.0; views.len()];
    let bottom = Node::Row(
        vec![
            Node::Grid(plots, 2),
            text_log("Rounds, doublings, refinement", "/log"),
        ],
        vec![3.0, 2.0],
    );
    Layout {
        root: Node::Column(vec![Node::Row(views, shares), bottom], vec![3.0, 2.0]),
        timeline: "merge",
    }
}
