//! A Rerun blueprint written archetype by archetype: containers, views with their properties
//! (the 3D eye, the plot axes) and the panels.
//!
//! The SDK's builder (`rerun::blueprint`) cannot set a view's properties from Rust in 0.36.3,
//! so this writes the same entities it would (`viewport`, `container/<id>`, `view/<id>`,
//! `view/<id>/ViewContents`, `view/<id>/<Property>`, the panels) into a blueprint stream of its
//! own and sends that to the recording. Ids are derived from a seed, so one layout always gives
//! the same blueprint.

use rerun::external::re_log_types::{ApplicationId, BlueprintActivationCommand, LogMsg};
use rerun::external::re_sdk_types::blueprint::archetypes::{
    ContainerBlueprint, EyeControls3D, PanelBlueprint, ScalarAxis, TimeAxis, TimePanelBlueprint,
    ViewBlueprint, ViewContents, ViewportBlueprint,
};
use rerun::external::re_sdk_types::blueprint::components::{
    ColumnShare, ContainerKind, IncludedContent, PanelState, PlayState, QueryExpression,
    RootContainer, RowShare, TimelineName, ViewClass,
};
use rerun::external::re_sdk_types::datatypes::{TimeInt, TimeRange, TimeRangeBoundary};
use rerun::{RecordingStream, RecordingStreamBuilder};
use sha2::{Digest, Sha256};

use crate::record::rrd::uuid_text;

/// A 3D eye: where it stands and what it looks at (world coordinates, Z up).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Eye {
    /// The eye's position.
    pub position: [f32; 3],
    /// The point it looks at and orbits around.
    pub target: [f32; 3],
}

/// What a view shows.
#[derive(Clone, Debug)]
pub(crate) enum ViewKind {
    /// A 3D view, with its eye when given (else the viewer frames what it has loaded).
    Spatial(Option<Eye>),
    /// A plot over a sequence timeline: the ticks shown (`x`) and the value range (`y`).
    Plot {
        x: Option<(i64, i64)>,
        y: Option<(f64, f64)>,
    },
    /// A table of text log rows.
    TextLog,
}

/// One view: its kind, name, origin and entity queries (`+ /path/**`).
#[derive(Clone, Debug)]
pub(crate) struct View {
    pub kind: ViewKind,
    pub name: String,
    pub origin: String,
    pub contents: Vec<String>,
}

/// A container of views or containers, laid out in a row, a column or a grid.
#[derive(Clone, Debug)]
pub(crate) enum Node {
    /// Children left to right, with their width shares.
    Row(Vec<Node>, Vec<f32>),
    /// Children top to bottom, with their height shares.
    Column(Vec<Node>, Vec<f32>),
    /// Children in a grid of this many columns.
    Grid(Vec<Node>, u32),
    /// A view.
    View(View),
}

/// A whole layout: the root and the timeline the time panel opens on (following, so the cursor
/// stands at the newest tick); the blueprint and selection panels open collapsed.
#[derive(Clone, Debug)]
pub(crate) struct Layout {
    pub root: Node,
    pub timeline: &'static str,
}

/// Hands out ids derived from a seed, as UUID-shaped 16 bytes.
struct Ids {
    seed: String,
    next: u32,
}

impl Ids {
    fn next(&mut self) -> [u8; 16] {
        let mut h = Sha256::new();
        h.update(self.seed.as_bytes());
        h.update(self.next.to_le_bytes());
        self.next += 1;
        let mut id = [0u8; 16];
        id.copy_from_slice(&h.finalize()[..16]);
        // Version 4, RFC 4122 variant: a well-formed UUID.
        id[6] = (id[6] & 0x0f) | 0x40;
        id[8] = (id[8] & 0x3f) | 0x80;
        id
    }
}

impl Layout {
    /// The blueprint's messages: a blueprint store of application `app` whose id and every
    /// container and view id derive from `seed`.
    fn messages(&self, app: ApplicationId, seed: &str) -> anyhow::Result<Vec<LogMsg>> {
        let mut ids = Ids {
            seed: seed.to_string(),
            next: 0,
        };
        let store = uuid_text(&ids.next());
        let (bp, storage) = RecordingStreamBuilder::new(app)
            .recording_id(store)
            .blueprint()
            .memory()?;
        bp.set_time_sequence("blueprint", 0);
        let root = log_node(&bp, &self.root, &mut ids)?;
        let root_id = match root {
            Logged::Container(id) => id,
            Logged::View(_) => anyhow::bail!("a layout's root is a container"),
        };
        bp.log(
            "viewport",
            &ViewportBlueprint::new().with_root_container(RootContainer(root_id.into())),
        )?;
        let collapsed = PanelBlueprint::new().with_state(PanelState::Collapsed);
        bp.log("blueprint_panel", &collapsed)?;
        bp.log("selection_panel", &collapsed)?;
        bp.log(
            "time_panel",
            &TimePanelBlueprint::new()
                .with_state(PanelState::Collapsed)
                .with_timeline(TimelineName(self.timeline.into()))
                .with_play_state(PlayState::Following),
        )?;
        bp.flush_blocking()?;
        Ok(storage.take())
    }

