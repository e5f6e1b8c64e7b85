//! The layout the `.rrd` file opens on (a Rerun blueprint, sent with `with_blueprint`).
//!
//! Left: a 3D view of the scene and the grouping boxes (scrub the `merge` or `round`
//! timeline); beside it, when levels are written, a 3D view of the tree levels and the cover,
//! if any (scrub `level`).
//! Right: four plots of the merge series and the refinement's SAH (`record --refine`) above the
//! text log of rounds, doublings and refinement. The time
//! panel opens expanded on the `merge` timeline.

use rerun::blueprint::components::PanelState;
use rerun::blueprint::{
    Blueprint, ContainerLike, Grid, Horizontal, Spatial3DView, TextLogView, TimePanel,
    TimeSeriesView, Vertical,
};

use crate::record::Detail;

/// The blueprint for a recording written at `detail`.
pub(super) fn layout(detail: Detail) -> Blueprint {
    let mut views: Vec<ContainerLike> = vec![
        Spatial3DView::new("Grouping (timelines merge, round)")
            .with_origin("/")
            .with_contents(["+ /scene/**", "+ /grouping/**", "+ /refine/**"])
            .into(),
    ];
    if detail.levels() {
        views.push(
            Spatial3DView::new("Levels (timeline level)")
                .with_origin("/")
                .with_contents(["+ /levels/**", "+ /cover/**"])
                .into(),
        );
    }
    let plot = |name: &str, series: &[&str]| -> ContainerLike {
        TimeSeriesView::new(name)
            .with_origin("/series")
            .with_contents(series.iter().map(|s| format!("+ /series/{s}")))
            .into()
    };
    let plots = Grid::new([
        plot("Cost", &["cost"]),
        plot("diameter, DLimit, GLimit", &["limits"]),
        plot("Fill, Balance", &["fill_balance"]),
        plot("MPairs length", &["queue_len"]),
        plot("SAH (timeline refine)", &["refine_sah"]),
    ])
    .with_grid_columns(2);
    let side = Vertical::new([
        plots.into(),
        TextLogView::new("Rounds, doublings, refinement")
            .with_origin("/log")
            .into(),
    ])
    .with_row_shares([2.0, 1.0]);
    let shares: Vec<f32> = std::iter::repeat_n(2.0, views.len()).chain([2.0]).collect();
    views.push(side.into());
    Blueprint::new(Horizontal::new(views).with_column_shares(shares)).with_time_panel(
        TimePanel::new()
            .with_state(PanelState::Expanded)
            .with_timeline("merge"),
    )
}
