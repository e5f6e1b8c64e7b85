//! The typed protobuf messages of the `/grouping/*` topics and their decoding.
//!
//! Each message is a flat struct of scalars declared once by `flat_message!`: the macro
//! derives [`foxglove::Encode`] (protobuf schema + encoder; field number = declaration order,
//! starting at 1) and generates the matching decoder from the same field list, so the writer
//! and the reader cannot drift apart. foxglove 0.30 offers no decoder for derived types, and a
//! flat message of varints and doubles needs only the few lines of wire parsing below.

use crate::geom::{Aabb, P3};
use crate::grouping::{Merge, Part, PartKind};

/// A scalar the flat decoder understands: its protobuf wire type and conversion from the raw
/// varint or 64-bit value.
pub trait WireScalar: Sized {
    /// Protobuf wire type: 0 (varint) or 1 (64-bit).
    const WIRE: u8;
    /// Converts the raw field value.
    fn from_raw(raw: u64) -> Option<Self>;
}

impl WireScalar for u32 {
    const WIRE: u8 = 0;
    fn from_raw(raw: u64) -> Option<Self> {
        u32::try_from(raw).ok()
    }
}

impl WireScalar for u64 {
    const WIRE: u8 = 0;
    fn from_raw(raw: u64) -> Option<Self> {
        Some(raw)
    }
}

impl WireScalar for bool {
    const WIRE: u8 = 0;
    fn from_raw(raw: u64) -> Option<Self> {
        Some(raw != 0)
    }
}

impl WireScalar for f64 {
    const WIRE: u8 = 1;
    fn from_raw(raw: u64) -> Option<Self> {
        Some(f64::from_bits(raw))
    }
}

/// Reads one varint at `*pos`.
fn varint(buf: &[u8], pos: &mut usize) -> Result<u64, String> {
    let mut v = 0u64;
    for shift in (0..64).step_by(7) {
        let byte = *buf.get(*pos).ok_or("message ends inside a varint")?;
        *pos += 1;
        v |= u64::from(byte & 0x7f) << shift;
        if byte & 0x80 == 0 {
            return Ok(v);
        }
    }
    Err("varint longer than 10 bytes".into())
}

/// Splits a protobuf message into `(field number, wire type, raw value)` for its varint and
/// 64-bit fields; length-delimited and 32-bit fields are skipped.
pub fn wire_fields(buf: &[u8]) -> Result<Vec<(u64, u8, u64)>, String> {
    let mut out = Vec::new();
    let mut pos = 0;
    while pos < buf.len() {
        let tag = varint(buf, &mut pos)?;
        let (field, wire) = (tag >> 3, (tag & 7) as u8);
        match wire {
            0 => out.push((field, 0, varint(buf, &mut pos)?)),
            1 => {
                let bytes = buf
                    .get(pos..pos + 8)
                    .ok_or("message ends inside a double")?;
                out.push((
                    field,
                    1,
                    u64::from_le_bytes(bytes.try_into().expect("8 bytes")),
                ));
                pos += 8;
            }
            2 => {
                let len = varint(buf, &mut pos)?;
                pos = usize::try_from(len)
                    .ok()
                    .and_then(|l| pos.checked_add(l))
                    .filter(|&end| end <= buf.len())
                    .ok_or("length-delimited field runs past the message")?;
            }
            5 => {
                pos = pos
                    .checked_add(4)
                    .filter(|&e| e <= buf.len())
                    .ok_or("message ends inside a fixed32")?
            }
            w => return Err(format!("unsupported wire type {w}")),
        }
    }
    Ok(out)
}