    /// Sends the layout to `rec` as its active and default blueprint.
    pub(crate) fn send(&self, rec: &RecordingStream, seed: &str) -> anyhow::Result<()> {
        let app = rec
            .store_info()
            .map(|info| info.application_id().clone())
            .unwrap_or_else(|| ApplicationId::from("wraptree"));
        let msgs = self.messages(app, seed)?;
        let Some(blueprint_id) = msgs.first().map(|m| m.store_id().clone()) else {
            anyhow::bail!("the blueprint stream wrote nothing");
        };
        rec.send_blueprint(
            msgs,
            BlueprintActivationCommand {
                blueprint_id,
                make_active: true,
                make_default: true,
            },
        );
        Ok(())
    }
}

enum Logged {
    Container([u8; 16]),
    View([u8; 16]),
}

impl Logged {
    fn path(&self) -> String {
        match self {
            Logged::Container(id) => format!("container/{}", uuid_text(id)),
            Logged::View(id) => format!("view/{}", uuid_text(id)),
        }
    }
}

/// Logs `node` and its children; returns its id.
fn log_node(bp: &RecordingStream, node: &Node, ids: &mut Ids) -> anyhow::Result<Logged> {
    let (kind, children) = match node {
        Node::View(v) => return log_view(bp, v, ids),
        Node::Row(c, _) => (ContainerKind::Horizontal, c),
        Node::Column(c, _) => (ContainerKind::Vertical, c),
        Node::Grid(c, _) => (ContainerKind::Grid, c),
    };
    let id = ids.next();
    let contents = children
        .iter()
        .map(|c| Ok(IncludedContent(log_node(bp, c, ids)?.path().into())))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let mut arch = ContainerBlueprint::new(kind).with_contents(contents);
    match node {
        Node::Row(_, shares) => {
            arch = arch.with_col_shares(shares.iter().map(|&s| ColumnShare(s.into())))
        }
        Node::Column(_, shares) => {
            arch = arch.with_row_shares(shares.iter().map(|&s| RowShare(s.into())))
        }
        Node::Grid(_, columns) => arch = arch.with_grid_columns(*columns),
        Node::View(_) => {}
    }
    let logged = Logged::Container(id);
    bp.log(logged.path(), &arch)?;
    Ok(logged)
}

fn log_view(bp: &RecordingStream, v: &View, ids: &mut Ids) -> anyhow::Result<Logged> {
    let logged = Logged::View(ids.next());
    let path = logged.path();
    let class = match v.kind {
        ViewKind::Spatial(_) => "3D",
        ViewKind::Plot { .. } => "TimeSeries",
        ViewKind::TextLog => "TextLog",
    };
    let queries = v.contents.iter().map(|q| QueryExpression(q.clone().into()));
    bp.log(format!("{path}/ViewContents"), &ViewContents::new(queries))?;
    bp.log(
        path.as_str(),
        &ViewBlueprint::new(ViewClass(class.into()))
            .with_display_name(v.name.as_str())
            .with_space_origin(v.origin.as_str()),
    )?;
    match v.kind {
        ViewKind::Spatial(Some(eye)) => bp.log(
            format!("{path}/EyeControls3D"),
            &EyeControls3D::new()
                .with_position(eye.position)
                .with_look_target(eye.target)
                .with_eye_up([0.0, 0.0, 1.0]),
        )?,
        ViewKind::Plot { x, y } => {
            if let Some((start, end)) = x {
                let range = TimeRange {
                    start: TimeRangeBoundary::Absolute(TimeInt(start)),
                    end: TimeRangeBoundary::Absolute(TimeInt(end)),
                };
                bp.log(
                    format!("{path}/TimeAxis"),
                    &TimeAxis::new().with_view_range(range),
                )?;
            }
            if let Some((lo, hi)) = y {
                bp.log(
                    format!("{path}/ScalarAxis"),
                    &ScalarAxis::new().with_range([lo, hi]),
                )?;
            }
        }
        ViewKind::Spatial(None) | ViewKind::TextLog => {}
    }
    Ok(logged)
}
