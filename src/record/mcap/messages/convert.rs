//! Conversions between the grouping's and refinement's events and their messages.

use super::{MergeEvent, PartEvent, RefineStepEvent};
use crate::geom::{Aabb, P3};
use crate::grouping::{Merge, Part, PartKind};
use crate::refine::StepKind;

impl From<&crate::refine::Step> for RefineStepEvent {
    fn from(s: &crate::refine::Step) -> Self {
        let (a, p) = (&s.aabb, &s.parent_aabb);
        let (kind, treelet_leaves) = match s.kind {
            StepKind::Move => (0, 0),
            StepKind::Treelet { leaves } => (1, leaves),
        };
        RefineStepEvent {
            step: s.step,
            pass: s.pass,
            kind,
            treelet_leaves,
            node: s.node,
            parent: s.parent,
            sibling: s.sibling,
            target: s.target,
            min_x: a.min.x,
            min_y: a.min.y,
            min_z: a.min.z,
            max_x: a.max.x,
            max_y: a.max.y,
            max_z: a.max.z,
            parent_min_x: p.min.x,
            parent_min_y: p.min.y,
            parent_min_z: p.min.z,
            parent_max_x: p.max.x,
            parent_max_y: p.max.y,
            parent_max_z: p.max.z,
            sah_before: s.sah_before,
            sah: s.sah,
        }
    }
}

impl From<&RefineStepEvent> for crate::refine::Step {
    fn from(e: &RefineStepEvent) -> Self {
        let b = |lo: [f64; 3], hi: [f64; 3]| Aabb {
            min: P3::new(lo[0], lo[1], lo[2]),
            max: P3::new(hi[0], hi[1], hi[2]),
        };
        crate::refine::Step {
            step: e.step,
            pass: e.pass,
            kind: match e.kind {
                0 => StepKind::Move,
                _ => StepKind::Treelet {
                    leaves: e.treelet_leaves,
                },
            },
            node: e.node,
            parent: e.parent,
            sibling: e.sibling,
            target: e.target,
            aabb: b([e.min_x, e.min_y, e.min_z], [e.max_x, e.max_y, e.max_z]),
            parent_aabb: b(
                [e.parent_min_x, e.parent_min_y, e.parent_min_z],
                [e.parent_max_x, e.parent_max_y, e.parent_max_z],
            ),
            sah_before: e.sah_before,
            sah: e.sah,
        }
    }
}

impl From<&Part> for PartEvent {
    fn from(p: &Part) -> Self {
        let mut e = PartEvent {
            id: p.id,
            bodies: p.bodies,
            first_step: p.first_step,
            ..PartEvent::default()
        };
        match p.kind {
            PartKind::Chunk { level, keep } => {
                e.kind = 0;
                e.level = level;
                e.keep = keep;
            }
            PartKind::Component { index } => {
                e.kind = 1;
                e.index = index;
            }
            PartKind::Copy {
                of,
                rotation: r,
                translation: t,
            } => {
                e.kind = 2;
                e.index = of;
                [e.r0, e.r1, e.r2, e.r3, e.r4, e.r5, e.r6, e.r7, e.r8] = r.map(Some);
                [e.tx, e.ty, e.tz] = t.map(Some);
            }
            PartKind::Top => e.kind = 3,
            PartKind::Twins => e.kind = 4,
        }
        e
    }
}

impl TryFrom<&PartEvent> for Part {
    type Error = String;
    fn try_from(e: &PartEvent) -> Result<Self, String> {
        let kind = match e.kind {
            0 => PartKind::Chunk {
                level: e.level,
                keep: e.keep,
            },
            1 => PartKind::Component { index: e.index },
            2 => {
                let r = [e.r0, e.r1, e.r2, e.r3, e.r4, e.r5, e.r6, e.r7, e.r8];
                let t = [e.tx, e.ty, e.tz];
                let (Some(rotation), Some(translation)) = (present(r), present(t)) else {
                    return Err("a copy part without its rotation and translation".into());
                };
                PartKind::Copy {
                    of: e.index,
                    rotation,
                    translation,
                }
            }
            3 => PartKind::Top,
            4 => PartKind::Twins,
            k => return Err(format!("unknown part kind {k}")),
        };
        Ok(Part {
            id: e.id,
            kind,
            bodies: e.bodies,
            first_step: e.first_step,
        })
    }
}

impl From<&Merge> for MergeEvent {
    /// Every field, the AABB included.
    fn from(m: &Merge) -> Self {
        let (lo, hi) = (m.aabb.min, m.aabb.max);
        MergeEvent {
            step: m.step,
            round: m.round,
            a: m.a,
            b: m.b,
            new: m.new,
            min_x: Some(lo.x),
            min_y: Some(lo.y),
            min_z: Some(lo.z),
            max_x: Some(hi.x),
            max_y: Some(hi.y),
            max_z: Some(hi.z),
            diameter: m.diameter,
            fill: m.fill,
            balance: m.balance,
            cost: m.cost,
            queue_len: m.queue_len,
            active: m.active,
        }
    }
}

impl MergeEvent {
    /// The message without its AABB, which readers derive from the children's boxes.
    pub fn without_box(self) -> MergeEvent {
        MergeEvent {
            min_x: None,
            min_y: None,
            min_z: None,
            max_x: None,
            max_y: None,
            max_z: None,
            ..self
        }
    }

    /// The merge, its AABB `None` when the message leaves it out. Err: only some of its six
    /// values present.
    pub fn to_merge(&self) -> Result<(Merge, Option<Aabb>), String> {
        let corners = [
            self.min_x, self.min_y, self.min_z, self.max_x, self.max_y, self.max_z,
        ];
        let aabb = match present(corners) {
            Some([x0, y0, z0, x1, y1, z1]) => Some(Aabb {
                min: P3::new(x0, y0, z0),
                max: P3::new(x1, y1, z1),
            }),
            None if corners.iter().all(Option::is_none) => None,
            None => return Err("an AABB with only some of its corners".into()),
        };
        let merge = Merge {
            step: self.step,
            round: self.round,
            a: self.a,
            b: self.b,
            new: self.new,
            aabb: aabb.unwrap_or(Aabb::EMPTY),
            diameter: self.diameter,
            fill: self.fill,
            balance: self.balance,
            cost: self.cost,
            queue_len: self.queue_len,
            active: self.active,
        };
        Ok((merge, aabb))
    }
}

/// The values of `v` when every one is present.
fn present<const K: usize>(v: [Option<f64>; K]) -> Option<[f64; K]> {
    v.iter()
        .copied()
        .collect::<Option<Vec<f64>>>()?
        .try_into()
        .ok()
}
