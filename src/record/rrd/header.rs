//! What the file holds before the first event (recording id, name and properties, the
//! origin transforms, the scene mesh, static styles) and the marks of a run stopped early.

use sha2::{Digest, Sha256};

use super::{ACTIVE_BLUE, PrimMesh, RrdRecorder, SCENE_GREY, columns, send_static};
use crate::grouping::Pregroup;
use crate::record::{Outcome, RunInfo};
use crate::scene::components;
use rerun::RecordingStream;

/// The recording id: a UUID-shaped hex digest of the scene hash and the resolved parameters.
pub(super) fn recording_id(info: &RunInfo<'_>) -> String {
    let mut h = Sha256::new();
    h.update(b"wraptree rrd\0");
    h.update(info.source.sha256.as_bytes());
    h.update(b"\0");
    h.update(
        serde_json::to_string(info.params)
            .unwrap_or_default()
            .as_bytes(),
    );
    super::uuid_text(&h.finalize())
}

impl RrdRecorder {
    /// Metadata, transforms, the scene mesh and static styling.
    pub(super) fn write_header(&self, info: &RunInfo<'_>, mesh: &PrimMesh) -> anyhow::Result<()> {
        let rec = self.rec()?;
        send_run_properties(rec, info)?;
        let o = self.origin;
        for root in ["scene", "grouping", "levels", "refine"] {
            send_static(
                rec,
                root,
                &rerun::Transform3D::from_translation([o.x as f32, o.y as f32, o.z as f32]),
            )?;
        }
        send_static(rec, "/", &rerun::ViewCoordinates::RIGHT_HAND_Z_UP())?;
        send_static(rec, "scene/primitives", &scene_primitives(info, mesh))?;
        for ((path, names), colors) in columns::SERIES.iter().zip(columns::SERIES_COLORS) {
            let lines = rerun::SeriesLines::new()
                .with_names(names.iter().copied())
                .with_colors(colors.iter().copied());
            send_static(rec, path, &lines)?;
        }
        if self.detail.merges() {
            columns::log_styles(rec, "grouping/merge")?;
            send_static(
                rec,
                "grouping/active",
                &rerun::Boxes3D::update_fields()
                    .with_colors([ACTIVE_BLUE])
                    .with_radii([rerun::components::Radius::new_ui_points(0.5)])
                    .with_fill_mode(rerun::components::FillMode::MajorWireframe),
            )?;
        }
        Ok(())
    }

    /// Marks a run stopped before the root: a warning line in `log/doublings` at the last
    /// merge, and the recording property `wraptree_outcome` with `complete` = `false`,
    /// `stop_reason` (`interrupted`, `max-seconds`, `max-pairs` or `unknown`) and `merges`.
    pub(super) fn mark_incomplete(&mut self, outcome: &Outcome<'_>) -> anyhow::Result<()> {
        let reason = outcome.stopped.map_or("unknown", |s| s.reason.name());
        let line = format!(
            "incomplete: stopped ({reason}) after {} merges; no tree levels",
            outcome.merges
        );
        let warn = rerun::TextLogLevel::WARN;
        self.columns
            .push_text(self.merges, self.round, format_args!("{line}"), warn);
        let rec = self.rec()?;
        let text = |s: String| [rerun::components::Text::from(s)];
        rec.send_property(
            "wraptree_outcome",
            &rerun::AnyValues::default()
                .with_component::<rerun::components::Text>("complete", text("false".into()))
                .with_component::<rerun::components::Text>("stop_reason", text(reason.into()))
                .with_component::<rerun::components::Text>(
                    "merges",
                    text(outcome.merges.to_string()),
                ),
        )?;
        Ok(())
    }
}

/// The recording's name (scene file and size) and its `wraptree` property: version, scene,
/// SHA-256, primitives, parameters (JSON) and detail.
fn send_run_properties(rec: &RecordingStream, info: &RunInfo<'_>) -> anyhow::Result<()> {
    let scene = info.scene;
    rec.send_recording_name(format!(
        "{} ({} primitives)",
        info.source.file_name,
        scene.len()
    ))?;
    let text = |s: String| [rerun::components::Text::from(s)];
    rec.send_property(
        "wraptree",
        &rerun::AnyValues::default()
            .with_component::<rerun::components::Text>(
                "version",
                text(env!("CARGO_PKG_VERSION").into()),
            )
            .with_component::<rerun::components::Text>(
                "format_version",
                text(crate::record::FORMAT_VERSION.to_string()),
            )
            .with_component::<rerun::components::Text>("scene", text(info.source.file_name.clone()))
            .with_component::<rerun::components::Text>("sha256", text(info.source.sha256.clone()))
            .with_component::<rerun::components::Text>("primitives", text(scene.len().to_string()))
            .with_component::<rerun::components::Text>(
                "params",
                text(serde_json::to_string(info.params)?),
            )
            .with_component::<rerun::components::Text>(
                "detail",
                text(format!("{:?}", info.detail).to_lowercase()),
            ),
    )?;
    Ok(())
}

/// Every input primitive in one shaded mesh: light grey, or with pre-grouping one colour per
/// component.
fn scene_primitives(info: &RunInfo<'_>, mesh: &PrimMesh) -> rerun::Mesh3D {
    let scene = info.scene;
    let primitives = mesh.to_mesh3d();
    match info.params.mode.pregroup {
        Pregroup::None => primitives.with_albedo_factor(SCENE_GREY),
        Pregroup::Objects => {
            primitives.with_vertex_colors(mesh.component_colors(&components::objects(scene).of))
        }
        Pregroup::Connected => {
            primitives.with_vertex_colors(mesh.component_colors(&components::connected(scene).of))
        }
    }
}