/// Declares a flat message: the struct (deriving [`foxglove::Encode`]) and its `decode`.
macro_rules! flat_message {
    ($(#[$meta:meta])* $name:ident { $($(#[$fmeta:meta])* $field:ident: $ty:ty,)+ }) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, Default, PartialEq, foxglove::Encode)]
        pub struct $name {
            $($(#[$fmeta])* pub $field: $ty,)+
        }

        impl $name {
            /// Decodes a message written by the derived encoder; every field must be present once
            /// with its declared wire type (unknown fields are ignored).
            pub fn decode(buf: &[u8]) -> Result<Self, String> {
                const FIELDS: &[&str] = &[$(stringify!($field)),+];
                let mut out = Self::default();
                let mut seen = 0u64;
                for (number, wire, raw) in wire_fields(buf)? {
                    let mut index = 0u64;
                    $(
                        index += 1;
                        if number == index {
                            if wire != <$ty as WireScalar>::WIRE {
                                return Err(format!("field `{}` has wire type {wire}", stringify!($field)));
                            }
                            out.$field = <$ty as WireScalar>::from_raw(raw)
                                .ok_or(concat!("field `", stringify!($field), "` out of range"))?;
                            seen |= 1 << (index - 1);
                        }
                    )+
                }
                if let Some(missing) = (0..FIELDS.len()).find(|&i| seen & (1 << i) == 0) {
                    return Err(format!("field `{}` missing", FIELDS[missing]));
                }
                Ok(out)
            }
        }
    };
}

flat_message! {
    /// One merge of step 4(a), on `/grouping/merge`: every field of [`Merge`].
    MergeEvent {
        /// 0-based merge index.
        step: u32,
        /// Round (DLimit doublings so far).
        round: u32,
        /// First merged body (smaller id).
        a: u32,
        /// Second merged body (larger id).
        b: u32,
        /// New body id (N + step).
        new: u32,
        /// AABB lower corner, x.
        min_x: f64,
        /// AABB lower corner, y.
        min_y: f64,
        /// AABB lower corner, z.
        min_z: f64,
        /// AABB upper corner, x.
        max_x: f64,
        /// AABB upper corner, y.
        max_y: f64,
        /// AABB upper corner, z.
        max_z: f64,
        /// Diameter of the new body.
        diameter: f64,
        /// Fill.
        fill: f64,
        /// Balance.
        balance: f64,
        /// Cost.
        cost: f64,
        /// MPairs length after the pop.
        queue_len: u32,
        /// Whether the new body is active (else dormant).
        active: bool,
    }
}

flat_message! {
    /// A round start (`doubling == false`) or a DLimit doubling (`doubling == true`), on
    /// `/grouping/round`. For a round start `merges` is 0; for a doubling `round` is the round
    /// that ended, `dlimit`/`glimit` the new limits, `merges` the merges made in that round and
    /// `active`, `dormant`, `pairs` are 0.
    RoundEvent {
        /// Doubling (true) or round start (false).
        doubling: bool,
        /// Round index.
        round: u32,
        /// DLimit (new DLimit for a doubling).
        dlimit: f64,
        /// GLimit (new GLimit for a doubling).
        glimit: f64,
        /// Active bodies at the round start.
        active: u32,
        /// Dormant bodies at the round start.
        dormant: u32,
        /// Eligible pairs found by the round's voxel scan.
        pairs: u64,
        /// Merges made in the round that ended (doublings only).
        merges: u32,
    }
}

flat_message! {
    /// A new body exceeding DLimit (step 4c), on `/grouping/dormant`.
    DormantEvent {
        /// Round index.
        round: u32,
        /// The body.
        body: u32,
        /// Its diameter.
        diameter: f64,
    }
}

flat_message! {
    /// The end of grouping, on `/grouping/finish`.
    FinishEvent {
        /// Root body id.
        root: u32,
        /// Rounds run.
        rounds: u32,
        /// Merges made (N − 1).
        merges: u32,
    }
}

flat_message! {
    /// One kept step of the refinement (`record --refine`), on `/refine/step`: every field of
    /// [`crate::refine::Step`], its kind flattened.
    RefineStepEvent {
        /// 0-based step index.
        step: u32,
        /// Pass.
        pass: u32,
        /// 0 a move, 1 a rebuilt treelet.
        kind: u32,
        /// The treelet's leaves (0 for a move).
        treelet_leaves: u32,
        /// The moved subtree.
        node: u32,
        /// Its parent slot, moved with it.
        parent: u32,
        /// Its old sibling.
        sibling: u32,
        /// Its new sibling.
        target: u32,
        /// Moved subtree's box, lower corner x.
        min_x: f64,
        /// Lower corner y.
        min_y: f64,
        /// Lower corner z.
        min_z: f64,
        /// Upper corner x.
        max_x: f64,
        /// Upper corner y.
        max_y: f64,
        /// Upper corner z.
        max_z: f64,
        /// New parent's box, lower corner x.
        parent_min_x: f64,
        /// Lower corner y.
        parent_min_y: f64,
        /// Lower corner z.
        parent_min_z: f64,
        /// Upper corner x.
        parent_max_x: f64,
        /// Upper corner y.
        parent_max_y: f64,
        /// Upper corner z.
        parent_max_z: f64,
        /// SAH before the step.
        sah_before: f64,
        /// SAH after the step.
        sah: f64,
    }
}

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

flat_message! {
    /// A part of the run (a chunk of the partitioned schedule, a component, a copy, the top),
    /// on `/grouping/part`: every field of [`Part`], its kind flattened (fields a kind does not
    /// have are 0).
    PartEvent {
        /// 0-based part index.
        id: u32,
        /// 0 chunk, 1 component, 2 copy, 3 top.
        kind: u32,
        /// Bodies the part starts from.
        bodies: u32,
        /// Step of the part's first merge.
        first_step: u32,
        /// Chunk: depth in the split.
        level: u32,
        /// Chunk: bodies left for the level above.
        keep: u32,
        /// Component: its index; copy: the component it copies.
        index: u32,
        /// Copy: rotation, row-major, 0 0.
        r0: f64,
        /// Rotation 0 1.
        r1: f64,
        /// Rotation 0 2.
        r2: f64,
        /// Rotation 1 0.
        r3: f64,
        /// Rotation 1 1.
        r4: f64,
        /// Rotation 1 2.
        r5: f64,
        /// Rotation 2 0.
        r6: f64,
        /// Rotation 2 1.
        r7: f64,
        /// Rotation 2 2.
        r8: f64,
        /// Copy: translation x.
        tx: f64,
        /// Translation y.
        ty: f64,
        /// Translation z.
        tz: f64,
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
                [e.r0, e.r1, e.r2, e.r3, e.r4, e.r5, e.r6, e.r7, e.r8] = r;
                [e.tx, e.ty, e.tz] = t;
            }
            PartKind::Top => e.kind = 3,
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
            2 => PartKind::Copy {
                of: e.index,
                rotation: [e.r0, e.r1, e.r2, e.r3, e.r4, e.r5, e.r6, e.r7, e.r8],
                translation: [e.tx, e.ty, e.tz],
            },
            3 => PartKind::Top,
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
    fn from(m: &Merge) -> Self {
        MergeEvent {
            step: m.step,
            round: m.round,
            a: m.a,
            b: m.b,
            new: m.new,
            min_x: m.aabb.min.x,
            min_y: m.aabb.min.y,
            min_z: m.aabb.min.z,
            max_x: m.aabb.max.x,
            max_y: m.aabb.max.y,
            max_z: m.aabb.max.z,
            diameter: m.diameter,
            fill: m.fill,
            balance: m.balance,
            cost: m.cost,
            queue_len: m.queue_len,
            active: m.active,
        }
    }
}

impl From<&MergeEvent> for Merge {
    fn from(e: &MergeEvent) -> Self {
        Merge {
            step: e.step,
            round: e.round,
            a: e.a,
            b: e.b,
            new: e.new,
            aabb: Aabb {
                min: P3::new(e.min_x, e.min_y, e.min_z),
                max: P3::new(e.max_x, e.max_y, e.max_z),
            },
            diameter: e.diameter,
            fill: e.fill,
            balance: e.balance,
            cost: e.cost,
            queue_len: e.queue_len,
            active: e.active,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use foxglove::Encode;

    fn encode<T: Encode>(m: &T) -> Vec<u8> {
        let mut buf = Vec::new();
        m.encode(&mut buf).expect("encode");
        buf
    }

    #[test]
    fn merge_round_trips_with_distinct_values() {
        // Every field gets a different value, so swapping two fields would be caught.
        let m = Merge {
            step: 7,
            round: 3,
            a: 11,
            b: 13,
            new: 17,
            aabb: Aabb {
                min: P3::new(-1.5, -2.5, -3.5),
                max: P3::new(4.25, 5.25, 6.25),
            },
            diameter: 9.125,
            fill: 0.75,
            balance: 1.0625,
            cost: 6.5,
            queue_len: 1 << 20,
            active: true,
        };
        let bytes = encode(&MergeEvent::from(&m));
        assert_eq!(Merge::from(&MergeEvent::decode(&bytes).unwrap()), m);
        let r = RoundEvent {
            doubling: true,
            round: 2,
            dlimit: 0.5,
            glimit: 0.125,
            active: 5,
            dormant: 6,
            pairs: u64::MAX,
            merges: 9,
        };
        assert_eq!(RoundEvent::decode(&encode(&r)).unwrap(), r);
        let f = FinishEvent {
            root: 4,
            rounds: 2,
            merges: 2,
        };
        assert_eq!(FinishEvent::decode(&encode(&f)).unwrap(), f);
        for kind in [
            PartKind::Chunk { level: 3, keep: 5 },
            PartKind::Component { index: 6 },
            PartKind::Copy {
                of: 2,
                rotation: [0.5, -1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0],
                translation: [9.0, 10.0, -11.0],
            },
            PartKind::Top,
        ] {
            let p = Part {
                id: 4,
                kind,
                bodies: 19,
                first_step: 1 << 30,
            };
            let back = PartEvent::decode(&encode(&PartEvent::from(&p))).unwrap();
            assert_eq!(Part::try_from(&back).unwrap(), p);
        }
        let bad = PartEvent {
            kind: 9,
            ..PartEvent::default()
        };
        assert!(Part::try_from(&bad).is_err());
    }

    #[test]
    fn schema_is_protobuf() {
        let schema = MergeEvent::get_schema().unwrap();
        assert_eq!(schema.name, "mergeevent.MergeEvent");
        assert_eq!(schema.encoding, "protobuf");
        assert_eq!(MergeEvent::get_message_encoding(), "protobuf");
    }

    #[test]
    fn bad_bytes_are_errors() {
        let bytes = encode(&MergeEvent::default());
        assert!(MergeEvent::decode(&bytes[..bytes.len() - 3]).is_err());
        assert!(MergeEvent::decode(&[]).unwrap_err().contains("missing"));
        assert!(MergeEvent::decode(&[0xff; 12]).is_err());
        // A foreign message with the right field numbers but wrong wire types.
        assert!(DormantEvent::decode(&encode(&FinishEvent::default())).is_err());
    }
}
