//! The typed protobuf messages of the `/grouping/*` topics and their decoding.
//!
//! Each message is a flat struct of scalars declared once by `flat_message!`: the macro
//! derives [`foxglove::Encode`] (protobuf schema + encoder; field number = declaration order,
//! starting at 1) and generates the matching decoder from the same field list, so the writer
//! and the reader cannot drift apart. foxglove 0.30 offers no decoder for derived types, and a
//! flat message of varints and doubles needs only the few lines of wire parsing in
//! `wire.rs`; `convert.rs` maps the events to messages and back.

mod convert;
#[cfg(test)]
mod tests;
mod wire;

pub use wire::{WireScalar, wire_fields};

/// Declares a flat message: the struct (deriving [`foxglove::Encode`]) and its `decode`.
macro_rules! flat_message {
    ($(#[$meta:meta])* $name:ident { $($(#[$fmeta:meta])* $field:ident: $ty:ty,)+ }) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, Default, PartialEq, foxglove::Encode)]
        pub struct $name {
            $($(#[$fmeta])* pub $field: $ty,)+
        }

        impl $name {
            /// Decodes a message written by the derived encoder; every field that is not an
            /// `Option` must be present, each with its declared wire type (unknown fields are
            /// ignored).
            pub fn decode(buf: &[u8]) -> Result<Self, String> {
                const FIELDS: &[&str] = &[$(stringify!($field)),+];
                const OPTIONAL: &[bool] = &[$(<$ty as WireScalar>::OPTIONAL),+];
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
                if let Some(missing) =
                    (0..FIELDS.len()).find(|&i| seen & (1 << i) == 0 && !OPTIONAL[i])
                {
                    return Err(format!("field `{}` missing", FIELDS[missing]));
                }
                Ok(out)
            }
        }
    };
}

flat_message! {
    /// One merge of step 4(a), on `/grouping/merge`: every field of [`Merge`](crate::grouping::Merge),
    /// the AABB only where the children's boxes do not give it.
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
        /// AABB lower corner, x. This and the five below are left out when the AABB is the
        /// union of `a`'s and `b`'s (always, in a grouping run; protobuf readers see 0, and
        /// `replay` derives it from the scene's primitives and the earlier merges). Recordings
        /// made before hold them.
        min_x: Option<f64>,
        /// AABB lower corner, y.
        min_y: Option<f64>,
        /// AABB lower corner, z.
        min_z: Option<f64>,
        /// AABB upper corner, x.
        max_x: Option<f64>,
        /// AABB upper corner, y.
        max_y: Option<f64>,
        /// AABB upper corner, z.
        max_z: Option<f64>,
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

flat_message! {
    /// A part of the run (a chunk of the partitioned schedule, a component, a copy, the top,
    /// bodies with identical boxes),
    /// on `/grouping/part`: every field of [`Part`](crate::grouping::Part), its kind flattened (the
    /// scalar fields a kind does not have are 0; the copy's transform is absent).
    PartEvent {
        /// 0-based part index.
        id: u32,
        /// 0 chunk, 1 component, 2 copy, 3 top, 4 identical boxes (twins).
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
        /// Copy: rotation, row-major, 0 0 (this and the eleven below are written for copies
        /// only; other parts leave them out, 98 bytes less each, and protobuf readers see 0).
        r0: Option<f64>,
        /// Rotation 0 1.
        r1: Option<f64>,
        /// Rotation 0 2.
        r2: Option<f64>,
        /// Rotation 1 0.
        r3: Option<f64>,
        /// Rotation 1 1.
        r4: Option<f64>,
        /// Rotation 1 2.
        r5: Option<f64>,
        /// Rotation 2 0.
        r6: Option<f64>,
        /// Rotation 2 1.
        r7: Option<f64>,
        /// Rotation 2 2.
        r8: Option<f64>,
        /// Copy: translation x.
        tx: Option<f64>,
        /// Translation y.
        ty: Option<f64>,
        /// Translation z.
        tz: Option<f64>,
    }
}
