//! The layout the `.rrd` file opens on (a Rerun blueprint, sent with `with_blueprint`).
//!
//! Top, side by side (wide views, so the scene is framed whole at 1280×720): a 3D view of the
//! scene and the grouping boxes (scrub the `merge` or `round` timeline) and, when levels are
//! written, a 3D view of the tree levels and the cover, if any (scrub `level`).
//! Bottom: the plots of the merge series (and, for a refined run, `record --refine`, the
//! refinement's SAH on the `refine` timeline) in a grid of two columns beside the text log of
//! rounds, doublings and refinement.
//!
//! Every view shows something when the file is opened: the time panel opens collapsed (the play
//! bar alone) on the `merge` timeline, following, so the cursor stands at the last merge; there
//! the Grouping view shows the scene with the root's merge, the plots and the log the whole run,
//! and the Levels view the preview level, which is also on the `merge` and `round` timelines
//! (see `levels.rs`). The blueprint and selection panels open collapsed.

use rerun::blueprint::components::{PanelState, PlayState};
use rerun::blueprint::{
    Blueprint, BlueprintPanel, ContainerLike, Grid, Horizontal, SelectionPanel, Spatial3DView,
    TextLogView, TimePanel, TimeSeriesView, Vertical,
};

use crate::record::Detail;

/// The blueprint for a recording written at `detail`, with the SAH plot when the tree is
/// `refined` (without a refinement that plot would stay empty).
pub(super) fn layout(detail: Detail, refined: bool) -> Blueprint {
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
    let mut plots = vec![
        plot("Cost", &["cost"]),
        plot("diameter, DLimit, GLimit", &["limits"]),
        plot("Fill, Balance", &["fill_balance"]),
        plot("MPairs length", &["queue_len"]),
    ];
    if refined {
        plots.push(plot("SAH (timeline refine)", &["refine_sah"]));
    }
    let plots = Grid::new(plots).with_grid_columns(2);
    let bottom = Horizontal::new([
        plots.into(),
        TextLogView::new("Rounds, doublings, refinement")
            .with_origin("/log")
            .into(),
    ])
    .with_column_shares([3.0, 2.0]);
    let top = Horizontal::new(views);
    let root = Vertical::new([top.into(), bottom.into()]).with_row_shares([3.0, 2.0]);
    Blueprint::new(root)
        .with_blueprint_panel(BlueprintPanel::new().with_state(PanelState::Collapsed))
        .with_selection_panel(SelectionPanel::new().with_state(PanelState::Collapsed))
        .with_time_panel(
            TimePanel::new()
                .with_state(PanelState::Collapsed)
                .with_timeline("merge")
                .with_play_state(PlayState::Following),
        )
}
